/*
 * arithmetic.h: stage 3 of a draw, its arithmetic once its table values are read (surrogate.kernels.arithmetic:
 * _chain, _folded, _moved, _velocity, speed_factors, to_speed, speed_ratio_squared, _mirrored): the conditional
 * chain of the six state variables, the fold into the physical ranges, the move to the incident α1 and |V⁻|, the
 * mirror sign; and its block form (rbs_arithmetic_block). Local frame, V⁺ in units of |V⁻|, Ω⁺ in units of |V⁻|/a. Same
 * operations, same order, fma() where numba fuses.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#ifndef RBS_ARITHMETIC_H
#define RBS_ARITHMETIC_H

#include "fastmath.h"
#include "frame.h"
#include "gather.h"

/* The state (α2, β2, s, Ω_x, Ω_y, Ω_z) reflected into the range of a rebound: α2 into [0, π], β2 below
 * π/2, s into [0, 1] (surrogate.kernels.arithmetic._folded). */
RBS_INLINE void rbs_folded(double alpha2, double beta2, double s, double wx, double wy, double wz, double state[6])
{
    alpha2 = fabs(alpha2);
    s = fabs(s);
    state[0] = alpha2 > RBS_PI ? RBS_TWO_PI - alpha2 : alpha2;
    state[1] = beta2 > RBS_HALF_PI ? RBS_PI - beta2 : beta2;
    state[2] = s > 1.0 ? 2.0 - s : s;
    state[3] = wx;
    state[4] = wy;
    state[5] = wz;
}

/* The folded state of one component from its residual quantiles q and slopes b (chain order α2, |β2|,
 * s, Ω_z, Ω_x, Ω_y; surrogate.kernels.arithmetic._chain). */
RBS_INLINE void rbs_chain(const double q[6], const double b[15], double state[6])
{
    double x0 = q[0];
    double x1 = fma(b[0], x0, q[1]);
    double x2 = fma(b[2], x1, fma(b[1], x0, q[2]));
    double x3 = fma(b[5], x2, fma(b[4], x1, fma(b[3], x0, q[3])));
    double x4 = fma(b[9], x3, fma(b[8], x2, fma(b[7], x1, fma(b[6], x0, q[4]))));
    double x5 = fma(b[14], x4, fma(b[13], x3, fma(b[12], x2, fma(b[11], x1, fma(b[10], x0, q[5])))));
    rbs_folded(x0, x1, x2, x4, x5, x3, state);
}

/* m + (x − m_cell) · ratio */
RBS_INLINE double rbs_shifted(double x, rbs_term term)
{
    return fma(x - term.mean_cell, term.ratio, term.mean);
}

/* The folded state moved to the incident α1 (surrogate.kernels.arithmetic._moved), then folded again. */
RBS_INLINE void rbs_moved(const double state[6], const rbs_term terms[6], double out[6])
{
    rbs_folded(rbs_shifted(state[0], terms[0]), state[1] * terms[1].ratio, rbs_shifted(state[2], terms[2]),
               state[3] * terms[3].ratio, state[4] * terms[4].ratio, rbs_shifted(state[5], terms[5]), out);
}

/* V⁺ (local frame, units of |V⁻|) of a rebound at (α2, β2) with speed ratio s */
RBS_INLINE void rbs_velocity(double alpha2, double beta2, double s, double v[3])
{
    double sb, cb, sa, ca;
    rbs_sincos(beta2, &sb, &cb);
    rbs_sincos(alpha2, &sa, &ca);
    double scb = s * cb;
    v[0] = scb * ca;
    v[1] = scb * sa;
    v[2] = s * sb;
}

/* The factors of rbs_to_speed (surrogate.kernels.arithmetic.speed_factors): whether the regime is 0 (returned), the
 * factor *f of V⁺ − V⁻ (regime 0) or of the normal rebound velocity (regime 1), the factor *g of the spin and of
 * V⁺ − V⁻ off the normal. */
/* The wall law's normal restitution a = 1 − (1 − f) sin α1 at the incident and the drawn grid speed, from its factors f
 * there (surrogate.kernels.arithmetic.restitutions) */
RBS_INLINE void rbs_restitutions(double f_target, double f_grid, double sin_alpha1, double *a_target, double *a_grid)
{
    *a_target = 1.0 - (1.0 - f_target) * sin_alpha1;
    *a_grid = 1.0 - (1.0 - f_grid) * sin_alpha1;
}

RBS_INLINE int rbs_speed_factors(double regime, double f_target, double f_grid, double sin_alpha1, double *f, double *g)
{
    double a_target, a_grid;
    rbs_restitutions(f_target, f_grid, sin_alpha1, &a_target, &a_grid);
    int few = regime == 0.0;
    *f = few ? (1.0 + a_target) / (1.0 + a_grid) : a_target / a_grid;
    *g = few ? *f : 1.0;
    return few;
}

/* A rebound drawn at grid speed V_iv moved to the incident speed V (surrogate.kernels.arithmetic.to_speed): x = (vx,
 * vy, vz, wx, wy, wz) in place; f_target, f_grid = exp(−k V^p) at V and V_iv. */
RBS_INLINE void rbs_to_speed(double regime, double f_target, double f_grid, double cos_alpha1, double sin_alpha1,
                                double x[6])
{
    double f, g;
    int few = rbs_speed_factors(regime, f_target, f_grid, sin_alpha1, &f, &g);
    double vx_few = fma(f, x[0] - cos_alpha1, cos_alpha1);
    double vy_few = fabs(fma(f, x[1] + sin_alpha1, -sin_alpha1));
    x[0] = few ? vx_few : x[0];
    x[1] = few ? vy_few : x[1] * f;
    x[2] = g * x[2];
    /* a speed lifted above |V⁻| is folded back, s → 2 − s (surrogate.kernels.arithmetic.to_speed) */
    double s = sqrt(fma(x[0], x[0], fma(x[1], x[1], x[2] * x[2])));
    double shrink = s > 1.0 ? (2.0 - s) / s : 1.0;
    x[0] = x[0] * shrink;
    x[1] = x[1] * shrink;
    x[2] = x[2] * shrink;
    x[3] = g * x[3];
    x[4] = g * x[4];
    x[5] = g * x[5];
}

/* |V⁺|²/|V⁻|² a rebound may reach above 1 (surrogate.kernels.arithmetic.SPEED_TOLERANCE) */
#define RBS_SPEED_TOLERANCE 1e-12

/* s² = |V⁺|²/|V⁻|² of a local-frame V⁺ x[0..2] in units of |V⁻| (surrogate.kernels.arithmetic.speed_ratio_squared) */
RBS_INLINE double rbs_speed_ratio_squared(const double x[3])
{
    return fma(x[0], x[0], fma(x[1], x[1], x[2] * x[2]));
}

/* A drawn x (local frame, units of |V⁻|) that may be reported as a rebound whatever table was loaded: leaving
 * the wall and no faster than it came (surrogate.kernels.arithmetic.drawn_ok). */
RBS_INLINE int rbs_drawn_ok(const double x[6])
{
    return (x[1] > 0.0) & (rbs_speed_ratio_squared(x) <= 1.0 + RBS_SPEED_TOLERANCE);
}

/* the mirror symmetry Z → −Z when u < 1/2 */
RBS_INLINE void rbs_mirrored(double u, double x[6])
{
    double mirror = u < 0.5 ? -1.0 : 1.0;
    x[2] = mirror * x[2];
    x[3] = mirror * x[3];
    x[4] = mirror * x[4];
}

/* The results of a block of RBS_BLOCK particles (pipeline.c), field-major: status, V⁺ (m/s), Ω⁺ (rad/s) */
typedef struct rbs_block_results {
    double status[RBS_BLOCK], V[3][RBS_BLOCK], W[3][RBS_BLOCK];
} rbs_block_results;

/* Stage 3 for a gathered block (surrogate.kernels.arithmetic.arithmetic_block): the arithmetic of every
 * draw, branch-free (rbs_draw_in_cell and rbs_to_global with selects), then the outputs of its m rows from
 * `start`; u11 the mirror uniforms u[11] */
RBS_INLINE void rbs_arithmetic_block(const rbs_gathered *k, const rbs_frames *f, const rbs_cells *c,
                                     const double u11[RBS_BLOCK], int scaled, rbs_block_results *r, size_t start,
                                     size_t m, double *V_out, double *Omega_out, signed char *status)
{
    for (size_t b = 0; b < RBS_BLOCK; b++) {
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
        int move_alpha1 = scaled & (c->wa[b] > 0.0);
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
        rbs_to_speed(k->regime[b], f_target, k->f_grid[b], f->cos_a1[b], f->sin_a1[b], x);
        int move_speed = scaled & (c->wv[b] > 0.0);
        for (int j = 0; j < 6; j++) x[j] = move_speed ? x[j] : local[j];
        rbs_mirrored(u11[b], x);
        double speed = f->speed[b], w = speed / f->a[b], v[3], o[3], n[3];
        for (int j = 0; j < 3; j++) {
            n[j] = f->n[j][b];
            v[j] = speed * rbs_dot(x[0], x[1], x[2], f->ex[j][b], n[j], f->ez[j][b]);
            o[j] = w * rbs_dot(x[3], x[4], x[5], f->ex[j][b], n[j], f->ez[j][b]);
        }
        /* rbs_to_global's status */
        int ok = f->ok[b] != 0.0, trapped = k->trapped[b] > 0.5;
        int rebounded = ok & (trapped == 0) & rbs_drawn_ok(x) & rbs_rebound_ok(v, o, n);
        r->status[b] = rebounded ? (double)RBS_OK : ok & trapped ? (double)RBS_TRAPPED : (double)RBS_INVALID;
        for (int j = 0; j < 3; j++) {
            r->V[j][b] = rebounded ? v[j] : NAN;
            r->W[j][b] = rebounded ? o[j] : NAN;
        }
    }
    for (size_t b = 0; b < m; b++) {
        size_t i = start + b;
        int valid = f->valid[b] != 0.0;
        status[i] = valid ? (signed char)r->status[b] : (signed char)RBS_INVALID;
        for (int j = 0; j < 3; j++) {
            V_out[3 * i + j] = valid ? r->V[j][b] : NAN;
            Omega_out[3 * i + j] = valid ? r->W[j][b] : NAN;
        }
    }
}

#endif /* RBS_ARITHMETIC_H */
