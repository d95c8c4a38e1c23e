/*
 * wall_hit.c: every wall hit answered, spinning or not (surrogate.kernels.wall_hit: rebound_path, rebound,
 * rebound_typed; rbs_rebound, rbs_rebound_path): the path of a hit (the table where its law is valid, the direct
 * model elsewhere) and the rebound along it.
 *
 * A hit consumes RBS_U_PER_DRAW uniforms whatever path answers it, so a stream stays aligned. The table path
 * is rbs_table_hit with those uniforms; the direct path draws the shape from the mix with u[0] as the
 * table path does and gives the direct model u[1..RBS_U_PER_REBOUND] as its own uniforms. A hit of a grain key
 * takes the key's uniforms in the slots the key fixes (rbs_keyed_uniforms).
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#include <math.h>

#include "frame.h"
#include "locate.h"
#include "paths.h"
#include "records.h"
#include "table_arguments.h"

/* NaN into the outputs a caller gave (any may be NULL) */
static void nan_out(double *x)
{
    if (x)
        for (int k = 0; k < 3; k++) x[k] = NAN;
}

/* The path under RBS_METHOD_AUTO, RBS_PATH_NONE for a bad input (surrogate.kernels.wall_hit._auto_path): the table
 * iff |Ω⁻| a/|V⁻| <= RBS_SPIN_TOLERANCE and α1, |V⁻| lie inside the grid, edges included. α1 and |V⁻| come from
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
    return valid ? (table ? RBS_PATH_TABLE : RBS_PATH_DIRECT) : RBS_PATH_NONE;
}

/* The path of a hit under `method` (surrogate.kernels.wall_hit.rebound_path); RBS_PATH_NONE for a bad input or an
 * unknown method */
RBS_INLINE int hit_path(const rbs_table *t, const rbs_hit *hit, int method)
{
    int path = auto_path(t, hit->V, hit->Omega, hit->n, hit->a);
    if (path == RBS_PATH_NONE || method == RBS_METHOD_AUTO)
        return path;
    if (method == RBS_METHOD_TABLE)
        return RBS_PATH_TABLE;
    return method == RBS_METHOD_DIRECT ? RBS_PATH_DIRECT : RBS_PATH_NONE;
}

/* RBS_HOT: the x86-64-v3 version has fma() as one instruction, as the table path (the same bits either way) */
RBS_HOT int rbs_rebound_path(const rbs_table *t, const rbs_hit *hit, const rbs_options *options)
{
    int method, interpolation;
    if (!t || !RBS_RECORD_OK(hit, rbs_hit) || !rbs_options_read(options, &method, &interpolation))
        return RBS_PATH_NONE;
    return hit_path(t, hit, method);
}

RBS_HOT int rbs_rebound(const rbs_table *t, const rbs_mix *mix, const rbs_hit *hit, const rbs_options *options,
                        rbs_result *result)
{
    if (!RBS_RECORD_OK(result, rbs_result)) {
        /* a record too small is refused; its status says so where it reaches that far */
        if (result && RBS_HAS_FIELD(result, rbs_result, status))
            result->status = RBS_INVALID;
        return RBS_INVALID;
    }
    int status = RBS_INVALID, path = RBS_PATH_NONE, shape = -1, n_collisions = -1;
    if (!RBS_RECORD_OK(hit, rbs_hit)) {
        nan_out(result->V);
        nan_out(result->Omega);
    } else {
        double drawn[RBS_U_PER_DRAW], keyed[RBS_U_PER_DRAW];
        const double *u = hit->u;
        if (!u) {
            rbs_rng_fill(hit->rng, drawn, RBS_U_PER_DRAW);      /* NaN (refused) for a NULL or all-zero rng */
            u = drawn;
        }
        int method = RBS_METHOD_AUTO, interpolation = RBS_INTERPOLATION_SCALED;
        if (t && rbs_options_read(options, &method, &interpolation) && hit->grain_key >= RBS_NO_KEY)
            path = hit_path(t, hit, method);
        if (hit->grain_key >= 0 && path != RBS_PATH_NONE) {
            /* surrogate.kernels.wall_hit._keyed_rebound: the uniforms checked before the key's replace some */
            if (rbs_uniforms_ok(u, 1)) {
                rbs_keyed_uniforms(hit->grain_key, u, path == RBS_PATH_DIRECT, keyed);
                u = keyed;
            } else {
                path = RBS_PATH_NONE;
            }
        }
        status = rbs_rebound_along(t, mix, path, hit->V, hit->Omega, hit->n, hit->a, u, interpolation, result->V,
                                   result->Omega, &shape, &n_collisions);
    }
    const int invalid = status == RBS_INVALID;
    result->status = status;
    result->path = invalid ? RBS_PATH_NONE : path;
    result->shape = invalid ? -1 : shape;
    result->n_collisions = invalid ? -1 : n_collisions;
    return status;
}

int rbs_rebound_along(const rbs_table *t, const rbs_mix *mix, int path, const double V[3], const double Omega[3],
                      const double n[3], double a, const double u[RBS_U_PER_DRAW], int interpolation, double V_out[3],
                      double Omega_out[3], int *shape, int *n_collisions)
{
    *shape = -1;
    *n_collisions = -1;
    if (path == RBS_PATH_NONE || !u || !V_out || !Omega_out || !rbs_table_arguments_ok(t, mix, interpolation)
        || !rbs_uniforms_ok(u, 1)) {
        nan_out(V_out);
        nan_out(Omega_out);
        return RBS_INVALID;
    }
    if (path == RBS_PATH_TABLE)
        return rbs_table_hit(t, mix, V, n, a, u, interpolation, V_out, Omega_out, shape);
    /* the table's shape drawn as the table path draws it, then its index in the direct model's shapes */
    int64_t drawn = rbs_mix_shape(rbs_mix_cdf(mix), mix->n_shapes, u[0]);
    *shape = (int)drawn;
    return rbs_direct_hit(t, t->model_shape[drawn], V, Omega, n, a, u + 1, V_out, Omega_out,
                          n_collisions);
}
