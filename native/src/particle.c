/*
 * particle.c: one particle (surrogate.kernels.particle: rebound_tuple, draw_local): validity, impact frame,
 * grid look-up, cache hints, the draw in its cell, back to the global frame.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#include <math.h>

#include "draw.h"
#include "frame.h"
#include "locate.h"
#include "rebound_internal.h"

RBS_HOT int rbs_rebound(const rbs_table *t, const rbs_mix *mix, const double V[3], const double n[3], double a,
                const double u[RBS_U_PER_DRAW], int interpolation, double V_out[3], double Omega_out[3])
{
    const double Vi[3] = {V[0], V[1], V[2]}, ni[3] = {n[0], n[1], n[2]};
    if (!rbs_arguments_ok(t, mix, interpolation) || !rbs_moves_into_wall(Vi, ni)) {
        for (int k = 0; k < 3; k++) V_out[k] = Omega_out[k] = NAN;
        return RBS_INVALID;
    }
    rbs_frame f;
    double x[6];
    rbs_impact_frame(Vi, ni, u[12], &f);
    rbs_cell cell = rbs_cell_of(t, mix->cdf, mix->n_shapes, f.alpha1, f.speed, u);
    rbs_hint_draw(t, cell.drawn, u);
    int status = rbs_draw_in_cell(t, &cell, f.cos_alpha1, f.sin_alpha1, u, interpolation == RBS_SCALED, x);
    rbs_to_global(status, x, f.speed, a, f.ex, ni, f.ez, V_out, Omega_out);
    return status;
}

RBS_HOT int rbs_draw_local(const rbs_table *t, const rbs_mix *mix, double alpha1_deg, double speed_m_s,
                   const double u[RBS_U_PER_DRAW], int interpolation, double out[RBS_LOCAL_SIZE])
{
    if (!rbs_arguments_ok(t, mix, interpolation)) {
        for (int k = 0; k < RBS_LOCAL_SIZE; k++) out[k] = NAN;
        return RBS_INVALID;
    }
    rbs_cell cell = rbs_cell_of(t, mix->cdf, mix->n_shapes, alpha1_deg, speed_m_s, u);
    rbs_hint_draw(t, cell.drawn, u);
    double sin_a1, cos_a1, x[6];
    rbs_sincos(alpha1_deg * RBS_DEG_TO_RAD, &sin_a1, &cos_a1);
    int status = rbs_draw_in_cell(t, &cell, cos_a1, sin_a1, u, interpolation == RBS_SCALED, x);
    if (status != RBS_REBOUNDED) {
        for (int k = 0; k < RBS_LOCAL_SIZE; k++) out[k] = NAN;
        return status;
    }
    double s = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
    out[0] = atan2(x[1], x[0]);                 /* libm, as numba's math.atan2 */
    out[1] = s > 0.0 ? asin(x[2] / s) : 0.0;    /* libm, as numba's math.asin */
    out[2] = s;
    out[3] = x[3];
    out[4] = x[4];
    out[5] = x[5];
    return status;
}
