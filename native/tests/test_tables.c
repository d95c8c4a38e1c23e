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

#include "check.h"
#include "rebound_scatter.h"

static void unit(rbs_rng *rng, double *v)
{
    double norm;
    do {
        for (int k = 0; k < 3; k++) v[k] = 2.0 * rbs_rng_uniform(rng) - 1.0;
        norm = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    } while (norm < 1e-3 || norm > 1.0);
    for (int k = 0; k < 3; k++) v[k] /= norm;
}

/* every output NaN (count numbers) */
static int all_nan(const double *x, int count)
{
    for (int k = 0; k < count; k++)
        if (!isnan(x[k])) return 0;
    return 1;
}

/* a rebound's outputs: finite, leaving the wall (V⁺·n > 0) */
static int physical(const double *V_out, const double *W_out, const double *n)
{
    for (int k = 0; k < 3; k++)
        if (!isfinite(V_out[k]) || !isfinite(W_out[k])) return 0;
    return V_out[0] * n[0] + V_out[1] * n[1] + V_out[2] * n[2] > 0.0;
}

/* Hostile arguments to the draw functions: uniforms outside [0, 1) or NaN, NULL pointers, extreme
 * speeds, half-sizes and normals, an all-zero generator, local states outside the physical range. None may
 * crash or read outside the table (the sanitizers watch); each gives RBS_INVALID and NaN, or a finite
 * rebound leaving the wall. */
static void hostile_draws(const rbs_table *table, const rbs_mix *mix, double vlo, double vhi)
{
    const double V[3] = {40.0, -0.3, 0.0}, n[3] = {0.0, 1.0, 0.0};
    double u[RBS_U_PER_DRAW], good[RBS_U_PER_DRAW], V_out[3], W_out[3], out[RBS_LOCAL_SIZE], ref[RBS_LOCAL_SIZE];
    rbs_rng rng;
    rbs_rng_seed(&rng, 25);
    rbs_rng_fill(&rng, good, RBS_U_PER_DRAW);
    const int good_status = rbs_table_rebound(table, mix, V, n, 1e-4, good, RBS_SCALED, V_out, W_out);
    CHECK(good_status == RBS_REBOUNDED || good_status == RBS_TRAPPED, "good uniforms: status %d", good_status);
    int st;

    static const double bad[] = {-0.5, 1.0, 1e6, 1e300, -1e300, INFINITY, -INFINITY, NAN, -1e-300};
    for (int k = 0; k < RBS_U_PER_DRAW; k++) {
        for (size_t j = 0; j < sizeof bad / sizeof bad[0]; j++) {
            memcpy(u, good, sizeof u);
            u[k] = bad[j];
            st = rbs_table_rebound(table, mix, V, n, 1e-4, u, j % 2, V_out, W_out);
            CHECK(st == RBS_INVALID && all_nan(V_out, 3) && all_nan(W_out, 3), "u[%d] = %g: status %d", k, bad[j], st);
            st = rbs_draw_local(table, mix, 45.0, 200.0, u, j % 2, out);
            CHECK(st == RBS_INVALID && all_nan(out, RBS_LOCAL_SIZE), "local u[%d] = %g: status %d", k, bad[j], st);
        }
    }

    /* NULL pointers */
    CHECK(rbs_table_rebound(table, mix, NULL, n, 1e-4, good, RBS_SCALED, V_out, W_out) == RBS_INVALID
          && all_nan(V_out, 3), "NULL V");
    CHECK(rbs_table_rebound(table, mix, V, NULL, 1e-4, good, RBS_SCALED, V_out, W_out) == RBS_INVALID, "NULL n");
    CHECK(rbs_table_rebound(table, mix, V, n, 1e-4, NULL, RBS_SCALED, V_out, W_out) == RBS_INVALID, "NULL u");
    CHECK(rbs_table_rebound(table, mix, V, n, 1e-4, good, RBS_SCALED, NULL, W_out) == RBS_INVALID && all_nan(W_out, 3),
          "NULL V_out");
    CHECK(rbs_table_rebound(table, mix, V, n, 1e-4, good, RBS_SCALED, V_out, NULL) == RBS_INVALID, "NULL Omega_out");
    CHECK(rbs_draw_local(table, mix, 45.0, 200.0, NULL, RBS_SCALED, out) == RBS_INVALID, "local NULL u");
    CHECK(rbs_draw_local(table, mix, 45.0, 200.0, good, RBS_SCALED, NULL) == RBS_INVALID, "local NULL out");
    signed char status[3];
    double Vm[9], nm[9], am[3], um[3 * RBS_U_PER_DRAW], Vo[9], Wo[9];
    for (int i = 0; i < 3; i++) {
        memcpy(Vm + 3 * i, V, sizeof V);
        memcpy(nm + 3 * i, n, sizeof n);
        memcpy(um + RBS_U_PER_DRAW * i, good, sizeof good);
        am[i] = 1e-4;
    }
    rbs_table_rebound_many(table, mix, 3, NULL, nm, am, um, RBS_SCALED, Vo, Wo, status);
    CHECK(status[0] == RBS_INVALID && status[2] == RBS_INVALID && all_nan(Vo, 9), "many: NULL V");
    rbs_table_rebound_many(table, mix, 3, Vm, nm, am, um, RBS_SCALED, NULL, NULL, status);
    CHECK(status[1] == RBS_INVALID, "many: NULL outputs");
    rbs_table_rebound_many(table, mix, 3, Vm, nm, am, NULL, RBS_SCALED, NULL, NULL, NULL);
    rbs_table_rebound_many_rng(table, mix, 3, Vm, nm, am, NULL, RBS_SCALED, Vo, Wo, status);
    CHECK(status[0] == RBS_INVALID, "many_rng: NULL rng");
    um[RBS_U_PER_DRAW + 5] = -0.5;     /* row 1's u[5]: that row alone is invalid */
    rbs_table_rebound_many(table, mix, 3, Vm, nm, am, um, RBS_SCALED, Vo, Wo, status);
    CHECK(status[1] == RBS_INVALID && status[0] == good_status && status[2] == good_status, "many, one bad row: %d %d %d", status[0],
          status[1], status[2]);

    /* generators: NULL and all zero (xoshiro256+'s fixed point) give NaN, never u = 0 forever */
    rbs_rng_seed(NULL, 1);
    rbs_rng_seed_stream(NULL, 1, 2);
    CHECK(isnan(rbs_rng_uniform(NULL)), "uniform of NULL");
    rbs_rng_fill(NULL, u, RBS_U_PER_DRAW);
    CHECK(all_nan(u, RBS_U_PER_DRAW), "fill from NULL");
    rbs_rng_fill(&rng, NULL, 5);
    rbs_table_rebound_uniforms(NULL, 3, um);
    CHECK(all_nan(um, 3 * RBS_U_PER_DRAW), "rebound_uniforms from NULL");
    rbs_rng zero = {{0, 0, 0, 0}};
    CHECK(isnan(rbs_rng_uniform(&zero)), "uniform of the zero state");
    rbs_rng_fill(&zero, u, RBS_U_PER_DRAW);
    CHECK(all_nan(u, RBS_U_PER_DRAW), "fill from the zero state");
    CHECK(rbs_table_rebound(table, mix, V, n, 1e-4, u, RBS_SCALED, V_out, W_out) == RBS_INVALID, "zero state draw");
    rbs_table_rebound_many_rng(table, mix, 3, Vm, nm, am, &zero, RBS_SCALED, Vo, Wo, status);
    CHECK(status[0] == RBS_INVALID && status[2] == RBS_INVALID, "many_rng: zero state");

    /* extreme particles: |V⁻| overflowing or underflowing, bad half-sizes and normals */
    static const double speeds[] = {1e200, 1e154, 1e-160, 1e-200, 5e-324};
    for (size_t j = 0; j < sizeof speeds / sizeof speeds[0]; j++) {
        const double Vs[3] = {speeds[j] * 0.8, -speeds[j] * 0.6, 0.0};
        st = rbs_table_rebound(table, mix, Vs, n, 1e-4, good, RBS_SCALED, V_out, W_out);
        CHECK(st == RBS_INVALID ? all_nan(V_out, 3) : st == RBS_TRAPPED || physical(V_out, W_out, n),
              "|V| = %g: status %d, V+ = (%g, %g, %g)", speeds[j], st, V_out[0], V_out[1], V_out[2]);
    }
    static const double sizes[] = {0.0, -1e-4, NAN, INFINITY, 5e-324, -INFINITY};
    for (size_t j = 0; j < sizeof sizes / sizeof sizes[0]; j++) {
        st = rbs_table_rebound(table, mix, V, n, sizes[j], good, RBS_SCALED, V_out, W_out);
        CHECK(st == RBS_INVALID && all_nan(W_out, 3), "a = %g: status %d", sizes[j], st);
    }
    static const double lengths[] = {1e200, 2.0, 0.5, 1.0 + 1e-5, 1e-200};
    for (size_t j = 0; j < sizeof lengths / sizeof lengths[0]; j++) {
        const double nl[3] = {0.0, lengths[j], 0.0};
        st = rbs_table_rebound(table, mix, V, nl, 1e-4, good, RBS_SCALED, V_out, W_out);
        CHECK(st == RBS_INVALID && all_nan(V_out, 3), "|n| = %g: status %d", lengths[j], st);
    }

    /* local draws: α1 outside (0, 90] or NaN, |V⁻| not finite and > 0; a huge |V⁻| is the top grid edge */
    static const double alphas[] = {NAN, -5.0, 0.0, 90.0001, 1e30, -INFINITY, INFINITY};
    for (size_t j = 0; j < sizeof alphas / sizeof alphas[0]; j++)
        CHECK(rbs_draw_local(table, mix, alphas[j], 200.0, good, RBS_SCALED, out) == RBS_INVALID
              && all_nan(out, RBS_LOCAL_SIZE), "local alpha1 = %g", alphas[j]);
    static const double local_speeds[] = {NAN, -1.0, 0.0, INFINITY, -INFINITY};
    for (size_t j = 0; j < sizeof local_speeds / sizeof local_speeds[0]; j++)
        CHECK(rbs_draw_local(table, mix, 45.0, local_speeds[j], good, RBS_SCALED, out) == RBS_INVALID,
              "local speed = %g", local_speeds[j]);
    int top = rbs_draw_local(table, mix, 45.0, vhi, good, RBS_SCALED, ref);
    CHECK(rbs_draw_local(table, mix, 45.0, 1e25, good, RBS_SCALED, out) == top
          && (top != RBS_REBOUNDED || memcmp(out, ref, sizeof out) == 0), "speed 1e25 is not the top grid edge");
    int bottom = rbs_draw_local(table, mix, 45.0, vlo, good, RBS_SCALED, ref);
    CHECK(rbs_draw_local(table, mix, 45.0, 1e-300, good, RBS_SCALED, out) == bottom
          && (bottom != RBS_REBOUNDED || memcmp(out, ref, sizeof out) == 0), "speed 1e-300 is not the bottom grid edge");

    /* random hostile uniforms and particles: whatever comes back as a rebound is finite and leaves the wall */
    for (int i = 0; i < 20000; i++) {
        double Vr[3], nr[3];
        for (int k = 0; k < RBS_U_PER_DRAW; k++) u[k] = 3.0 * rbs_rng_uniform(&rng) - 1.0;
        for (int k = 0; k < 3; k++) {
            Vr[k] = ldexp(2.0 * rbs_rng_uniform(&rng) - 1.0, (int)(1200.0 * rbs_rng_uniform(&rng)) - 600);
            nr[k] = 2.0 * rbs_rng_uniform(&rng) - 1.0;
        }
        double a = ldexp(rbs_rng_uniform(&rng), (int)(1200.0 * rbs_rng_uniform(&rng)) - 600);
        st = rbs_table_rebound(table, mix, Vr, nr, a, u, i % 2, V_out, W_out);
        CHECK(st == RBS_INVALID || st == RBS_TRAPPED || physical(V_out, W_out, nr), "random hostile draw %d", i);
        st = rbs_draw_local(table, mix, 100.0 * u[0], ldexp(u[1], (int)(2000.0 * u[2]) - 1000), u, i % 2, out);
        CHECK(st == RBS_INVALID || st == RBS_TRAPPED || (isfinite(out[2]) && out[2] >= 0.0), "random local draw %d", i);
    }
}

/* every hit answered (rbs_rebound_rng, rbs_rebound, rbs_rebound_path): spinning and hostile hits under
 * the three methods; whatever rebounds is finite and leaves the wall, the rest is NaN */
static void spin_draws(const rbs_table *table, const rbs_mix *mix, double vlo, double vhi)
{
    rbs_rng rng;
    rbs_rng_seed_stream(&rng, 28, 1);
    const double n[3] = {0.0, 1.0, 0.0}, still[3] = {0.0, 0.0, 0.0}, a = 1e-4;
    double V[3] = {100.0, -100.0, 0.0}, V_out[3], W_out[3], u[RBS_U_PER_DRAW];
    double spin[3] = {0.0, 0.0, 0.3 * sqrt(2e4) / a};        /* |Omega-| a/|V-| = 0.3 */
    rbs_rng_fill(&rng, u, RBS_U_PER_DRAW);
    CHECK(rbs_rebound_path(table, V, still, n, a, RBS_AUTO) == RBS_PATH_TABLE, "no spin at 45 deg: the table");
    CHECK(rbs_rebound_path(table, V, spin, n, a, RBS_AUTO) == RBS_PATH_DIRECT, "spin 0.3: the direct model");
    CHECK(rbs_rebound_path(table, V, spin, n, a, RBS_TABLE) == RBS_PATH_TABLE, "method table");
    CHECK(rbs_rebound_path(table, V, still, n, a, RBS_DIRECT) == RBS_PATH_DIRECT, "method direct");
    /* the direct model does not take a user's grain yet: a hit of one it would answer is RBS_INVALID */
    int grains = 0;
    for (int i = 0; i < rbs_table_n_shapes(table); i++) {
        rbs_shape_info shape;
        rbs_table_shape_info(table, i, &shape);
        grains += shape.family < 0;
    }
    for (int method = RBS_AUTO; method <= RBS_DIRECT; method++) {
        int st = rbs_rebound(table, mix, V, spin, n, a, u, method, RBS_SCALED, V_out, W_out);
        CHECK(st == RBS_REBOUNDED ? physical(V_out, W_out, n)
                                  : (st != RBS_INVALID || (grains > 0 && method != RBS_TABLE)) && all_nan(V_out, 3),
              "spinning hit, method %d: status %d", method, st);
    }
    /* NULL pointers, bad methods, bad Omega-, a NULL or all-zero rng */
    const double bad_spins[3] = {NAN, INFINITY, -INFINITY};
    for (int j = 0; j < 3; j++) {
        double W_bad[3] = {1.0, bad_spins[j], 1.0};
        CHECK(rbs_rebound_path(table, V, W_bad, n, a, RBS_AUTO) == RBS_INVALID, "Omega %g: path", bad_spins[j]);
        CHECK(rbs_rebound(table, mix, V, W_bad, n, a, u, RBS_TABLE, RBS_SCALED, V_out, W_out) == RBS_INVALID
              && all_nan(V_out, 3) && all_nan(W_out, 3), "Omega %g", bad_spins[j]);
    }
    CHECK(rbs_rebound(NULL, mix, V, spin, n, a, u, RBS_AUTO, RBS_SCALED, V_out, W_out) == RBS_INVALID
          && all_nan(V_out, 3), "spin: NULL table");
    CHECK(rbs_rebound(table, NULL, V, spin, n, a, u, RBS_AUTO, RBS_SCALED, V_out, W_out) == RBS_INVALID,
          "spin: NULL mix");
    CHECK(rbs_rebound(table, mix, NULL, spin, n, a, u, RBS_AUTO, RBS_SCALED, V_out, W_out) == RBS_INVALID,
          "spin: NULL V");
    CHECK(rbs_rebound(table, mix, V, NULL, n, a, u, RBS_AUTO, RBS_SCALED, V_out, W_out) == RBS_INVALID,
          "spin: NULL Omega");
    CHECK(rbs_rebound(table, mix, V, spin, NULL, a, u, RBS_AUTO, RBS_SCALED, V_out, W_out) == RBS_INVALID,
          "spin: NULL n");
    CHECK(rbs_rebound(table, mix, V, spin, n, a, NULL, RBS_AUTO, RBS_SCALED, V_out, W_out) == RBS_INVALID,
          "spin: NULL u");
    CHECK(rbs_rebound(table, mix, V, spin, n, a, u, RBS_AUTO, RBS_SCALED, NULL, W_out) == RBS_INVALID
          && all_nan(W_out, 3), "spin: NULL V_out");
    CHECK(rbs_rebound(table, mix, V, spin, n, a, u, RBS_AUTO, RBS_SCALED, V_out, NULL) == RBS_INVALID,
          "spin: NULL Omega_out");
    CHECK(rbs_rebound(table, mix, V, spin, n, a, u, 3, RBS_SCALED, V_out, W_out) == RBS_INVALID, "method 3");
    CHECK(rbs_rebound(table, mix, V, spin, n, a, u, RBS_AUTO, 9, V_out, W_out) == RBS_INVALID,
          "spin: unknown interpolation");
    CHECK(rbs_rebound_path(table, NULL, spin, n, a, RBS_AUTO) == RBS_INVALID, "path: NULL V");
    CHECK(rbs_rebound_path(table, V, spin, n, a, -1) == RBS_INVALID, "path: method -1");
    rbs_rng zero = {{0, 0, 0, 0}};
    CHECK(rbs_rebound_rng(table, mix, V, spin, n, a, NULL, RBS_AUTO, RBS_SCALED, V_out, W_out) == RBS_INVALID
          && all_nan(V_out, 3), "spin: NULL rng");
    CHECK(rbs_rebound_rng(table, mix, V, spin, n, a, &zero, RBS_AUTO, RBS_SCALED, V_out, W_out) == RBS_INVALID,
          "spin: zero rng");
    /* random hits over and beyond the grid, spins from none to 2 |V-|/a, random methods; hostile particles */
    for (int i = 0; i < 3000; i++) {
        double Vr[3], nr[3], Wr[3];
        unit(&rng, nr);
        unit(&rng, Wr);
        double speed = 0.3 * vlo + 1.5 * vhi * rbs_rng_uniform(&rng);
        double ratio = i % 3 == 0 ? 0.0 : 2.0 * rbs_rng_uniform(&rng);
        for (int k = 0; k < 3; k++) {
            Vr[k] = speed * (2.0 * rbs_rng_uniform(&rng) - 1.0);
            Wr[k] *= ratio * speed / a;
        }
        if (i % 50 == 0) Vr[i % 3] = i % 100 == 0 ? NAN : 1e300;
        if (i % 70 == 0) nr[0] *= 3.0;
        int method = (int)(3.0 * rbs_rng_uniform(&rng)), path = rbs_rebound_path(table, Vr, Wr, nr, a, method);
        int st = rbs_rebound_rng(table, mix, Vr, Wr, nr, a, &rng, method, i % 2, V_out, W_out);
        CHECK(path != RBS_INVALID || st == RBS_INVALID, "random spin hit %d: path invalid, status %d", i, st);
        CHECK(st == RBS_REBOUNDED ? physical(V_out, W_out, nr) : all_nan(V_out, 3) && all_nan(W_out, 3),
              "random spin hit %d: status %d", i, st);
    }
    /* rbs_rebound_spin, kept for programs written against 0.x: rbs_rebound_rng's bits, its stream advanced alike */
    rbs_rng r_new, r_old;
    rbs_rng_seed_stream(&r_new, 28, 2);
    r_old = r_new;
    for (int i = 0; i < 40; i++) {
        const double *Omega = i % 2 ? spin : still;
        double V_new[3], W_new[3], V_old[3], W_old[3];
        int st_new = rbs_rebound_rng(table, mix, V, Omega, n, a, &r_new, i % 3, RBS_SCALED, V_new, W_new);
        int st_old = rbs_rebound_spin(table, mix, V, Omega, n, a, &r_old, i % 3, RBS_SCALED, V_old, W_old);
        CHECK(st_new == st_old && memcmp(V_new, V_old, sizeof V_new) == 0 && memcmp(W_new, W_old, sizeof W_new) == 0
              && memcmp(&r_new, &r_old, sizeof r_new) == 0, "rbs_rebound_spin (0.x), hit %d", i);
    }
}

static void draw_from(const char *path)
{
    char message[1024];
    rbs_table *table = NULL;
    int code = rbs_table_open(path, &table, message, sizeof message);
    CHECK(code == RBS_OK && table != NULL, "%s", message);
    if (!table) return;
    int n_shapes = rbs_table_n_shapes(table);
    CHECK(n_shapes >= 1 && n_shapes <= RBS_TABLE_MAX_SHAPES, "%d shapes", n_shapes);
    for (int i = 0; i < n_shapes; i++) {
        rbs_shape_info shape;
        CHECK(rbs_table_shape_info(table, i, &shape) == RBS_OK && strcmp(shape.name, rbs_table_shape_name(table, i)) == 0
              && (shape.kind == RBS_SMOOTH) == (shape.n_vertices == 0) && (shape.n_vertices == 0) == !shape.vertices,
              "shape info %d", i);
        for (int k = 0; k < 3 * shape.n_vertices; k++)
            CHECK(fabs(shape.vertices[k]) <= 1.5 + 1e-9, "shape %d vertex coordinate %g", i, shape.vertices[k]);
    }
    rbs_shape_info none;
    CHECK(rbs_table_shape_info(table, n_shapes, &none) == RBS_ERR_ARGUMENT
          && rbs_table_shape_info(table, 0, NULL) == RBS_ERR_ARGUMENT, "shape info out of range");
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

    /* mixes, good and bad: sized by the table, and 1.0's values (tables of at most RBS_MAX_SHAPES shapes) */
    rbs_mix *mix = rbs_mix_new_equal(table), other;
    CHECK(mix != NULL && mix->n_shapes == n_shapes, "equal mix");
    if (!mix) return;
    const char *names[2] = {rbs_table_shape_name(table, 0), "nonsense"};
    double weights[2] = {1.0, 0.0};
    rbs_mix *block = rbs_mix_new_from_weights(table, 2, names, weights, message, sizeof message);
    CHECK(!block && strstr(message, "nonsense"), "unknown name accepted by rbs_mix_new_from_weights");
    block = rbs_mix_new_from_shape(table, rbs_table_shape_name(table, n_shapes - 1), message, sizeof message);
    CHECK(block != NULL, "%s", message);
    rbs_mix_free(block);
    rbs_mix_free(NULL);
    CHECK(rbs_mix_new_equal(NULL) == NULL, "a mix of no table");
    if (n_shapes > RBS_MAX_SHAPES) {
        CHECK(rbs_mix_equal(table, &other) == RBS_ERR_ARGUMENT
              && rbs_mix_from_shape(table, "mix", &other, message, sizeof message) == RBS_ERR_ARGUMENT
              && strstr(message, "rbs_mix_new_"), "a value mix of %d shapes: %s", n_shapes, message);
    } else {
        CHECK(rbs_mix_equal(table, &other) == RBS_OK && memcmp(other.cdf, mix->cdf, sizeof other.cdf) == 0,
              "the value and the block give one equal mix");
    }
    CHECK((rbs_mix_from_weights(table, 1, names, weights, &other, message, sizeof message) == RBS_OK)
          == (n_shapes <= RBS_MAX_SHAPES), "%s", message);
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
    CHECK((rbs_mix_from_shape(table, "mix", &other, NULL, 0) == RBS_OK) == (n_shapes <= RBS_MAX_SHAPES), "mix by name");
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
        int st = rbs_table_rebound(table, mix, V + 3 * i, n + 3 * i, a[i], u + RBS_U_PER_DRAW * i, i % 2,
                                   V_one + 3 * i, W_one + 3 * i);
        CHECK(st == RBS_REBOUNDED || st == RBS_TRAPPED || st == RBS_INVALID, "status %d", st);
        rebounded += st == RBS_REBOUNDED;
    }
    CHECK(rebounded > N / 2, "%d rebounded of %d", rebounded, N);
    rbs_table_rebound_many(table, mix, N, V, n, a, u, RBS_SCALED, V_out, Omega_out, status);
    for (int i = 0; i < N; i += 2)
        CHECK(memcmp(V_out + 3 * i, V_one + 3 * i, 3 * sizeof(double)) == 0 || isnan(V_out[3 * i]),
              "many differs from one at %d", i);
    rbs_table_rebound_many_rng(table, mix, N, V, n, a, &rng, RBS_STOCHASTIC, V_out, Omega_out, status);
    rbs_table_rebound_many_rng(table, mix, 0, V, n, a, &rng, RBS_SCALED, V_out, Omega_out, status);
    rbs_table_rebound_many_rng(table, mix, 31, V, n, a, &rng, RBS_SCALED, V_out, Omega_out, status);
    rbs_table_rebound_many(table, mix, 33, V, n, a, u, 7, V_out, Omega_out, status);
    CHECK(status[0] == RBS_INVALID && isnan(V_out[0]), "unknown interpolation gives invalid");
    for (int i = 0; i < 2000; i++) {
        double out[RBS_LOCAL_SIZE], alpha1 = -5.0 + 100.0 * u[i];
        int st = rbs_draw_local(table, mix, alpha1, 0.5 * vlo + 2.0 * vhi * u[i + 1], u + RBS_U_PER_DRAW * (i % N),
                                i % 2, out);
        if (alpha1 > 0.0 && alpha1 <= 90.0)
            CHECK(st == RBS_REBOUNDED || st == RBS_TRAPPED, "local status %d at alpha1 %g", st, alpha1);
        else
            CHECK(st == RBS_INVALID, "local status %d at alpha1 %g", st, alpha1);
        if (st == RBS_REBOUNDED) CHECK(out[2] >= 0.0 && out[2] <= 1.0, "s = %g", out[2]);
    }
    double out[RBS_LOCAL_SIZE];
    CHECK(rbs_draw_local(table, mix, NAN, NAN, u, RBS_SCALED, out) == RBS_INVALID, "NaN local draw");
    hostile_draws(table, mix, vlo, vhi);
    spin_draws(table, mix, vlo, vhi);
    CHECK(rbs_draw_local(table, NULL, 45.0, 100.0, u, RBS_SCALED, out) == RBS_INVALID, "NULL mix");
    rbs_mix wrong = {n_shapes + 1, {1.0, 1.0, 1.0, 1.0}};
    CHECK(rbs_table_rebound(table, &wrong, V, n, a[0], u, RBS_SCALED, V_out, Omega_out) == RBS_INVALID,
          "mix of another table");
    free(V);
    free(n);
    free(a);
    free(u);
    free(V_out);
    free(Omega_out);
    free(V_one);
    free(W_one);
    free(status);
    rbs_mix_free(mix);
    rbs_table_close(table);
}

int main(int argc, char **argv)
{
    if (argc < 2 || argc % 2 != 0) {
        fprintf(stderr, "usage: %s GOOD.h5 [PATH EXPECTED_CODE]...\n", argv[0]);
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
            draw_from(argv[i]);         /* a good table among the files: every draw function on it */
        }
        printf("%s: %d %s\n", argv[i], code, message);
    }
    for (int c = -1; c <= 6; c++) CHECK(rbs_error_string(c) != NULL, "error string %d", c);
    printf("%s: %d failure(s)\n", argv[0], failures);
    return failures == 0 ? 0 : 1;
}
