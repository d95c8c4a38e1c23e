/*
 * draw.h: one draw in a located cell (surrogate.kernels.draw.draw_in_cell): the table reads of gather.h and
 * the arithmetic of arithmetic.h in turn, for one particle (table_path.c). Local frame, V⁺ in units of |V⁻|,
 * Ω⁺ in units of |V⁻|/a.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#ifndef RBS_DRAW_H
#define RBS_DRAW_H

#include "arithmetic.h"
#include "gather.h"
#include "locate.h"

/* The chain's folded state of a draw in `cell`, moved in place to the incident α1 when `scaled` and wa > 0
 * (surrogate.kernels.arithmetic.at_alpha1) */
RBS_INLINE void rbs_at_alpha1(const rbs_table *t, const rbs_cell *cell, int scaled, double state[6])
{
    if (scaled && cell->wa > 0.0) {
        rbs_term terms[6];
        double moved[6];
        rbs_alpha1_terms(t, cell->below, cell->wa, cell->drawn, terms);
        rbs_moved(state, terms, moved);
        for (int k = 0; k < 6; k++) state[k] = moved[k];
    }
}

/* Offset in t->clusters of the component u[4] picks in the drawn cell, and its chain variables in `chain`
 * (surrogate.kernels.gather.gather: the draw's table reads) */
RBS_INLINE int64_t rbs_drawn_chain(const rbs_table *t, const rbs_cell *cell, const double *u, double chain[6])
{
    const float *r = t->clusters;
    int64_t row = rbs_component(t, cell->drawn, u[4]);
    double q[6], b[15];
    rbs_quantiles(t, cell->drawn, row, u, q);
    for (int k = 0; k < 15; k++) b[k] = (double)r[row + ROW_SLOPE + k];
    rbs_chain(q, b, chain);
    return row;
}

/* The rebound of the component at `row` with its chain variables `chain` (rbs_drawn_chain; unchanged), in x
 * (surrogate.kernels.arithmetic.arithmetic); the status, RBS_INVALID for a draw rbs_drawn_ok refuses */
RBS_INLINE int rbs_draw_chain(const rbs_table *t, const rbs_cell *cell, int64_t row, const double chain[6],
                              double cos_alpha1, double sin_alpha1, const double *u, int scaled, double x[6])
{
    double state[6] = {chain[0], chain[1], chain[2], chain[3], chain[4], chain[5]};
    double regime = (double)t->clusters[row + ROW_REGIME];
    rbs_at_alpha1(t, cell, scaled, state);
    rbs_velocity(state[0], state[1], state[2], x);
    x[3] = state[3];
    x[4] = state[4];
    x[5] = state[5];
    if (scaled && cell->wv > 0.0) {
        double f_target, f_grid;
        rbs_restitution_factors(t, cell->jv, cell->wv, cell->iv, &f_target, &f_grid);
        rbs_to_speed(regime, f_target, f_grid, cos_alpha1, sin_alpha1, x);
    }
    rbs_mirrored(u[11], x);
    return rbs_drawn_ok(x) ? RBS_OK : RBS_INVALID;
}

/* Whether the draw of uniforms u in the drawn cell is a trapped particle (surrogate.kernels.gather.is_trapped) */
RBS_INLINE int rbs_drawn_trapped(const rbs_table *t, const rbs_cell *cell, const double *u)
{
    return u[3] < t->cells[cell->drawn * CELL_SIZE + CELL_P_TRAPPED];
}

/* The whole draw in a located cell (surrogate.kernels.draw.draw_in_cell): x = (vx, vy, vz, wx, wy, wz) local;
 * returns the status (NaN state when trapped; RBS_INVALID for a draw rbs_drawn_ok refuses). */
RBS_INLINE int rbs_draw_in_cell(const rbs_table *t, const rbs_cell *cell, double cos_alpha1, double sin_alpha1,
                                   const double *u, int scaled, double x[6])
{
    if (rbs_drawn_trapped(t, cell, u)) {
        for (int k = 0; k < 6; k++) x[k] = NAN;
        return RBS_TRAPPED;
    }
    double chain[6];
    int64_t row = rbs_drawn_chain(t, cell, u, chain);
    return rbs_draw_chain(t, cell, row, chain, cos_alpha1, sin_alpha1, u, scaled, x);
}

#endif /* RBS_DRAW_H */
