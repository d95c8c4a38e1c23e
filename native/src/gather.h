/*
 * gather.h: stage 2 of a draw, the table values it reads once located (surrogate.kernels.gather: _quantile,
 * _alpha1_terms, moved_term, restitution_factors), and its block form (rbs_gather_block).
 *
 * A draw reads its component row (located by locate.h), six pairs of residual-shape levels, the cell
 * records of the drawn cell and of its α1 neighbours, and the restitution pieces.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#ifndef RBS_GATHER_H
#define RBS_GATHER_H

#include "fastmath.h"
#include "internal.h"
#include "locate.h"

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

/* (ratio, m_cell, m) of state variable k for the α1 move (surrogate.kernels.gather._term) */
typedef struct rbs_term {
    double ratio, mean_cell, mean;
} rbs_term;

/* (ratio, m_cell, m) of a variable whose mean, sd and 1/sd sit at offsets at_* from a cell record's start in
 * `cells`: the records of the α1 below (lo), above (hi) and the drawn cell (here) (surrogate.kernels.gather.moved_term;
 * the state's cell records and the work's) */
RBS_INLINE rbs_term rbs_moved_term(const double *cells, int64_t lo, int64_t hi, int64_t here, double wa, int at_mean,
                                   int at_sd, int at_inv_sd)
{
    double sd = fma(wa, cells[hi + at_sd], (1.0 - wa) * cells[lo + at_sd]);
    double inv_sd = cells[here + at_inv_sd];
    double mean = fma(wa, cells[hi + at_mean], (1.0 - wa) * cells[lo + at_mean]);
    rbs_term term = {inv_sd > 0.0 ? sd * inv_sd : 1.0, cells[here + at_mean], mean};
    return term;
}

/* The terms that move a state drawn from cell `drawn` to the incident α1 (surrogate.kernels.gather._alpha1_terms):
 * m and σ linear in α1 (weight wa) between cell `below` and the next α1 up; with wa = 0 the cell above
 * is not read. */
RBS_INLINE void rbs_alpha1_terms(const rbs_table *t, int64_t below, double wa, int64_t drawn, rbs_term terms[6])
{
    int64_t lo = below * CELL_SIZE, here = drawn * CELL_SIZE;
    int64_t hi = wa > 0.0 ? (below + t->n_speed) * CELL_SIZE : lo;
    for (int k = 0; k < 6; k++)
        terms[k] = rbs_moved_term(t->cells, lo + k, hi + k, here + k, wa, CELL_MEAN, CELL_SD, CELL_INV_SD);
}

/* exp(−k V^p) at the incident speed (interval jv, weight wv) and at the drawn grid speed iv */
RBS_INLINE void rbs_restitution_factors(const rbs_table *t, int64_t jv, double wv, int64_t iv, double *f_target,
                                           double *f_grid)
{
    *f_target = rbs_restitution_at(t->restitution_pieces, t->n_pieces, jv, wv);
    *f_grid = t->speed_restitution[iv];
}

/* The gathered records of a block of RBS_BLOCK particles (pipeline.c), field-major: particle b at [b]; the
 * restitution piece at the incident speed (its 10 coefficients and the point) is evaluated by the arithmetic */
typedef struct rbs_gathered {
    double trapped[RBS_BLOCK], regime[RBS_BLOCK], piece[10][RBS_BLOCK], piece_x[RBS_BLOCK], f_grid[RBS_BLOCK],
        q[6][RBS_BLOCK], slope[15][RBS_BLOCK], ratio[6][RBS_BLOCK], mean_cell[6][RBS_BLOCK], mean[6][RBS_BLOCK];
} rbs_gathered;

/* Stage 2 for the m particles of a located block (surrogate.kernels.gather.gather_block): the table values of
 * every draw */
RBS_INLINE void rbs_gather_block(const rbs_table *t, const double u[RBS_U_PER_DRAW][RBS_BLOCK], size_t m,
                                 const rbs_frames *f, const rbs_cells *c, rbs_gathered *k)
{
    const float *r = t->clusters;
    for (size_t b = 0; b < m; b++) {
        int64_t drawn = c->drawn[b], row = c->row[b];
        if (f->valid[b] != 0.0) {
            k->trapped[b] = u[3][b] < t->cells[drawn * CELL_SIZE + CELL_P_TRAPPED] ? 1.0 : 0.0;
            k->regime[b] = (double)r[row + ROW_REGIME];
            for (int j = 0; j < 6; j++) k->q[j][b] = rbs_quantile(t, drawn, row, j, u[5 + j][b]);
            for (int j = 0; j < 15; j++) k->slope[j][b] = (double)r[row + ROW_SLOPE + j];
        }
        rbs_term terms[6];
        rbs_alpha1_terms(t, c->below[b], c->wa[b], drawn, terms);
        for (int j = 0; j < 6; j++) {
            k->ratio[j][b] = terms[j].ratio;
            k->mean_cell[j][b] = terms[j].mean_cell;
            k->mean[j][b] = terms[j].mean;
        }
        /* the restitution piece at the incident speed (evaluated in the SIMD loop) and the grid speed's factor */
        double x = c->wv[b] * (double)t->n_pieces;
        int64_t i = rbs_clamp_index(rbs_trunc(x), t->n_pieces - 1);
        k->piece_x[b] = 2.0 * (x - (double)i) - 1.0;
        const double *piece = t->restitution_pieces + (c->jv[b] * t->n_pieces + i) * 10;
        for (int d = 0; d < 10; d++) k->piece[d][b] = piece[d];
        k->f_grid[b] = t->speed_restitution[c->iv[b]];
    }
}

#endif /* RBS_GATHER_H */
