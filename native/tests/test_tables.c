/*
 * test_tables.c: open good and bad tables, draw, close: run under AddressSanitizer and
 * UndefinedBehaviorSanitizer by tests/native (no report may appear, no leak). The public API alone.
 *
 *   rbs_test_tables GOOD.h5 [BAD_PATH EXPECTED_STATUS]...
 *
 * Exit status 0 when every check passes; each failure is printed.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#include <math.h>
#include <stddef.h>
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

/* two results field by field, vectors bit for bit (a memcmp of the records would read their padding) */
static int same_result(const rbs_result *a, const rbs_result *b)
{
    return a->status == b->status && a->path == b->path && a->shape == b->shape && a->n_collisions == b->n_collisions
           && a->wall_hits == b->wall_hits && memcmp(a->V, b->V, sizeof a->V) == 0
           && memcmp(a->Omega, b->Omega, sizeof a->Omega) == 0
           && memcmp(&a->wall_work_normal, &b->wall_work_normal, sizeof a->wall_work_normal) == 0
           && memcmp(&a->wall_work_tangential, &b->wall_work_tangential, sizeof a->wall_work_tangential) == 0;
}

/* a hit of V, Omega (NULL: none), n, a with the uniforms u (NULL: from rng) */
static rbs_hit make_hit(const double V[3], const double Omega[3], const double n[3], double a, const double *u,
                        rbs_rng *rng)
{
    rbs_hit hit = RBS_HIT_INIT;
    for (int k = 0; k < 3; k++) {
        hit.V[k] = V[k];
        hit.Omega[k] = Omega ? Omega[k] : 0.0;
        hit.n[k] = n[k];
    }
    hit.a = a;
    hit.u = u;
    hit.rng = rng;
    return hit;
}

static rbs_options make_options(int method, int interpolation)
{
    rbs_options options = RBS_OPTIONS_INIT;
    options.method = method;
    options.interpolation = interpolation;
    return options;
}

/* the table path of one hit not spinning (rbs_rebound, RBS_METHOD_TABLE): its status, V⁺ and Ω⁺ */
static int table_hit(const rbs_table *table, const rbs_mix *mix, const double V[3], const double n[3], double a,
                     const double *u, int interpolation, double V_out[3], double W_out[3])
{
    rbs_hit hit = make_hit(V, NULL, n, a, u, NULL);
    rbs_options options = make_options(RBS_METHOD_TABLE, interpolation);
    rbs_result result = RBS_RESULT_INIT;
    rbs_table_info info = RBS_TABLE_INFO_INIT;
    int status = rbs_rebound(table, mix, &hit, &options, &result);
    CHECK(status == result.status, "the status returned is the result's");
    CHECK(status == RBS_INVALID ? result.path == RBS_PATH_NONE && result.shape == -1
                                : result.path == RBS_PATH_TABLE && result.shape >= 0 && result.n_collisions == -1,
          "table hit: status %d, path %d, shape %d, collisions %d", status, result.path, result.shape,
          result.n_collisions);
    /* the work on the wall: NaN for RBS_INVALID and from the corpus' tables of format 4.0, which have none; else never
     * negative (not finite only where E⁻ = |V⁻|²/2 overflows, as in numba) */
    int drawn = status != RBS_INVALID && rbs_table_info_get(table, &info) == RBS_OK && info.format_minor >= 1;
    CHECK(drawn ? !(result.wall_work_normal < 0.0) && !(result.wall_work_tangential < 0.0)
                : isnan(result.wall_work_normal) && isnan(result.wall_work_tangential),
          "table hit: status %d, work %g, %g", status, result.wall_work_normal, result.wall_work_tangential);
    memcpy(V_out, result.V, sizeof result.V);
    memcpy(W_out, result.Omega, sizeof result.Omega);
    return status;
}

static int local_draw(const rbs_table *table, const rbs_mix *mix, double alpha1, double speed, const double *u,
                      int interpolation, double *out)
{
    rbs_options options = make_options(RBS_METHOD_AUTO, interpolation);
    return rbs_draw_local(table, mix, alpha1, speed, u, &options, out);
}

/* rbs_draw_many of count rows, uniforms u (NULL: from rng) */
static int many(const rbs_table *table, const rbs_mix *mix, size_t count, const double *V, const double *n,
                const double *a, const double *u, rbs_rng *rng, int interpolation, double *V_out, double *W_out,
                signed char *status)
{
    rbs_hits hits = RBS_HITS_INIT;
    hits.count = count;
    hits.V = V;
    hits.n = n;
    hits.a = a;
    hits.u = u;
    hits.rng = rng;
    rbs_results results = RBS_RESULTS_INIT;
    results.V = V_out;
    results.Omega = W_out;
    results.status = status;
    rbs_options options = make_options(RBS_METHOD_TABLE, interpolation);
    return rbs_draw_many(table, mix, &hits, &options, &results);
}

/* Hostile arguments to the draw functions: uniforms outside [0, 1) or NaN, NULL pointers, records too small,
 * extreme speeds, half-sizes and normals, an all-zero generator, local states outside the physical range. None may
 * crash or read outside the table (the sanitizers watch); each gives RBS_INVALID and NaN, or a finite rebound
 * leaving the wall. */
static void hostile_draws(const rbs_table *table, const rbs_mix *mix, double vlo, double vhi)
{
    const double V[3] = {40.0, -0.3, 0.0}, n[3] = {0.0, 1.0, 0.0};
    double u[RBS_U_PER_DRAW], good[RBS_U_PER_DRAW], V_out[3], W_out[3], out[RBS_LOCAL_SIZE], ref[RBS_LOCAL_SIZE];
    rbs_rng rng;
    rbs_rng_seed(&rng, 25);
    rbs_rng_fill(&rng, good, RBS_U_PER_DRAW);
    const int good_status = table_hit(table, mix, V, n, 1e-4, good, RBS_INTERPOLATION_SCALED, V_out, W_out);
    CHECK(good_status == RBS_OK || good_status == RBS_TRAPPED, "good uniforms: status %d", good_status);
    int st;

    static const double bad[] = {-0.5, 1.0, 1e6, 1e300, -1e300, INFINITY, -INFINITY, NAN, -1e-300};
    for (int k = 0; k < RBS_U_PER_DRAW; k++) {
        for (size_t j = 0; j < sizeof bad / sizeof bad[0]; j++) {
            memcpy(u, good, sizeof u);
            u[k] = bad[j];
            st = table_hit(table, mix, V, n, 1e-4, u, (int)(j % 2), V_out, W_out);
            CHECK(st == RBS_INVALID && all_nan(V_out, 3) && all_nan(W_out, 3), "u[%d] = %g: status %d", k, bad[j], st);
            st = local_draw(table, mix, 45.0, 200.0, u, (int)(j % 2), out);
            CHECK(st == RBS_INVALID && all_nan(out, RBS_LOCAL_SIZE), "local u[%d] = %g: status %d", k, bad[j], st);
        }
    }

    /* NULL pointers and records: a NULL hit or options record too small still writes NaN into the result; a NULL or
     * too small result gets nothing */
    rbs_hit hit = make_hit(V, NULL, n, 1e-4, good, NULL);
    rbs_options options = make_options(RBS_METHOD_TABLE, RBS_INTERPOLATION_SCALED);
    rbs_result result = RBS_RESULT_INIT;
    CHECK(rbs_rebound(table, mix, NULL, &options, &result) == RBS_INVALID && all_nan(result.V, 3)
          && result.path == RBS_PATH_NONE && result.shape == -1, "NULL hit");
    CHECK(rbs_rebound(table, mix, &hit, &options, NULL) == RBS_INVALID, "NULL result");
    CHECK(rbs_rebound(NULL, mix, &hit, &options, &result) == RBS_INVALID && all_nan(result.Omega, 3), "NULL table");
    CHECK(rbs_rebound(table, NULL, &hit, &options, &result) == RBS_INVALID, "NULL mix");
    {
        rbs_options defaults = RBS_OPTIONS_INIT;
        rbs_result with_defaults = RBS_RESULT_INIT;
        int st_null = rbs_rebound(table, mix, &hit, NULL, &result);
        CHECK(st_null == rbs_rebound(table, mix, &hit, &defaults, &with_defaults)
              && memcmp(result.V, with_defaults.V, sizeof result.V) == 0 && result.path == with_defaults.path,
              "NULL options: the defaults");
    }
    hit.size = sizeof hit - 1;
    CHECK(rbs_rebound(table, mix, &hit, &options, &result) == RBS_INVALID && all_nan(result.V, 3), "hit too small");
    hit.size = 0;
    CHECK(rbs_rebound(table, mix, &hit, &options, &result) == RBS_INVALID, "hit of size 0");
    CHECK(rbs_rebound_path(table, &hit, &options) == RBS_PATH_NONE, "path: hit too small");
    hit.size = sizeof hit;
    options.size = sizeof options / 2;
    CHECK(rbs_rebound(table, mix, &hit, &options, &result) == RBS_INVALID && all_nan(result.V, 3), "options too small");
    CHECK(rbs_rebound_path(table, &hit, &options) == RBS_PATH_NONE, "path: options too small");
    CHECK(local_draw(table, mix, 45.0, 200.0, good, 7, out) == RBS_INVALID, "local: unknown interpolation");
    CHECK(rbs_draw_local(table, mix, 45.0, 200.0, good, &options, out) == RBS_INVALID
          && all_nan(out, RBS_LOCAL_SIZE), "local: options too small");
    options.size = sizeof options;
    result.size = sizeof result / 2;
    result.status = 99;
    result.V[0] = 99.0;
    CHECK(rbs_rebound(table, mix, &hit, &options, &result) == RBS_INVALID && result.status == RBS_INVALID
          && result.V[0] == 99.0, "result too small: its status says so, nothing else written");
    result.size = offsetof(rbs_result, status);
    result.status = 99;
    CHECK(rbs_rebound(table, mix, &hit, &options, &result) == RBS_INVALID && result.status == 99,
          "result not reaching its status: nothing written");
    result.size = sizeof result;
    {   /* records of a later version, larger than 1.0's: accepted, the 1.0 fields read and written */
        struct { rbs_hit hit; double later[8]; } big_hit;
        struct { rbs_options options; int later[8]; } big_options;
        struct { rbs_result result; double later[8]; } big_result;
        memset(&big_hit, 0, sizeof big_hit);
        memset(&big_options, 0, sizeof big_options);
        memset(&big_result, 0, sizeof big_result);
        big_hit.hit = hit;
        big_hit.hit.size = sizeof big_hit;
        big_options.options = options;
        big_options.options.size = sizeof big_options;
        big_result.result.size = sizeof big_result;
        CHECK(rbs_rebound(table, mix, &hit, &options, &result) == good_status, "1.0 records");
        CHECK(rbs_rebound(table, mix, &big_hit.hit, &big_options.options, &big_result.result) == good_status
              && (good_status != RBS_OK || memcmp(big_result.result.V, result.V, sizeof result.V) == 0),
              "larger records");
        CHECK(big_result.later[0] == 0.0, "a field past the library's record written");
    }
    CHECK(rbs_draw_local(table, mix, 45.0, 200.0, NULL, NULL, out) == RBS_INVALID, "local NULL u");
    CHECK(rbs_draw_local(table, mix, 45.0, 200.0, good, NULL, NULL) == RBS_INVALID, "local NULL out");

    /* many: NULL arrays, NULL records, a bad method, one bad row */
    signed char status[3];
    double Vm[9], nm[9], am[3], um[3 * RBS_U_PER_DRAW], Vo[9], Wo[9];
    for (int i = 0; i < 3; i++) {
        memcpy(Vm + 3 * i, V, sizeof V);
        memcpy(nm + 3 * i, n, sizeof n);
        memcpy(um + RBS_U_PER_DRAW * i, good, sizeof good);
        am[i] = 1e-4;
    }
    CHECK(many(table, mix, 3, NULL, nm, am, um, NULL, RBS_INTERPOLATION_SCALED, Vo, Wo, status) == RBS_INVALID
          && status[0] == RBS_INVALID && status[2] == RBS_INVALID && all_nan(Vo, 9), "many: NULL V");
    CHECK(many(table, mix, 3, Vm, nm, am, um, NULL, RBS_INTERPOLATION_SCALED, NULL, NULL, status) == RBS_INVALID
          && status[1] == RBS_INVALID, "many: NULL outputs");
    many(table, mix, 3, Vm, nm, am, NULL, NULL, RBS_INTERPOLATION_SCALED, NULL, NULL, NULL);
    CHECK(many(table, mix, 3, Vm, nm, am, NULL, NULL, RBS_INTERPOLATION_SCALED, Vo, Wo, status) == RBS_INVALID
          && status[0] == RBS_INVALID, "many: no uniforms, NULL rng");
    CHECK(many(table, mix, 0, NULL, NULL, NULL, um, NULL, RBS_INTERPOLATION_SCALED, NULL, NULL, NULL) == RBS_OK,
          "many: no rows");
    {
        rbs_hits hits = RBS_HITS_INIT;
        rbs_results results = RBS_RESULTS_INIT;
        hits.count = 3, hits.V = Vm, hits.n = nm, hits.a = am, hits.u = um;
        results.V = Vo, results.Omega = Wo, results.status = status;
        rbs_options direct = make_options(RBS_METHOD_DIRECT, RBS_INTERPOLATION_SCALED);
        CHECK(rbs_draw_many(table, mix, &hits, &direct, &results) == RBS_INVALID && status[2] == RBS_INVALID,
              "many: the direct method");
        CHECK(rbs_draw_many(table, mix, &hits, NULL, &results) == RBS_OK && status[0] == good_status,
              "many: NULL options");
        CHECK(rbs_draw_many(table, mix, NULL, NULL, &results) == RBS_INVALID, "many: NULL hits");
        CHECK(rbs_draw_many(table, mix, &hits, NULL, NULL) == RBS_INVALID, "many: NULL results");
        hits.size = 8;
        status[0] = 7;
        CHECK(rbs_draw_many(table, mix, &hits, NULL, &results) == RBS_INVALID && status[0] == 7,
              "many: hits too small, nothing written");
        hits.size = sizeof hits;
        results.size = 8;
        CHECK(rbs_draw_many(table, mix, &hits, NULL, &results) == RBS_INVALID && status[0] == 7,
              "many: results too small, nothing written");
    }
    um[RBS_U_PER_DRAW + 5] = -0.5;     /* row 1's u[5]: that row alone is invalid */
    many(table, mix, 3, Vm, nm, am, um, NULL, RBS_INTERPOLATION_SCALED, Vo, Wo, status);
    CHECK(status[1] == RBS_INVALID && status[0] == good_status && status[2] == good_status,
          "many, one bad row: %d %d %d", status[0], status[1], status[2]);

    /* generators: NULL and all zero (xoshiro256+'s fixed point) give NaN, never u = 0 forever */
    rbs_rng_seed(NULL, 1);
    rbs_rng_seed_stream(NULL, 1, 2);
    CHECK(isnan(rbs_rng_uniform(NULL)), "uniform of NULL");
    rbs_rng_fill(NULL, u, RBS_U_PER_DRAW);
    CHECK(all_nan(u, RBS_U_PER_DRAW), "fill from NULL");
    rbs_rng_fill(&rng, NULL, 5);
    rbs_draw_many_uniforms(NULL, 3, um);
    CHECK(all_nan(um, 3 * RBS_U_PER_DRAW), "draw_many_uniforms from NULL");
    rbs_rng zero = {{0, 0, 0, 0}};
    CHECK(isnan(rbs_rng_uniform(&zero)), "uniform of the zero state");
    rbs_rng_fill(&zero, u, RBS_U_PER_DRAW);
    CHECK(all_nan(u, RBS_U_PER_DRAW), "fill from the zero state");
    CHECK(table_hit(table, mix, V, n, 1e-4, u, RBS_INTERPOLATION_SCALED, V_out, W_out) == RBS_INVALID,
          "zero state draw");
    CHECK(many(table, mix, 3, Vm, nm, am, NULL, &zero, RBS_INTERPOLATION_SCALED, Vo, Wo, status) == RBS_INVALID
          && status[0] == RBS_INVALID && status[2] == RBS_INVALID, "many: zero state");

    /* extreme particles: |V⁻| overflowing or underflowing, bad half-sizes and normals */
    static const double speeds[] = {1e200, 1e154, 1e-160, 1e-200, 5e-324};
    for (size_t j = 0; j < sizeof speeds / sizeof speeds[0]; j++) {
        const double Vs[3] = {speeds[j] * 0.8, -speeds[j] * 0.6, 0.0};
        st = table_hit(table, mix, Vs, n, 1e-4, good, RBS_INTERPOLATION_SCALED, V_out, W_out);
        CHECK(st == RBS_INVALID ? all_nan(V_out, 3) : st == RBS_TRAPPED || physical(V_out, W_out, n),
              "|V| = %g: status %d, V+ = (%g, %g, %g)", speeds[j], st, V_out[0], V_out[1], V_out[2]);
    }
    static const double sizes[] = {0.0, -1e-4, NAN, INFINITY, 5e-324, -INFINITY};
    for (size_t j = 0; j < sizeof sizes / sizeof sizes[0]; j++) {
        st = table_hit(table, mix, V, n, sizes[j], good, RBS_INTERPOLATION_SCALED, V_out, W_out);
        CHECK(st == RBS_INVALID && all_nan(W_out, 3), "a = %g: status %d", sizes[j], st);
    }
    static const double lengths[] = {1e200, 2.0, 0.5, 1.0 + 1e-5, 1e-200};
    for (size_t j = 0; j < sizeof lengths / sizeof lengths[0]; j++) {
        const double nl[3] = {0.0, lengths[j], 0.0};
        st = table_hit(table, mix, V, nl, 1e-4, good, RBS_INTERPOLATION_SCALED, V_out, W_out);
        CHECK(st == RBS_INVALID && all_nan(V_out, 3), "|n| = %g: status %d", lengths[j], st);
    }

    /* local draws: α1 outside (0, 90] or NaN, |V⁻| not finite and > 0; a huge |V⁻| is the top grid edge */
    static const double alphas[] = {NAN, -5.0, 0.0, 90.0001, 1e30, -INFINITY, INFINITY};
    for (size_t j = 0; j < sizeof alphas / sizeof alphas[0]; j++)
        CHECK(local_draw(table, mix, alphas[j], 200.0, good, RBS_INTERPOLATION_SCALED, out) == RBS_INVALID
              && all_nan(out, RBS_LOCAL_SIZE), "local alpha1 = %g", alphas[j]);
    static const double local_speeds[] = {NAN, -1.0, 0.0, INFINITY, -INFINITY};
    for (size_t j = 0; j < sizeof local_speeds / sizeof local_speeds[0]; j++)
        CHECK(local_draw(table, mix, 45.0, local_speeds[j], good, RBS_INTERPOLATION_SCALED, out) == RBS_INVALID,
              "local speed = %g", local_speeds[j]);
    int top = local_draw(table, mix, 45.0, vhi, good, RBS_INTERPOLATION_SCALED, ref);
    CHECK(local_draw(table, mix, 45.0, 1e25, good, RBS_INTERPOLATION_SCALED, out) == top
          && (top != RBS_OK || memcmp(out, ref, sizeof out) == 0), "speed 1e25 is not the top grid edge");
    int bottom = local_draw(table, mix, 45.0, vlo, good, RBS_INTERPOLATION_SCALED, ref);
    CHECK(local_draw(table, mix, 45.0, 1e-300, good, RBS_INTERPOLATION_SCALED, out) == bottom
          && (bottom != RBS_OK || memcmp(out, ref, sizeof out) == 0), "speed 1e-300 is not the bottom grid edge");

    /* random hostile uniforms and particles: whatever comes back as a rebound is finite and leaves the wall */
    for (int i = 0; i < 20000; i++) {
        double Vr[3], nr[3];
        for (int k = 0; k < RBS_U_PER_DRAW; k++) u[k] = 3.0 * rbs_rng_uniform(&rng) - 1.0;
        for (int k = 0; k < 3; k++) {
            Vr[k] = ldexp(2.0 * rbs_rng_uniform(&rng) - 1.0, (int)(1200.0 * rbs_rng_uniform(&rng)) - 600);
            nr[k] = 2.0 * rbs_rng_uniform(&rng) - 1.0;
        }
        double a = ldexp(rbs_rng_uniform(&rng), (int)(1200.0 * rbs_rng_uniform(&rng)) - 600);
        st = table_hit(table, mix, Vr, nr, a, u, i % 2, V_out, W_out);
        CHECK(st == RBS_INVALID || st == RBS_TRAPPED || physical(V_out, W_out, nr), "random hostile draw %d", i);
        st = local_draw(table, mix, 100.0 * u[0], ldexp(u[1], (int)(2000.0 * u[2]) - 1000), u, i % 2, out);
        CHECK(st == RBS_INVALID || st == RBS_TRAPPED || (isfinite(out[2]) && out[2] >= 0.0), "random local draw %d", i);
    }
}

/* every hit answered (rbs_rebound, rbs_rebound_path): spinning and hostile hits under the three methods, uniforms
 * given or drawn, with and without a grain key; whatever rebounds is finite and leaves the wall, the rest is NaN */
static void spin_draws(const rbs_table *table, const rbs_mix *mix, double vlo, double vhi)
{
    rbs_rng rng;
    rbs_rng_seed_stream(&rng, 28, 1);
    const double n[3] = {0.0, 1.0, 0.0}, still[3] = {0.0, 0.0, 0.0}, a = 1e-4;
    double V[3] = {100.0, -100.0, 0.0}, u[RBS_U_PER_DRAW];
    double spin[3] = {0.0, 0.0, 0.3 * sqrt(2e4) / a};        /* |Omega-| a/|V-| = 0.3 */
    rbs_rng_fill(&rng, u, RBS_U_PER_DRAW);
    rbs_options options[3];
    for (int method = RBS_METHOD_AUTO; method <= RBS_METHOD_DIRECT; method++)
        options[method] = make_options(method, RBS_INTERPOLATION_SCALED);
    rbs_hit hit_still = make_hit(V, still, n, a, u, NULL), hit = make_hit(V, spin, n, a, u, NULL);
    CHECK(rbs_rebound_path(table, &hit_still, NULL) == RBS_PATH_TABLE, "no spin at 45 deg: the table");
    CHECK(rbs_rebound_path(table, &hit, NULL) == RBS_PATH_DIRECT, "spin 0.3: the direct model");
    CHECK(rbs_rebound_path(table, &hit, &options[RBS_METHOD_TABLE]) == RBS_PATH_TABLE, "method table");
    CHECK(rbs_rebound_path(table, &hit_still, &options[RBS_METHOD_DIRECT]) == RBS_PATH_DIRECT, "method direct");
    for (int method = RBS_METHOD_AUTO; method <= RBS_METHOD_DIRECT; method++) {
        rbs_result r = RBS_RESULT_INIT;
        int st = rbs_rebound(table, mix, &hit, &options[method], &r);
        CHECK(st == RBS_OK ? physical(r.V, r.Omega, n)
                           : st != RBS_INVALID && all_nan(r.V, 3),
              "spinning hit, method %d: status %d", method, st);
        int direct = method != RBS_METHOD_TABLE;
        CHECK(st == RBS_INVALID || (r.path == (direct ? RBS_PATH_DIRECT : RBS_PATH_TABLE) && r.shape >= 0
                                    && r.shape < rbs_table_n_shapes(table) && (r.n_collisions >= 0) == direct),
              "spinning hit, method %d: path %d, shape %d, collisions %d", method, r.path, r.shape, r.n_collisions);
    }
    /* bad methods, bad Omega-, a NULL or all-zero rng, a bad key */
    const double bad_spins[3] = {NAN, INFINITY, -INFINITY};
    for (int j = 0; j < 3; j++) {
        double W_bad[3] = {1.0, bad_spins[j], 1.0};
        rbs_hit bad = make_hit(V, W_bad, n, a, u, NULL);
        rbs_result r = RBS_RESULT_INIT;
        CHECK(rbs_rebound_path(table, &bad, NULL) == RBS_PATH_NONE, "Omega %g: path", bad_spins[j]);
        CHECK(rbs_rebound(table, mix, &bad, &options[RBS_METHOD_TABLE], &r) == RBS_INVALID && all_nan(r.V, 3)
              && all_nan(r.Omega, 3), "Omega %g", bad_spins[j]);
    }
    rbs_result r = RBS_RESULT_INIT;
    rbs_options bad_method = make_options(3, RBS_INTERPOLATION_SCALED);
    CHECK(rbs_rebound(table, mix, &hit, &bad_method, &r) == RBS_INVALID, "method 3");
    CHECK(rbs_rebound_path(table, &hit, &bad_method) == RBS_PATH_NONE, "path: method 3");
    bad_method.method = -1;
    CHECK(rbs_rebound_path(table, &hit, &bad_method) == RBS_PATH_NONE, "path: method -1");
    rbs_options bad_interpolation = make_options(RBS_METHOD_AUTO, 9);
    CHECK(rbs_rebound(table, mix, &hit, &bad_interpolation, &r) == RBS_INVALID, "spin: unknown interpolation");
    CHECK(rbs_rebound_path(NULL, &hit, NULL) == RBS_PATH_NONE, "path: NULL table");
    CHECK(rbs_rebound_path(table, NULL, NULL) == RBS_PATH_NONE, "path: NULL hit");
    rbs_rng zero = {{0, 0, 0, 0}};
    rbs_hit drawn = make_hit(V, spin, n, a, NULL, NULL);
    CHECK(rbs_rebound(table, mix, &drawn, NULL, &r) == RBS_INVALID && all_nan(r.V, 3), "spin: NULL rng");
    drawn.rng = &zero;
    CHECK(rbs_rebound(table, mix, &drawn, NULL, &r) == RBS_INVALID, "spin: zero rng");
    rbs_hit keyed = hit;
    keyed.grain_key = -2;
    CHECK(rbs_rebound(table, mix, &keyed, NULL, &r) == RBS_INVALID && all_nan(r.V, 3), "grain key -2");

    /* random hits over and beyond the grid, spins from none to 2 |V-|/a, random methods, keyed or not; hostile
     * particles */
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
        int method = (int)(3.0 * rbs_rng_uniform(&rng));
        rbs_options o = make_options(method, i % 2);
        rbs_hit h = make_hit(Vr, Wr, nr, a, NULL, &rng);
        if (i % 5 == 0) h.grain_key = rbs_grain_key(28, 0, (uint64_t)i);
        int path = rbs_rebound_path(table, &h, &o);
        rbs_result res = RBS_RESULT_INIT;
        int st = rbs_rebound(table, mix, &h, &o, &res);
        CHECK(path != RBS_PATH_NONE || st == RBS_INVALID, "random spin hit %d: path invalid, status %d", i, st);
        CHECK(st == RBS_INVALID || res.path == path, "random spin hit %d: path %d, result's %d", i, path, res.path);
        CHECK(st == RBS_OK ? physical(res.V, res.Omega, nr) : all_nan(res.V, 3) && all_nan(res.Omega, 3),
              "random spin hit %d: status %d", i, st);
        if (h.grain_key >= 0 && st != RBS_INVALID) {
            rbs_grain grain = RBS_GRAIN_INIT;
            CHECK(rbs_grain_info(table, mix, h.grain_key, &grain) == RBS_OK && grain.shape == res.shape,
                  "random keyed hit %d: shape %d, the grain's %d", i, res.shape, grain.shape);
        }
    }
    /* uniforms drawn from an rng: the bits of the same uniforms given, the rng advanced by RBS_U_PER_DRAW */
    rbs_rng r_drawn, r_given;
    rbs_rng_seed_stream(&r_drawn, 28, 2);
    r_given = r_drawn;
    for (int i = 0; i < 40; i++) {
        double ug[RBS_U_PER_DRAW];
        rbs_rng_fill(&r_given, ug, RBS_U_PER_DRAW);
        rbs_hit h_drawn = make_hit(V, i % 2 ? spin : still, n, a, NULL, &r_drawn);
        rbs_hit h_given = make_hit(V, i % 2 ? spin : still, n, a, ug, NULL);
        h_drawn.grain_key = h_given.grain_key = i % 4 == 3 ? rbs_grain_key(1, 2, (uint64_t)i) : RBS_NO_KEY;
        rbs_result a_drawn = RBS_RESULT_INIT, a_given = RBS_RESULT_INIT;
        int st_drawn = rbs_rebound(table, mix, &h_drawn, &options[i % 3], &a_drawn);
        int st_given = rbs_rebound(table, mix, &h_given, &options[i % 3], &a_given);
        CHECK(st_drawn == st_given && same_result(&a_drawn, &a_given)
              && memcmp(&r_drawn, &r_given, sizeof r_drawn) == 0, "uniforms drawn and given differ, hit %d", i);
    }
}

/* a rough wall (options' roughness on this table): grazing, spinning, keyed and hostile hits under the three methods;
 * whatever rebounds is finite and leaves the mean wall, the rest is NaN, 1 to RBS_MAX_WALL_HITS facet hits (0 for
 * RBS_INVALID); uniforms drawn are those given; roughness 0 is the smooth wall; bad roughnesses are refused */
static void rough_draws(const rbs_table *table, const rbs_mix *mix, double vlo, double vhi)
{
    rbs_rng rng, r_drawn;
    rbs_rng_seed_stream(&rng, 29, 1);
    rbs_rng_seed_stream(&r_drawn, 29, 2);
    const double a = 1e-4;
    int rehits = 0;
    for (int i = 0; i < 600; i++) {
        double V[3], n[3], W[3], u[RBS_U_PER_DRAW], t[3];
        unit(&rng, n);
        unit(&rng, t);
        unit(&rng, W);
        double speed = 0.5 * vlo + 1.2 * vhi * rbs_rng_uniform(&rng);
        double alpha1_deg = i % 2 ? 1.0 + 4.0 * rbs_rng_uniform(&rng) : 90.0 * rbs_rng_uniform(&rng);
        double alpha1 = alpha1_deg * 0.017453292519943295;
        double tn = t[0] * n[0] + t[1] * n[1] + t[2] * n[2], tt = 0.0;
        for (int k = 0; k < 3; k++) {
            t[k] -= tn * n[k];
            tt += t[k] * t[k];
        }
        double ratio = i % 3 == 0 ? 0.0 : 0.5 * rbs_rng_uniform(&rng);
        for (int k = 0; k < 3; k++) {
            V[k] = speed * (cos(alpha1) * t[k] / sqrt(tt) - sin(alpha1) * n[k]);
            W[k] *= ratio * speed / a;
        }
        if (i % 60 == 0) V[i % 3] = i % 120 == 0 ? NAN : 1e300;
        rbs_rng_fill(&rng, u, RBS_U_PER_DRAW);
        rbs_options o = make_options(i % 3, i % 2);
        o.roughness_deg = i % 7 == 0 ? RBS_MAX_ROUGHNESS_DEG : 45.0 * rbs_rng_uniform(&rng);
        rbs_rng r_given = r_drawn;
        double ug[RBS_U_PER_DRAW];
        rbs_rng_fill(&r_given, ug, RBS_U_PER_DRAW);
        rbs_hit h = make_hit(V, W, n, a, i % 4 == 1 ? ug : u, NULL), h_drawn = make_hit(V, W, n, a, NULL, &r_drawn);
        if (i % 5 == 0) h.grain_key = h_drawn.grain_key = rbs_grain_key(29, 0, (uint64_t)i);
        rbs_result r = RBS_RESULT_INIT, r_from_rng = RBS_RESULT_INIT;
        int st = rbs_rebound(table, mix, &h, &o, &r);
        CHECK(st == r.status && (st == RBS_INVALID ? r.wall_hits == 0 : r.wall_hits >= 1
                                 && r.wall_hits <= RBS_MAX_WALL_HITS), "rough hit %d: status %d, %d wall hits", i, st,
              r.wall_hits);
        CHECK(st == RBS_OK ? physical(r.V, r.Omega, n) : all_nan(r.V, 3) && all_nan(r.Omega, 3),
              "rough hit %d: status %d", i, st);
        rehits += r.wall_hits > 1;
        if (i % 4 == 1) {
            rbs_rebound(table, mix, &h_drawn, &o, &r_from_rng);
            CHECK(same_result(&r, &r_from_rng) && memcmp(&r_drawn, &r_given, sizeof r_drawn) == 0,
                  "rough hit %d: uniforms drawn and given differ", i);
        } else {
            r_drawn = r_given;
        }
        /* roughness 0: the smooth wall */
        rbs_options smooth = make_options(i % 3, i % 2);
        smooth.roughness_deg = 0.0;
        rbs_result r_zero = RBS_RESULT_INIT, r_smooth = RBS_RESULT_INIT;
        rbs_rebound(table, mix, &h, &smooth, &r_zero);
        smooth.roughness_deg = RBS_ROUGHNESS_OF_TABLE;
        rbs_rebound(table, mix, &h, &smooth, &r_smooth);
        CHECK(same_result(&r_zero, &r_smooth) && (r_zero.status == RBS_INVALID) == (r_zero.wall_hits == 0)
              && r_zero.wall_hits <= 1, "rough hit %d: roughness 0 is not the smooth wall", i);
    }
    CHECK(rehits > 0, "no facet re-hit in 600 rough hits");
    const double V[3] = {100.0, -5.0, 0.0}, n[3] = {0.0, 1.0, 0.0}, still[3] = {0.0, 0.0, 0.0};
    double u[RBS_U_PER_DRAW];
    rbs_rng_fill(&rng, u, RBS_U_PER_DRAW);
    rbs_hit h = make_hit(V, still, n, a, u, NULL);
    static const double bad[] = {NAN, INFINITY, 45.000000000000007, 46.0, 1e300};
    for (int j = 0; j < (int)(sizeof bad / sizeof bad[0]); j++) {
        rbs_options o = make_options(RBS_METHOD_AUTO, RBS_INTERPOLATION_SCALED);
        o.roughness_deg = bad[j];
        rbs_result r = RBS_RESULT_INIT;
        CHECK(rbs_rebound(table, mix, &h, &o, &r) == RBS_INVALID && r.wall_hits == 0 && r.path == RBS_PATH_NONE
              && all_nan(r.V, 3), "roughness %g", bad[j]);
        CHECK(rbs_rebound_path(table, &h, &o) == RBS_PATH_NONE, "path: roughness %g", bad[j]);
    }
    /* rbs_draw_many: the smooth wall only */
    double Vm[3] = {100.0, -100.0, 0.0}, am = a, Vo[3], Wo[3];
    signed char status = 7;
    rbs_hits hits = RBS_HITS_INIT;
    hits.count = 1;
    hits.V = Vm;
    hits.n = n;
    hits.a = &am;
    hits.u = u;
    rbs_results results = RBS_RESULTS_INIT;
    results.V = Vo;
    results.Omega = Wo;
    results.status = &status;
    rbs_options o = make_options(RBS_METHOD_AUTO, RBS_INTERPOLATION_SCALED);
    o.roughness_deg = 10.0;
    CHECK(rbs_draw_many(table, mix, &hits, &o, &results) == RBS_INVALID && status == RBS_INVALID && all_nan(Vo, 3),
          "draw_many on a rough wall");
    o.roughness_deg = 0.0;
    CHECK(rbs_draw_many(table, mix, &hits, &o, &results) == RBS_OK && status == RBS_OK, "draw_many, roughness 0");
}

/* what a table tells about itself */
static void table_records(const rbs_table *table)
{
    int n_shapes = rbs_table_n_shapes(table);
    CHECK(n_shapes >= 1 && n_shapes <= RBS_TABLE_MAX_SHAPES, "%d shapes", n_shapes);
    for (int i = 0; i < n_shapes; i++) {
        rbs_shape_info shape = RBS_SHAPE_INFO_INIT;
        CHECK(rbs_table_shape_info(table, i, &shape) == RBS_OK && strcmp(shape.name, rbs_table_shape_name(table, i)) == 0
              && (shape.kind == RBS_KIND_SMOOTH) == (shape.n_vertices == 0) && (shape.n_vertices == 0) == !shape.vertices
              && shape.family >= RBS_FAMILY_NONE && shape.family <= RBS_FAMILY_TETRAHEDRON,
              "shape info %d", i);
        for (int k = 0; k < 3 * shape.n_vertices; k++)
            CHECK(fabs(shape.vertices[k]) <= 1.5 + 1e-9, "shape %d vertex coordinate %g", i, shape.vertices[k]);
    }
    rbs_shape_info none = RBS_SHAPE_INFO_INIT;
    CHECK(rbs_table_shape_info(table, n_shapes, &none) == RBS_INVALID && rbs_table_shape_info(table, 0, NULL) == RBS_INVALID
          && rbs_table_shape_info(table, -1, &none) == RBS_INVALID, "shape info out of range");
    none.size = sizeof none / 2;
    CHECK(rbs_table_shape_info(table, 0, &none) == RBS_INVALID, "shape info too small");
    CHECK(rbs_table_shape_name(table, n_shapes) == NULL, "shape name beyond the count");
    CHECK(rbs_table_shape_name(table, -1) == NULL, "shape name -1");

    rbs_table_info info = RBS_TABLE_INFO_INIT;
    CHECK(rbs_table_info_get(table, &info) == RBS_OK, "info");
    int n_alpha1 = 0, n_speed = 0;
    const double *alpha1 = rbs_table_alpha1_grid(table, &n_alpha1), *speed = rbs_table_speed_grid(table, &n_speed);
    /* the loader reads format 3 until format RBS_TABLE_FORMAT_MAJOR is written */
    CHECK(info.kernel_bytes > 0 && info.format_major >= 3 && info.format_major <= RBS_TABLE_FORMAT_MAJOR
          && info.n_shapes == n_shapes && info.n_alpha1 == n_alpha1 && info.n_speed == n_speed
          && info.alpha1_min_deg == alpha1[0] && info.alpha1_max_deg == alpha1[n_alpha1 - 1]
          && info.speed_min_m_s == speed[0] && info.speed_max_m_s == speed[n_speed - 1]
          && info.alpha1_min_deg <= info.alpha1_max_deg && info.speed_min_m_s <= info.speed_max_m_s, "info fields");
    rbs_table_info small = RBS_TABLE_INFO_INIT;
    small.size = sizeof small - sizeof small.kernel_bytes;
    CHECK(rbs_table_info_get(table, &small) == RBS_INVALID && small.n_shapes == 0, "info too small: nothing written");
    CHECK(rbs_table_info_get(NULL, &info) == RBS_INVALID && rbs_table_info_get(table, NULL) == RBS_INVALID, "info NULL");

    rbs_wall_info wall = RBS_WALL_INFO_INIT;
    CHECK(rbs_table_wall(table, &wall) == RBS_OK && wall.name != NULL, "wall");
    int tabulated = strcmp(wall.family, "tabulated") == 0;
    CHECK(tabulated || strcmp(wall.family, "exponential") == 0, "wall family %s", wall.family);
    if (!tabulated) {
        static const char *const names[3] = {"k", "p", "q"};
        CHECK(wall.n_parameters == 3 && wall.n_contact_speeds == 0 && wall.n_contact_sines == 0
              && !wall.contact_speed_m_s && !wall.contact_sine && !wall.restitution, "exponential wall: no arrays");
        for (int k = 0; k < 3 && wall.n_parameters == 3; k++)
            CHECK(strcmp(wall.parameter_names[k], names[k]) == 0 && isfinite(wall.parameter_values[k])
                  && (k == 2 || wall.parameter_values[k] > 0.0), "wall parameter %d: %g", k, wall.parameter_values[k]);
    } else {
        /* the tabulated law's rules (direct_model.wall.TabulatedWall), as the loader checked them */
        int ns = wall.n_contact_speeds, nz = wall.n_contact_sines;
        CHECK(wall.n_parameters == 1 && strcmp(wall.parameter_names[0], "q") == 0 && isfinite(wall.parameter_values[0])
              && ns >= 1 && ns <= 16 && nz >= 2 && nz <= 16 && wall.contact_speed_m_s && wall.contact_sine
              && wall.restitution, "tabulated wall: %d speeds, %d sines", ns, nz);
        for (int i = 0; wall.contact_speed_m_s && i < ns; i++)
            CHECK(wall.contact_speed_m_s[i] > (i ? wall.contact_speed_m_s[i - 1] : 0.0), "speed node %d", i);
        for (int j = 0; wall.contact_sine && j < nz; j++)
            CHECK(j ? wall.contact_sine[j] > wall.contact_sine[j - 1] : wall.contact_sine[j] == 0.0, "sine node %d", j);
        CHECK(!wall.contact_sine || wall.contact_sine[nz - 1] == 1.0, "the last sine node is 1");
        for (int k = 0; wall.restitution && k < ns * nz; k++)
            CHECK(wall.restitution[k] > 0.0 && wall.restitution[k] <= 1.0, "a_nc %d: %g", k, wall.restitution[k]);
    }
    /* a record of the 1.0 size (up to speed_range_m_s): its later fields left alone */
    rbs_wall_info old = RBS_WALL_INFO_INIT;
    old.size = offsetof(rbs_wall_info, speed_range_m_s) + sizeof old.speed_range_m_s;
    old.n_contact_speeds = -7;
    CHECK(rbs_table_wall(table, &old) == RBS_OK && old.family == wall.family && old.n_contact_speeds == -7
          && !old.restitution, "a 1.0 wall record");
    wall.size = 4;
    CHECK(rbs_table_wall(table, &wall) == RBS_INVALID && rbs_table_wall(NULL, &wall) == RBS_INVALID, "wall refused");

    static const char *const arrays[] = {"alpha1_axis", "speed_axis", "cells", "clusters", "dictionary",
                                         "speed_restitution", "restitution_pieces", "work_rows", "work_dictionary",
                                         "work_cells"};
    for (int i = 0; i < 10; i++) {
        const void *data = NULL;
        size_t count = 0;
        int dtype = -1;
        /* the work's arrays are empty for the corpus' tables of format 4.0, which have no work datasets */
        int filled = i < 7 || info.format_minor >= 1;
        CHECK(rbs_table_kernel_array(table, arrays[i], &data, &count, &dtype) == RBS_OK
              && (filled ? data && count > 0 : !data && count == 0)
              && dtype == (i == 3 || i == 4 || i == 7 || i == 8 ? RBS_DTYPE_FLOAT32 : RBS_DTYPE_FLOAT64), "%s",
              arrays[i]);
    }
    CHECK(rbs_table_kernel_array(table, "nothing", NULL, NULL, NULL) == RBS_INVALID, "unknown array");
}

/* mixes, good and bad; a mix of another table is refused */
static void mixes(const rbs_table *table, const rbs_mix *mix, const char *path)
{
    char message[1024];
    int n_shapes = rbs_table_n_shapes(table);
    const char *names[2] = {rbs_table_shape_name(table, 0), "nonsense"};
    double weights[2] = {1.0, 0.0};
    rbs_mix *other = rbs_mix_new_from_weights(table, 2, names, weights, message, sizeof message);
    CHECK(!other && strstr(message, "nonsense"), "unknown name accepted by rbs_mix_new_from_weights");
    other = rbs_mix_new_from_shape(table, rbs_table_shape_name(table, n_shapes - 1), message, sizeof message);
    CHECK(other != NULL, "%s", message);
    rbs_mix_free(other);
    rbs_mix_free(NULL);
    CHECK(rbs_mix_new_equal(NULL) == NULL, "a mix of no table");
    other = rbs_mix_new_from_weights(table, 1, names, weights, message, sizeof message);
    CHECK(other != NULL, "%s", message);
    rbs_mix_free(other);
    weights[0] = -0.5;
    CHECK(!rbs_mix_new_from_weights(table, 1, names, weights, message, sizeof message), "negative weight accepted");
    weights[0] = 0.7;
    CHECK(!rbs_mix_new_from_weights(table, 1, names, weights, message, sizeof message), "weights summing to 0.7");
    weights[0] = NAN;
    CHECK(!rbs_mix_new_from_weights(table, 1, names, weights, message, sizeof message), "NaN weight accepted");
    CHECK(!rbs_mix_new_from_weights(table, 1, NULL, weights, message, sizeof message) && strlen(message) > 0,
          "NULL names accepted");
    other = rbs_mix_new_from_shape(table, "mix", NULL, 0);
    CHECK(other != NULL, "mix by name");
    rbs_mix_free(other);
    CHECK(!rbs_mix_new_from_shape(table, "sphere", message, 8) && strlen(message) < 8,
          "bad shape name, short message buffer");

    /* the same file opened again is another table: its mixes are refused by this one, and the reverse */
    rbs_table *again = NULL;
    CHECK(rbs_table_open(path, &again, message, sizeof message) == RBS_OK, "%s", message);
    if (!again) return;
    rbs_mix *foreign = rbs_mix_new_equal(again);
    const double V[3] = {100.0, -100.0, 0.0}, n[3] = {0.0, 1.0, 0.0};
    double u[RBS_U_PER_DRAW], out[RBS_LOCAL_SIZE];
    rbs_rng rng;
    rbs_rng_seed(&rng, 5);
    rbs_rng_fill(&rng, u, RBS_U_PER_DRAW);
    rbs_hit hit = make_hit(V, NULL, n, 1e-4, u, NULL);
    rbs_result r = RBS_RESULT_INIT;
    rbs_grain grain = RBS_GRAIN_INIT;
    CHECK(rbs_rebound(table, foreign, &hit, NULL, &r) == RBS_INVALID && rbs_rebound(again, mix, &hit, NULL, &r) == RBS_INVALID
          && rbs_rebound(again, foreign, &hit, NULL, &r) != RBS_INVALID, "a mix of another table");
    CHECK(rbs_draw_local(table, foreign, 45.0, 100.0, u, NULL, out) == RBS_INVALID, "local: a mix of another table");
    CHECK(rbs_grain_info(table, foreign, 3, &grain) == RBS_INVALID && rbs_grain_info(again, foreign, 3, &grain) == RBS_OK,
          "grain: a mix of another table");
    rbs_mix_free(foreign);
    rbs_table_close(again);
}

static void draw_from(const char *path)
{
    char message[1024];
    rbs_table *table = NULL;
    int code = rbs_table_open(path, &table, message, sizeof message);
    CHECK(code == RBS_OK && table != NULL, "%s", message);
    if (!table) return;
    int n_shapes = rbs_table_n_shapes(table);
    table_records(table);
    rbs_table_info info = RBS_TABLE_INFO_INIT;
    rbs_table_info_get(table, &info);
    const double vlo = info.speed_min_m_s, vhi = info.speed_max_m_s;

    rbs_mix *mix = rbs_mix_new_equal(table);
    CHECK(mix != NULL, "equal mix");
    if (!mix) return;
    mixes(table, mix, path);

    /* grains: a key's grain, the same on every call; key < 0 refused */
    rbs_grain grain = RBS_GRAIN_INIT, again = RBS_GRAIN_INIT;
    CHECK(rbs_grain_info(table, mix, 12345, &grain) == RBS_OK && rbs_grain_info(table, mix, 12345, &again) == RBS_OK
          && grain.shape >= 0 && grain.shape < n_shapes && grain.shape == again.shape
          && memcmp(&grain.ratio_ba, &again.ratio_ba, 3 * sizeof(double)) == 0, "grain info");
    CHECK(rbs_grain_info(table, mix, -1, &grain) == RBS_INVALID && rbs_grain_info(table, mix, 1, NULL) == RBS_INVALID,
          "grain info refused");
    again.size = 2;
    CHECK(rbs_grain_info(table, mix, 1, &again) == RBS_INVALID, "grain record too small");
    CHECK(rbs_grain_key(1, 2, 3) >= 0 && rbs_grain_key(1, 2, 3) == rbs_grain_key(1, 2, 3), "grain key");

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
        int st = table_hit(table, mix, V + 3 * i, n + 3 * i, a[i], u + RBS_U_PER_DRAW * i, i % 2, V_one + 3 * i,
                           W_one + 3 * i);
        CHECK(st == RBS_OK || st == RBS_TRAPPED || st == RBS_INVALID, "status %d", st);
        rebounded += st == RBS_OK;
    }
    CHECK(rebounded > N / 2, "%d rebounded of %d", rebounded, N);
    many(table, mix, N, V, n, a, u, NULL, RBS_INTERPOLATION_SCALED, V_out, Omega_out, status);
    for (int i = 0; i < N; i += 2)
        CHECK(memcmp(V_out + 3 * i, V_one + 3 * i, 3 * sizeof(double)) == 0 || isnan(V_out[3 * i]),
              "many differs from one at %d", i);
    /* many with uniforms drawn: rbs_draw_many_uniforms's uniforms, the rng advanced alike */
    rbs_rng r_many = rng, r_uniforms = rng;
    CHECK(many(table, mix, 100, V, n, a, NULL, &r_many, RBS_INTERPOLATION_STOCHASTIC, V_out, Omega_out, status) == RBS_OK,
          "many from an rng");
    rbs_draw_many_uniforms(&r_uniforms, 100, u);
    many(table, mix, 100, V, n, a, u, NULL, RBS_INTERPOLATION_STOCHASTIC, V_one, W_one, status);
    CHECK(memcmp(&r_many, &r_uniforms, sizeof r_many) == 0 && memcmp(V_out, V_one, 3 * 100 * sizeof *V_out) == 0,
          "many from an rng: the uniforms of rbs_draw_many_uniforms");
    many(table, mix, N, V, n, a, NULL, &rng, RBS_INTERPOLATION_STOCHASTIC, V_out, Omega_out, status);
    many(table, mix, 0, V, n, a, NULL, &rng, RBS_INTERPOLATION_SCALED, V_out, Omega_out, status);
    many(table, mix, 31, V, n, a, NULL, &rng, RBS_INTERPOLATION_SCALED, V_out, Omega_out, status);
    CHECK(many(table, mix, 33, V, n, a, u, NULL, 7, V_out, Omega_out, status) == RBS_INVALID
          && status[0] == RBS_INVALID && isnan(V_out[0]), "unknown interpolation gives invalid");
    for (int i = 0; i < 2000; i++) {
        double out[RBS_LOCAL_SIZE], alpha1 = -5.0 + 100.0 * u[i];
        int st = local_draw(table, mix, alpha1, 0.5 * vlo + 2.0 * vhi * u[i + 1], u + RBS_U_PER_DRAW * (i % 100),
                            i % 2, out);
        if (alpha1 > 0.0 && alpha1 <= 90.0)
            CHECK(st == RBS_OK || st == RBS_TRAPPED, "local status %d at alpha1 %g", st, alpha1);
        else
            CHECK(st == RBS_INVALID, "local status %d at alpha1 %g", st, alpha1);
        if (st == RBS_OK) CHECK(out[2] >= 0.0 && out[2] <= 1.0, "s = %g", out[2]);
    }
    double out[RBS_LOCAL_SIZE];
    CHECK(local_draw(table, mix, NAN, NAN, u, RBS_INTERPOLATION_SCALED, out) == RBS_INVALID, "NaN local draw");
    hostile_draws(table, mix, vlo, vhi);
    spin_draws(table, mix, vlo, vhi);
    rough_draws(table, mix, vlo, vhi);
    CHECK(local_draw(table, NULL, 45.0, 100.0, u, RBS_INTERPOLATION_SCALED, out) == RBS_INVALID, "NULL mix");
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
        fprintf(stderr, "usage: %s GOOD.h5 [PATH EXPECTED_STATUS]...\n", argv[0]);
        return 2;
    }
    CHECK(rbs_version_number() == RBS_VERSION_NUMBER && strcmp(rbs_version(), "1.4.1") == 0
          && RBS_VERSION_NUMBER == 1004001, "version %s, %d", rbs_version(), rbs_version_number());
    rbs_table_close(NULL);
    CHECK(rbs_table_open(argv[1], NULL, NULL, 0) == RBS_INVALID, "NULL table pointer");
    for (int repeat = 0; repeat < 2; repeat++) draw_from(argv[1]);
    for (int i = 2; i + 1 < argc; i += 2) {
        char message[2048];
        rbs_table *table = (rbs_table *)&message;     /* must be set to NULL on failure */
        int expected = atoi(argv[i + 1]);
        int code = rbs_table_open(argv[i], &table, message, sizeof message);
        CHECK(code == expected, "%s: status %d (%s), expected %d: %s", argv[i], code, rbs_status_string(code), expected,
              message);
        if (code != RBS_OK) {
            CHECK(code < 0, "a refusal is negative: %d", code);
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
    static const int statuses[] = {RBS_OK, RBS_TRAPPED, RBS_FAILED, RBS_INVALID, RBS_ERR_IO, RBS_ERR_FORMAT,
                                   RBS_ERR_VERSION, RBS_ERR_MEMORY};
    for (size_t s = 0; s < sizeof statuses / sizeof statuses[0]; s++)
        CHECK(strcmp(rbs_status_string(statuses[s]), "unknown status") != 0, "status string %d", statuses[s]);
    CHECK(strcmp(rbs_status_string(99), "unknown status") == 0 && strcmp(rbs_status_string(-6), "unknown status") == 0,
          "status string of no status");
    printf("%s: %d failure(s)\n", argv[0], failures);
    return failures == 0 ? 0 : 1;
}
