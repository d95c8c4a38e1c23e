/*
 * many.c: many particles on one thread (surrogate.blocks: rebound_many, rebound_many_rng).
 *
 * Rows go through a pipeline of blocks of RBS_BLOCK particles, so that one block's table reads are in
 * flight while the blocks before it are computed:
 *   1. locate: impact frames, grid cells, cache hints for the component rows the uniforms pick;
 *   2. resolve (a block later): the alias table of each row, hints for the component row and the
 *      residual-shape levels;
 *   3. draw (a block later): the arithmetic of each draw (the per-particle code, so the same bits).
 * rbs_rebound_many_rng draws each block's uniforms from RBS_BLOCK xoshiro256+ lanes as it enters.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#include <math.h>
#include <string.h>

#include "arithmetic.h"
#include "frame.h"
#include "locate.h"
#include "rebound_internal.h"
#include "rng_internal.h"

#define STAGES 3

/* what a row carries from one stage to the next */
typedef struct located {
    rbs_frame frame;
    rbs_cell cell;
    int64_t row;        /* the component row (after stage 2) */
    int valid;
} located;

typedef struct block {
    double u[RBS_BLOCK * RBS_U_PER_DRAW];       /* row-major: uniforms of row b at b · 13 */
    located p[RBS_BLOCK];
    size_t start, m;
} block;

/* stage 1: frames, cells, hints for the rows the uniforms pick */
RBS_INLINE void locate_block(const rbs_table *t, const rbs_mix *mix, const double *V, const double *n, block *blk)
{
    for (size_t b = 0; b < blk->m; b++) {
        size_t i = blk->start + b;
        located *p = &blk->p[b];
        const double *u = blk->u + b * RBS_U_PER_DRAW;
        p->valid = rbs_moves_into_wall(V + 3 * i, n + 3 * i);
        if (!p->valid) continue;
        rbs_impact_frame(V + 3 * i, n + 3 * i, u[12], &p->frame);
        p->cell = rbs_cell_of(t, mix->cdf, mix->n_shapes, p->frame.alpha1, p->frame.speed, u);
        double x;
        int64_t c;
        p->row = rbs_first_row(t, p->cell.drawn, u[4], &x, &c);
        rbs_hint_row(t, p->row);
    }
}

/* stage 2: the components through the alias tables, hints for their rows and levels */
RBS_INLINE void resolve_block(const rbs_table *t, block *blk)
{
    for (size_t b = 0; b < blk->m; b++) {
        located *p = &blk->p[b];
        if (!p->valid) continue;
        const double *u = blk->u + b * RBS_U_PER_DRAW;
        p->row = rbs_component(t, p->cell.drawn, u[4]);
        rbs_hint_row(t, p->row);
        rbs_hint_levels(t, p->cell.drawn, u);
        RBS_PREFETCH(t->cells + p->cell.drawn * CELL_SIZE);
    }
}

/* stage 3: the draws and their outputs */
RBS_INLINE void draw_block(const rbs_table *t, const double *n, const double *a, int scaled, block *blk, double *V_out,
                       double *W_out, signed char *status)
{
    for (size_t b = 0; b < blk->m; b++) {
        size_t i = blk->start + b;
        located *p = &blk->p[b];
        if (!p->valid) {
            for (int k = 0; k < 3; k++) V_out[3 * i + k] = W_out[3 * i + k] = NAN;
            status[i] = RBS_INVALID;
            continue;
        }
        double x[6];
        int st = rbs_draw_in_cell(t, &p->cell, p->frame.cos_alpha1, p->frame.sin_alpha1, blk->u + b * RBS_U_PER_DRAW,
                                  scaled, x);
        rbs_to_global(st, x, p->frame.speed, a[i], p->frame.ex, n + 3 * i, p->frame.ez, V_out + 3 * i, W_out + 3 * i);
        status[i] = (signed char)st;
    }
}

RBS_HOT static void run_blocks(const rbs_table *t, const rbs_mix *mix, size_t count, const double *V, const double *n,
                       const double *a, const double *u, rbs_rng *rng, int interpolation, double *V_out,
                       double *W_out, signed char *status)
{
    if (!rbs_arguments_ok(t, mix, interpolation)) {
        for (size_t i = 0; i < count; i++) {
            for (int k = 0; k < 3; k++) V_out[3 * i + k] = W_out[3 * i + k] = NAN;
            status[i] = RBS_INVALID;
        }
        return;
    }
    const int scaled = interpolation == RBS_SCALED;
    block blocks[STAGES];
    uint64_t lanes[4 * RBS_BLOCK];
    double ub[RBS_BLOCK * RBS_U_PER_DRAW];
    if (rng) rbs_lanes_seed(rng, lanes);
    size_t n_blocks = (count + RBS_BLOCK - 1) / RBS_BLOCK;
    for (size_t k = 0; k < n_blocks + STAGES - 1; k++) {
        if (k < n_blocks) {
            block *blk = &blocks[k % STAGES];
            blk->start = k * RBS_BLOCK;
            blk->m = count - blk->start < RBS_BLOCK ? count - blk->start : RBS_BLOCK;
            if (rng) {
                rbs_lanes_fill(lanes, ub);
                for (size_t b = 0; b < blk->m; b++)
                    for (int q = 0; q < RBS_U_PER_DRAW; q++) blk->u[b * RBS_U_PER_DRAW + q] = ub[q * RBS_BLOCK + b];
            } else {
                memcpy(blk->u, u + blk->start * RBS_U_PER_DRAW, blk->m * RBS_U_PER_DRAW * sizeof(double));
            }
            locate_block(t, mix, V, n, blk);
        }
        if (k >= 1 && k <= n_blocks) resolve_block(t, &blocks[(k - 1) % STAGES]);
        if (k >= 2) draw_block(t, n, a, scaled, &blocks[(k - 2) % STAGES], V_out, W_out, status);
    }
}

void rbs_rebound_many(const rbs_table *t, const rbs_mix *mix, size_t count, const double *V, const double *n,
                      const double *a, const double *u, int interpolation, double *V_out, double *Omega_out,
                      signed char *status)
{
    run_blocks(t, mix, count, V, n, a, u, NULL, interpolation, V_out, Omega_out, status);
}

void rbs_rebound_many_rng(const rbs_table *t, const rbs_mix *mix, size_t count, const double *V, const double *n,
                          const double *a, rbs_rng *rng, int interpolation, double *V_out, double *Omega_out,
                          signed char *status)
{
    if (!rng) {
        run_blocks(t, NULL, count, V, n, a, NULL, NULL, interpolation, V_out, Omega_out, status);
        return;
    }
    run_blocks(t, mix, count, V, n, a, NULL, rng, interpolation, V_out, Omega_out, status);
}
