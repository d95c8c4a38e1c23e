/*
 * gather.h: the table reads of a draw (surrogate.kernels.draw: _component, _quantile, _alpha1_terms,
 * _restitution_factors) and the cache hints that put them in flight together (_hint_draw).
 *
 * A draw reads a component row (Walker's alias table picks it), six pairs of residual-shape levels,
 * the cell records of the drawn cell and of its α1 neighbours, and the restitution pieces.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#ifndef RBS_GATHER_H
#define RBS_GATHER_H

#include "fastmath.h"
#include "internal.h"

/* read hint, level-2 cache (prefetcht1), as surrogate.kernels.memory.prefetch */
#if defined(__GNUC__)
#define RBS_PREFETCH(address) __builtin_prefetch((const void *)(address), 0, 2)
#else
#define RBS_PREFETCH(address) ((void)(address))
#endif

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

/* loc + scale · S(u) of chain variable k in the component at `row` (linear between levels i, i + 1) */
RBS_INLINE double rbs_quantile(const rbs_table *t, int64_t cell, int64_t row, int k, double u)
{
    const float *r = t->clusters;
    int64_t levels = t->n_levels - 1;
    double x = u * (double)levels;
    int64_t i = rbs_clamp_index(rbs_trunc(x), levels - 1);
    int64_t at = rbs_level(t, cell, k, i) + (int64_t)r[row + ROW_SHAPE + k];
    double lo = (double)t->dictionary[at], hi = (double)t->dictionary[at + t->n_dictionary];
    return fma((double)r[row + ROW_SCALE + k], fma(x - (double)i, hi - lo, lo), (double)r[row + ROW_LOC + k]);
}

/* the six residual quantiles of a draw (u[5..10]) */
RBS_INLINE void rbs_quantiles(const rbs_table *t, int64_t cell, int64_t row, const double *u, double q[6])
{
    for (int k = 0; k < 6; k++) q[k] = rbs_quantile(t, cell, row, k, u[5 + k]);
}

/* (ratio, m_cell, m) of state variable k for the α1 move (surrogate.kernels.draw._term) */
typedef struct rbs_term {
    double ratio, mean_cell, mean;
} rbs_term;

/* The terms that move a state drawn from cell `drawn` to the incident α1 (surrogate.kernels.draw._alpha1_terms):
 * m and σ linear in α1 (weight wa) between cell `below` and the next α1 up; with wa = 0 the cell above
 * is not read. */
RBS_INLINE void rbs_alpha1_terms(const rbs_table *t, int64_t below, double wa, int64_t drawn, rbs_term terms[6])
{
    const double *cells = t->cells;
    int64_t lo = below * CELL_SIZE, here = drawn * CELL_SIZE;
    int64_t hi = wa > 0.0 ? (below + t->n_speed) * CELL_SIZE : lo;
    for (int k = 0; k < 6; k++) {
        double sd = fma(wa, cells[hi + CELL_SD + k], (1.0 - wa) * cells[lo + CELL_SD + k]);
        double inv_sd = cells[here + CELL_INV_SD + k];
        double mean = fma(wa, cells[hi + CELL_MEAN + k], (1.0 - wa) * cells[lo + CELL_MEAN + k]);
        terms[k].ratio = inv_sd > 0.0 ? sd * inv_sd : 1.0;
        terms[k].mean_cell = cells[here + CELL_MEAN + k];
        terms[k].mean = mean;
    }
}

/* exp(−k V^p) at the incident speed (interval jv, weight wv) and at the drawn grid speed iv */
RBS_INLINE void rbs_restitution_factors(const rbs_table *t, int64_t jv, double wv, int64_t iv, double *f_target,
                                           double *f_grid)
{
    *f_target = rbs_restitution_at(t->restitution_pieces, t->n_pieces, jv, wv);
    *f_grid = t->speed_restitution[iv];
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

#endif /* RBS_GATHER_H */
