/*
 * rbs_bench_direct.c: the C timing loop of benchmarks/bench_direct.py --runtime (the direct model).
 *
 *   rbs_bench_direct TABLE.h5 STATES.bin SHAPE REPEATS SEED [OUT.bin]
 *
 * STATES.bin: int64 count, then V (count, 3) m/s, Omega (count, 3) rad/s, n (count, 3), a (count) m, as
 * float64 (row-major). SHAPE: a shape code (RBS_ELLIPSOID ..). The loop a solver runs: per state,
 * rbs_rng_fill (RBS_U_PER_REBOUND uniforms from one stream of SEED, as numba's fill_uniforms draws them)
 * and rbs_rebound_direct. Printed as one JSON object, best of REPEATS: us_per_rebound (this thread's CPU
 * time, which leaves out the time other jobs take on a shared machine), us_per_rebound_wall, and the
 * counts of each status. With OUT.bin, the outputs (V_out, Omega_out as float64 (count, 3), status as
 * int8) are written there, for a comparison of the bits with numba's.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "rebound_scatter.h"

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

int main(int argc, char **argv)
{
    if (argc < 6) {
        fprintf(stderr, "usage: %s TABLE.h5 STATES.bin SHAPE REPEATS SEED [OUT.bin]\n", argv[0]);
        return 2;
    }
    int shape = atoi(argv[3]), repeats = atoi(argv[4]);
    unsigned long long seed = strtoull(argv[5], NULL, 10);
    char message[1024];
    rbs_table *table = NULL;
    if (rbs_table_open(argv[1], &table, message, sizeof message) != RBS_OK) {
        fprintf(stderr, "%s\n", message);
        return 1;
    }
    FILE *f = fopen(argv[2], "rb");
    long long count = 0;
    if (!f || fread(&count, sizeof count, 1, f) != 1 || count <= 0) {
        fprintf(stderr, "%s: cannot read the states\n", argv[2]);
        return 1;
    }
    size_t N = (size_t)count;
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
            status[i] = (signed char)rbs_rebound_direct(table, shape, V + 3 * i, Omega + 3 * i, n + 3 * i, a[i], u,
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
           "\"rebounded\": %zu, \"trapped\": %zu, \"failed\": %zu, \"invalid\": %zu}\n",
           N, repeats, best / (double)N * 1e6, best_wall / (double)N * 1e6, counts[0], counts[1], counts[2], counts[3]);
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
