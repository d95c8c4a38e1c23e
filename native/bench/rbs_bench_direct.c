/*
 * rbs_bench_direct.c: the C timing loop of benchmarks/bench_direct.py --runtime (the direct model).
 *
 *   rbs_bench_direct TABLE.h5 STATES.bin SHAPE REPEATS SEED [OUT.bin [PIECES.bin]]
 *
 * STATES.bin: int64 count, then V (count, 3) m/s, Omega (count, 3) rad/s, n (count, 3), a (count) m, as
 * float64 (row-major). SHAPE: a shape code (RBS_ELLIPSOID ..). The loop a solver runs: per state,
 * rbs_rng_fill (RBS_U_PER_REBOUND uniforms from one stream of SEED, as numba's fill_uniforms draws them)
 * and rbs_direct_rebound. Printed as one JSON object, best of REPEATS: us_per_rebound (this thread's CPU
 * time, which leaves out the time other jobs take on a shared machine), us_per_rebound_wall, and the
 * counts of each status. With OUT.bin, the outputs (V_out, Omega_out as float64 (count, 3), status as
 * int8) are written there, for a comparison of the bits with numba's.
 *
 * With PIECES.bin (int64 m, then per row as float64: semi-axes (3), R row-major (9), vertices (MAX_VERTICES,
 * 3), vertex count, Ω after the rebound ((m/s)/a, 3), a time t (a/(m/s)), the model-frame inputs vt, vn, wx,
 * wy, wz, the RBS_U_PER_REBOUND uniforms), the pieces of bench_direct.py's time split are timed as its numba
 * loops time them, in µs per call: us_model_frame (rbs_rebound_model_frame alone), us_flight_setup (K in the
 * lab frame, ℓ, rbs_rotation_init, rbs_curvature_bound, rbs_jerk_bound), us_orientation (rbs_rotation_at at t),
 * us_lowest_points (rbs_lowest_points with the rates and g̈ for the curvatures), us_collision (the body at rest
 * touching the wall at its lowest point hit at (vt, vn, 0): K⁻¹ in the lab frame, rbs_collide); each the best of
 * 5 × REPEATS.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "bench_io.h"
#include "rebound_scatter.h"

#include "collision.h"   /* the model's internal kernels, for the time split, and the direct path alone */
#include "flight.h"
#include "paths.h"
#include "rotation.h"
#include "runtime.h"
#include "shapes.h"

/* one row of PIECES.bin */
enum { PIECE_SEMI = 0, PIECE_R = 3, PIECE_VERTS = 12, PIECE_NV = PIECE_VERTS + 3 * MAX_VERTICES, PIECE_W, PIECE_T = PIECE_W + 3,
       PIECE_MODEL, PIECE_U = PIECE_MODEL + 5, PIECE_SIZE = PIECE_U + RBS_U_PER_REBOUND };

static double seconds(clockid_t clock)
{
    struct timespec t;
    clock_gettime(clock, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int read_doubles(FILE *f, double *x, size_t count)
{
    return fread(x, sizeof *x, count, f) == count;
}

/* out = R diag(d) Rᵀ (R row-major): a body-frame principal tensor in the lab frame */
static void lab_tensor(const double *R, const double *d, double *out)
{
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            out[3 * i + j] = R[3 * i] * d[0] * R[3 * j] + R[3 * i + 1] * d[1] * R[3 * j + 1] + R[3 * i + 2] * d[2] * R[3 * j + 2];
}

static void principal(const double *params, int shape, const double *semi, double K[3])
{
    double a2 = semi[0] * semi[0], b2 = semi[1] * semi[1], c2 = semi[2] * semi[2], s = params[P_KFAC + shape];
    K[0] = s * (b2 + c2);
    K[1] = s * (a2 + c2);
    K[2] = s * (a2 + b2);
}

/* the pieces, piece k over all m rows (see the header); returns a sum that keeps the calls alive */
static double run_piece(int k, const double *params, const rbs_shape_arrays *shapes, int shape, const double *rows,
                        size_t m, double *rot)
{
    double sum = 0.0, K[3], Kinv[3], T[9], ell[3], R[9], W[3], h[MAX_VERTICES], h1[MAX_VERTICES], curv[3];
    double verts[3 * MAX_VERTICES];
    int kind = shapes->kind[shape];
    for (size_t i = 0; i < m; i++) {
        const double *x = rows + i * PIECE_SIZE, *semi = x + PIECE_SEMI;
        int nv = (int)x[PIECE_NV];
        for (int j = 0; j < 3 * (nv > 1 ? nv : 1); j++) verts[j] = x[PIECE_VERTS + j]; /* the ellipsoid: 1 point */
        if (k == 0) {
            double V[3], Wo[3];
            sum += rbs_rebound_model_frame(params, shapes, shape, x[PIECE_MODEL], x[PIECE_MODEL + 1],
                                           x[PIECE_MODEL + 2],
                                           x[PIECE_MODEL + 3], x[PIECE_MODEL + 4], x + PIECE_U, V, Wo);
        } else if (k == 1) {
            const double *Wr = x + PIECE_W;
            principal(params, shape, semi, K);
            lab_tensor(x + PIECE_R, K, T);
            for (int j = 0; j < 3; j++) ell[j] = T[3 * j] * Wr[0] + T[3 * j + 1] * Wr[1] + T[3 * j + 2] * Wr[2];
            rbs_rotation_init(K, x + PIECE_R, ell, rot + i * RBS_ROT_PARAMS_SIZE);
            double Rb = rbs_bounding_radius(kind, semi, verts, nv);
            sum += rbs_curvature_bound(kind, semi, Rb, K, ell, Wr) + rbs_jerk_bound(kind, semi, Rb, K, ell, Wr);
        } else if (k == 2) {
            rbs_rotation_at(rot + i * RBS_ROT_PARAMS_SIZE, x[PIECE_T], R, W);
            sum += R[0];
        } else if (k == 3) {
            principal(params, shape, semi, K);
            sum += rbs_lowest_points(kind, verts, nv, semi, K, x + PIECE_R, x + PIECE_W, 1.0, 0.0, h, h1, curv);
        } else {
            double V[3] = {x[PIECE_MODEL], x[PIECE_MODEL + 1], 0.0}, W0[3] = {0.0, 0.0, 0.0}, dV[3], dW[3], r[3];
            const double *Ri = x + PIECE_R;
            principal(params, shape, semi, K);
            int n = rbs_lowest_points(kind, verts, nv, semi, K, Ri, W0, 0.0, 0.0, h, h1, curv), low = 0;
            for (int j = 0; j < n; j++) low = h[j] < h[low] ? j : low;
            for (int j = 0; j < 3; j++) {
                r[j] = Ri[3 * j] * verts[3 * low] + Ri[3 * j + 1] * verts[3 * low + 1] + Ri[3 * j + 2] * verts[3 * low + 2];
                Kinv[j] = 1.0 / K[j];
            }
            lab_tensor(Ri, Kinv, T);
            sum += rbs_collide(V, W0, r, T, params + P_WALL, dV, dW);
        }
    }
    return sum;
}

/* µs per call of each piece, best of runs (thread CPU time), printed as JSON members */
static int time_pieces(const rbs_table *table, int shape, const char *path, int runs)
{
    const double *params = NULL;
    size_t n_params = 0;
    int dtype = 0;
    if (rbs_table_kernel_array(table, "direct_parameters", (const void **)&params, &n_params, &dtype) != RBS_OK) {
        fprintf(stderr, "the table has no direct parameters\n");
        return 0;
    }
    FILE *f = fopen(path, "rb");
    long long count = 0;
    if (!f || fread(&count, sizeof count, 1, f) != 1 || count <= 0) {
        fprintf(stderr, "%s: cannot read the pieces\n", path);
        return 0;
    }
    size_t m = (size_t)count;
    double *rows = malloc(m * PIECE_SIZE * sizeof *rows), *rot = malloc(m * RBS_ROT_PARAMS_SIZE * sizeof *rot);
    if (!rows || !rot || !read_doubles(f, rows, m * PIECE_SIZE)) {
        fprintf(stderr, "%s: cannot read the pieces\n", path);
        return 0;
    }
    fclose(f);
    /* the families' shapes, as the loader builds them from the parameters */
    int8_t kind[RBS_N_FAMILIES];
    int64_t vertex_start[RBS_N_FAMILIES + 1];
    double vertices[3 * FAMILY_VERTEX_ROWS], moments[3 * RBS_N_FAMILIES], law[4 * RBS_N_FAMILIES];
    double law_cdf[2 * RBS_N_FAMILIES];
    uint8_t hands[RBS_N_FAMILIES];
    rbs_family_shapes_fill(kind, vertex_start, vertices, moments, law, law_cdf, hands, params[P_KAPPA],
                           params + P_ASPECT_MEAN, params + P_CDF_LOW, params + P_KFAC);
    rbs_shape_arrays families = {.n_shapes = RBS_N_FAMILIES, .kind = kind, .vertex_start = vertex_start,
                                 .vertices = vertices, .second_moments = moments, .aspect = law,
                                 .aspect_cdf = law_cdf, .both_hands = hands};
    static const char *names[5] = {"us_model_frame", "us_flight_setup", "us_orientation", "us_lowest_points",
                                   "us_collision"};
    double keep = 0.0;
    for (int k = 0; k < 5; k++) {
        double best = INFINITY;
        for (int r = 0; r < runs + 1; r++) {    /* run 0 is the warm-up */
            double c0 = seconds(CLOCK_THREAD_CPUTIME_ID);
            keep += run_piece(k, params, &families, shape, rows, m, rot);
            double cpu = seconds(CLOCK_THREAD_CPUTIME_ID) - c0;
            if (r > 0 && cpu < best) best = cpu;
        }
        printf(", \"%s\": %.4f", names[k], best / (double)m * 1e6);
    }
    printf(", \"pieces_checksum\": %.17g", keep);
    free(rows);
    free(rot);
    return 1;
}

int main(int argc, char **argv)
{
    if (argc < 6) {
        fprintf(stderr, "usage: %s TABLE.h5 STATES.bin SHAPE REPEATS SEED [OUT.bin]\n", argv[0]);
        return 2;
    }
    int shape = atoi(argv[3]), repeats = atoi(argv[4]);
    unsigned long long seed = strtoull(argv[5], NULL, 10);
    size_t N = 0;
    rbs_table *table = bench_open_table(argv[1]);
    FILE *f = table ? bench_open_states(argv[2], &N) : NULL;
    if (!f) return 1;
    double *V = malloc(3 * N * sizeof *V), *Omega = malloc(3 * N * sizeof *Omega), *n = malloc(3 * N * sizeof *n);
    double *a = malloc(N * sizeof *a), *V_out = malloc(3 * N * sizeof *V_out);
    double *Omega_out = malloc(3 * N * sizeof *Omega_out);
    signed char *status = malloc(N);
    if (!V || !Omega || !n || !a || !V_out || !Omega_out || !status || !read_doubles(f, V, 3 * N)
        || !read_doubles(f, Omega, 3 * N) || !read_doubles(f, n, 3 * N) || !read_doubles(f, a, N)) {
        fprintf(stderr, "%s: cannot read the states\n", argv[2]);
        return 1;
    }
    fclose(f);

    double best = INFINITY, best_wall = INFINITY;
    for (int r = 0; r < repeats + 1; r++) {         /* run 0 is the warm-up */
        rbs_rng rng;
        rbs_rng_seed(&rng, seed);
        double w0 = seconds(CLOCK_MONOTONIC), c0 = seconds(CLOCK_THREAD_CPUTIME_ID);
        for (size_t i = 0; i < N; i++) {
            double u[RBS_U_PER_REBOUND];
            rbs_rng_fill(&rng, u, RBS_U_PER_REBOUND);
            status[i] = (signed char)rbs_direct_rebound(table, shape, V + 3 * i, Omega + 3 * i, n + 3 * i, a[i], u,
                                                        V_out + 3 * i, Omega_out + 3 * i);
        }
        double cpu = seconds(CLOCK_THREAD_CPUTIME_ID) - c0, wall = seconds(CLOCK_MONOTONIC) - w0;
        if (r > 0 && cpu < best) best = cpu;
        if (r > 0 && wall < best_wall) best_wall = wall;
        if (r == 0 && argc > 6) {
            FILE *out = fopen(argv[6], "wb");
            if (!out || !(fwrite(V_out, sizeof *V_out, 3 * N, out) == 3 * N
                          && fwrite(Omega_out, sizeof *Omega_out, 3 * N, out) == 3 * N
                          && fwrite(status, 1, N, out) == N)) {
                fprintf(stderr, "%s: cannot write the results\n", argv[6]);
                return 1;
            }
            fclose(out);
        }
    }
    size_t counts[4] = {0, 0, 0, 0};                /* rebounded, trapped, failed, invalid */
    for (size_t i = 0; i < N; i++) counts[status[i] == RBS_INVALID ? 3 : status[i]]++;
    printf("{\"count\": %zu, \"repeats\": %d, \"us_per_rebound\": %.4f, \"us_per_rebound_wall\": %.4f, "
           "\"rebounded\": %zu, \"trapped\": %zu, \"failed\": %zu, \"invalid\": %zu",
           N, repeats, best / (double)N * 1e6, best_wall / (double)N * 1e6, counts[0], counts[1], counts[2], counts[3]);
    if (argc > 7 && !time_pieces(table, shape, argv[7], 5 * repeats)) return 1;
    printf("}\n");
    free(V);
    free(Omega);
    free(n);
    free(a);
    free(V_out);
    free(Omega_out);
    free(status);
    rbs_table_close(table);
    return 0;
}
