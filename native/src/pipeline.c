/*
 * pipeline.c: many particles on one thread, the table path (rbs_draw_many; surrogate.kernels.pipeline:
 * table_rebound_many, table_rebound_many_rng).
 *
 * Rows go through a pipeline of blocks of RBS_BLOCK particles, so that one block's table reads are in
 * flight while the blocks before it are computed. This file only schedules: while block k is located
 * (rbs_locate_block, locate.h), block k - 1 has its components resolved (rbs_resolve_block) and block
 * k - 2 is gathered (rbs_gather_block, gather.h) and drawn (rbs_arithmetic_block, arithmetic.h). Each
 * stage's block form does the operations of the per-particle code in the same order, so
 * rbs_draw_many gives the table path's bits row by row. Without uniforms given, rbs_draw_many draws each
 * block's uniforms from RBS_BLOCK xoshiro256+ lanes as it enters (surrogate.kernels.rng.fill_lanes).
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#include <math.h>
#include <string.h>

#include "arithmetic.h"
#include "records.h"
#include "rng_internal.h"
#include "table_arguments.h"

#define STAGES 3
#define B RBS_BLOCK

/* One block: its rows, uniforms (uniform q of particle b at [q][b]) and the records of its stages */
typedef struct block {
    size_t start, m;
    double u[RBS_U_PER_DRAW][B];
    rbs_frames frames;
    rbs_cells cells;
    rbs_gathered gathered;
    rbs_block_results results;
} block;

RBS_HOT static void run_blocks(const rbs_table *t, const rbs_mix *mix, size_t count, const double *V, const double *n,
                               const double *a, const double *u, rbs_rng *rng, int scaled, double *V_out,
                               double *Omega_out, signed char *status)
{
    block blocks[STAGES];
    uint64_t lanes[4 * RBS_BLOCK];
    memset(blocks, 0, sizeof blocks);
    if (rng) rbs_lanes_seed(rng, lanes);
    size_t n_blocks = (count + B - 1) / B;
    for (size_t j = 0; j < n_blocks + STAGES - 1; j++) {
        if (j < n_blocks) {
            block *k = &blocks[j % STAGES];
            k->start = j * B;
            k->m = count - k->start < B ? count - k->start : B;
            if (rng) {
                rbs_lanes_fill(lanes, &k->u[0][0]);
            } else {
                for (int q = 0; q < RBS_U_PER_DRAW; q++)
                    for (size_t b = 0; b < k->m; b++) k->u[q][b] = u[(k->start + b) * RBS_U_PER_DRAW + q];
            }
            rbs_locate_block(t, mix, V, n, a, k->start, k->m, k->u, rng == NULL, &k->frames, &k->cells);
        }
        if (j >= 1 && j <= n_blocks) {
            block *k = &blocks[(j - 1) % STAGES];
            rbs_resolve_block(t, k->u, k->m, &k->frames, &k->cells);
        }
        if (j >= 2) {
            block *k = &blocks[(j - 2) % STAGES];
            rbs_gather_block(t, k->u, k->m, &k->frames, &k->cells, &k->gathered);
            rbs_arithmetic_block(&k->gathered, &k->frames, &k->cells, k->u[11], scaled, &k->results, k->start, k->m,
                                 V_out, Omega_out, status);
        }
    }
}

/* NaN and RBS_INVALID into the outputs a caller gave (any may be NULL) */
static void all_invalid(size_t count, double *V_out, double *Omega_out, signed char *status)
{
    for (size_t i = 0; i < count; i++) {
        for (int k = 0; k < 3; k++) {
            if (V_out) V_out[3 * i + k] = NAN;
            if (Omega_out) Omega_out[3 * i + k] = NAN;
        }
        if (status) status[i] = RBS_INVALID;
    }
}

int rbs_draw_many(const rbs_table *t, const rbs_mix *mix, const rbs_hits *hits, const rbs_options *options,
                  rbs_results *results)
{
    if (!RBS_RECORD_OK(results, rbs_results) || !RBS_RECORD_OK(hits, rbs_hits))
        return RBS_INVALID;     /* no outputs, or no count: nothing written */
    const size_t count = hits->count;
    double *V_out = results->V, *Omega_out = results->Omega;
    signed char *status = results->status;
    int method, interpolation;
    double roughness;
    /* the smooth wall only: a rough wall's facet hits are rbs_rebound's */
    int ok = rbs_options_read(options, &method, &interpolation)
             && (method == RBS_METHOD_AUTO || method == RBS_METHOD_TABLE)
             && rbs_table_arguments_ok(t, mix, interpolation)
             && rbs_options_roughness(options, t->wall_roughness, &roughness) && roughness == 0.0
             && (hits->u || rbs_rng_ok(hits->rng))
             && (count == 0 || (hits->V && hits->n && hits->a && V_out && Omega_out && status));
    if (!ok) {
        all_invalid(count, V_out, Omega_out, status);
        return RBS_INVALID;
    }
    run_blocks(t, mix, count, hits->V, hits->n, hits->a, hits->u, hits->u ? NULL : hits->rng,
               interpolation == RBS_INTERPOLATION_SCALED, V_out, Omega_out, status);
    return RBS_OK;
}
