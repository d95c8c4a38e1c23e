/*
 * locate.h: the grid look-up of a draw (surrogate.kernels.draw.locate and the cell choice of surrogate.kernels.draw.locate).
 *
 * An axis record (derive.c) holds a uniform auxiliary grid whose points store the index of the grid
 * interval holding them; a query reads that index and corrects it by at most one step: O(1), no search.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#ifndef RBS_LOCATE_H
#define RBS_LOCATE_H

#include "fastmath.h"
#include "internal.h"

/* (j, w): the grid interval [g_j, g_{j+1}] holding x and the weight of g_{j+1}. Outside the grid, the
 * nearest edge with weight 0 or 1; a one-point grid gives (0, 0). */
RBS_INLINE void rbs_locate(const double *axis, int64_t axis_len, int64_t n, double x, int64_t *j_out,
                              double *w_out)
{
    if (n == 1) {
        *j_out = 0;
        *w_out = 0.0;
        return;
    }
    const int64_t inverse = AXIS_GRID + n;      /* where the inverse spacings start */
    const int64_t lookup = inverse + n - 1;     /* where the look-up indices start */
    const int64_t last = axis_len - 1 - lookup;
    /* capped before the conversion: a huge x (or NaN) would convert to INT64_MIN, which the lower clamp
     * sends to the first point, an interior cell for x above the grid */
    double t = (x - axis[AXIS_ORIGIN]) * axis[AXIS_INV_STEP];
    t = t < (double)last ? t : (double)last;
    int64_t k = rbs_trunc(t);
    k = k < 0 ? 0 : k;
    int64_t j = (int64_t)axis[lookup + k];
    j += (int64_t)((x >= axis[AXIS_GRID + j + 1]) & (j < n - 2));   /* one-step correction */
    double w = (x - axis[AXIS_GRID + j]) * axis[inverse + j];
    *j_out = j;
    *w_out = rbs_fmin_py(rbs_fmax_py(w, 0.0), 1.0);
}

/* The cell a draw reads (surrogate.kernels.draw.locate): shape from u[0] and the mix, grid intervals and weights,
 * the neighbour (ia, iv) drawn with those weights from u[1], u[2] (stochastic interpolation). */
typedef struct rbs_cell {
    int64_t drawn;      /* number of cell (shape, ia, iv) */
    int64_t below;      /* number of cell (shape, ja, iv): the lower α1 neighbour at the drawn speed */
    int64_t jv, iv;     /* speed interval, drawn speed index */
    double wa, wv;      /* weights of the upper α1 and speed neighbours */
} rbs_cell;

RBS_INLINE rbs_cell rbs_cell_of(const rbs_table *t, const double *cdf, int n_shapes, double alpha1, double speed,
                                   const double *u)
{
    rbs_cell c;
    int64_t shape = 0, ja;
    for (int k = 0; k < n_shapes - 1; k++) shape += (int64_t)(u[0] >= cdf[k]);
    rbs_locate(t->alpha1_axis, (int64_t)t->alpha1_axis_len, t->n_alpha1, alpha1, &ja, &c.wa);
    rbs_locate(t->speed_axis, (int64_t)t->speed_axis_len, t->n_speed, speed, &c.jv, &c.wv);
    int64_t ia = ja + (int64_t)(u[1] < c.wa);
    c.iv = c.jv + (int64_t)(u[2] < c.wv);
    c.below = (shape * t->n_alpha1 + ja) * t->n_speed + c.iv;
    c.drawn = c.below + (ia - ja) * t->n_speed;
    return c;
}

#endif /* RBS_LOCATE_H */
