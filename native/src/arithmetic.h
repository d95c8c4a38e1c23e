/*
 * arithmetic.h: the arithmetic of a draw once its table values are read (surrogate.kernels.draw: _chain,
 * _folded, _moved, _velocity, _to_speed, _mirrored): the conditional chain of the six state variables,
 * the fold into the physical ranges, the move to the incident α1 and |V⁻|, the mirror sign. Local frame,
 * V⁺ in units of |V⁻|, Ω⁺ in units of |V⁻|/a. Same operations, same order, fma() where numba fuses.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#ifndef RBS_ARITHMETIC_H
#define RBS_ARITHMETIC_H

#include "fastmath.h"
#include "gather.h"
#include "locate.h"

/* The state (α2, β2, s, Ω_x, Ω_y, Ω_z) reflected into the range of a rebound: α2 into [0, π], β2 below
 * π/2, s into [0, 1] (surrogate.kernels.draw._folded). */
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
 * s, Ω_z, Ω_x, Ω_y; surrogate.kernels.draw._chain). */
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

/* The folded state moved to the incident α1 (surrogate.kernels.draw._moved), then folded again. */
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

/* A rebound drawn at grid speed V_iv moved to the incident speed V (surrogate.kernels.draw.to_speed): x = (vx,
 * vy, vz, wx, wy, wz) in place; f_target, f_grid = exp(−k V^p) at V and V_iv. */
RBS_INLINE void rbs_to_speed(double regime, double f_target, double f_grid, double cos_alpha1, double sin_alpha1,
                                double x[6])
{
    double a_target = 1.0 - (1.0 - f_target) * sin_alpha1;
    double a_grid = 1.0 - (1.0 - f_grid) * sin_alpha1;
    int few = regime == 0.0;
    double f = few ? (1.0 + a_target) / (1.0 + a_grid) : a_target / a_grid;
    double g = few ? f : 1.0;
    double vx_few = fma(f, x[0] - cos_alpha1, cos_alpha1);
    double vy_few = fabs(fma(f, x[1] + sin_alpha1, -sin_alpha1));
    x[0] = few ? vx_few : x[0];
    x[1] = few ? vy_few : x[1] * f;
    x[2] = g * x[2];
    x[3] = g * x[3];
    x[4] = g * x[4];
    x[5] = g * x[5];
}

/* the mirror symmetry Z → −Z when u < 1/2 */
RBS_INLINE void rbs_mirrored(double u, double x[6])
{
    double mirror = u < 0.5 ? -1.0 : 1.0;
    x[2] = mirror * x[2];
    x[3] = mirror * x[3];
    x[4] = mirror * x[4];
}

/* The whole draw in a located cell (surrogate.kernels.draw.draw_in_cell): x = (vx, vy, vz, wx, wy, wz) local;
 * returns the status (NaN state when trapped). */
RBS_INLINE int rbs_draw_in_cell(const rbs_table *t, const rbs_cell *cell, double cos_alpha1, double sin_alpha1,
                                   const double *u, int scaled, double x[6])
{
    if (u[3] < t->cells[cell->drawn * CELL_SIZE + CELL_P_TRAPPED]) {
        for (int k = 0; k < 6; k++) x[k] = NAN;
        return RBS_TRAPPED;
    }
    const float *r = t->clusters;
    int64_t row = rbs_component(t, cell->drawn, u[4]);
    double q[6], b[15], state[6];
    rbs_quantiles(t, cell->drawn, row, u, q);
    for (int k = 0; k < 15; k++) b[k] = (double)r[row + ROW_SLOPE + k];
    rbs_chain(q, b, state);
    double regime = (double)r[row + ROW_REGIME];
    if (scaled && cell->wa > 0.0) {
        rbs_term terms[6];
        double moved[6];
        rbs_alpha1_terms(t, cell->below, cell->wa, cell->drawn, terms);
        rbs_moved(state, terms, moved);
        for (int k = 0; k < 6; k++) state[k] = moved[k];
    }
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
    return RBS_REBOUNDED;
}

#endif /* RBS_ARITHMETIC_H */
