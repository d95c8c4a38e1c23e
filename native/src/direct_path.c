/*
 * direct_path.c: the direct model at run time in the caller's frame (surrogate.kernels.direct_path:
 * direct_rebound, _valid), the direct path of rbs_rebound: the checks of the inputs, the impact frame of the hit
 * (frame.h, the sampler's), the rebound in the model's frame (runtime.c), V⁺ and Ω⁺ back in the caller's frame
 * (rbs_to_global), and the rebound's work on the wall.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#include <limits.h>
#include <math.h>

#include "frame.h"
#include "paths.h"
#include "runtime.h"

/* NaN into the outputs a caller gave (any may be NULL) */
static void nan_out(double *x)
{
    if (x)
        for (int k = 0; k < 3; k++) x[k] = NAN;
}

/* the inputs in their ranges (surrogate.kernels.direct_path._valid): uniforms 0 <= u < 1 as numba compares them */
static int valid(const rbs_shape_arrays *shapes, int shape, const double *V, const double *Omega, const double *n,
                 double a, const double *u)
{
    int ok = rbs_moves_into_wall(V[0], V[1], V[2], n[0], n[1], n[2]) && rbs_particle_ok(n[0], n[1], n[2], a)
             && rbs_finite(Omega[0] + Omega[1] + Omega[2]) && shape >= 0 && shape < shapes->n_shapes;
    for (int k = 0; ok && k < RBS_U_PER_REBOUND; k++) ok = 0.0 <= u[k] && u[k] < 1.0;
    return ok;
}

RBS_HOT int rbs_direct_hit(const rbs_table *t, int shape, const double V[3], const double Omega[3], const double n[3],
                           double a, const double u[RBS_U_PER_REBOUND], double V_out[3], double Omega_out[3],
                           int *n_collisions, double wall_work[2])
{
    *n_collisions = -1;
    wall_work[0] = wall_work[1] = NAN;
    if (!t || !V || !Omega || !n || !u || !V_out || !Omega_out
        || !valid(&t->direct_shapes, shape, V, Omega, n, a, u)) {
        nan_out(V_out);
        nan_out(Omega_out);
        return RBS_INVALID;
    }
    rbs_frame f;
    rbs_impact_frame(V, n, u[U_AXIS], &f);
    const double *ex = f.ex, *ez = f.ez;
    /* Ω⁻ in (m/s)/a, the model's unit: rad/s times a */
    double x[6], work[2];
    long long collisions = -1;
    int status = rbs_rebound_model_frame_counted(
        t->direct_parameters, &t->direct_shapes, shape, rbs_dot(V[0], V[1], V[2], ex[0], ex[1], ex[2]),
        rbs_dot(V[0], V[1], V[2], n[0], n[1], n[2]), a * rbs_dot(Omega[0], Omega[1], Omega[2], ex[0], ex[1], ex[2]),
        a * rbs_dot(Omega[0], Omega[1], Omega[2], n[0], n[1], n[2]),
        a * rbs_dot(Omega[0], Omega[1], Omega[2], ez[0], ez[1], ez[2]), u, x, x + 3, &collisions, work);
    if (status != RBS_OK) {
        nan_out(V_out);
        nan_out(Omega_out);
        status = status == RBS_TRAPPED ? RBS_TRAPPED : RBS_FAILED;
    } else {
        status = rbs_to_global(status, 1, x, 1.0, a, ex, n, ez, V_out, Omega_out);
    }
    /* the count as an int: at most n_max (an integer below 2^53 by the loader's check) plus one, clamped */
    *n_collisions = status == RBS_INVALID ? -1 : collisions > INT_MAX ? INT_MAX : (int)collisions;
    /* the wall work in m²/s² as the model gives it: a scalar of the rebound, in no frame (surrogate.kernels.hit.hit:
       NaN for RBS_INVALID, a rebound rbs_to_global refuses) */
    if (status != RBS_INVALID) {
        wall_work[0] = work[0];
        wall_work[1] = work[1];
    }
    return status;
}

int rbs_direct_rebound(const rbs_table *t, int shape, const double V[3], const double Omega[3], const double n[3],
                       double a, const double u[RBS_U_PER_REBOUND], double V_out[3], double Omega_out[3])
{
    int n_collisions;
    double wall_work[2];
    return rbs_direct_hit(t, shape, V, Omega, n, a, u, V_out, Omega_out, &n_collisions, wall_work);
}
