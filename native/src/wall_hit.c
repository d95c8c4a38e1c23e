/*
 * wall_hit.c: every wall hit answered, spinning or not (surrogate.kernels.wall_hit: rebound_path, rebound,
 * rebound_typed; rbs_rebound, rbs_rebound_path): the path of a hit (the table where its law is valid, the direct
 * model elsewhere) and the rebound along it.
 *
 * A hit consumes RBS_U_PER_DRAW uniforms whatever path answers it, so a stream stays aligned. The table path
 * is rbs_table_hit with those uniforms; the direct path draws the shape from the mix with u[0] as the
 * table path does and gives the direct model u[1..RBS_U_PER_REBOUND] as its own uniforms. A hit of a grain key
 * takes the key's uniforms in the slots the key fixes (rbs_keyed_uniforms). On a rough wall (roughness > 0) the hit
 * is a chain of facet hits (rough_rebound; surrogate.kernels.wall_hit.rough_rebound), each along its own path.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#include <math.h>
#include <string.h>

#include "facet.h"
#include "frame.h"
#include "locate.h"
#include "paths.h"
#include "records.h"
#include "rng_internal.h"
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
RBS_INLINE int path_of(const rbs_table *t, const double V[3], const double Omega[3], const double n[3], double a,
                       int method)
{
    int path = auto_path(t, V, Omega, n, a);
    if (path == RBS_PATH_NONE || method == RBS_METHOD_AUTO)
        return path;
    if (method == RBS_METHOD_TABLE)
        return RBS_PATH_TABLE;
    return method == RBS_METHOD_DIRECT ? RBS_PATH_DIRECT : RBS_PATH_NONE;
}

RBS_INLINE int hit_path(const rbs_table *t, const rbs_hit *hit, int method)
{
    return path_of(t, hit->V, hit->Omega, hit->n, hit->a, method);
}

/* RBS_HOT: the x86-64-v3 version has fma() as one instruction, as the table path (the same bits either way) */
RBS_HOT int rbs_rebound_path(const rbs_table *t, const rbs_hit *hit, const rbs_options *options)
{
    int method, interpolation;
    double roughness;
    if (!t || !RBS_RECORD_OK(hit, rbs_hit) || !rbs_options_read(options, &method, &interpolation)
        || !rbs_options_roughness(options, t->wall_roughness, &roughness))
        return RBS_PATH_NONE;
    return hit_path(t, hit, method);
}

/* What a rough hit gives (the fields of rbs_result but its size, status and vectors) */
typedef struct rough_out {
    int path, shape, n_collisions, wall_hits;
    double wall_work[2];
} rough_out;

/* A facet hit of the table's shape `shape` along `path` (surrogate.kernels.wall_hit._shape_rebound; u[0] unused) */
static int shape_rebound(const rbs_table *t, int shape, int path, const double V[3], const double Omega[3],
                         const double n[3], double a, const double u[RBS_U_PER_DRAW], int interpolation,
                         double V_out[3], double Omega_out[3], int *n_collisions, double wall_work[2])
{
    *n_collisions = -1;
    wall_work[0] = wall_work[1] = NAN;
    if (path == RBS_PATH_TABLE)
        return rbs_table_shape_hit(t, shape, V, n, a, u, interpolation, V_out, Omega_out, wall_work);
    if (path == RBS_PATH_DIRECT && rbs_uniforms_ok(u, 1))
        return rbs_direct_hit(t, t->model_shape[shape], V, Omega, n, a, u + 1, V_out, Omega_out, n_collisions,
                              wall_work);
    nan_out(V_out);
    nan_out(Omega_out);
    return RBS_INVALID;
}

/* One hit on a rough wall of roughness Δγ = `roughness` degrees (surrogate.kernels.wall_hit.rough_rebound with the
 * shape from the mix): its status, V⁺ and Ω⁺ into V_out and Omega_out (NaN unless rebounded), the rest into *out (the
 * wall work summed over the facet hits in their order from 0, NaN once a table of format 4.0 answered one). `key` the
 * grain key or RBS_NO_KEY, u the hit's uniforms (not keyed). */
static int rough_rebound(const rbs_table *t, const rbs_mix *mix, int64_t key, const double V_in[3],
                         const double Omega_in[3], const double n[3], double a, const double u[RBS_U_PER_DRAW],
                         int method, int interpolation, double roughness, double V_out[3], double Omega_out[3],
                         rough_out *out)
{
    nan_out(V_out);
    nan_out(Omega_out);
    int path = path_of(t, V_in, Omega_in, n, a, method);
    if (path == RBS_PATH_NONE || key < RBS_NO_KEY || !rbs_uniforms_ok(u, 1) || !(roughness > 0.0)
        || !(roughness <= RBS_MAX_ROUGHNESS_DEG) || !rbs_table_arguments_ok(t, mix, interpolation))
        return RBS_INVALID;
    const double u0 = key >= 0 ? rbs_grain_uniform((uint64_t)key, 0) : u[0];     /* grain.c's SLOT_SHAPE */
    const int shape = (int)rbs_mix_shape(rbs_mix_cdf(mix), mix->n_shapes, u0);
    const int64_t facets = rbs_facet_key(u);
    int64_t slot = 0;
    double V[3] = {V_in[0], V_in[1], V_in[2]}, W[3] = {Omega_in[0], Omega_in[1], Omega_in[2]};
    double facet_u[RBS_U_PER_DRAW], keyed[RBS_U_PER_DRAW], Vn[3], Wn[3];
    memcpy(facet_u, u, sizeof facet_u);
    out->shape = shape;
    out->n_collisions = -1;
    out->wall_work[0] = out->wall_work[1] = 0.0;
    for (int wall_hits = 1; wall_hits <= RBS_MAX_WALL_HITS; wall_hits++) {
        double facet[3];
        out->wall_hits = wall_hits;
        if (!rbs_facet_normal(V, n, roughness, facets, &slot, facet)) {
            out->path = path;
            out->n_collisions = -1;
            return RBS_FAILED;
        }
        path = path_of(t, V, W, facet, a, method);
        const double *hit_u = facet_u;
        if (key >= 0) {
            rbs_keyed_uniforms(key, facet_u, path == RBS_PATH_DIRECT, keyed);
            hit_u = keyed;
        }
        double work[2];
        int status = shape_rebound(t, shape, path, V, W, facet, a, hit_u, interpolation, Vn, Wn, &out->n_collisions,
                                   work);
        out->wall_work[0] += work[0];
        out->wall_work[1] += work[1];
        out->path = path;
        if (status != RBS_OK || rbs_dot(Vn[0], Vn[1], Vn[2], n[0], n[1], n[2]) > 0.0) {
            if (status == RBS_OK) {
                memcpy(V_out, Vn, sizeof Vn);
                memcpy(Omega_out, Wn, sizeof Wn);
            }
            return status;
        }
        memcpy(V, Vn, sizeof V);
        memcpy(W, Wn, sizeof W);
        for (int k = 0; k < RBS_U_PER_DRAW; k++)
            facet_u[k] = rbs_grain_uniform((uint64_t)facets, (uint64_t)(slot + k));
        slot += RBS_U_PER_DRAW;
    }
    return RBS_TRAPPED;     /* still into the mean wall after RBS_MAX_WALL_HITS facet hits */
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
    int status = RBS_INVALID, path = RBS_PATH_NONE, shape = -1, n_collisions = -1, wall_hits = 1;
    double roughness = 0.0, wall_work[2] = {NAN, NAN};
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
        int ok = t && rbs_options_read(options, &method, &interpolation)
                 && rbs_options_roughness(options, t->wall_roughness, &roughness) && hit->grain_key >= RBS_NO_KEY;
        if (ok && roughness != 0.0) {
            rough_out out = {RBS_PATH_NONE, -1, -1, 0, {NAN, NAN}};
            status = rough_rebound(t, mix, hit->grain_key, hit->V, hit->Omega, hit->n, hit->a, u, method,
                                   interpolation, roughness, result->V, result->Omega, &out);
            path = out.path;
            shape = out.shape;
            n_collisions = out.n_collisions;
            wall_hits = out.wall_hits;
            wall_work[0] = out.wall_work[0];
            wall_work[1] = out.wall_work[1];
        } else {
            if (ok)
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
            status = rbs_rebound_along(t, mix, path, hit->V, hit->Omega, hit->n, hit->a, u, interpolation,
                                       result->V, result->Omega, &shape, &n_collisions, wall_work);
        }
    }
    const int invalid = status == RBS_INVALID;
    result->status = status;
    result->path = invalid ? RBS_PATH_NONE : path;
    result->shape = invalid ? -1 : shape;
    result->n_collisions = invalid ? -1 : n_collisions;
    if (RBS_HAS_FIELD(result, rbs_result, wall_hits))
        result->wall_hits = invalid ? 0 : wall_hits;
    if (RBS_HAS_FIELD(result, rbs_result, wall_work_tangential)) {
        result->wall_work_normal = invalid ? NAN : wall_work[0];
        result->wall_work_tangential = invalid ? NAN : wall_work[1];
    }
    return status;
}

int rbs_rebound_along(const rbs_table *t, const rbs_mix *mix, int path, const double V[3], const double Omega[3],
                      const double n[3], double a, const double u[RBS_U_PER_DRAW], int interpolation, double V_out[3],
                      double Omega_out[3], int *shape, int *n_collisions, double wall_work[2])
{
    *shape = -1;
    *n_collisions = -1;
    wall_work[0] = wall_work[1] = NAN;
    if (path == RBS_PATH_NONE || !u || !V_out || !Omega_out || !rbs_table_arguments_ok(t, mix, interpolation)
        || !rbs_uniforms_ok(u, 1)) {
        nan_out(V_out);
        nan_out(Omega_out);
        return RBS_INVALID;
    }
    if (path == RBS_PATH_TABLE)
        return rbs_table_hit(t, mix, V, n, a, u, interpolation, V_out, Omega_out, shape, wall_work);
    /* the table's shape drawn as the table path draws it, then its index in the direct model's shapes */
    int64_t drawn = rbs_mix_shape(rbs_mix_cdf(mix), mix->n_shapes, u[0]);
    *shape = (int)drawn;
    return rbs_direct_hit(t, t->model_shape[drawn], V, Omega, n, a, u + 1, V_out, Omega_out, n_collisions,
                          wall_work);
}
