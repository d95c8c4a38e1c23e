/*
 * test_threads.c: concurrent draws from one table on several threads give the same results as one
 * thread, stream by stream (run by tests/native, also under the sanitizers).
 *
 *   rbs_test_threads TABLE.h5 THREADS ROWS
 *
 * Thread t draws ROWS incident states and their rebounds from stream t of seed 7
 * (rbs_rng_seed_stream), with rbs_rebound per particle (RBS_METHOD_TABLE, uniforms given), with rbs_draw_many
 * (uniforms from the rng) and with rbs_rebound (uniforms from the rng, every other hit spinning, |Ω⁻| a/|V⁻| = 0.5:
 * the direct model answers it); then the main thread redoes every stream alone and compares the bits.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rebound_scatter.h"

typedef struct work {
    const rbs_table *table;
    const rbs_mix *mix;
    pthread_barrier_t *start;
    uint64_t stream;
    size_t rows;
    double *V_out, *Omega_out;      /* (3 rows, 3): per-particle results, the many-particle ones, the spin ones */
    signed char *status;        /* (3 rows) */
} work;

static void *draw(void *argument)
{
    work *w = argument;
    size_t N = w->rows;
    double *V = malloc(3 * N * sizeof *V), *n = malloc(3 * N * sizeof *n), *a = malloc(N * sizeof *a);
    rbs_rng rng;
    rbs_rng_seed_stream(&rng, 7, w->stream);
    for (size_t i = 0; i < N; i++) {
        double u[6];
        rbs_rng_fill(&rng, u, 6);
        double z = 2.0 * u[0] - 1.0, phi = 6.283185307179586 * u[1], r = sqrt(1.0 - z * z);
        n[3 * i] = r * cos(phi);
        n[3 * i + 1] = r * sin(phi);
        n[3 * i + 2] = z;
        double speed = 20.0 + 300.0 * u[2];
        for (int k = 0; k < 3; k++) V[3 * i + k] = speed * ((2.0 * u[3 + k] - 1.0) - 1.5 * n[3 * i + k]);
        a[i] = 1e-4;
    }
    if (w->start) pthread_barrier_wait(w->start);
    rbs_options table_path = RBS_OPTIONS_INIT;
    table_path.method = RBS_METHOD_TABLE;
    rbs_hit hit = RBS_HIT_INIT;
    rbs_result result = RBS_RESULT_INIT;
    for (size_t i = 0; i < N; i++) {
        double u[RBS_U_PER_DRAW];
        rbs_rng_fill(&rng, u, RBS_U_PER_DRAW);
        memcpy(hit.V, V + 3 * i, sizeof hit.V);
        memcpy(hit.n, n + 3 * i, sizeof hit.n);
        hit.a = a[i];
        hit.u = u;
        w->status[i] = (signed char)rbs_rebound(w->table, w->mix, &hit, &table_path, &result);
        memcpy(w->V_out + 3 * i, result.V, sizeof result.V);
        memcpy(w->Omega_out + 3 * i, result.Omega, sizeof result.Omega);
    }
    rbs_hits hits = RBS_HITS_INIT;
    rbs_results results = RBS_RESULTS_INIT;
    hits.count = N, hits.V = V, hits.n = n, hits.a = a, hits.rng = &rng;
    results.V = w->V_out + 3 * N, results.Omega = w->Omega_out + 3 * N, results.status = w->status + N;
    rbs_draw_many(w->table, w->mix, &hits, NULL, &results);
    hit.u = NULL;
    hit.rng = &rng;
    for (size_t i = 0; i < N; i++) {
        const double *v = V + 3 * i;
        double w_i = i % 2 ? 0.5 * sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) / a[i] : 0.0;
        const double Omega[3] = {0.6 * w_i, 0.0, 0.8 * w_i};
        memcpy(hit.V, v, sizeof hit.V);
        memcpy(hit.Omega, Omega, sizeof hit.Omega);
        memcpy(hit.n, n + 3 * i, sizeof hit.n);
        hit.a = a[i];
        w->status[2 * N + i] = (signed char)rbs_rebound(w->table, w->mix, &hit, NULL, &result);
        memcpy(w->V_out + 3 * (2 * N + i), result.V, sizeof result.V);
        memcpy(w->Omega_out + 3 * (2 * N + i), result.Omega, sizeof result.Omega);
    }
    free(V);
    free(n);
    free(a);
    return NULL;
}

static work make_work(const rbs_table *table, const rbs_mix *mix, uint64_t stream, size_t rows)
{
    work w = {table, mix, NULL, stream, rows, malloc(9 * rows * sizeof(double)), malloc(9 * rows * sizeof(double)),
              malloc(3 * rows)};
    return w;
}

static void free_work(work *w)
{
    free(w->V_out);
    free(w->Omega_out);
    free(w->status);
}

int main(int argc, char **argv)
{
    if (argc < 4) {
        fprintf(stderr, "usage: %s TABLE.h5 THREADS ROWS\n", argv[0]);
        return 2;
    }
    int threads = atoi(argv[2]);
    size_t rows = (size_t)atol(argv[3]);
    char message[1024];
    rbs_table *table = NULL;
    if (rbs_table_open(argv[1], &table, message, sizeof message) != RBS_OK) {
        fprintf(stderr, "%s\n", message);
        return 1;
    }
    rbs_mix *mix = rbs_mix_new_equal(table);
    if (!mix) {
        fprintf(stderr, "out of memory\n");
        return 1;
    }
    pthread_t *ids = malloc((size_t)threads * sizeof *ids);
    work *jobs = malloc((size_t)threads * sizeof *jobs);
    pthread_barrier_t start;
    pthread_barrier_init(&start, NULL, (unsigned)threads);
    for (int t = 0; t < threads; t++) {
        jobs[t] = make_work(table, mix, (uint64_t)t, rows);
        jobs[t].start = &start;
        pthread_create(&ids[t], NULL, draw, &jobs[t]);
    }
    for (int t = 0; t < threads; t++) pthread_join(ids[t], NULL);
    pthread_barrier_destroy(&start);
    int differ = 0;
    size_t rebounded = 0;
    for (int t = 0; t < threads; t++) {
        work alone = make_work(table, mix, (uint64_t)t, rows);
        draw(&alone);
        if (memcmp(alone.V_out, jobs[t].V_out, 9 * rows * sizeof(double)) != 0
            || memcmp(alone.Omega_out, jobs[t].Omega_out, 9 * rows * sizeof(double)) != 0
            || memcmp(alone.status, jobs[t].status, 3 * rows) != 0) {
            fprintf(stderr, "stream %d: the threaded draws differ from the draws of one thread\n", t);
            differ++;
        }
        for (size_t i = 0; i < 3 * rows; i++) rebounded += alone.status[i] == RBS_OK;
        free_work(&alone);
        free_work(&jobs[t]);
    }
    printf("%d threads x %zu rows (per particle, many, spinning or not): %zu rebounded, %d stream(s) differ\n", threads, rows,
           rebounded, differ);
    free(ids);
    free(jobs);
    rbs_mix_free(mix);
    rbs_table_close(table);
    return differ == 0 && rebounded > 0 ? 0 : 1;
}
