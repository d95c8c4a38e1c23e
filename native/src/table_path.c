/*
 * table_path.c: one particle by the table's law (surrogate.kernels.table_path: table_rebound, draw_local; the
 * table path of rbs_rebound, and rbs_draw_local):
 * validity, impact frame, grid look-up, cache hints, the draw in its cell, its work on the wall (work.h), back to
 * the global frame.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#include <math.h>

#include "draw.h"
#include "frame.h"
#include "locate.h"
#include "paths.h"
#include "records.h"
#include "table_arguments.h"
#include "work.h"

/* NaN into the outputs a caller gave (any may be NULL) */
static void nan_out(double *x, int count)
{
    if (x)
        for (int k = 0; k < count; k++) x[k] = NAN;
}

/* the inputs the table path checks first (surrogate.kernels.table_path.table_shape_rebound, moves_into_wall) */
RBS_INLINE int inputs_ok(const rbs_table *t, const double *V, const double *n, const double *u, const double *V_out,
                         const double *Omega_out, int interpolation)
{
    return V && n && u && V_out && Omega_out && t
           && (interpolation == RBS_INTERPOLATION_SCALED || interpolation == RBS_INTERPOLATION_STOCHASTIC)
           && rbs_moves_into_wall(V[0], V[1], V[2], n[0], n[1], n[2]);
}

/* The table path of a particle of the table's shape `shape` (a valid index), inputs checked by inputs_ok
 * (surrogate.kernels.table_path.table_shape_rebound) */
RBS_INLINE int hit_in_shape(const rbs_table *t, int64_t shape, const double V[3], const double n[3], double a,
                            const double u[RBS_U_PER_DRAW], int interpolation, double V_out[3], double Omega_out[3],
                            int *shape_out, double wall_work[2])
{
    const double Vi[3] = {V[0], V[1], V[2]}, ni[3] = {n[0], n[1], n[2]};
    const int scaled = interpolation == RBS_INTERPOLATION_SCALED;
    rbs_frame f;
    double x[6];
    rbs_impact_frame(Vi, ni, u[12], &f);
    rbs_cell cell = rbs_cell_in_shape(t, shape, f.alpha1, f.speed, u);
    rbs_hint_draw(t, cell.drawn, u);
    double first;
    int64_t c;
    rbs_hint_work(t, cell.drawn, rbs_first_row(t, cell.drawn, u[4], &first, &c), u);
    int status = rbs_draw_with_work(t, &cell, f.cos_alpha1, f.sin_alpha1, f.speed, u, scaled, x, wall_work);
    int ok = rbs_particle_ok(ni[0], ni[1], ni[2], a) & rbs_uniforms_ok(u, 1);
    status = rbs_to_global(status, ok, x, f.speed, a, f.ex, ni, f.ez, V_out, Omega_out);
    *shape_out = status == RBS_INVALID ? -1 : (int)cell.shape;
    if (status == RBS_INVALID)      /* a refused hit's work is NaN (surrogate.kernels.hit.hit) */
        wall_work[0] = wall_work[1] = NAN;
    return status;
}

RBS_HOT int rbs_table_hit(const rbs_table *t, const rbs_mix *mix, const double V[3], const double n[3], double a,
                          const double u[RBS_U_PER_DRAW], int interpolation, double V_out[3], double Omega_out[3],
                          int *shape, double wall_work[2])
{
    *shape = -1;
    if (!rbs_table_arguments_ok(t, mix, interpolation) || !inputs_ok(t, V, n, u, V_out, Omega_out, interpolation)) {
        nan_out(V_out, 3);
        nan_out(Omega_out, 3);
        nan_out(wall_work, 2);
        return RBS_INVALID;
    }
    return hit_in_shape(t, rbs_mix_shape(rbs_mix_cdf(mix), mix->n_shapes, u[0]), V, n, a, u, interpolation, V_out,
                        Omega_out, shape, wall_work);
}

RBS_HOT int rbs_table_shape_hit(const rbs_table *t, int shape, const double V[3], const double n[3], double a,
                                const double u[RBS_U_PER_DRAW], int interpolation, double V_out[3],
                                double Omega_out[3], double wall_work[2])
{
    int drawn;
    if (!inputs_ok(t, V, n, u, V_out, Omega_out, interpolation) || shape < 0 || shape >= t->n_shapes) {
        nan_out(V_out, 3);
        nan_out(Omega_out, 3);
        nan_out(wall_work, 2);
        return RBS_INVALID;
    }
    return hit_in_shape(t, shape, V, n, a, u, interpolation, V_out, Omega_out, &drawn, wall_work);
}

int rbs_table_rebound(const rbs_table *t, const rbs_mix *mix, const double V[3], const double n[3], double a,
                      const double u[RBS_U_PER_DRAW], int interpolation, double V_out[3], double Omega_out[3])
{
    int shape;
    double wall_work[2];
    return rbs_table_hit(t, mix, V, n, a, u, interpolation, V_out, Omega_out, &shape, wall_work);
}

/* a local incident state a draw takes (surrogate.kernels.table_path.local_ok): α1 in (0, 90] deg, |V⁻| finite
 * and > 0 m/s */
static inline int local_ok(double alpha1_deg, double speed_m_s)
{
    return alpha1_deg > 0.0 && alpha1_deg <= 90.0 && speed_m_s > 0.0 && rbs_finite(speed_m_s);
}

RBS_HOT int rbs_draw_local(const rbs_table *t, const rbs_mix *mix, double alpha1_deg, double speed_m_s,
                           const double u[RBS_U_PER_DRAW], const rbs_options *options, double out[RBS_LOCAL_SIZE])
{
    int method, interpolation;      /* the method is not read */
    if (!u || !out || !rbs_options_read(options, &method, &interpolation)
        || !rbs_table_arguments_ok(t, mix, interpolation) || !local_ok(alpha1_deg, speed_m_s)) {
        nan_out(out, RBS_LOCAL_SIZE);
        return RBS_INVALID;
    }
    rbs_cell cell = rbs_cell_of(t, rbs_mix_cdf(mix), mix->n_shapes, alpha1_deg, speed_m_s, u);
    rbs_hint_draw(t, cell.drawn, u);
    double sin_a1, cos_a1, x[6];
    rbs_sincos(alpha1_deg * RBS_DEG_TO_RAD, &sin_a1, &cos_a1);
    int status = rbs_draw_in_cell(t, &cell, cos_a1, sin_a1, u, interpolation == RBS_INTERPOLATION_SCALED, x);
    static const double wall_normal[3] = {0.0, 1.0, 0.0};
    int ok = rbs_uniforms_ok(u, 1) & (status != RBS_OK || rbs_rebound_ok(x, x + 3, wall_normal));
    status = ok ? status : RBS_INVALID;
    if (status != RBS_OK) {
        nan_out(out, RBS_LOCAL_SIZE);
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
