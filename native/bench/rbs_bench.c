/*
 * rbs_bench.c: the C timing loops of benchmarks/bench_native.py.
 *
 *   rbs_bench TABLE.h5 STATES.bin REPEATS SEED [OUT.bin]
 *
 * STATES.bin: int64 count, then V (count, 3), n (count, 3), a (count) as float64 (row-major). Times, best
 * of REPEATS, in ns per reflected state, printed as one JSON object:
 *   c_per_particle   a solver's loop: rbs_rng_fill (13 uniforms) and rbs_rebound (RBS_METHOD_TABLE, the uniforms
 *                    given) per particle
 *   c_many           rbs_draw_many on all the states, uniforms from the rng (32 xoshiro256+ lanes)
 *   c_many_given     rbs_draw_many on pre-drawn uniforms (their drawing not timed)
 *   c_rng            the 13 uniforms per state alone (rbs_rng_fill)
 *   c_grant_tabakoff the deterministic Grant–Tabakoff sphere bounce, same loop (bench_sampler.py's (d))
 *   c_spin_still     rbs_rebound with the uniforms from the rng (RBS_METHOD_AUTO, Ω⁻ = 0): the path decision's cost
 * and, under "cpu", the thread CPU time per state of each best run (steadier when other work shares the CPU);
 * then, in µs per hit, c_spin_spinning_us: rbs_rebound (RBS_METHOD_AUTO, rng) on the first SPINNING states with
 * |Ω⁻| a/|V⁻| = 0.3 about random axes (the direct model answers them), one timed run.
 *
 * With OUT.bin, the results of the first rbs_draw_many call from the rng (V_out, Omega_out as float64
 * (count, 3), status as int8) are written there, for a comparison of the bits.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "bench_io.h"
#include "rebound_scatter.h"

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static double cpu_now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* the best wall time of a stage, and the thread CPU time of that best run */
static void keep(int r, double wall, double cpu, double *best, double *best_cpu)
{
    if (r > 0 && wall < *best) {
        *best = wall;
        *best_cpu = cpu;
    }
}

/* Grant & Tabakoff (1975) restitution ratios, sand on 2024 aluminium, as polynomials in β1 (rad):
 * the bounce of benchmarks/bench_sampler.py (grant_tabakoff_bounce), written the same way. */
static void grant_tabakoff_bounce(const double *V, const double *n, double *V_out)
{
    static const double GT_NORMAL[4] = {1.0, -0.4159, 0.4994, -0.292};
    static const double GT_TANGENTIAL[4] = {1.0, -2.12, 3.0775, -1.1};
    double vn = V[0] * n[0] + V[1] * n[1] + V[2] * n[2];
    double tx = V[0] - vn * n[0], ty = V[1] - vn * n[1], tz = V[2] - vn * n[2];
    double vt = sqrt(tx * tx + ty * ty + tz * tz);
    double speed = sqrt(vn * vn + vt * vt);
    double ex[3] = {0.0, 0.0, 0.0};
    if (vt > 1e-12 * speed) {
        ex[0] = tx / vt;
        ex[1] = ty / vt;
        ex[2] = tz / vt;
    }
    double ez[3] = {ex[1] * n[2] - ex[2] * n[1], ex[2] * n[0] - ex[0] * n[2], ex[0] * n[1] - ex[1] * n[0]};
    double beta1 = atan2(-vn, vt);
    double e_n = GT_NORMAL[0] + beta1 * (GT_NORMAL[1] + beta1 * (GT_NORMAL[2] + beta1 * GT_NORMAL[3]));
    double e_t = GT_TANGENTIAL[0] + beta1 * (GT_TANGENTIAL[1] + beta1 * (GT_TANGENTIAL[2] + beta1 * GT_TANGENTIAL[3]));
    double lx = e_t * vt, ly = -e_n * vn, lz = 0.0;
    for (int k = 0; k < 3; k++) V_out[k] = lx * ex[k] + ly * n[k] + lz * ez[k];
}

int main(int argc, char **argv)
{
    if (argc < 5) {
        fprintf(stderr, "usage: %s TABLE.h5 STATES.bin REPEATS SEED\n", argv[0]);
        return 2;
    }
    int repeats = atoi(argv[3]);
    unsigned long long seed = strtoull(argv[4], NULL, 10);
    size_t N = 0;
    rbs_table *table = bench_open_table(argv[1]);
    FILE *f = table ? bench_open_states(argv[2], &N) : NULL;
    if (!f) return 1;
    double *V = malloc(3 * N * sizeof *V), *n = malloc(3 * N * sizeof *n), *a = malloc(N * sizeof *a);
    double *V_out = malloc(3 * N * sizeof *V_out), *Omega_out = malloc(3 * N * sizeof *Omega_out);
    double *U = malloc(RBS_U_PER_DRAW * N * sizeof *U);
    signed char *status = malloc(N);
    if (!V || !n || !a || !V_out || !Omega_out || !U || !status || fread(V, sizeof *V, 3 * N, f) != 3 * N
        || fread(n, sizeof *n, 3 * N, f) != 3 * N || fread(a, sizeof *a, N, f) != N) {
        fprintf(stderr, "%s: cannot read the states\n", argv[2]);
        return 1;
    }
    fclose(f);
    rbs_mix *mix = rbs_mix_new_equal(table);      /* the table's shapes, however many, equal weights */
    if (!mix) {
        fprintf(stderr, "out of memory\n");
        return 1;
    }
    /* first touch of the outputs, and a warm-up of every loop */
    for (size_t i = 0; i < 3 * N; i++) V_out[i] = Omega_out[i] = 0.0;
    rbs_rng rng;
    rbs_rng_seed(&rng, seed);
    rbs_rng_fill(&rng, U, RBS_U_PER_DRAW * N);

    double best[6] = {INFINITY, INFINITY, INFINITY, INFINITY, INFINITY, INFINITY}, cpu[6] = {0.0};
    double checksum = 0.0;
    rbs_options table_path = RBS_OPTIONS_INIT;
    table_path.method = RBS_METHOD_TABLE;
    rbs_hits hits = RBS_HITS_INIT;           /* every state; from the rng, or the uniforms U */
    hits.count = N, hits.V = V, hits.n = n, hits.a = a;
    rbs_results results = RBS_RESULTS_INIT;
    results.V = V_out, results.Omega = Omega_out, results.status = status;
    rbs_hit hit = RBS_HIT_INIT;             /* Ω⁻ = 0 */
    rbs_result result = RBS_RESULT_INIT;
    for (int r = 0; r < repeats + 1; r++) {         /* run 0 is the warm-up */
        double t0, dt, c0;
        /* (1) per particle: uniforms and one call per hit */
        rbs_rng_seed(&rng, seed);
        t0 = now();
        c0 = cpu_now();
        for (size_t i = 0; i < N; i++) {
            double u[RBS_U_PER_DRAW];
            rbs_rng_fill(&rng, u, RBS_U_PER_DRAW);
            for (int k = 0; k < 3; k++) {
                hit.V[k] = V[3 * i + k];
                hit.n[k] = n[3 * i + k];
            }
            hit.a = a[i];
            hit.u = u;
            status[i] = (signed char)rbs_rebound(table, mix, &hit, &table_path, &result);
            for (int k = 0; k < 3; k++) {
                V_out[3 * i + k] = result.V[k];
                Omega_out[3 * i + k] = result.Omega[k];
            }
        }
        dt = now() - t0;
        keep(r, dt, cpu_now() - c0, &best[0], &cpu[0]);
        checksum += V_out[0];
        /* (2) many particles, uniforms from the lanes */
        rbs_rng_seed(&rng, seed);
        t0 = now();
        c0 = cpu_now();
        hits.u = NULL;
        hits.rng = &rng;
        rbs_draw_many(table, mix, &hits, NULL, &results);
        dt = now() - t0;
        keep(r, dt, cpu_now() - c0, &best[1], &cpu[1]);
        checksum += V_out[0];
        if (r == 0 && argc > 5) {
            FILE *out = fopen(argv[5], "wb");
            if (!out || fwrite(V_out, sizeof *V_out, 3 * N, out) != 3 * N || fwrite(Omega_out, sizeof *Omega_out, 3 * N, out) != 3 * N
                || fwrite(status, 1, N, out) != N) {
                fprintf(stderr, "%s: cannot write the results\n", argv[5]);
                return 1;
            }
            fclose(out);
        }
        /* (3) many particles, uniforms given */
        t0 = now();
        c0 = cpu_now();
        hits.u = U;
        hits.rng = NULL;
        rbs_draw_many(table, mix, &hits, NULL, &results);
        dt = now() - t0;
        keep(r, dt, cpu_now() - c0, &best[2], &cpu[2]);
        checksum += V_out[0];
        /* (4) the uniforms alone */
        rbs_rng_seed(&rng, seed);
        double sum = 0.0;
        t0 = now();
        c0 = cpu_now();
        for (size_t i = 0; i < N; i++) {
            double u[RBS_U_PER_DRAW];
            rbs_rng_fill(&rng, u, RBS_U_PER_DRAW);
            for (int k = 0; k < RBS_U_PER_DRAW; k++) sum += u[k];
        }
        dt = now() - t0;
        keep(r, dt, cpu_now() - c0, &best[3], &cpu[3]);
        checksum += sum;
        /* (5) the Grant–Tabakoff bounce */
        t0 = now();
        c0 = cpu_now();
        for (size_t i = 0; i < N; i++) grant_tabakoff_bounce(V + 3 * i, n + 3 * i, V_out + 3 * i);
        dt = now() - t0;
        keep(r, dt, cpu_now() - c0, &best[4], &cpu[4]);
        checksum += V_out[0];
        /* (6) per particle through rbs_rebound, uniforms from the rng, no spin: the table answers, after the path
         * decision */
        rbs_rng_seed(&rng, seed);
        hit.u = NULL;
        hit.rng = &rng;
        t0 = now();
        c0 = cpu_now();
        for (size_t i = 0; i < N; i++) {
            for (int k = 0; k < 3; k++) {
                hit.V[k] = V[3 * i + k];
                hit.n[k] = n[3 * i + k];
            }
            hit.a = a[i];
            status[i] = (signed char)rbs_rebound(table, mix, &hit, NULL, &result);
            for (int k = 0; k < 3; k++) {
                V_out[3 * i + k] = result.V[k];
                Omega_out[3 * i + k] = result.Omega[k];
            }
        }
        dt = now() - t0;
        keep(r, dt, cpu_now() - c0, &best[5], &cpu[5]);
        checksum += V_out[0];
    }
    size_t trapped = 0;
    for (size_t i = 0; i < N; i++) trapped += status[i] != RBS_OK;
    size_t still_direct = 0;
    for (size_t i = 0; i < N; i++) {
        for (int k = 0; k < 3; k++) {
            hit.V[k] = V[3 * i + k];
            hit.n[k] = n[3 * i + k];
        }
        hit.a = a[i];
        still_direct += rbs_rebound_path(table, &hit, NULL) == RBS_PATH_DIRECT;
    }
    /* spinning hits: |Ω⁻| a/|V⁻| = 0.3 about random axes; the direct model answers */
    enum { SPINNING = 20000 };
    size_t n_spin = N < SPINNING ? N : SPINNING, spin_direct = 0;
    double *Omega = malloc(3 * n_spin * sizeof *Omega);
    rbs_rng_seed(&rng, seed + 1);
    for (size_t i = 0; i < n_spin; i++) {
        double w[3], ww, speed = sqrt(V[3 * i] * V[3 * i] + V[3 * i + 1] * V[3 * i + 1] + V[3 * i + 2] * V[3 * i + 2]);
        do {
            for (int k = 0; k < 3; k++) w[k] = 2.0 * rbs_rng_uniform(&rng) - 1.0;
            ww = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
        } while (ww > 1.0 || ww < 1e-3);
        for (int k = 0; k < 3; k++) {
            Omega[3 * i + k] = 0.3 * speed / a[i] * w[k] / ww;
            hit.V[k] = V[3 * i + k];
            hit.Omega[k] = Omega[3 * i + k];
            hit.n[k] = n[3 * i + k];
        }
        hit.a = a[i];
        spin_direct += rbs_rebound_path(table, &hit, NULL) == RBS_PATH_DIRECT;
    }
    rbs_rng_seed(&rng, seed);
    hit.u = NULL;
    hit.rng = &rng;
    double t0 = now();
    for (size_t i = 0; i < n_spin; i++) {
        for (int k = 0; k < 3; k++) {
            hit.V[k] = V[3 * i + k];
            hit.Omega[k] = Omega[3 * i + k];
            hit.n[k] = n[3 * i + k];
        }
        hit.a = a[i];
        status[i] = (signed char)rbs_rebound(table, mix, &hit, NULL, &result);
    }
    double spinning_us = (now() - t0) / (double)n_spin * 1e6;
    size_t spin_failed = 0;
    for (size_t i = 0; i < n_spin; i++) spin_failed += status[i] == RBS_FAILED;
    free(Omega);
    printf("{\"count\": %zu, \"repeats\": %d, \"c_per_particle\": %.3f, \"c_many\": %.3f, \"c_many_given\": %.3f, "
           "\"c_rng\": %.3f, \"c_grant_tabakoff\": %.3f, \"cpu\": {\"c_per_particle\": %.3f, \"c_many\": %.3f, "
           "\"c_many_given\": %.3f, \"c_rng\": %.3f, \"c_grant_tabakoff\": %.3f, \"c_spin_still\": %.3f}, "
           "\"not_rebounded\": %zu, \"checksum\": %.17g, \"c_spin_still\": %.3f, \"still_direct\": %zu, "
           "\"c_spin_spinning_us\": %.4f, \"spinning\": %zu, \"spinning_direct\": %zu, \"spinning_failed\": %zu}\n",
           N, repeats, best[0] / (double)N * 1e9, best[1] / (double)N * 1e9, best[2] / (double)N * 1e9,
           best[3] / (double)N * 1e9, best[4] / (double)N * 1e9, cpu[0] / (double)N * 1e9, cpu[1] / (double)N * 1e9,
           cpu[2] / (double)N * 1e9, cpu[3] / (double)N * 1e9, cpu[4] / (double)N * 1e9, cpu[5] / (double)N * 1e9,
           trapped, checksum, best[5] / (double)N * 1e9, still_direct, spinning_us, n_spin, spin_direct, spin_failed);
    free(V);
    free(n);
    free(a);
    free(V_out);
    free(Omega_out);
    free(U);
    free(status);
    rbs_mix_free(mix);
    rbs_table_close(table);
    return 0;
}
