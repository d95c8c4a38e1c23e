/*
 * wall_hit.c: every wall hit answered, spinning or not (surrogate.kernels.wall_hit: rebound_path, rebound,
 * rebound_typed): the path of a hit (the table where its law is valid, the direct model elsewhere) and the rebound
 * along it.
 *
 * A hit consumes RBS_U_PER_DRAW uniforms whatever path answers it, so a stream stays aligned. The table path
 * is rbs_table_rebound with those uniforms; the direct path draws the shape from the mix with u[0] as the
 * table path does and gives the direct model u[1..RBS_U_PER_REBOUND] as its own uniforms.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#include <math.h>

#include "frame.h"
#include "locate.h"
#include "table_arguments.h"

/* NaN into the outputs a caller gave (any may be NULL) */
static void nan_out(double *x)
{
    if (x)
        for (int k = 0; k < 3; k++) x[k] = NAN;
}

/* The path under RBS_AUTO, RBS_INVALID for a bad input (surrogate.kernels.wall_hit._auto_path): the table iff
 * |Ω⁻| a/|V⁻| <= RBS_SPIN_TOLERANCE and α1, |V⁻| lie inside the grid, edges included. α1 and |V⁻| come from
 * the incidence alone, as the table path computes them; the rest of the impact frame is not needed. */
RBS_INLINE int auto_path(const rbs_table *t, const double V[3], const double Omega[3], const double n[3], double a)
{
    rbs_incidence_parts in = rbs_incidence(V, n);
    double alpha1 = rbs_incidence_angle(in.vn, in.vt);
    double spin = a * sqrt(rbs_dot(Omega[0], Omega[1], Omega[2], Omega[0], Omega[1], Omega[2])) / in.speed;
    const double *alpha1_grid = t->alpha1_axis + AXIS_GRID, *speed_grid = t->speed_axis + AXIS_GRID;
    int table = (spin <= RBS_SPIN_TOLERANCE) & (alpha1 >= alpha1_grid[0]) & (alpha1 <= alpha1_grid[t->n_alpha1 - 1])
                & (in.speed >= speed_grid[0]) & (in.speed <= speed_grid[t->n_speed - 1]);
    int valid = (in.vn < 0.0) & rbs_finite(V[0] + V[1] + V[2]) & rbs_particle_ok(n[0], n[1], n[2], a)
                & rbs_finite(Omega[0] + Omega[1] + Omega[2]);
    return valid ? (table ? RBS_PATH_TABLE : RBS_PATH_DIRECT) : RBS_INVALID;
}

/* RBS_HOT: the x86-64-v3 version has fma() as one instruction, as rbs_table_rebound (the same bits either way) */
RBS_HOT int rbs_rebound_path(const rbs_table *t, const double V[3], const double Omega[3], const double n[3], double a,
                             int method)
{
    if (!t || !V || !Omega || !n)
        return RBS_INVALID;
    int path = auto_path(t, V, Omega, n, a);
    if (path == RBS_INVALID || method == RBS_AUTO)
        return path;
    if (method == RBS_TABLE)
        return RBS_PATH_TABLE;
    return method == RBS_DIRECT ? RBS_PATH_DIRECT : RBS_INVALID;
}

RBS_HOT int rbs_rebound(const rbs_table *t, const rbs_mix *mix, const double V[3], const double Omega[3],
                        const double n[3], double a, const double u[RBS_U_PER_DRAW], int method, int interpolation,
                        double V_out[3], double Omega_out[3])
{
    return rbs_rebound_along(t, mix, rbs_rebound_path(t, V, Omega, n, a, method), V, Omega, n, a, u, interpolation,
                             V_out, Omega_out);
}

int rbs_rebound_along(const rbs_table *t, const rbs_mix *mix, int path, const double V[3], const double Omega[3],
                      const double n[3], double a, const double u[RBS_U_PER_DRAW], int interpolation, double V_out[3],
                      double Omega_out[3])
{
    if (path == RBS_INVALID || !u || !V_out || !Omega_out || !rbs_table_arguments_ok(t, mix, interpolation)
        || !rbs_uniforms_ok(u, 1)) {
        nan_out(V_out);
        nan_out(Omega_out);
        return RBS_INVALID;
    }
    if (path == RBS_PATH_TABLE)
        return rbs_table_rebound(t, mix, V, n, a, u, interpolation, V_out, Omega_out);
    /* the table's shape drawn as the table path draws it, then its index in the direct model's shapes */
    int64_t shape = rbs_mix_shape(rbs_mix_cdf(mix), mix->n_shapes, u[0]);
    return rbs_direct_rebound(t, t->model_shape ? t->model_shape[shape] : -1, V, Omega, n, a, u + 1, V_out, Omega_out);
}

int rbs_rebound_rng(const rbs_table *t, const rbs_mix *mix, const double V[3], const double Omega[3], const double n[3],
                    double a, rbs_rng *rng, int method, int interpolation, double V_out[3], double Omega_out[3])
{
    double u[RBS_U_PER_DRAW];
    rbs_rng_fill(rng, u, RBS_U_PER_DRAW);       /* NaN (refused) for a NULL or all-zero rng */
    return rbs_rebound(t, mix, V, Omega, n, a, u, method, interpolation, V_out, Omega_out);
}

/* kept for programs written against 0.x (rebound_scatter.h) */
int rbs_rebound_spin(const rbs_table *t, const rbs_mix *mix, const double V[3], const double Omega[3],
                     const double n[3], double a, rbs_rng *rng, int method, int interpolation, double V_out[3],
                     double Omega_out[3])
{
    return rbs_rebound_rng(t, mix, V, Omega, n, a, rng, method, interpolation, V_out, Omega_out);
}
