/*
 * work.h: the work of a table draw on the wall (surrogate.kernels.work: work_key, _work_quantile, _root_share,
 * work_variables, trapped_work, drawn_work and draw_with_work; docs/model.md §4.7): W_n and W_t, m²/s² per unit
 * particle mass, drawn jointly with the rebound of the table path (table_path.c).
 *
 * A table of format 4.1 continues each component's chain with two work variables, the rotational energy fraction
 * r = E_Ω⁺/E⁻ and the root of the normal share ν = √(W_n/(W_n + W_t)): each its residual quantile plus slopes on
 * the draw's chain variables (and r). The work is what the drawn rebound's energy leaves, W = E⁻ (1 − s² − r), with
 * W_n = ν² W at the drawn grid speed; between grid points r and ν move with the draw, and between grid speeds W_n
 * and W_t move as one collision's, by (1 − a(V)²)/(1 − a(V_j)²) and (1 + a(V))/(1 + a(V_j)), then each by the
 * least relative change that closes W. Their two residual uniforms are keyed uniforms of the hit's work key, so
 * the work takes nothing of the caller's stream. Same operations, same order, fma() where numba fuses.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#ifndef RBS_WORK_H
#define RBS_WORK_H

#include "draw.h"
#include "rng_internal.h"

#define RBS_WORK_DOMAIN 0xBB67AE8584CAA73Bull     /* the work keys' start (surrogate.kernels.work._WORK_DOMAIN) */

/* loc + scale · S(u) of work variable w of the component whose work row is at `row` of t->work_rows, in cell number
 * `cell` (as rbs_quantile, from the work's own dictionary) */
/* offset in t->work_dictionary of the level of work variable w that u picks in cell number `cell`, and in *dt the
 * interpolation parameter there (surrogate.kernels.work._level_at) */
RBS_INLINE int64_t rbs_work_level(const rbs_table *t, int64_t cell, int w, double u, double *dt)
{
    int64_t levels = t->n_levels - 1;
    double x = u * (double)levels;
    int64_t i = rbs_clamp_index(rbs_trunc(x), levels - 1);
    *dt = x - (double)i;
    return ((cell * N_WORK + w) * t->n_levels + i) * t->n_dictionary;
}

/* cache hints for the work's reads of a draw with uniforms u from the component at offset `row` of t->clusters in
 * cell number `drawn`: its work row and the levels its keyed uniforms pick (surrogate.kernels.work.hint_work) */
RBS_INLINE void rbs_hint_work(const rbs_table *t, int64_t drawn, int64_t row, const double *u)
{
    if (!t->has_work)
        return;
    int64_t at = row / ROW_SIZE * WORK_ROW_SIZE;
    RBS_PREFETCH(t->work_rows + at);
    RBS_PREFETCH(t->work_rows + at + WORK_ROW_SIZE - 1);
    int64_t key = rbs_hit_key(u, RBS_U_PER_DRAW, RBS_WORK_DOMAIN);
    for (int w = 0; w < N_WORK; w++) {
        double dt;
        int64_t level = rbs_work_level(t, drawn, w, rbs_grain_uniform((uint64_t)key, (uint64_t)w), &dt);
        RBS_PREFETCH(t->work_dictionary + level);
        RBS_PREFETCH(t->work_dictionary + level + t->n_dictionary);
    }
}

RBS_INLINE double rbs_work_quantile(const rbs_table *t, int64_t cell, int64_t row, int w, double u)
{
    const float *r = t->work_rows;
    double dt;
    int64_t at = rbs_work_level(t, cell, w, u, &dt) + (int64_t)r[row + WORK_ROW_SHAPE + w];
    double lo = (double)t->work_dictionary[at], hi = (double)t->work_dictionary[at + t->n_dictionary];
    return fma((double)r[row + WORK_ROW_SCALE + w], fma(dt, hi - lo, lo), (double)r[row + WORK_ROW_LOC + w]);
}

/* ν reflected into [0, 1] (the chain's linear shifts can step outside by a hair) */
RBS_INLINE double rbs_root_share(double nu)
{
    nu = fabs(nu);
    return nu > 1.0 ? 2.0 - nu : nu;
}

/* (r, ν) of the component at offset `row` of t->clusters in cell number `cell`, given the draw's chain variables x
 * (chain order) and its work key: the residual quantiles plus the slopes on x (and r), folded (r >= 0, ν in [0, 1]) */
RBS_INLINE void rbs_work_variables(const rbs_table *t, int64_t cell, int64_t row, const double x[N_CHAIN],
                                   int64_t key, double *r_out, double *nu_out)
{
    const float *rows = t->work_rows;
    int64_t at = row / ROW_SIZE * WORK_ROW_SIZE;       /* the component's work row */
    double r = rbs_work_quantile(t, cell, at, 0, rbs_grain_uniform((uint64_t)key, 0));
    double nu = rbs_work_quantile(t, cell, at, 1, rbs_grain_uniform((uint64_t)key, 1));
    for (int j = 0; j < N_CHAIN; j++) {
        r = fma((double)rows[at + WORK_ROW_SLOPE + j], x[j], r);
        nu = fma((double)rows[at + WORK_ROW_SLOPE + N_CHAIN + j], x[j], nu);
    }
    nu = fma((double)rows[at + WORK_ROW_SLOPE + 2 * N_CHAIN], r, nu);
    *r_out = fabs(r);
    *nu_out = rbs_root_share(nu);
}

/* x if x > 0, else 0 */
RBS_INLINE double rbs_positive(double x)
{
    return x > 0.0 ? x : 0.0;
}

/* (W_n, W_t), m²/s², of a trapped draw in cell number `drawn` at |V⁻| = speed m/s: its cell's trapped particles'
 * mean */
RBS_INLINE void rbs_trapped_work(const rbs_table *t, int64_t drawn, double speed, double work[2])
{
    int64_t at = drawn * WORK_CELL_SIZE + WORK_CELL_TRAPPED;
    double energy = 0.5 * speed * speed;
    work[0] = energy * t->work_cells[at];
    work[1] = energy * t->work_cells[at + 1];
}

/* W_n of the pair (W_n, W_t) = (normal, tangential) (≥ 0, not both 0) changed to sum to `total` (≥ 0) by the least
 * relative change of each: the difference split in proportion to their squares; kept in [0, total]
 * (surrogate.kernels.work.closed_normal) */
RBS_INLINE double rbs_closed_normal(double normal, double tangential, double total)
{
    double squares = normal * normal + tangential * tangential;
    double work_n = normal + (total - normal - tangential) * (normal * normal / squares);
    work_n = work_n > 0.0 ? work_n : 0.0;
    return work_n < total ? work_n : total;
}

/* (W_n, W_t), m²/s², into work, of the draw in `cell` with uniforms u from the component at `row` with the chain
 * variables `chain` (rbs_drawn_chain), that returned `status` and the local V⁺ x[0..2] (units of |V⁻|), at sin α1
 * and |V⁻| = speed m/s (surrogate.kernels.work.drawn_work); NaN for a table without the work or a draw neither
 * rebounded nor trapped. `row` and `chain` are read for a rebound only. */
RBS_INLINE void rbs_drawn_work(const rbs_table *t, const rbs_cell *cell, int64_t row, const double chain[6], int status,
                               const double x[3], double sin_alpha1, double speed, const double *u, int scaled,
                               double work[2])
{
    work[0] = work[1] = NAN;
    if (!t->has_work || (status != RBS_OK && status != RBS_TRAPPED))
        return;
    if (status == RBS_TRAPPED) {
        rbs_trapped_work(t, cell->drawn, speed, work);
        return;
    }
    const float *c = t->clusters;
    double state[6] = {chain[0], chain[1], chain[2], chain[3], chain[4], chain[5]}, r, nu;
    const double ordered[N_CHAIN] = {state[0], state[1], state[2], state[5], state[3], state[4]};
    rbs_work_variables(t, cell->drawn, row, ordered, rbs_hit_key(u, RBS_U_PER_DRAW, RBS_WORK_DOMAIN), &r, &nu);
    if (scaled && cell->wa > 0.0) {
        int64_t lo = cell->below * WORK_CELL_SIZE, hi = (cell->below + t->n_speed) * WORK_CELL_SIZE;
        int64_t here = cell->drawn * WORK_CELL_SIZE;
        rbs_term r_term = rbs_moved_term(t->work_cells, lo, hi, here, cell->wa, WORK_CELL_MEAN, WORK_CELL_SD,
                                         WORK_CELL_INV_SD);
        rbs_term nu_term = rbs_moved_term(t->work_cells, lo + 1, hi + 1, here + 1, cell->wa, WORK_CELL_MEAN,
                                           WORK_CELL_SD, WORK_CELL_INV_SD);
        r = fabs(rbs_shifted(r, r_term));
        nu = rbs_root_share(rbs_shifted(nu, nu_term));
    }
    double s2 = rbs_speed_ratio_squared(x);
    double normal = nu * nu, tangential = (1.0 - nu) * (1.0 + nu);     /* the shares of W at the grid speed */
    double energy = 0.5 * speed * speed;
    if (scaled && cell->wv > 0.0) {
        /* between grid speeds each part moves as one collision's, W_n ∝ 1 − a² and W_t ∝ λ ∝ 1 + a (units of E⁻),
         * then both change by the least relative amount that closes the moved rebound's energy */
        rbs_at_alpha1(t, cell, scaled, state);
        double s0 = state[2];                                           /* s at the drawn grid speed */
        double grid_total = rbs_positive(1.0 - s0 * s0 - r);
        double f_target, f_grid, f, g, a_target, a_grid;
        rbs_restitution_factors(t, cell->jv, cell->wv, cell->iv, &f_target, &f_grid);
        rbs_speed_factors((double)c[row + ROW_REGIME], f_target, f_grid, sin_alpha1, &f, &g);
        rbs_restitutions(f_target, f_grid, sin_alpha1, &a_target, &a_grid);
        r *= g * g;
        double total = rbs_positive(1.0 - s2 - r);
        double moved_n = normal * grid_total
                         * ((1.0 - a_target) * (1.0 + a_target) / ((1.0 - a_grid) * (1.0 + a_grid)));
        double moved_t = tangential * grid_total * ((1.0 + a_target) / (1.0 + a_grid));
        if (moved_n * moved_n + moved_t * moved_t > 0.0) {
            double work_n = rbs_closed_normal(moved_n, moved_t, total);
            work[0] = energy * work_n;
            work[1] = energy * (total - work_n);
            return;
        }
    }
    double total = rbs_positive(1.0 - s2 - r);
    double weights = normal + tangential;
    if (!(weights > 0.0)) {
        work[0] = work[1] = 0.0;
        return;
    }
    work[0] = energy * (total * normal / weights);
    work[1] = energy * (total * tangential / weights);
}

/* The draw in a located cell (rbs_draw_in_cell: the status, x) and its work on the wall (rbs_drawn_work, into
 * work) from one read of its component and chain (surrogate.kernels.work.draw_with_work), at sin α1, cos α1 and
 * |V⁻| = speed m/s */
RBS_INLINE int rbs_draw_with_work(const rbs_table *t, const rbs_cell *cell, double cos_alpha1, double sin_alpha1,
                                  double speed, const double *u, int scaled, double x[6], double work[2])
{
    if (rbs_drawn_trapped(t, cell, u)) {
        for (int k = 0; k < 6; k++) x[k] = NAN;
        work[0] = work[1] = NAN;
        if (t->has_work)
            rbs_trapped_work(t, cell->drawn, speed, work);
        return RBS_TRAPPED;
    }
    double chain[6];
    int64_t row = rbs_drawn_chain(t, cell, u, chain);
    int status = rbs_draw_chain(t, cell, row, chain, cos_alpha1, sin_alpha1, u, scaled, x);
    rbs_drawn_work(t, cell, row, chain, status, x, sin_alpha1, speed, u, scaled, work);
    return status;
}

#endif /* RBS_WORK_H */
