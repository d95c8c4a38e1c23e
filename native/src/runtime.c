/*
 * runtime.c: the direct model at run time (direct_model.runtime: normal_quantile, aspect_ratio,
 * uniform_quaternion, rebound_model_frame): the random inputs of one rebound from RBS_U_PER_REBOUND uniforms,
 * the particle's body from the shape arrays (shapes.c), every other model parameter from the P_* array, then the
 * rebound (body_rebound.c). The same operations in the same order as the numba kernels; libm's sqrt, log, sin
 * and cos. The work space of one call: a scanned body's vertices and their heights and rates (40 bytes a vertex), on
 * the stack up to MAX_STACK_VERTICES vertices (10 KiB), above in one malloc freed before the return (no buffer is
 * shared: threads may call it on one table); a walked hull's (hull_walk.h) none per vertex: its walk's 2 KiB on the
 * stack.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#include <math.h>
#include <stdlib.h>

#include "body_rebound.h"
#include "fastmath.h"
#include "pymath.h"
#include "runtime.h"
#include "shapes.h"

_Static_assert(RBS_TETRAHEDRON + 1 == RBS_N_FAMILIES, "RBS_N_FAMILIES counts the family codes (N_PARAMS rests on it)");

double rbs_normal_quantile(double p)
{
    double q = p - 0.5;
    if (fabs(q) <= 0.425) {
        double r = 0.180625 - q * q;
        return q * (((((((2509.0809287301226727 * r + 33430.575583588128105) * r + 67265.770927008700853) * r
                        + 45921.953931549871457) * r + 13731.693765509461125) * r + 1971.5909503065514427) * r
                     + 133.14166789178437745) * r + 3.387132872796366608) / (
            ((((((5226.495278852545925 * r + 28729.085735721942674) * r + 39307.89580009271061) * r
               + 21213.794301586595867) * r + 5394.1960214247511077) * r + 687.1870074920579083) * r
             + 42.313330701600911252) * r + 1.0);
    }
    double r = sqrt(-log(q < 0.0 ? p : 1.0 - p)), x;
    if (r <= 5.0) {
        r -= 1.6;
        x = (((((((7.7454501427834140764e-4 * r + 0.0227238449892691845833) * r + 0.24178072517745061177) * r
                + 1.27045825245236838258) * r + 3.64784832476320460504) * r + 5.7694972214606914055) * r
              + 4.6303378461565452959) * r + 1.42343711074968357734) / (
            ((((((1.05075007164441684324e-9 * r + 5.475938084995344946e-4) * r + 0.0151986665636164571966) * r
               + 0.14810397642748007459) * r + 0.68976733498510000455) * r + 1.6763848301838038494) * r
             + 2.05319162663775882187) * r + 1.0);
    } else {
        r -= 5.0;
        x = (((((((2.01033439929228813265e-7 * r + 2.71155556874348757815e-5) * r + 0.0012426609473880784386) * r
                + 0.026532189526576123093) * r + 0.29656057182850489123) * r + 1.7848265399172913358) * r
              + 5.4637849111641143699) * r + 6.6579046435011037772) / (
            ((((((2.04426310338993978564e-15 * r + 1.4215117583164458887e-7) * r + 1.8463183175100546818e-5) * r
               + 7.868691311456132591e-4) * r + 0.0148753612908506148525) * r + 0.13692988092273580531) * r
             + 0.59983220655588793769) * r + 1.0);
    }
    return q < 0.0 ? -x : x;
}

double rbs_aspect_ratio(const double law[4], const double cdf[2], double u)
{
    double lo = cdf[0], hi = cdf[1];
    double x = law[0] + law[1] * rbs_normal_quantile(lo + u * (hi - lo));
    return py_min(py_max(x, law[2]), law[3]);
}

void rbs_uniform_quaternion(double u0, double u1, double u2, double q[4])
{
    double s = sqrt(1.0 - u0), c = sqrt(u0);
    q[0] = s * sin(2.0 * RBS_PI * u1);
    q[1] = s * cos(2.0 * RBS_PI * u1);
    q[2] = c * sin(2.0 * RBS_PI * u2);
    q[3] = c * cos(2.0 * RBS_PI * u2);
}

int rbs_rebound_model_frame(const double *params, const rbs_shape_arrays *shapes, int shape, double vt, double vn,
                            double wx, double wy, double wz, const double *u, double V[3], double W[3])
{
    long long n_collisions;
    double wall_work[2];
    return rbs_rebound_model_frame_counted(params, shapes, shape, vt, vn, wx, wy, wz, u, V, W, &n_collisions,
                                           wall_work);
}

int rbs_rebound_model_frame_counted(const double *params, const rbs_shape_arrays *shapes, int shape, double vt,
                                    double vn, double wx, double wy, double wz, const double *u, double V[3],
                                    double W[3], long long *n_collisions, double wall_work[2])
{
    double quat[4], R0[9], K[3], semi[3], scale[3], stack[5 * MAX_STACK_VERTICES];
    /* a scanned shape's vertex rows: room for the particle's vertices (an ellipsoid's one row: its support point);
     * a walked one needs none */
    int walked = rbs_walked(shapes, shape);
    int64_t rows = walked ? 1 : shapes->vertex_start[shape + 1] - shapes->vertex_start[shape];
    int room = rows > MAX_STACK_VERTICES ? (int)rows : MAX_STACK_VERTICES;
    double *verts = stack;
    if (room > MAX_STACK_VERTICES && !(verts = malloc(5 * (size_t)room * sizeof *verts))) {
        *n_collisions = 0;
        wall_work[0] = wall_work[1] = 0.0;
        return RBS_FAILED;
    }
    rbs_uniform_quaternion(u[U_ORIENTATION], u[U_ORIENTATION + 1], u[U_ORIENTATION + 2], quat);
    rbs_quaternion_to_matrix(quat, R0);
    const double *law = shapes->aspect + 4 * shape, *cdf = shapes->aspect_cdf + 2 * shape;
    /* fixed proportions (a NaN law): no quantile of NaN, which would raise FE_INVALID in solvers that trap it */
    int fixed = isnan(law[0]);
    double ratio_ba = fixed ? 1.0 : rbs_aspect_ratio(law, cdf, u[U_RATIOS]);
    double ratio_cb = fixed ? 1.0 : rbs_aspect_ratio(law, cdf, u[U_RATIOS + 1]);
    double hand = !shapes->both_hands[shape] || u[U_HAND] < 0.5 ? 1.0 : -1.0;
    int nv = rbs_particle_body(shapes, shape, ratio_ba, ratio_cb, hand, walked ? NULL : verts, K, semi, scale);
    int kind = shapes->kind[shape];
    rbs_hull hull;
    if (walked) rbs_particle_hull(shapes, shape, scale, &hull);
    double Rb = walked ? sqrt(rbs_walk_farthest(&hull)) : rbs_bounding_radius(kind, semi, verts, nv);
    const double V0[3] = {vt, vn, 0.0}, W0[3] = {wx, wy, wz};
    long long n_steps;
    /* n_max and max_steps as numba's int() of the float64 parameters; the heights and rates after the vertices */
    int status = rbs_body_rebound_in(kind, verts, nv, semi, K, Rb, R0, V0, W0, params + P_WALL,
                                     rbs_trunc(params[P_N_MAX]), params[P_CONTACT_TOL], params[P_SET_TOL],
                                     rbs_trunc(params[P_MAX_STEPS]), V, W, n_collisions, &n_steps, wall_work,
                                     verts + 3 * room, verts + 4 * room, walked ? &hull : NULL);
    if (verts != stack) free(verts);
    return status;
}
