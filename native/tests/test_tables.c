/*
 * test_tables.c: open good and bad tables, draw, close: run under AddressSanitizer and
 * UndefinedBehaviorSanitizer by tests/native (no report may appear, no leak).
 *
 *   rbs_test_tables GOOD.h5 [BAD_PATH EXPECTED_CODE]...
 *
 * Exit status 0 when every check passes; each failure is printed.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rebound_scatter.h"

static int failures = 0;

#define CHECK(condition, ...)                           \
    do {                                                \
        if (!(condition)) {                             \
            fprintf(stderr, "FAILED %s: ", #condition); \
            fprintf(stderr, __VA_ARGS__);               \
            fprintf(stderr, "\n");                      \
            failures++;                                 \
        }                                               \
    } while (0)

static void unit(rbs_rng *rng, double *v)
{
    double norm;
    do {
        for (int k = 0; k < 3; k++) v[k] = 2.0 * rbs_rng_uniform(rng) - 1.0;
        norm = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    } while (norm < 1e-3 || norm > 1.0);
    for (int k = 0; k < 3; k++) v[k] /= norm;
}

static void draw_from(const char *path)
{
    char message[1024];
    rbs_table *table = NULL;
    int code = rbs_table_open(path, &table, message, sizeof message);
    CHECK(code == RBS_OK && table != NULL, "%s", message);
    if (!table) return;
    int n_shapes = rbs_table_n_shapes(table);
    CHECK(n_shapes >= 1 && n_shapes <= RBS_MAX_SHAPES, "%d shapes", n_shapes);
    CHECK(rbs_table_shape_name(table, n_shapes) == NULL, "shape name beyond the count");
    CHECK(rbs_table_shape_name(table, -1) == NULL, "shape name -1");
    double lo, hi, vlo, vhi;
    rbs_table_alpha1_range(table, &lo, &hi);
    rbs_table_speed_range(table, &vlo, &vhi);
    CHECK(lo <= hi && vlo <= vhi, "ranges");
    rbs_table_info info;
    rbs_table_info_get(table, &info);
    CHECK(info.kernel_bytes > 0 && info.format_major == RBS_TABLE_MAJOR, "info");
    static const char *const arrays[] = {"alpha1_axis", "speed_axis", "cells", "clusters", "dictionary",
                                         "speed_restitution", "restitution_pieces"};
    for (int i = 0; i < 7; i++) {
        const void *data = NULL;
        size_t count = 0;
        int dtype = -1;
        CHECK(rbs_table_kernel_array(table, arrays[i], &data, &count, &dtype) == RBS_OK && data && count > 0,
              "%s", arrays[i]);
    }
    CHECK(rbs_table_kernel_array(table, "nothing", NULL, NULL, NULL) == RBS_ERR_ARGUMENT, "unknown array");

    /* mixes, good and bad */
    rbs_mix mix, other;
    CHECK(rbs_mix_equal(table, &mix) == RBS_OK, "equal mix");
    const char *names[2] = {rbs_table_shape_name(table, 0), "nonsense"};
    double weights[2] = {1.0, 0.0};
    CHECK(rbs_mix_from_weights(table, 1, names, weights, &other, message, sizeof message) == RBS_OK, "%s", message);
    CHECK(rbs_mix_from_weights(table, 2, names, weights, &other, message, sizeof message) == RBS_ERR_ARGUMENT,
          "unknown name accepted");
    weights[0] = -0.5;
    CHECK(rbs_mix_from_weights(table, 1, names, weights, &other, message, sizeof message) == RBS_ERR_ARGUMENT,
          "negative weight accepted");
    weights[0] = 0.7;
    CHECK(rbs_mix_from_weights(table, 1, names, weights, &other, message, sizeof message) == RBS_ERR_ARGUMENT,
          "weights summing to 0.7 accepted");
    weights[0] = NAN;
    CHECK(rbs_mix_from_weights(table, 1, names, weights, &other, message, sizeof message) == RBS_ERR_ARGUMENT,
          "NaN weight accepted");
    CHECK(rbs_mix_from_shape(table, "mix", &other, NULL, 0) == RBS_OK, "mix by name");
    CHECK(rbs_mix_from_shape(table, "sphere", &other, message, 8) == RBS_ERR_ARGUMENT && strlen(message) < 8,
          "bad shape name, short message buffer");

    /* draws: one by one, many, many with uniforms drawn, local */
    enum { N = 5000 };
    double *V = malloc(3 * N * sizeof *V), *n = malloc(3 * N * sizeof *n), *a = malloc(N * sizeof *a);
    double *u = malloc(RBS_U_PER_DRAW * N * sizeof *u);
    double *V_out = malloc(3 * N * sizeof *V_out), *Omega_out = malloc(3 * N * sizeof *Omega_out);
    double *V_one = malloc(3 * N * sizeof *V_one), *W_one = malloc(3 * N * sizeof *W_one);
    signed char *status = malloc(N);
    rbs_rng rng;
    rbs_rng_seed_stream(&rng, 42, 3);
    for (int i = 0; i < N; i++) {
        double t[3], nn[3];
        unit(&rng, nn);
        unit(&rng, t);
        double alpha1 = (95.0 * rbs_rng_uniform(&rng) - 2.0) * 0.017453292519943295;
        double speed = 0.5 * vlo + 1.5 * (vhi - 0.5 * vlo) * rbs_rng_uniform(&rng);
        double tn = t[0] * nn[0] + t[1] * nn[1] + t[2] * nn[2];
        for (int k = 0; k < 3; k++) t[k] -= tn * nn[k];
        double tl = sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
        for (int k = 0; k < 3; k++) {
            n[3 * i + k] = nn[k];
            V[3 * i + k] = speed * (cos(alpha1) * t[k] / tl - sin(alpha1) * nn[k]);
        }
        if (i % 97 == 0) V[3 * i] = NAN;
        if (i % 89 == 0) for (int k = 0; k < 3; k++) V[3 * i + k] = 0.0;
        if (i % 83 == 0) for (int k = 0; k < 3; k++) V[3 * i + k] = -speed * nn[k];
        a[i] = 1e-4;
    }
    rbs_rng_fill(&rng, u, RBS_U_PER_DRAW * N);
    int rebounded = 0;
    for (int i = 0; i < N; i++) {
        int st = rbs_rebound(table, &mix, V + 3 * i, n + 3 * i, a[i], u + RBS_U_PER_DRAW * i, i % 2, V_one + 3 * i,
                             W_one + 3 * i);
        CHECK(st == RBS_REBOUNDED || st == RBS_TRAPPED || st == RBS_INVALID, "status %d", st);
        rebounded += st == RBS_REBOUNDED;
    }
    CHECK(rebounded > N / 2, "%d rebounded of %d", rebounded, N);
    rbs_rebound_many(table, &mix, N, V, n, a, u, RBS_SCALED, V_out, Omega_out, status);
    for (int i = 0; i < N; i += 2)
        CHECK(memcmp(V_out + 3 * i, V_one + 3 * i, 3 * sizeof(double)) == 0 || isnan(V_out[3 * i]),
              "many differs from one at %d", i);
    rbs_rebound_many_rng(table, &mix, N, V, n, a, &rng, RBS_STOCHASTIC, V_out, Omega_out, status);
    rbs_rebound_many_rng(table, &mix, 0, V, n, a, &rng, RBS_SCALED, V_out, Omega_out, status);
    rbs_rebound_many_rng(table, &mix, 31, V, n, a, &rng, RBS_SCALED, V_out, Omega_out, status);
    rbs_rebound_many(table, &mix, 33, V, n, a, u, 7, V_out, Omega_out, status);
    CHECK(status[0] == RBS_INVALID && isnan(V_out[0]), "unknown interpolation gives invalid");
    for (int i = 0; i < 2000; i++) {
        double out[RBS_LOCAL_SIZE];
        int st = rbs_draw_local(table, &mix, -5.0 + 100.0 * u[i] , 0.5 * vlo + 2.0 * vhi * u[i + 1],
                                u + RBS_U_PER_DRAW * (i % N), i % 2, out);
        CHECK(st == RBS_REBOUNDED || st == RBS_TRAPPED, "local status %d", st);
        if (st == RBS_REBOUNDED) CHECK(out[2] >= 0.0 && out[2] <= 1.0, "s = %g", out[2]);
    }
    double out[RBS_LOCAL_SIZE];
    CHECK(rbs_draw_local(table, &mix, NAN, NAN, u, RBS_SCALED, out) != 99, "NaN local draw");
    CHECK(rbs_draw_local(table, NULL, 45.0, 100.0, u, RBS_SCALED, out) == RBS_INVALID, "NULL mix");
    rbs_mix wrong = mix;
    wrong.n_shapes = n_shapes + 1;
    CHECK(rbs_rebound(table, &wrong, V, n, a[0], u, RBS_SCALED, V_out, Omega_out) == RBS_INVALID, "mix of another table");
    free(V);
    free(n);
    free(a);
    free(u);
    free(V_out);
    free(Omega_out);
    free(V_one);
    free(W_one);
    free(status);
    rbs_table_close(table);
}

int main(int argc, char **argv)
{
    if (argc < 2 || argc % 2 != 0) {
        fprintf(stderr, "usage: %s GOOD.h5 [BAD_PATH EXPECTED_CODE]...\n", argv[0]);
        return 2;
    }
    rbs_table_close(NULL);
    CHECK(rbs_table_open(argv[1], NULL, NULL, 0) == RBS_ERR_ARGUMENT, "NULL table pointer");
    for (int repeat = 0; repeat < 2; repeat++) draw_from(argv[1]);
    for (int i = 2; i + 1 < argc; i += 2) {
        char message[2048];
        rbs_table *table = (rbs_table *)&message;     /* must be set to NULL on failure */
        int expected = atoi(argv[i + 1]);
        int code = rbs_table_open(argv[i], &table, message, sizeof message);
        CHECK(code == expected, "%s: code %d (%s), expected %d: %s", argv[i], code, rbs_error_string(code), expected,
              message);
        if (code != RBS_OK) {
            CHECK(table == NULL, "table not NULL after a failure");
            CHECK(strstr(message, argv[i]) != NULL, "the message does not name the file: %s", message);
            char tiny[16];
            CHECK(rbs_table_open(argv[i], &table, tiny, sizeof tiny) == code && strlen(tiny) < sizeof tiny,
                  "short buffer");
            CHECK(rbs_table_open(argv[i], &table, NULL, 0) == code, "NULL message");
        } else {
            rbs_table_close(table);
        }
        printf("%s: %d %s\n", argv[i], code, message);
    }
    for (int c = -1; c <= 6; c++) CHECK(rbs_error_string(c) != NULL, "error string %d", c);
    printf("%s: %d failure(s)\n", argv[0], failures);
    return failures == 0 ? 0 : 1;
}
