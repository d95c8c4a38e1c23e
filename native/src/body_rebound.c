/*
 * body_rebound.c: a whole rebound of the direct model (direct_model.body_rebound: body_rebound,
 * quaternion_to_matrix, lab_tensor): with Ω⁻ = 0 the body starts touching the wall, otherwise with its centre at
 * the bounding radius; then search the flight for the next contact (flight.c, rotation.c) and collide
 * (collision.c) until the body escapes (rebounded), n_max is exceeded (trapped) or a search or collision fails
 * (failed). The same operations in the same order as the numba kernels; the work space: the heights and rates
 * of the nv vertices (the caller's, or on the stack up to MAX_STACK_VERTICES, 4 KiB, and one malloc above) and a
 * few 3-vectors and matrices on the stack.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#include <math.h>
#include <stdlib.h>

#include "body_rebound.h"
#include "collision.h"
#include "flight.h"
#include "rebound_scatter.h"
#include "rotation.h"
#include "shapes.h"

void rbs_quaternion_to_matrix(const double q[4], double R[9])
{
    double n = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    double w = q[0] / n, x = q[1] / n, y = q[2] / n, z = q[3] / n;
    R[0] = 1.0 - 2.0 * (y * y + z * z);
    R[1] = 2.0 * (x * y - w * z);
    R[2] = 2.0 * (x * z + w * y);
    R[3] = 2.0 * (x * y + w * z);
    R[4] = 1.0 - 2.0 * (x * x + z * z);
    R[5] = 2.0 * (y * z - w * x);
    R[6] = 2.0 * (x * z - w * y);
    R[7] = 2.0 * (y * z + w * x);
    R[8] = 1.0 - 2.0 * (x * x + y * y);
}

/* out = R diag(diag) Rᵀ: a body-frame principal tensor in the lab frame */
static void lab_tensor(const double *R, const double *diag, double *out)
{
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            out[3 * i + j] = R[3 * i] * diag[0] * R[3 * j] + R[3 * i + 1] * diag[1] * R[3 * j + 1]
                             + R[3 * i + 2] * diag[2] * R[3 * j + 2];
}

int rbs_body_rebound(int kind, double *verts, int nv, const double semi[3], const double K[3], double Rb,
                     const double R0[9], const double V0[3], const double W0[3], const double *wall, long long n_max,
                     double contact_tol, double set_tol, long long max_steps, double V[3], double W[3],
                     long long *n_collisions, long long *n_steps, double wall_work[2])
{
    double stack[2 * MAX_STACK_VERTICES], *h = stack;
    /* a large hull's heights and rates on the heap: one block per call, so that threads share nothing */
    if (nv > MAX_STACK_VERTICES && !(h = malloc(2 * (size_t)nv * sizeof *h))) {
        *n_collisions = 0;
        *n_steps = 0;
        if (wall_work) wall_work[0] = wall_work[1] = 0.0;
        return RBS_FAILED;
    }
    int room = nv > MAX_STACK_VERTICES ? nv : MAX_STACK_VERTICES;
    int status = rbs_body_rebound_in(kind, verts, nv, semi, K, Rb, R0, V0, W0, wall, n_max, contact_tol, set_tol,
                                     max_steps, V, W, n_collisions, n_steps, wall_work, h, h + room, NULL);
    if (h != stack) free(h);
    return status;
}

int rbs_body_rebound_in(int kind, double *verts, int nv, const double semi[3], const double K[3], double Rb,
                        const double R0[9], const double V0[3], const double W0[3], const double *wall,
                        long long n_max, double contact_tol, double set_tol, long long max_steps, double V[3],
                        double W[3], long long *n_collisions, long long *n_steps, double wall_work[2], double *h,
                        double *h1, const rbs_hull *hull)
{
    double curv[3];
    rbs_walk walk;
    double params[RBS_ROT_PARAMS_SIZE], R[9], K_lab[9], Kinv_lab[9];
    double Kinv[3], ell[3], rc[3], dV[3], dW[3], Wt[3];

    for (int k = 0; k < 3; k++) Kinv[k] = 1.0 / K[k];
    for (int k = 0; k < 9; k++) R[k] = R0[k];
    for (int k = 0; k < 3; k++) {
        V[k] = V0[k];
        W[k] = W0[k];
    }

    double y;
    if (hull) {
        rbs_walk_clear(&walk);
        const double g[3] = {R[3], R[4], R[5]};
        walk.start = rbs_walk_map_start(hull, g);
    }
    if (hull && W0[0] == 0.0 && W0[1] == 0.0 && W0[2] == 0.0) {
        const double g[3] = {R[3], R[4], R[5]};
        int low;
        rbs_walk_lowest(hull, g, 0.0, walk.start, &walk, &y, &low);
        y = -y;
    } else if (W0[0] == 0.0 && W0[1] == 0.0 && W0[2] == 0.0) {
        int n = rbs_lowest_points(kind, verts, nv, semi, K, R, W, 0.0, 0.0, h, h1, curv);
        /* numpy's min: the first NaN, else the smallest */
        double lowest = h[0];
        for (int i = 1; i < n && lowest == lowest; i++)
            if (!(h[i] == h[i]) || h[i] < lowest) lowest = h[i];
        y = -lowest;
    } else {
        y = Rb;
    }
    long long n_coll = 0, steps_total = 0;
    double work_n = 0.0, work_t = 0.0;
    int status = RBS_FAILED;
    for (;;) {
        lab_tensor(R, K, K_lab);
        for (int i = 0; i < 3; i++) ell[i] = K_lab[3 * i] * W[0] + K_lab[3 * i + 1] * W[1] + K_lab[3 * i + 2] * W[2];
        double M = rbs_curvature_bound(kind, semi, Rb, K, ell, W);
        double M3 = rbs_jerk_bound(kind, semi, Rb, K, ell, W);
        for (int k = 0; k < 3; k++) Wt[k] = W[k];
        double t = 0.0;
        long long steps = 0;
        int code = rbs_find_contact(kind, verts, nv, semi, Rb, K, ell, M, M3, params, y, V[1], contact_tol, set_tol,
                                    max_steps, &t, R, Wt, h, h1, curv, rc, &steps, hull, &walk);
        steps_total += steps;
        if (code == SEARCH_ESCAPED) {
            status = RBS_OK;
            break;
        }
        if (code == SEARCH_STALLED) break;
        if (n_coll == n_max) {
            status = RBS_TRAPPED;
            break;
        }
        y += V[1] * t;
        for (int k = 0; k < 3; k++) W[k] = Wt[k];
        lab_tensor(R, Kinv, Kinv_lab);
        int outcome = rbs_collide(V, W, rc, Kinv_lab, wall, dV, dW);
        if (outcome != COLLISION_OK && outcome != COLLISION_MULTIPLE_ROOTS) break;
        double hit_n, hit_t;
        rbs_wall_work(V, W, rc, dV, dW, &hit_n, &hit_t);
        work_n += hit_n;
        work_t += hit_t;
        for (int k = 0; k < 3; k++) {
            V[k] += dV[k];
            W[k] += dW[k];
        }
        n_coll += 1;
    }
    *n_collisions = n_coll;
    *n_steps = steps_total;
    if (wall_work) {
        wall_work[0] = work_n;
        wall_work[1] = work_t;
    }
    return status;
}
