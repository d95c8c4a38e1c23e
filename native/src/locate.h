/*
 * locate.h: stage 1 of a draw, where it reads (surrogate.kernels.locate): the grid look-up (rbs_locate, as
 * grid_interval), the cell (rbs_cell_of, as locate), the component row through Walker's alias table
 * (rbs_component, as component), the cache hints that put the reads in flight together (rbs_hint_draw, as
 * hint), and the block forms of the pipeline (rbs_locate_block, rbs_resolve_block).
 *
 * An axis record (layout.c) holds a uniform auxiliary grid whose points store the index of the grid
 * interval holding them; a query reads that index and corrects it by at most one step: O(1), no search.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#ifndef RBS_LOCATE_H
#define RBS_LOCATE_H

#include "fastmath.h"
#include "frame.h"
#include "internal.h"

/* read hint, level-2 cache (prefetcht1), as surrogate.kernels.memory.prefetch */
#if defined(__GNUC__)
#define RBS_PREFETCH(address) __builtin_prefetch((const void *)(address), 0, 2)
#else
#define RBS_PREFETCH(address) ((void)(address))
#endif

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

/* The cell a draw reads (surrogate.kernels.locate.locate): shape from u[0] and the mix, grid intervals and weights,
 * the neighbour (ia, iv) drawn with those weights from u[1], u[2] (stochastic interpolation). */
typedef struct rbs_cell {
    int64_t shape;      /* the table shape: drawn from the mix, or given */
    int64_t drawn;      /* number of cell (shape, ia, iv) */
    int64_t below;      /* number of cell (shape, ja, iv): the lower α1 neighbour at the drawn speed */
    int64_t jv, iv;     /* speed interval, drawn speed index */
    double wa, wv;      /* weights of the upper α1 and speed neighbours */
} rbs_cell;

/* the shape drawn from the mix: the first k with u0 < cdf[k] (surrogate.kernels.locate.mix_shape) */
RBS_INLINE int64_t rbs_mix_shape(const double *cdf, int n_shapes, double u0)
{
    int64_t shape = 0;
    for (int k = 0; k < n_shapes - 1; k++) shape += (int64_t)(u0 >= cdf[k]);
    return shape;
}

/* The cell of a draw of the table's shape `shape` (surrogate.kernels.locate.locate_in_shape; u[0] not read) */
RBS_INLINE rbs_cell rbs_cell_in_shape(const rbs_table *t, int64_t shape, double alpha1, double speed, const double *u)
{
    rbs_cell c;
    int64_t ja;
    c.shape = shape;
    rbs_locate(t->alpha1_axis, (int64_t)t->alpha1_axis_len, t->n_alpha1, alpha1, &ja, &c.wa);
    rbs_locate(t->speed_axis, (int64_t)t->speed_axis_len, t->n_speed, speed, &c.jv, &c.wv);
    int64_t ia = ja + (int64_t)(u[1] < c.wa);
    c.iv = c.jv + (int64_t)(u[2] < c.wv);
    c.below = (shape * t->n_alpha1 + ja) * t->n_speed + c.iv;
    c.drawn = c.below + (ia - ja) * t->n_speed;
    return c;
}

RBS_INLINE rbs_cell rbs_cell_of(const rbs_table *t, const double *cdf, int n_shapes, double alpha1, double speed,
                                const double *u)
{
    return rbs_cell_in_shape(t, rbs_mix_shape(cdf, n_shapes, u[0]), alpha1, speed, u);
}

/* offset of component c's row in cell number `cell` */
RBS_INLINE int64_t rbs_row(const rbs_table *t, int64_t cell, int64_t c)
{
    return (cell * t->n_clusters + c) * ROW_SIZE;
}

/* offset of level i of chain variable k's residual shapes in cell number `cell` */
RBS_INLINE int64_t rbs_level(const rbs_table *t, int64_t cell, int64_t k, int64_t i)
{
    return ((cell * 6 + k) * t->n_levels + i) * t->n_dictionary;
}

/* the row u4 picks before the alias table: t = u4 · C, c = ⌊t⌋ */
RBS_INLINE int64_t rbs_first_row(const rbs_table *t, int64_t cell, double u4, double *t_out, int64_t *c_out)
{
    double x = u4 * (double)t->n_clusters;
    int64_t c = rbs_clamp_index(rbs_trunc(x), t->n_clusters - 1);
    *t_out = x;
    *c_out = c;
    return rbs_row(t, cell, c);
}

/* the offset of the component row u4 draws in `cell`, through Walker's alias table */
RBS_INLINE int64_t rbs_component(const rbs_table *t, int64_t cell, double u4)
{
    double x;
    int64_t c;
    int64_t row = rbs_first_row(t, cell, u4, &x, &c);
    int64_t alias = (int64_t)t->clusters[row + ROW_ALIAS];
    c = x - (double)c >= (double)t->clusters[row + ROW_ALIAS_PROB] ? alias : c;
    return rbs_row(t, cell, c);
}

/* cache hints for a component row: its three cache lines */
RBS_INLINE void rbs_hint_row(const rbs_table *t, int64_t row)
{
    for (int j = 0; j < ROW_SIZE; j += 16) RBS_PREFETCH(t->clusters + row + j);
}

/* cache hints for the two residual-shape levels of each chain variable that u[5..10] pick */
RBS_INLINE void rbs_hint_levels(const rbs_table *t, int64_t drawn, const double *u)
{
    int64_t levels = t->n_levels - 1;
    for (int k = 0; k < 6; k++) {
        int64_t i = rbs_clamp_index(rbs_trunc(u[5 + k] * (double)levels), levels - 1);
        int64_t level = rbs_level(t, drawn, k, i);
        RBS_PREFETCH(t->dictionary + level);
        RBS_PREFETCH(t->dictionary + level + t->n_dictionary);
    }
}

/* the hints of a draw in `drawn`: the row u[4] picks (before its alias) and the levels */
RBS_INLINE void rbs_hint_draw(const rbs_table *t, int64_t drawn, const double *u)
{
    double x;
    int64_t c;
    rbs_hint_row(t, rbs_first_row(t, drawn, u[4], &x, &c));
    rbs_hint_levels(t, drawn, u);
}

/* The cell records of a block of RBS_BLOCK particles (pipeline.c), field-major: particle b at [b]; row is the
 * component row (before the alias table after rbs_locate_block, after it after rbs_resolve_block) */
typedef struct rbs_cells {
    int64_t drawn[RBS_BLOCK], below[RBS_BLOCK], jv[RBS_BLOCK], iv[RBS_BLOCK], row[RBS_BLOCK];
    double wa[RBS_BLOCK], wv[RBS_BLOCK];
} rbs_cells;

/* Stage 1 for the m rows from `start` (surrogate.kernels.locate.locate_block; uniforms u, checked if `given`):
 * their frame records, their cells
 * and the hints for the rows their uniforms u pick (invalid rows: cell 0, weights 0, so the later loops read
 * the table in range; their results are discarded) */
RBS_INLINE void rbs_locate_block(const rbs_table *t, const rbs_mix *mix, const double *V, const double *n,
                                 const double *a, size_t start, size_t m, const double u[RBS_U_PER_DRAW][RBS_BLOCK],
                                 int given, rbs_frames *f, rbs_cells *k)
{
    rbs_frame_block(V, n, a, start, m, u, given, f);
    for (size_t b = 0; b < m; b++) {
        if (f->valid[b] == 0.0) {
            k->drawn[b] = k->below[b] = k->jv[b] = k->iv[b] = k->row[b] = 0;
            k->wa[b] = k->wv[b] = 0.0;
            continue;
        }
        double ub[3] = {u[0][b], u[1][b], u[2][b]};
        rbs_cell c = rbs_cell_of(t, rbs_mix_cdf(mix), mix->n_shapes, f->alpha1[b], f->speed[b], ub);
        double x;
        int64_t first;
        k->drawn[b] = c.drawn;
        k->below[b] = c.below;
        k->jv[b] = c.jv;
        k->iv[b] = c.iv;
        k->wa[b] = c.wa;
        k->wv[b] = c.wv;
        k->row[b] = rbs_first_row(t, c.drawn, u[4][b], &x, &first);
        rbs_hint_row(t, k->row[b]);
    }
}

/* Stage 1, a block later (surrogate.kernels.locate.resolve_block): the components (alias tables), hints for
 * their rows, levels and cell records */
RBS_INLINE void rbs_resolve_block(const rbs_table *t, const double u[RBS_U_PER_DRAW][RBS_BLOCK], size_t m,
                                  const rbs_frames *f, rbs_cells *k)
{
    for (size_t b = 0; b < m; b++) {
        if (f->valid[b] == 0.0) continue;
        int64_t drawn = k->drawn[b];
        k->row[b] = rbs_component(t, drawn, u[4][b]);
        rbs_hint_row(t, k->row[b]);
        int64_t levels = t->n_levels - 1;
        for (int j = 0; j < 6; j++) {
            int64_t i = rbs_clamp_index(rbs_trunc(u[5 + j][b] * (double)levels), levels - 1);
            int64_t level = rbs_level(t, drawn, j, i);
            RBS_PREFETCH(t->dictionary + level);
            RBS_PREFETCH(t->dictionary + level + t->n_dictionary);
        }
        RBS_PREFETCH(t->cells + drawn * CELL_SIZE);
    }
}

#endif /* RBS_LOCATE_H */
