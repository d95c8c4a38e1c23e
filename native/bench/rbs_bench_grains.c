/*
 * rbs_bench_grains.c: the C timing loop of benchmarks/bench_grains.py (the direct model's cost per rebound against
 * a hull's size).
 *
 *   rbs_bench_grains SHAPES.bin STATES.bin REPEATS OUT.bin
 *
 * SHAPES.bin: the shape arrays of direct_model.shape_arrays.ShapeArrays as the script writes them: int64 n_shapes,
 * then each array of rbs_shape_arrays in its order (kind .. far), each as an int64 byte count and its bytes.
 * STATES.bin: int64 m, then the model-frame states (m, 5: vt, vn, Ω⁻a), their uniforms (m, RBS_U_PER_REBOUND) and
 * the model's parameters (N_PARAMS), float64. Per shape, rbs_rebound_model_frame on every state, best of REPEATS
 * in this thread's CPU time: printed as one JSON list of µs per rebound. OUT.bin receives each shape's V⁺, Ω⁺
 * ((m, 3) float64 each) and status (m int8), for a comparison of the bits with numba's.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "rebound_scatter.h"

#include "runtime.h" /* the model's internal kernels: rbs_rebound_model_frame on shape arrays */
#include "shapes.h"

#define N_ARRAYS 13

static double cpu_seconds(void)
{
    struct timespec t;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* the next array of f: its int64 byte count, then its bytes (malloc'ed; NULL for none or a failure, *ok = 0) */
static void *read_array(FILE *f, int *ok)
{
    long long bytes = -1;
    if (fread(&bytes, sizeof bytes, 1, f) != 1 || bytes < 0) {
        *ok = 0;
        return NULL;
    }
    void *x = malloc(bytes > 0 ? (size_t)bytes : 1);
    if (!x || fread(x, 1, (size_t)bytes, f) != (size_t)bytes) *ok = 0;
    return x;
}

int main(int argc, char **argv)
{
    if (argc != 5) {
        fprintf(stderr, "usage: %s SHAPES.bin STATES.bin REPEATS OUT.bin\n", argv[0]);
        return 2;
    }
    FILE *f = fopen(argv[1], "rb");
    long long n_shapes = 0;
    int ok = f && fread(&n_shapes, sizeof n_shapes, 1, f) == 1 && n_shapes > 0;
    void *arrays[N_ARRAYS] = {NULL};
    for (int k = 0; ok && k < N_ARRAYS; k++) arrays[k] = read_array(f, &ok);
    if (f) fclose(f);
    FILE *g = fopen(argv[2], "rb");
    long long m = 0;
    ok = ok && g && fread(&m, sizeof m, 1, g) == 1 && m > 0;
    double *model = ok ? malloc((size_t)m * 5 * sizeof *model) : NULL;
    double *u = ok ? malloc((size_t)m * RBS_U_PER_REBOUND * sizeof *u) : NULL;
    double params[N_PARAMS];
    ok = ok && model && u && fread(model, sizeof *model, (size_t)m * 5, g) == (size_t)m * 5
         && fread(u, sizeof *u, (size_t)m * RBS_U_PER_REBOUND, g) == (size_t)m * RBS_U_PER_REBOUND
         && fread(params, sizeof *params, N_PARAMS, g) == N_PARAMS;
    if (g) fclose(g);
    if (!ok) {
        fprintf(stderr, "%s, %s: cannot read the shapes and states\n", argv[1], argv[2]);
        return 1;
    }
    const rbs_shape_arrays shapes = {(int)n_shapes, arrays[0], arrays[1], arrays[2], arrays[3], arrays[4], arrays[5],
                                     arrays[6], arrays[7], arrays[8], arrays[9], arrays[10], arrays[11], arrays[12]};
    int repeats = atoi(argv[3]);
    double *V = malloc((size_t)m * 3 * sizeof *V), *W = malloc((size_t)m * 3 * sizeof *W);
    signed char *status = malloc((size_t)m);
    FILE *out = fopen(argv[4], "wb");
    if (!V || !W || !status || !out) {
        fprintf(stderr, "%s: cannot write the outputs\n", argv[4]);
        return 1;
    }
    printf("[");
    for (int shape = 0; shape < n_shapes; shape++) {
        double best = 1e300;
        for (int r = 0; r < (repeats > 0 ? repeats : 1); r++) {
            double t0 = cpu_seconds();
            for (long long i = 0; i < m; i++) {
                const double *x = model + 5 * i;
                status[i] = (signed char)rbs_rebound_model_frame(params, &shapes, shape, x[0], x[1], x[2], x[3], x[4],
                                                                 u + RBS_U_PER_REBOUND * i, V + 3 * i, W + 3 * i);
            }
            double t = cpu_seconds() - t0;
            best = t < best ? t : best;
        }
        printf("%s%.6g", shape ? ", " : "", 1e6 * best / (double)m);
        fwrite(V, sizeof *V, (size_t)m * 3, out);
        fwrite(W, sizeof *W, (size_t)m * 3, out);
        fwrite(status, 1, (size_t)m, out);
    }
    printf("]\n");
    fclose(out);
    for (int k = 0; k < N_ARRAYS; k++) free(arrays[k]);
    free(model);
    free(u);
    free(V);
    free(W);
    free(status);
    return 0;
}
