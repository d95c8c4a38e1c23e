/*
 * many.c: many particles on one thread (surrogate.kernels.pipeline: rebound_many, rebound_many_rng).
 *
 * Rows go through a pipeline of blocks of RBS_BLOCK particles, so that one block's table reads are in
 * flight while the blocks before it are computed (as surrogate/blocks.py does):
 *   1. locate: the impact frames (a branch-free loop over the block), the grid cells, cache hints for the
 *      component rows the uniforms pick;
 *   2. resolve (a block later): the alias table of each row, hints for the component row, the residual
 *      levels and the cell record;
 *   3. draw (a block later): the table values of every draw gathered into field-major scratch arrays,
 *      then the arithmetic as one branch-free loop over the block (SIMD where the compiler can), then the
 *      outputs.
 * Every step does the operations of the per-particle code in the same order, so rbs_rebound_many gives
 * rbs_rebound's bits row by row. rbs_rebound_many_rng draws each block's uniforms from RBS_BLOCK
 * xoshiro256+ lanes as it enters (surrogate.kernels.rng.fill_lanes).
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
#define B RBS_BLOCK

/* One block's scratch, field-major (field f of particle b at [f][b]): a compile-time stride for SIMD. */
typedef struct block {
    size_t start, m;
    double u[RBS_U_PER_DRAW][B];
    /* frame (step 1) */
    double Vin[3][B], valid[B], ok[B], normal[B], alpha1[B], speed[B], cos_a1[B], sin_a1[B], a[B], ex[3][B], ez[3][B], n[3][B];
    /* cell (steps 1, 2) */
    int64_t drawn[B], below[B], jv[B], iv[B], row[B];
    double wa[B], wv[B];
    /* gathered (step 3) */
    double trapped[B], regime[B], piece[10][B], piece_x[B], f_grid[B], q[6][B], slope[15][B], ratio[6][B], mean_cell[6][B],
        mean[6][B];
    /* results */
    double status[B], V[3][B], W[3][B];
} block;

/* step 1a: validity (rbs_moves_into_wall; `ok`: rbs_particle_ok and the uniforms' check) and impact frame of every row (rbs_impact_frame, the same
 * operations), on the block's rows copied field-major (rows past the end: V = 0, n = e_y, a = 1, invalid) */
RBS_INLINE void frames(const double *V, const double *n, const double *a, block *k)
{
    for (size_t b = 0; b < B; b++) {
        size_t i = k->start + b;
        int here = b < k->m;
        for (int j = 0; j < 3; j++) {
            k->Vin[j][b] = here ? V[3 * i + j] : 0.0;
            k->n[j][b] = here ? n[3 * i + j] : (j == 1 ? 1.0 : 0.0);
        }
        k->a[b] = here ? a[i] : 1.0;
    }
    for (size_t b = 0; b < B; b++) {       /* branch-free: SIMD across the block */
        double V0 = k->Vin[0][b], V1 = k->Vin[1][b], V2 = k->Vin[2][b];
        double n0 = k->n[0][b], n1 = k->n[1][b], n2 = k->n[2][b];
        double vn = rbs_dot(V0, V1, V2, n0, n1, n2);
        k->valid[b] = rbs_moves_into_wall(V0, V1, V2, n0, n1, n2) ? 1.0 : 0.0;
        k->ok[b] = rbs_particle_ok(n0, n1, n2, k->a[b]) & (k->ok[b] != 0.0) ? 1.0 : 0.0;
        double tx = fma(-vn, n0, V0), ty = fma(-vn, n1, V1), tz = fma(-vn, n2, V2);
        double vt = sqrt(fma(tx, tx, fma(ty, ty, tz * tz)));
        double speed = sqrt(fma(vn, vn, vt * vt));
        double inv = 1.0 / vt;
        k->ex[0][b] = tx * inv;
        k->ex[1][b] = ty * inv;
        k->ex[2][b] = tz * inv;
        k->normal[b] = vt > 1e-12 * speed ? 0.0 : 1.0;
        double inv_speed = 1.0 / speed;
        k->alpha1[b] = rbs_atan2_q1_simd(-vn, vt) * RBS_RAD_TO_DEG;
        k->speed[b] = speed;
        k->cos_a1[b] = vt * inv_speed;
        k->sin_a1[b] = -vn * inv_speed;
    }
    for (size_t b = 0; b < B; b++) {       /* normal impact (rare): the in-wall direction from u[12] */
        if (k->normal[b] != 0.0) {
            rbs_frame f;
            const double Vi[3] = {k->Vin[0][b], k->Vin[1][b], k->Vin[2][b]};
            const double ni[3] = {k->n[0][b], k->n[1][b], k->n[2][b]};
            rbs_impact_frame(Vi, ni, k->u[12][b], &f);
            for (int j = 0; j < 3; j++) k->ex[j][b] = f.ex[j];
        }
    }
    for (size_t b = 0; b < B; b++) {
        double ex0 = k->ex[0][b], ex1 = k->ex[1][b], ex2 = k->ex[2][b];
        double n0 = k->n[0][b], n1 = k->n[1][b], n2 = k->n[2][b];
        k->ez[0][b] = ex1 * n2 - ex2 * n1;
        k->ez[1][b] = ex2 * n0 - ex0 * n2;
        k->ez[2][b] = ex0 * n1 - ex1 * n0;
    }
}

/* step 1b: the cells and the hints for the rows the uniforms pick (invalid rows: cell 0, weights 0, so
 * the later loops read the table in range; their results are discarded) */
RBS_INLINE void cells(const rbs_table *t, const rbs_mix *mix, block *k)
{
    for (size_t b = 0; b < k->m; b++) {
        if (k->valid[b] == 0.0) {
            k->drawn[b] = k->below[b] = k->jv[b] = k->iv[b] = k->row[b] = 0;
            k->wa[b] = k->wv[b] = 0.0;
            continue;
        }
        double u[3] = {k->u[0][b], k->u[1][b], k->u[2][b]};
        rbs_cell c = rbs_cell_of(t, mix->cdf, mix->n_shapes, k->alpha1[b], k->speed[b], u);
        double x;
        int64_t first;
        k->drawn[b] = c.drawn;
        k->below[b] = c.below;
        k->jv[b] = c.jv;
        k->iv[b] = c.iv;
        k->wa[b] = c.wa;
        k->wv[b] = c.wv;
        k->row[b] = rbs_first_row(t, c.drawn, k->u[4][b], &x, &first);
        rbs_hint_row(t, k->row[b]);
    }
}

/* step 2: the components (alias tables), hints for their rows, levels and cell records */
RBS_INLINE void resolve(const rbs_table *t, block *k)
{
    for (size_t b = 0; b < k->m; b++) {
        if (k->valid[b] == 0.0) continue;
        int64_t drawn = k->drawn[b];
        k->row[b] = rbs_component(t, drawn, k->u[4][b]);
        rbs_hint_row(t, k->row[b]);
        int64_t levels = t->n_levels - 1;
        for (int j = 0; j < 6; j++) {
            int64_t i = rbs_clamp_index(rbs_trunc(k->u[5 + j][b] * (double)levels), levels - 1);
            int64_t level = rbs_level(t, drawn, j, i);
            RBS_PREFETCH(t->dictionary + level);
            RBS_PREFETCH(t->dictionary + level + t->n_dictionary);
        }
        RBS_PREFETCH(t->cells + drawn * CELL_SIZE);
    }
}

/* step 3a: the table values of every draw */
RBS_INLINE void gather(const rbs_table *t, block *k)
{
    const float *r = t->clusters;
    for (size_t b = 0; b < k->m; b++) {
        int64_t drawn = k->drawn[b], row = k->row[b];
        if (k->valid[b] != 0.0) {
            k->trapped[b] = k->u[3][b] < t->cells[drawn * CELL_SIZE + CELL_P_TRAPPED] ? 1.0 : 0.0;
            k->regime[b] = (double)r[row + ROW_REGIME];
            for (int j = 0; j < 6; j++) k->q[j][b] = rbs_quantile(t, drawn, row, j, k->u[5 + j][b]);
            for (int j = 0; j < 15; j++) k->slope[j][b] = (double)r[row + ROW_SLOPE + j];
        }
        rbs_term terms[6];
        rbs_alpha1_terms(t, k->below[b], k->wa[b], drawn, terms);
        for (int j = 0; j < 6; j++) {
            k->ratio[j][b] = terms[j].ratio;
            k->mean_cell[j][b] = terms[j].mean_cell;
            k->mean[j][b] = terms[j].mean;
        }
        /* the restitution piece at the incident speed (evaluated in the SIMD loop) and the grid speed's factor */
        double x = k->wv[b] * (double)t->n_pieces;
        int64_t i = rbs_clamp_index(rbs_trunc(x), t->n_pieces - 1);
        k->piece_x[b] = 2.0 * (x - (double)i) - 1.0;
        const double *piece = t->restitution_pieces + (k->jv[b] * t->n_pieces + i) * 10;
        for (int d = 0; d < 10; d++) k->piece[d][b] = piece[d];
        k->f_grid[b] = t->speed_restitution[k->iv[b]];
    }
}

/* step 3b: the arithmetic of every draw, branch-free (rbs_draw_in_cell and rbs_to_global with selects) */
RBS_INLINE void arithmetic(block *k, int scaled)
{
    for (size_t b = 0; b < B; b++) {
        double q[6], slope[15], state[6], moved[6], x[6];
        rbs_term terms[6];
        for (int j = 0; j < 6; j++) q[j] = k->q[j][b];
        for (int j = 0; j < 15; j++) slope[j] = k->slope[j][b];
        rbs_chain(q, slope, state);
        for (int j = 0; j < 6; j++) {
            terms[j].ratio = k->ratio[j][b];
            terms[j].mean_cell = k->mean_cell[j][b];
            terms[j].mean = k->mean[j][b];
        }
        rbs_moved(state, terms, moved);
        int move_alpha1 = scaled & (k->wa[b] > 0.0);
        for (int j = 0; j < 6; j++) state[j] = move_alpha1 ? moved[j] : state[j];
        double sb, cb, sa, ca;
        rbs_sincos_simd(state[1], &sb, &cb);
        rbs_sincos_simd(state[0], &sa, &ca);
        double scb = state[2] * cb;
        double local[6] = {scb * ca, scb * sa, state[2] * sb, state[3], state[4], state[5]};
        for (int j = 0; j < 6; j++) x[j] = local[j];
        double px = k->piece_x[b];             /* rbs_restitution_at's Horner steps, unrolled */
        double f_target = fma(k->piece[9][b], px, k->piece[8][b]);
        f_target = fma(f_target, px, k->piece[7][b]);
        f_target = fma(f_target, px, k->piece[6][b]);
        f_target = fma(f_target, px, k->piece[5][b]);
        f_target = fma(f_target, px, k->piece[4][b]);
        f_target = fma(f_target, px, k->piece[3][b]);
        f_target = fma(f_target, px, k->piece[2][b]);
        f_target = fma(f_target, px, k->piece[1][b]);
        f_target = fma(f_target, px, k->piece[0][b]);
        rbs_to_speed(k->regime[b], f_target, k->f_grid[b], k->cos_a1[b], k->sin_a1[b], x);
        int move_speed = scaled & (k->wv[b] > 0.0);
        for (int j = 0; j < 6; j++) x[j] = move_speed ? x[j] : local[j];
        rbs_mirrored(k->u[11][b], x);
        double speed = k->speed[b], w = speed / k->a[b], v[3], o[3], n[3];
        for (int j = 0; j < 3; j++) {
            n[j] = k->n[j][b];
            v[j] = speed * rbs_dot(x[0], x[1], x[2], k->ex[j][b], n[j], k->ez[j][b]);
            o[j] = w * rbs_dot(x[3], x[4], x[5], k->ex[j][b], n[j], k->ez[j][b]);
        }
        /* rbs_to_global's status */
        int ok = k->ok[b] != 0.0, trapped = k->trapped[b] > 0.5;
        int rebounded = ok & (trapped == 0) & rbs_rebound_ok(v, o, n);
        k->status[b] = rebounded ? (double)RBS_REBOUNDED : ok & trapped ? (double)RBS_TRAPPED : (double)RBS_INVALID;
        for (int j = 0; j < 3; j++) {
            k->V[j][b] = rebounded ? v[j] : NAN;
            k->W[j][b] = rebounded ? o[j] : NAN;
        }
    }
}

/* step 3c: the outputs */
RBS_INLINE void store(const block *k, double *V_out, double *Omega_out, signed char *status)
{
    for (size_t b = 0; b < k->m; b++) {
        size_t i = k->start + b;
        int valid = k->valid[b] != 0.0;
        status[i] = valid ? (signed char)k->status[b] : (signed char)RBS_INVALID;
        for (int j = 0; j < 3; j++) {
            V_out[3 * i + j] = valid ? k->V[j][b] : NAN;
            Omega_out[3 * i + j] = valid ? k->W[j][b] : NAN;
        }
    }
}

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
                for (size_t b = 0; b < B; b++) k->ok[b] = 1.0;    /* a lane's uniforms are in [0, 1) */
            } else {
                for (int q = 0; q < RBS_U_PER_DRAW; q++)
                    for (size_t b = 0; b < k->m; b++) k->u[q][b] = u[(k->start + b) * RBS_U_PER_DRAW + q];
                for (size_t b = 0; b < B; b++) k->ok[b] = rbs_uniforms_ok(&k->u[0][b], B) ? 1.0 : 0.0;
            }
            frames(V, n, a, k);
            cells(t, mix, k);
        }
        if (j >= 1 && j <= n_blocks) resolve(t, &blocks[(j - 1) % STAGES]);
        if (j >= 2) {
            block *k = &blocks[(j - 2) % STAGES];
            gather(t, k);
            arithmetic(k, scaled);
            store(k, V_out, Omega_out, status);
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

/* a table, a mix of its shape count, a known interpolation, no NULL array (with count > 0); else every row invalid */
static int arguments(const rbs_table *t, const rbs_mix *mix, int interpolation, size_t count, const double *V,
                     const double *n, const double *a, const void *uniforms, double *V_out, double *Omega_out,
                     signed char *status)
{
    int arrays = count == 0 || (V && n && a && uniforms && V_out && Omega_out && status);
    if (arrays && rbs_arguments_ok(t, mix, interpolation)) return 1;
    all_invalid(count, V_out, Omega_out, status);
    return 0;
}

void rbs_rebound_many(const rbs_table *t, const rbs_mix *mix, size_t count, const double *V, const double *n,
                      const double *a, const double *u, int interpolation, double *V_out, double *Omega_out,
                      signed char *status)
{
    if (arguments(t, mix, interpolation, count, V, n, a, u, V_out, Omega_out, status))
        run_blocks(t, mix, count, V, n, a, u, NULL, interpolation == RBS_SCALED, V_out, Omega_out, status);
}

void rbs_rebound_many_rng(const rbs_table *t, const rbs_mix *mix, size_t count, const double *V, const double *n,
                          const double *a, rbs_rng *rng, int interpolation, double *V_out, double *Omega_out,
                          signed char *status)
{
    if (arguments(t, rbs_rng_ok(rng) ? mix : NULL, interpolation, count, V, n, a, rng, V_out, Omega_out, status))
        run_blocks(t, mix, count, V, n, a, NULL, rng, interpolation == RBS_SCALED, V_out, Omega_out, status);
}
