/*
 * test_direct.c: the invariants of the direct model (docs/model.md §4, §5) on the C kernels, run under
 * AddressSanitizer and UndefinedBehaviorSanitizer by tests/native (no report may appear, no leak):
 *   - a collision never adds energy, ½|V|² + ½ΩᵀKΩ per unit mass (m²/s², lengths in units of a);
 *   - a collision keeps the angular momentum about the contact point, KΩ − r_c × V;
 *   - a free flight keeps the energy ½ΩᵀKΩ and the angular momentum L = KΩ (lab) to 1e-9;
 *   - a whole rebound never adds energy, for the four families and a grain of GRAIN_VERTICES vertices (its work
 *     space on the heap: rbs_body_rebound's, and rbs_rebound_model_frame's on the table's parameters);
 * each under the published exponential wall law and a tabulated one, every other trial;
 * then hostile calls of rbs_direct_rebound on a table (RBS_INVALID and NaN, never a crash), and four threads
 * calling it on one table give the bits of one thread.
 *
 *   rbs_test_direct GOOD.h5 [TABLE_WITHOUT_DIRECT_PARAMETERS.h5]
 *
 * Exit status 0 when every check passes; each failure is printed.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "body_rebound.h"
#include "check.h"
#include "collision.h"
#include "fastmath.h"
#include "paths.h"
#include "rebound_scatter.h"
#include "rotation.h"
#include "runtime.h"
#include "shapes.h"

#define TRIALS 20000

/* the walls of the trials, as the kernels' wall arrays (wall.h, layout W_*): the published exponential law (q 1, k 0.1,
 * p 0.61) and a tabulated one of 2 speed nodes (40, 300 m/s) × 3 sine nodes (q 0.8) */
static const double WALLS[2][WALL_ARRAY_SIZE] = {
    {EXPONENTIAL_CODE, 1.0, 0.1, 0.61},
    {TABULATED_CODE, 0.8, 2, 3, 40.0, 300.0, 0.0, 0.5, 1.0, 1.0, 0.8, 0.55, 1.0, 0.7, 0.42},
};

/* a random body: principal K (units a²) of half-extents (1, b/a, c/a) and factor s, orientation R */
static void random_body(rbs_rng *rng, double K[3], double R[9])
{
    double b = 0.5 + 0.5 * rbs_rng_uniform(rng), c = b * (0.5 + 0.5 * rbs_rng_uniform(rng));
    double s = 0.2 + 0.14 * rbs_rng_uniform(rng), q[4];
    K[0] = s * (b * b + c * c);
    K[1] = s * (1.0 + c * c);
    K[2] = s * (1.0 + b * b);
    rbs_uniform_quaternion(rbs_rng_uniform(rng), rbs_rng_uniform(rng), rbs_rng_uniform(rng), q);
    rbs_quaternion_to_matrix(q, R);
}

/* out = R diag(d) Rᵀ */
static void lab(const double R[9], const double d[3], double out[9])
{
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            out[3 * i + j] = R[3 * i] * d[0] * R[3 * j] + R[3 * i + 1] * d[1] * R[3 * j + 1] + R[3 * i + 2] * d[2] * R[3 * j + 2];
}

static void apply(const double A[9], const double x[3], double out[3])
{
    for (int i = 0; i < 3; i++) out[i] = A[3 * i] * x[0] + A[3 * i + 1] * x[1] + A[3 * i + 2] * x[2];
}

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void cross(const double a[3], const double b[3], double out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

static void collisions(rbs_rng *rng)
{
    int collided = 0;
    double worst_gain = -INFINITY, worst_momentum = 0.0;
    for (int trial = 0; trial < TRIALS; trial++) {
        double K[3], R[9], Kinv[3], K_lab[9], Kinv_lab[9], V[3], W[3], r[3], dV[3], dW[3];
        random_body(rng, K, R);
        for (int k = 0; k < 3; k++) Kinv[k] = 1.0 / K[k];
        lab(R, K, K_lab);
        lab(R, Kinv, Kinv_lab);
        double speed = 10.0 + 290.0 * rbs_rng_uniform(rng);
        for (int k = 0; k < 3; k++) {
            V[k] = speed * (2.0 * rbs_rng_uniform(rng) - 1.0);
            W[k] = speed * (2.0 * rbs_rng_uniform(rng) - 1.0);
            r[k] = 2.0 * rbs_rng_uniform(rng) - 1.0;
        }
        r[1] = -fabs(r[1]);     /* the contact point below the centre */
        int outcome = rbs_collide(V, W, r, Kinv_lab, WALLS[trial % 2], dV, dW);
        if (outcome != COLLISION_OK && outcome != COLLISION_MULTIPLE_ROOTS) continue;
        collided++;
        double V1[3], W1[3], KW0[3], KW1[3], rV0[3], rV1[3];
        for (int k = 0; k < 3; k++) {
            V1[k] = V[k] + dV[k];
            W1[k] = W[k] + dW[k];
        }
        apply(K_lab, W, KW0);
        apply(K_lab, W1, KW1);
        double e0 = 0.5 * dot3(V, V) + 0.5 * dot3(W, KW0), e1 = 0.5 * dot3(V1, V1) + 0.5 * dot3(W1, KW1);
        double gain = (e1 - e0) / e0;
        if (gain > worst_gain) worst_gain = gain;
        CHECK(gain <= 1e-12, "a collision added energy: %.3g relative (trial %d)", gain, trial);
        cross(r, V, rV0);
        cross(r, V1, rV1);
        double change = 0.0, scale = sqrt(dot3(KW0, KW0)) + sqrt(dot3(r, r) * dot3(V, V));
        for (int k = 0; k < 3; k++) change += fabs((KW1[k] - rV1[k]) - (KW0[k] - rV0[k]));
        if (change / scale > worst_momentum) worst_momentum = change / scale;
        CHECK(change <= 1e-12 * scale, "a collision changed the angular momentum about the contact point by %.3g "
              "relative (trial %d)", change / scale, trial);
    }
    CHECK(collided > TRIALS / 4, "only %d of %d trials collided", collided, TRIALS);
    printf("collisions: %d of %d approaching; energy change at most %.3g relative; angular momentum about the "
           "contact point kept to %.3g relative\n", collided, TRIALS, worst_gain, worst_momentum);
}

static void free_flights(rbs_rng *rng)
{
    static double params[RBS_ROT_PARAMS_SIZE];
    double worst_energy = 0.0, worst_momentum = 0.0;
    for (int trial = 0; trial < TRIALS / 10; trial++) {
        double K[3], R0[9], K_lab[9], W0[3], ell[3], R[9], W[3];
        random_body(rng, K, R0);
        lab(R0, K, K_lab);
        for (int k = 0; k < 3; k++) W0[k] = 2.0 * rbs_rng_uniform(rng) - 1.0;
        apply(K_lab, W0, ell);
        double energy = 0.5 * dot3(W0, ell), momentum = sqrt(dot3(ell, ell));
        rbs_rotation_init(K, R0, ell, params);
        for (int step = 1; step <= 8; step++) {
            double t = step * 10.0 * rbs_rng_uniform(rng), L[3], Kt[9];
            rbs_rotation_at(params, t, R, W);
            lab(R, K, Kt);
            apply(Kt, W, L);
            double de = fabs(0.5 * dot3(W, L) - energy) / energy;
            double dl = 0.0;
            for (int k = 0; k < 3; k++) dl += fabs(L[k] - ell[k]);
            dl /= momentum;
            if (de > worst_energy) worst_energy = de;
            if (dl > worst_momentum) worst_momentum = dl;
            CHECK(de <= 1e-9 && dl <= 1e-9, "a free flight changed the energy by %.3g or L by %.3g relative (trial %d, "
                  "t = %g)", de, dl, trial, t);
        }
    }
    printf("free flights: energy kept to %.3g relative, L (lab vector) to %.3g relative\n", worst_energy, worst_momentum);
}

/* The shapes of the rebounds: the four families (κ = 0.3, the default law) and, as shape 4, a grain of
 * GRAIN_VERTICES vertices on the ellipsoid of semi-axes (1, 0.7, 0.5) (each one a hull vertex; its second
 * moments the ellipsoid's, a valid inertia for the energy check), both hands, fixed proportions. */
#define GRAIN_VERTICES (2 * MAX_STACK_VERTICES)     /* beyond the stack's room: the heap's work space runs */
typedef struct test_shapes {
    rbs_shape_arrays arrays;
    int8_t kind[5];
    int64_t vertex_start[6];
    double vertices[3 * (FAMILY_VERTEX_ROWS + GRAIN_VERTICES)], second_moments[15], aspect[20], aspect_cdf[10];
    uint8_t both_hands[5];
} test_shapes;

static void make_shapes(test_shapes *s, rbs_rng *rng)
{
    const double law[4] = {0.8, 0.2, 0.5, 1.0}, cdf[2] = {0.06680720126885804, 0.8413447460685428};
    const double kfac[4] = {0.2, 0.33333333333333337, 0.3309571404654277, 0.2}, semi[3] = {1.0, 0.7, 0.5};
    rbs_family_shapes_fill(s->kind, s->vertex_start, s->vertices, s->second_moments, s->aspect, s->aspect_cdf,
                           s->both_hands, 0.3, law, cdf, kfac);
    s->kind[4] = KIND_POLYHEDRON;
    s->vertex_start[5] = FAMILY_VERTEX_ROWS + GRAIN_VERTICES;
    for (int i = 0; i < GRAIN_VERTICES; i++) {
        double p[3], norm = 0.0;
        for (int k = 0; k < 3; k++) {      /* a direction uniform enough for a test: a cube's point, normalised */
            p[k] = 2.0 * rbs_rng_uniform(rng) - 1.0;
            norm += p[k] * p[k];
        }
        for (int k = 0; k < 3; k++) s->vertices[3 * (FAMILY_VERTEX_ROWS + i) + k] = semi[k] * p[k] / sqrt(norm);
    }
    for (int k = 0; k < 3; k++) s->second_moments[12 + k] = semi[k] * semi[k] / 5.0;
    for (int k = 0; k < 4; k++) s->aspect[16 + k] = NAN;
    s->aspect_cdf[8] = s->aspect_cdf[9] = NAN;
    s->both_hands[4] = 1;
    /* no vertex graph: the grain of GRAIN_VERTICES is scanned (its work space on the heap) */
    s->arrays = (rbs_shape_arrays){.n_shapes = 5, .kind = s->kind, .vertex_start = s->vertex_start,
                                   .vertices = s->vertices, .second_moments = s->second_moments, .aspect = s->aspect,
                                   .aspect_cdf = s->aspect_cdf, .both_hands = s->both_hands};
}

static void rebounds(rbs_rng *rng)
{
    test_shapes shapes;
    make_shapes(&shapes, rng);
    double worst = -INFINITY, verts[3 * GRAIN_VERTICES];
    int counts[3] = {0, 0, 0};
    for (int trial = 0; trial < TRIALS / 10; trial++) {
        int shape = trial % 5;
        double ratio_ba = 0.5 + 0.5 * rbs_rng_uniform(rng), ratio_cb = 0.5 + 0.5 * rbs_rng_uniform(rng);
        double hand = rbs_rng_uniform(rng) < 0.5 ? 1.0 : -1.0, semi[3], scale[3];
        double q[4], R0[9], V0[3], W0[3], V[3], W[3], K[3], K0[9], KW0[3];
        rbs_uniform_quaternion(rbs_rng_uniform(rng), rbs_rng_uniform(rng), rbs_rng_uniform(rng), q);
        rbs_quaternion_to_matrix(q, R0);
        double speed = 10.0 + 290.0 * rbs_rng_uniform(rng), angle = 0.05 + 1.5 * rbs_rng_uniform(rng);
        V0[0] = speed * cos(angle);
        V0[1] = -speed * sin(angle);
        V0[2] = 0.0;
        for (int k = 0; k < 3; k++) W0[k] = trial % 8 < 4 ? 0.0 : 0.3 * speed * (2.0 * rbs_rng_uniform(rng) - 1.0);
        int nv = rbs_particle_body(&shapes.arrays, shape, ratio_ba, ratio_cb, hand, verts, K, semi, scale);
        int kind = shapes.kind[shape];
        double Rb = rbs_bounding_radius(kind, semi, verts, nv);
        long long n_coll, n_steps;
        double work[2];
        int status = rbs_body_rebound(kind, verts, nv, semi, K, Rb, R0, V0, W0, WALLS[trial % 2], 1000, 1e-10, 1e-9,
                                      100000, V, W, &n_coll, &n_steps, work);
        CHECK(status == RBS_OK || status == RBS_TRAPPED || status == RBS_FAILED, "status %d", status);
        if (status >= 0 && status < 3) counts[status]++;
        if (status != RBS_OK) continue;
        /* the final orientation is not returned: ΩᵀKΩ >= K_min |Ω|² bounds the final energy from below */
        lab(R0, K, K0);
        apply(K0, W0, KW0);
        double kmin = fmin(K[0], fmin(K[1], K[2]));
        double e0 = 0.5 * dot3(V0, V0) + 0.5 * dot3(W0, KW0);
        double gain = (0.5 * dot3(V, V) + 0.5 * kmin * dot3(W, W) - e0) / e0;
        if (gain > worst) worst = gain;
        CHECK(gain <= 1e-12, "a rebound added energy: at least %.3g relative (trial %d)", gain, trial);
        /* the work on the wall, each part >= 0, is the energy lost: e0 − W_n − W_t between the bounds of E⁺ (to
           round-off, 1e-13 e0 a collision) */
        double kmax = fmax(K[0], fmax(K[1], K[2])), after = e0 - work[0] - work[1], tol = 1e-13 * (n_coll + 1) * e0;
        CHECK(work[0] > 0.0 && work[1] >= 0.0 && after >= 0.5 * dot3(V, V) + 0.5 * kmin * dot3(W, W) - tol
                  && after <= 0.5 * dot3(V, V) + 0.5 * kmax * dot3(W, W) + tol,
              "the wall work %.17g, %.17g is not the energy lost (trial %d)", work[0], work[1], trial);
    }
    printf("rebounds: %d rebounded, %d trapped, %d failed; energy after (bounded below) / before − 1 at most %.3g\n", counts[0], counts[1], counts[2], worst);
}

/* The grain of GRAIN_VERTICES vertices on the table's model parameters: rbs_rebound_model_frame (its work space in
 * one malloc) gives the bits of rbs_particle_body and rbs_body_rebound (theirs in another) from the same uniforms. */
static void grain_model_frame(const rbs_table *table, rbs_rng *rng)
{
    const void *data = NULL;
    size_t count = 0;
    int dtype = -1;
    CHECK(rbs_table_kernel_array(table, "direct_parameters", &data, &count, &dtype) == RBS_OK && count == N_PARAMS,
          "the table's direct parameters");
    if (!data) return;
    const double *params = data;
    test_shapes shapes;
    make_shapes(&shapes, rng);
    int same = 0, rebounded = 0;
    for (int trial = 0; trial < 100; trial++) {
        double u[RBS_U_PER_REBOUND], q[4], R0[9], K[3], semi[3], scale[3], verts[3 * GRAIN_VERTICES];
        double V[3], W[3], Vr[3], Wr[3];
        rbs_rng_fill(rng, u, RBS_U_PER_REBOUND);
        double speed = 10.0 + 290.0 * rbs_rng_uniform(rng), angle = 0.05 + 1.5 * rbs_rng_uniform(rng);
        double W0[3] = {0.0, 0.0, 0.0}, V0[3] = {speed * cos(angle), -speed * sin(angle), 0.0};
        for (int k = 0; k < 3; k++) W0[k] = trial % 2 ? 0.0 : 0.3 * speed * (2.0 * rbs_rng_uniform(rng) - 1.0);
        int status = rbs_rebound_model_frame(params, &shapes.arrays, 4, V0[0], V0[1], W0[0], W0[1], W0[2], u, V, W);
        /* runtime.c's steps for a shape of fixed proportions in both hands */
        rbs_uniform_quaternion(u[U_ORIENTATION], u[U_ORIENTATION + 1], u[U_ORIENTATION + 2], q);
        rbs_quaternion_to_matrix(q, R0);
        int nv = rbs_particle_body(&shapes.arrays, 4, 1.0, 1.0, u[U_HAND] < 0.5 ? 1.0 : -1.0, verts, K, semi, scale);
        double Rb = rbs_bounding_radius(KIND_POLYHEDRON, semi, verts, nv);
        long long n_coll, n_steps;
        int again = rbs_body_rebound(KIND_POLYHEDRON, verts, nv, semi, K, Rb, R0, V0, W0, params + P_WALL,
                                     rbs_trunc(params[P_N_MAX]), params[P_CONTACT_TOL], params[P_SET_TOL],
                                     rbs_trunc(params[P_MAX_STEPS]), Vr, Wr, &n_coll, &n_steps, NULL);
        same += status == again && (status != RBS_OK || (memcmp(V, Vr, sizeof V) == 0 && memcmp(W, Wr, sizeof W) == 0));
        rebounded += status == RBS_OK;
    }
    CHECK(same == 100 && rebounded >= 80, "grain of %d vertices: %d of 100 the same, %d rebounded", GRAIN_VERTICES,
          same, rebounded);
    printf("grain of %d vertices (work space on the heap): %d rebounded, the bits of rbs_body_rebound\n",
           GRAIN_VERTICES, rebounded);
}

/* every output NaN */
static int all_nan(const double *x)
{
    return isnan(x[0]) && isnan(x[1]) && isnan(x[2]);
}

/* hostile inputs: RBS_INVALID and NaN outputs, never a crash */
static void hostile(const rbs_table *table, const rbs_table *without)
{
    const double V[3] = {100.0, -100.0, 0.0}, Omega[3] = {0.0, 0.0, 0.0}, n[3] = {0.0, 1.0, 0.0};
    const double u[RBS_U_PER_REBOUND] = {0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5};
    double Vo[3], Wo[3];
    CHECK(rbs_direct_rebound(table, RBS_PRISM, V, Omega, n, 1e-3, u, Vo, Wo) == RBS_OK, "a good call");
    {   /* rbs_direct_hit: the same bits, and the collisions of the rebound */
        double Vh[3], Wh[3], work[2];
        int n_collisions = -2;
        CHECK(rbs_direct_hit(table, RBS_PRISM, V, Omega, n, 1e-3, u, Vh, Wh, &n_collisions, work) == RBS_OK
              && memcmp(Vh, Vo, sizeof Vh) == 0 && memcmp(Wh, Wo, sizeof Wh) == 0 && n_collisions >= 1
              && work[0] > 0.0 && work[1] >= 0.0, "rbs_direct_hit: %d collisions", n_collisions);
        CHECK(rbs_direct_hit(table, -1, V, Omega, n, 1e-3, u, Vh, Wh, &n_collisions, work) == RBS_INVALID
              && n_collisions == -1 && isnan(work[0]) && isnan(work[1]), "rbs_direct_hit of no shape");
    }
#define INVALID(...)                                                                                    \
    do {                                                                                                \
        Vo[0] = Vo[1] = Vo[2] = Wo[0] = Wo[1] = Wo[2] = 0.0;                                            \
        int status_ = rbs_direct_rebound(__VA_ARGS__);                                                  \
        CHECK(status_ == RBS_INVALID && all_nan(Vo) && all_nan(Wo), "%s: status %d", #__VA_ARGS__, status_); \
    } while (0)
    INVALID(NULL, RBS_PRISM, V, Omega, n, 1e-3, u, Vo, Wo);
    INVALID(without, RBS_PRISM, V, Omega, n, 1e-3, u, Vo, Wo);
    INVALID(table, RBS_PRISM, NULL, Omega, n, 1e-3, u, Vo, Wo);
    INVALID(table, RBS_PRISM, V, NULL, n, 1e-3, u, Vo, Wo);
    INVALID(table, RBS_PRISM, V, Omega, NULL, 1e-3, u, Vo, Wo);
    INVALID(table, RBS_PRISM, V, Omega, n, 1e-3, NULL, Vo, Wo);
    INVALID(table, -1, V, Omega, n, 1e-3, u, Vo, Wo);
    INVALID(table, 4, V, Omega, n, 1e-3, u, Vo, Wo);
    INVALID(table, RBS_PRISM, V, Omega, n, NAN, u, Vo, Wo);
    INVALID(table, RBS_PRISM, V, Omega, n, INFINITY, u, Vo, Wo);
    INVALID(table, RBS_PRISM, V, Omega, n, 0.0, u, Vo, Wo);
    CHECK(rbs_direct_rebound(table, RBS_PRISM, V, Omega, n, 1e-3, u, NULL, Wo) == RBS_INVALID && all_nan(Wo),
          "NULL V_out");
    CHECK(rbs_direct_rebound(table, RBS_PRISM, V, Omega, n, 1e-3, u, Vo, NULL) == RBS_INVALID && all_nan(Vo),
          "NULL Omega_out");
    const double bad[] = {NAN, INFINITY, -INFINITY, 1.0, -1e-300, 2.0};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        for (int k = 0; k < 3; k++) {
            double Vb[3] = {V[0], V[1], V[2]}, Ob[3] = {1.0, 2.0, 3.0}, nb[3] = {n[0], n[1], n[2]};
            if (!isfinite(bad[i])) {
                Vb[k] = bad[i];
                INVALID(table, RBS_PRISM, Vb, Omega, n, 1e-3, u, Vo, Wo);
                Ob[k] = bad[i];
                INVALID(table, RBS_PRISM, V, Ob, n, 1e-3, u, Vo, Wo);
            }
            nb[k] = bad[i] + (k == 1 ? 1.0 : 0.0);
            if (!(fabs(nb[0] * nb[0] + nb[1] * nb[1] + nb[2] * nb[2] - 1.0) <= 1e-12)) INVALID(table, RBS_PRISM, V, Omega, nb, 1e-3, u, Vo, Wo);
        }
        for (int k = 0; k < RBS_U_PER_REBOUND; k++) {
            double ub[RBS_U_PER_REBOUND];
            memcpy(ub, u, sizeof ub);
            ub[k] = bad[i];
            if (!(bad[i] >= 0.0 && bad[i] < 1.0)) INVALID(table, RBS_PRISM, V, Omega, n, 1e-3, ub, Vo, Wo);
        }
    }
    const double away[3] = {100.0, 100.0, 0.0}, zero[3] = {0.0, 0.0, 0.0};
    INVALID(table, RBS_PRISM, away, Omega, n, 1e-3, u, Vo, Wo);
    INVALID(table, RBS_PRISM, zero, Omega, n, 1e-3, u, Vo, Wo);
    const double huge[3] = {1e308, 1e308, 0.0};
    INVALID(table, RBS_PRISM, V, huge, n, 1e-3, u, Vo, Wo);
#undef INVALID
    /* extreme but valid inputs: a status, finite outputs for a rebound, NaN otherwise */
    const double speeds[] = {1e-300, 1e-8, 1e8, 1e300}, sizes[] = {1e-300, 1e-12, 1e12, 1e300};
    for (size_t i = 0; i < 4; i++)
        for (size_t j = 0; j < 4; j++)
            for (int shape = 0; shape < 4; shape++) {
                const double Vx[3] = {speeds[i], -speeds[i], 0.0}, Ox[3] = {speeds[i] / sizes[j], 0.0, 0.0};
                for (int spin = 0; spin < 2; spin++) {
                    int status = rbs_direct_rebound(table, shape, Vx, spin ? Ox : Omega, n, sizes[j], u, Vo, Wo);
                    int finite = isfinite(Vo[0]) && isfinite(Vo[1]) && isfinite(Vo[2]) && isfinite(Wo[0])
                                 && isfinite(Wo[1]) && isfinite(Wo[2]);
                    CHECK(status == RBS_INVALID || status == RBS_OK || status == RBS_TRAPPED || status == RBS_FAILED,
                          "status %d", status);
                    CHECK(status == RBS_OK ? finite : all_nan(Vo) && all_nan(Wo), "outputs of status %d", status);
                }
            }
    printf("hostile inputs: RBS_INVALID with NaN outputs\n");
}

#define THREADED 4000   /* particles of the thread check */
#define THREADS 4

typedef struct job {
    const rbs_table *table;
    const double *V, *Omega, *u;
    double *V_out, *Omega_out;
    int *status;
    int first, last;
} job;

static void *run_job(void *arg)
{
    job *j = arg;
    const double n[3] = {0.0, 1.0, 0.0};
    for (int i = j->first; i < j->last; i++)
        j->status[i] = rbs_direct_rebound(j->table, i % 4, j->V + 3 * i, j->Omega + 3 * i, n, 1e-4,
                                          j->u + RBS_U_PER_REBOUND * i, j->V_out + 3 * i, j->Omega_out + 3 * i);
    return NULL;
}

/* THREADS threads on one table give the bits of one thread */
static void threads(const rbs_table *table, rbs_rng *rng)
{
    double *V = malloc(3 * THREADED * sizeof *V), *Omega = malloc(3 * THREADED * sizeof *Omega);
    double *u = malloc(RBS_U_PER_REBOUND * THREADED * sizeof *u), *out = malloc(4 * 3 * THREADED * sizeof *out);
    int *status = malloc(2 * THREADED * sizeof *status);
    if (!V || !Omega || !u || !out || !status) {
        CHECK(0, "out of memory");
        free(V), free(Omega), free(u), free(out), free(status);
        return;
    }
    for (int i = 0; i < THREADED; i++) {
        double angle = 0.05 + 1.5 * rbs_rng_uniform(rng);
        V[3 * i] = 150.0 * cos(angle);
        V[3 * i + 1] = -150.0 * sin(angle);
        V[3 * i + 2] = 0.0;
        for (int k = 0; k < 3; k++) Omega[3 * i + k] = i % 2 ? 0.0 : 3e5 * (2.0 * rbs_rng_uniform(rng) - 1.0);
        rbs_rng_fill(rng, u + RBS_U_PER_REBOUND * i, RBS_U_PER_REBOUND);
    }
    job one = {table, V, Omega, u, out, out + 3 * THREADED, status, 0, THREADED};
    run_job(&one);
    pthread_t thread[THREADS];
    job part[THREADS];
    for (int k = 0; k < THREADS; k++) {
        part[k] = (job){table, V, Omega, u, out + 6 * THREADED, out + 9 * THREADED, status + THREADED,
                        k * THREADED / THREADS, (k + 1) * THREADED / THREADS};
        CHECK(pthread_create(&thread[k], NULL, run_job, &part[k]) == 0, "thread %d", k);
    }
    for (int k = 0; k < THREADS; k++) pthread_join(thread[k], NULL);
    CHECK(memcmp(status, status + THREADED, THREADED * sizeof *status) == 0, "statuses differ between threads");
    CHECK(memcmp(out, out + 6 * THREADED, 6 * THREADED * sizeof *out) == 0, "outputs differ between threads");
    printf("threads: %d particles on %d threads, the bits of one thread\n", THREADED, THREADS);
    free(V), free(Omega), free(u), free(out), free(status);
}

int main(int argc, char **argv)
{
    if (argc < 2 || argc > 3) {
        fprintf(stderr, "usage: %s GOOD.h5 [TABLE_WITHOUT_DIRECT_PARAMETERS.h5]\n", argv[0]);
        return 2;
    }
    rbs_rng rng;
    rbs_rng_seed(&rng, 2027);
    collisions(&rng);
    free_flights(&rng);
    rebounds(&rng);
    rbs_table *table = NULL, *without = NULL;
    char message[1024];
    CHECK(rbs_table_open(argv[1], &table, message, sizeof message) == RBS_OK, "%s", message);
    if (argc == 3) CHECK(rbs_table_open(argv[2], &without, message, sizeof message) == RBS_OK, "%s", message);
    if (table) {
        hostile(table, without);
        grain_model_frame(table, &rng);
        threads(table, &rng);
    }
    rbs_table_close(table);
    rbs_table_close(without);
    printf("%s: %d failure(s)\n", argv[0], failures);
    return failures == 0 ? 0 : 1;
}
