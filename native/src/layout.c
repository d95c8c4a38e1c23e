/*
 * derive.c: the kernel arrays a table derives from its cell datasets, as surrogate.kernels.layout
 * derives them, with the same operations in the same order (so the same bits):
 *
 *   axis records       surrogate.kernels.layout.axis_record / interval_lookup
 *   component rows     surrogate.kernels.layout.kernel_rows, with Walker's alias tables (alias_table)
 *   cell records       surrogate.kernels.layout.cell_records
 *   restitution        exp(−k V^p) at the grid speeds, and surrogate.kernels.fastmath.restitution_pieces
 *
 * The restitution pieces are Chebyshev interpolants computed by numpy (chebinterpolate, cheb2poly);
 * rbs_restitution_pieces repeats numpy's arithmetic step by step, including the order in which the
 * matrix-vector product of chebinterpolate sums its terms (numpy's BLAS, OpenBLAS's dgemv kernels for
 * x86-64 AVX2: docs/native.md, "Bit identity"). The libm calls (sin, exp, pow, sqrt) are those numpy
 * makes on x86-64 without AVX-512, where numpy calls the C library.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"

void *rbs_aligned_alloc(size_t bytes)
{
    size_t rounded = (bytes + 63u) / 64u * 64u;
    if (rounded == 0) rounded = 64;
    return aligned_alloc(64, rounded);
}

/* ------------------------------------------------------------------------- axis records */

/* searchsorted(grid, x, side="right"): the number of grid points <= x */
static long count_le(const double *grid, int n, double x)
{
    long lo = 0, hi = n;
    while (lo < hi) {
        long mid = (lo + hi) / 2;
        if (grid[mid] <= x) lo = mid + 1; else hi = mid;
    }
    return lo;
}

/* surrogate.kernels.layout.axis_record(grid): [origin, 1/step, grid, inverse spacings, look-up indices] */
static double *axis_record(const double *grid, int n, size_t *len)
{
    if (n == 1) {
        double *r = malloc(5 * sizeof *r);
        if (!r) return NULL;
        r[0] = grid[0]; r[1] = 0.0; r[2] = grid[0]; r[3] = 0.0; r[4] = 0.0;
        *len = 5;
        return r;
    }
    double smallest = grid[1] - grid[0];
    for (int j = 1; j < n - 1; j++) {
        double d = grid[j + 1] - grid[j];
        if (d < smallest) smallest = d;
    }
    double step = smallest / 2.0;
    double span = ceil((grid[n - 1] - grid[0]) / step);
    if (!(span >= 0.0 && span < 1e8)) return NULL;
    size_t m = (size_t)span + 1;
    size_t total = 2 + (size_t)n + (size_t)(n - 1) + m;
    double *r = malloc(total * sizeof *r);
    if (!r) return NULL;
    r[AXIS_ORIGIN] = grid[0];
    r[AXIS_INV_STEP] = 1.0 / step;
    for (int j = 0; j < n; j++) r[AXIS_GRID + j] = grid[j];
    for (int j = 0; j < n - 1; j++) r[AXIS_GRID + n + j] = 1.0 / (grid[j + 1] - grid[j]);
    double *lookup = r + AXIS_GRID + n + (n - 1);
    for (size_t i = 0; i < m; i++) {
        double point = grid[0] + step * (double)i;
        long j = count_le(grid, n, point) - 1;
        if (j < 0) j = 0;
        if (j > n - 2) j = n - 2;
        lookup[i] = (double)j;
    }
    *len = total;
    return r;
}

/* ------------------------------------------------------------------------- alias tables */

/* numpy's pairwise summation of a float64 array (np.sum of a contiguous array) */
static double pairwise_sum(const double *a, size_t n)
{
    if (n < 8) {
        double res = 0.0;
        for (size_t i = 0; i < n; i++) res += a[i];
        return res;
    }
    if (n <= 128) {
        double r[8];
        size_t i;
        for (int j = 0; j < 8; j++) r[j] = a[j];
        for (i = 8; i < n - (n % 8); i += 8)
            for (int j = 0; j < 8; j++) r[j] += a[i + j];
        double res = ((r[0] + r[1]) + (r[2] + r[3])) + ((r[4] + r[5]) + (r[6] + r[7]));
        for (; i < n; i++) res += a[i];
        return res;
    }
    size_t n2 = n / 2;
    n2 -= n2 % 8;
    return pairwise_sum(a, n2) + pairwise_sum(a + n2, n - n2);
}

/* surrogate.kernels.layout.alias_table(weights): keep (float64) and alias; `stack` scratch of 2n ints */
static void alias_table(const double *weights, int n, double *keep, int *alias, int *stack)
{
    double factor = (double)n / pairwise_sum(weights, (size_t)n);
    int *small = stack, *large = stack + n;
    int n_small = 0, n_large = 0;
    for (int i = 0; i < n; i++) {
        keep[i] = weights[i] * factor;
        alias[i] = i;
    }
    for (int i = 0; i < n; i++)
        if (keep[i] < 1.0) small[n_small++] = i;
    for (int i = 0; i < n; i++)
        if (keep[i] >= 1.0) large[n_large++] = i;
    while (n_small > 0 && n_large > 0) {
        int lo = small[--n_small], hi = large[n_large - 1];
        alias[lo] = hi;
        keep[hi] -= 1.0 - keep[lo];
        if (keep[hi] < 1.0) small[n_small++] = large[--n_large];
    }
    for (int i = 0; i < n_small; i++) keep[small[i]] = 1.0;
    for (int i = 0; i < n_large; i++) keep[large[i]] = 1.0;
}

/* ------------------------------------------------------------------------- restitution pieces */

/* A numpy polynomial series (numpy.polynomial.polyutils semantics: trailing zeros trimmed) */
typedef struct series {
    int len;
    double c[RESTITUTION_DEGREE + 3];
} series;

static series trimseq(series s)
{
    if (s.len == 0 || s.c[s.len - 1] != 0.0) return s;
    int i;
    for (i = s.len - 1; i >= 0; i--)
        if (s.c[i] != 0.0) break;
    if (i < 0) i = 0;
    s.len = i + 1;
    return s;
}

static series scalar_series(double x)
{
    series s;
    s.len = 1;
    s.c[0] = x;
    return s;
}

/* polyutils._add */
static series poly_add(series a, series b)
{
    a = trimseq(a);
    b = trimseq(b);
    if (a.len > b.len) {
        for (int i = 0; i < b.len; i++) a.c[i] += b.c[i];
        return trimseq(a);
    }
    for (int i = 0; i < a.len; i++) b.c[i] += a.c[i];
    return trimseq(b);
}

/* polyutils._sub */
static series poly_sub(series a, series b)
{
    a = trimseq(a);
    b = trimseq(b);
    if (a.len > b.len) {
        for (int i = 0; i < b.len; i++) a.c[i] -= b.c[i];
        return trimseq(a);
    }
    for (int i = 0; i < b.len; i++) b.c[i] = -b.c[i];
    for (int i = 0; i < a.len; i++) b.c[i] += a.c[i];
    return trimseq(b);
}

/* polynomial.polymulx, times `factor` element by element (1 = none) */
static series poly_mulx(series s, double factor, int scale)
{
    s = trimseq(s);
    if (s.len == 1 && s.c[0] == 0.0) {
        if (scale) s.c[0] = s.c[0] * factor;
        return s;
    }
    series r;
    r.len = s.len + 1;
    r.c[0] = s.c[0] * 0.0;
    for (int i = 0; i < s.len; i++) r.c[i + 1] = s.c[i];
    if (scale)
        for (int i = 0; i < r.len; i++) r.c[i] = r.c[i] * factor;
    return r;
}

/* chebyshev.cheb2poly */
static series cheb2poly(series c)
{
    c = trimseq(c);
    int n = c.len;
    if (n < 3) return c;
    series c0 = scalar_series(c.c[n - 2]), c1 = scalar_series(c.c[n - 1]);
    for (int i = n - 1; i > 1; i--) {
        series tmp = c0;
        c0 = poly_sub(scalar_series(c.c[i - 2]), c1);
        c1 = poly_add(tmp, poly_mulx(c1, 2.0, 1));
    }
    return poly_add(c0, poly_mulx(c1, 1.0, 0));
}

#define N_CHEB (RESTITUTION_DEGREE + 1)

/* The product v · y of chebinterpolate (np.dot of the 10 × 10 Chebyshev matrix, C-contiguous, and a
 * vector) in the order numpy's BLAS sums it (OpenBLAS dgemv_t for AVX2: rows by fours with four
 * fused-multiply-add lanes over the first eight terms, the last two rows by two-lane SSE sums, then
 * the two remaining terms of every row added) */
static void chebyshev_product(const double v[N_CHEB][N_CHEB], const double *y, double *out)
{
    for (int i = 0; i < 8; i++) {
        double lane[4];
        for (int l = 0; l < 4; l++) lane[l] = fma(v[i][l + 4], y[l + 4], fma(v[i][l], y[l], 0.0));
        double sum = (lane[0] + lane[2]) + (lane[1] + lane[3]);
        out[i] = 0.0 + sum * 1.0;
    }
    for (int i = 8; i < N_CHEB; i++) {
        double even = 0.0, odd = 0.0;
        for (int k = 0; k < 8; k += 2) {
            even += v[i][k] * y[k];
            odd += v[i][k + 1] * y[k + 1];
        }
        out[i] = 0.0 + (even + odd) * 1.0;
    }
    double x8 = y[8] * 1.0, x9 = y[9] * 1.0;
    for (int i = 0; i < N_CHEB; i++) out[i] += fma(v[i][8], x8, v[i][9] * x9);
}

/* V^p as numpy's array ** float computes it (exponent 0.5: sqrt) */
static double power(double V, double p)
{
    return p == 0.5 ? sqrt(V) : pow(V, p);
}

double *rbs_restitution_pieces(const double *grid, int n, double k, double p, int *n_pieces, size_t *len)
{
    if (n == 1) {
        double *zeros = calloc(N_CHEB, sizeof *zeros);
        *n_pieces = 1;
        *len = N_CHEB;
        return zeros;
    }
    double ratio = (grid[1] - grid[0]) / grid[0];
    for (int j = 1; j < n - 1; j++) {
        double r = (grid[j + 1] - grid[j]) / grid[j];
        if (r > ratio || r != r) ratio = r;
    }
    double count = ceil(ratio / 0.25);
    if (!(count < 1e6)) return NULL;
    int pieces = count < 1.0 ? 1 : (int)count;
    /* chebpts1(10) and chebvander(x, 9) */
    double x[N_CHEB], v[N_CHEB][N_CHEB];
    double half_pi_over = 0.5 * 3.141592653589793 / N_CHEB;
    for (int i = 0; i < N_CHEB; i++) x[i] = sin(half_pi_over * (double)(2 * i - (N_CHEB - 1))) + 0.0;
    for (int q = 0; q < N_CHEB; q++) {
        v[0][q] = x[q] * 0.0 + 1.0;
        v[1][q] = x[q];
    }
    for (int i = 2; i < N_CHEB; i++)
        for (int q = 0; q < N_CHEB; q++) v[i][q] = v[i - 1][q] * (2.0 * x[q]) - v[i - 2][q];

    size_t total = (size_t)(n - 1) * (size_t)pieces * N_CHEB;
    double *coef = calloc(total, sizeof *coef);
    double *edges = malloc(((size_t)pieces + 1) * sizeof *edges);
    if (!coef || !edges) {
        free(coef);
        free(edges);
        return NULL;
    }
    for (int j = 0; j < n - 1; j++) {
        /* np.linspace(grid[j], grid[j + 1], pieces + 1) */
        double start = grid[j], stop = grid[j + 1];
        double step = (stop - start) / (double)pieces;
        for (int i = 0; i <= pieces; i++) edges[i] = (double)i * step + start;
        edges[pieces] = stop;
        for (int i = 0; i < pieces; i++) {
            double lo = edges[i], half = 0.5 * (edges[i + 1] - edges[i]);
            double y[N_CHEB], c[N_CHEB];
            for (int q = 0; q < N_CHEB; q++) y[q] = exp(-k * power(lo + (x[q] + 1.0) * half, p));
            chebyshev_product((const double(*)[N_CHEB])v, y, c);
            series s;
            s.len = N_CHEB;
            s.c[0] = c[0] / (double)N_CHEB;
            for (int q = 1; q < N_CHEB; q++) s.c[q] = c[q] / (0.5 * N_CHEB);
            series power_series = cheb2poly(s);
            double *out = coef + ((size_t)j * (size_t)pieces + (size_t)i) * N_CHEB;
            for (int q = 0; q < power_series.len && q < N_CHEB; q++) out[q] = power_series.c[q];
        }
    }
    free(edges);
    *n_pieces = pieces;
    *len = total;
    return coef;
}

/* ------------------------------------------------------------------------- all derived arrays */

static int all_finite(const double *x, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (!isfinite(x[i])) return 0;
    return 1;
}

static int all_finite_f(const float *x, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (!isfinite(x[i])) return 0;
    return 1;
}

int rbs_derive(rbs_table *t, const rbs_raw_cells *raw, const char **what)
{
    const size_t n_cells = (size_t)t->n_shapes * (size_t)t->n_alpha1 * (size_t)t->n_speed;
    const size_t C = (size_t)t->n_clusters, M = (size_t)t->n_dictionary, L1 = (size_t)t->n_levels;
    *what = NULL;

    t->alpha1_axis = axis_record(t->alpha1_deg, t->n_alpha1, &t->alpha1_axis_len);
    t->speed_axis = axis_record(t->speed_m_s, t->n_speed, &t->speed_axis_len);
    if (!t->alpha1_axis || !t->speed_axis) return RBS_ERR_MEMORY;

    /* cell records: P(trapped), means, sds, 1/sds */
    t->cells_len = n_cells * CELL_SIZE;
    t->cells = malloc(t->cells_len * sizeof *t->cells);
    if (!t->cells) return RBS_ERR_MEMORY;
    for (size_t cell = 0; cell < n_cells; cell++) {
        double *r = t->cells + cell * CELL_SIZE;
        double rebounded = (double)raw->status_counts[cell * 3], trapped = (double)raw->status_counts[cell * 3 + 1];
        r[CELL_P_TRAPPED] = trapped / (rebounded + trapped);
        for (int k = 0; k < 6; k++) {
            double sd = raw->std[cell * 6 + k];
            r[CELL_MEAN + k] = raw->mean[cell * 6 + k];
            r[CELL_SD + k] = sd;
            r[CELL_INV_SD + k] = sd > 0.0 ? 1.0 / sd : 0.0;
        }
    }

    /* component rows */
    t->clusters_len = n_cells * C * ROW_SIZE;
    t->clusters = rbs_aligned_alloc(t->clusters_len * sizeof *t->clusters);
    double *keep = malloc(C * sizeof *keep);
    int *alias = malloc(C * sizeof *alias), *stack = malloc(2 * C * sizeof *stack);
    if (!t->clusters || !keep || !alias || !stack) {
        free(keep);
        free(alias);
        free(stack);
        return RBS_ERR_MEMORY;
    }
    for (size_t cell = 0; cell < n_cells; cell++) {
        alias_table(raw->cluster_weight + cell * C, (int)C, keep, alias, stack);
        for (size_t c = 0; c < C; c++) {
            float *row = t->clusters + (cell * C + c) * ROW_SIZE;
            size_t at = cell * C + c;
            row[ROW_ALIAS_PROB] = (float)keep[c];
            row[ROW_ALIAS] = (float)alias[c];
            for (int k = 0; k < N_CHAIN; k++) {
                row[ROW_LOC + k] = raw->cluster_loc[at * N_CHAIN + k];
                row[ROW_SCALE + k] = raw->cluster_scale[at * N_CHAIN + k];
                row[ROW_SHAPE + k] = (float)raw->cluster_shape[at * N_CHAIN + k];
            }
            for (int k = 0; k < N_SLOPES; k++) row[ROW_SLOPE + k] = raw->cluster_slope[at * N_SLOPES + k];
            row[ROW_REGIME] = (float)raw->cluster_regime[at];
        }
    }
    free(keep);
    free(alias);
    free(stack);

    /* residual shapes, level-major: [cell, k, i, m] from [cell, k, m, i] */
    t->dictionary_len = n_cells * N_CHAIN * L1 * M;
    t->dictionary = rbs_aligned_alloc(t->dictionary_len * sizeof *t->dictionary);
    if (!t->dictionary) return RBS_ERR_MEMORY;
    for (size_t ck = 0; ck < n_cells * N_CHAIN; ck++)
        for (size_t i = 0; i < L1; i++)
            for (size_t m = 0; m < M; m++)
                t->dictionary[(ck * L1 + i) * M + m] = raw->shape_dictionary[(ck * M + m) * L1 + i];

    /* the wall law at the grid speeds and between them */
    t->speed_restitution = malloc((size_t)t->n_speed * sizeof *t->speed_restitution);
    if (!t->speed_restitution) return RBS_ERR_MEMORY;
    for (int j = 0; j < t->n_speed; j++)
        t->speed_restitution[j] = exp(-t->restitution_k * power(t->speed_m_s[j], t->restitution_p));
    t->restitution_pieces = rbs_restitution_pieces(t->speed_m_s, t->n_speed, t->restitution_k, t->restitution_p,
                                                   &t->n_pieces, &t->restitution_pieces_len);
    if (!t->restitution_pieces) return RBS_ERR_MEMORY;

    if (!all_finite(t->alpha1_axis, t->alpha1_axis_len)) *what = "alpha1_axis";
    else if (!all_finite(t->speed_axis, t->speed_axis_len)) *what = "speed_axis";
    else if (!all_finite(t->cells, t->cells_len)) *what = "cells (P(trapped), means, sds)";
    else if (!all_finite_f(t->clusters, t->clusters_len)) *what = "clusters (component rows)";
    else if (!all_finite_f(t->dictionary, t->dictionary_len)) *what = "dictionary (residual shapes)";
    else if (!all_finite(t->speed_restitution, (size_t)t->n_speed)) *what = "speed_restitution";
    else if (!all_finite(t->restitution_pieces, t->restitution_pieces_len)) *what = "restitution_pieces";
    return *what ? RBS_ERR_FORMAT : RBS_OK;
}
