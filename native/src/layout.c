/*
 * layout.c: the kernel arrays a table derives from its cell datasets, as surrogate.kernels.layout
 * derives them, with the same operations in the same order (so the same bits):
 *
 *   axis records       surrogate.kernels.layout.axis_record / interval_lookup
 *   component rows     surrogate.kernels.layout.kernel_rows, with Walker's alias tables (alias_table)
 *   cell records       surrogate.kernels.layout.cell_records
 *   the work's arrays  surrogate.kernels.layout.work_arrays (a table of format 4.1)
 *   restitution        surrogate.kernels.fastmath.restitution_factor at the grid speeds, and
 *                      surrogate.kernels.fastmath.restitution_pieces between them, of the table's wall array
 *                      (wall.h: the exponential family's exp(−k V^p), or the tabulated family's a_nc(V, 1))
 *
 * Every sum is a plain loop in index order and the only libm calls are exp and pow on one value at
 * a time, as the Python side makes them: no step depends on which SIMD kernels numpy or its BLAS pick
 * on a given CPU (docs/native.md, "Bit identity").
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

/* surrogate.kernels.layout.alias_table(weights): keep (float64) and alias; `stack` scratch of 2n ints */
static void alias_table(const double *weights, int n, double *keep, int *alias, int *stack)
{
    double total = 0.0;
    for (int i = 0; i < n; i++) total += weights[i];
    double factor = (double)n / total;
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

#define N_NODES (RESTITUTION_DEGREE + 1)   /* surrogate.kernels.fastmath.N_NODES */

/* surrogate.kernels.fastmath.restitution_factor: the wall's restitution factor f(V) = a_nc(V, 1), exp(−k V^p) for
 * the exponential family, V in m/s */
double rbs_restitution_factor(double V, const double *wall)
{
    if (wall[W_FAMILY] == EXPONENTIAL_CODE) return exp(-wall[W_K] * pow(V, wall[W_P]));
    return rbs_tabulated_restitution(wall, V, 1.0);
}

/* surrogate.kernels.fastmath.restitution_pieces, loop for loop */
double *rbs_restitution_pieces(const double *grid, int n, const double *wall, int *n_pieces, size_t *len)
{
    if (n == 1) {
        double *zeros = calloc(N_NODES, sizeof *zeros);
        *n_pieces = 1;
        *len = N_NODES;
        return zeros;
    }
    double widest = 0.0;
    for (int j = 0; j < n - 1; j++) {
        double r = (grid[j + 1] - grid[j]) / grid[j];
        if (r > widest) widest = r;
    }
    double count = ceil(widest / (RESTITUTION_PIECE_RATIO - 1.0));
    if (!(count < 1e6)) return NULL;
    int pieces = count < 1.0 ? 1 : (int)count;

    /* CHEBYSHEV_NODES, CHEBYSHEV_POWERS and the basis T_j(x_q) at [j][q] */
    double basis[N_NODES][N_NODES], powers[N_NODES][N_NODES];
    static const double x[N_NODES] = {0x1.f9b24942fe45cp-1,  0x1.c83201d3d2c6dp-1,  0x1.6a09e667f3bcdp-1,
                                      0x1.d0e2e2b44de01p-2,  0x1.4060b67a85375p-3,  -0x1.4060b67a85375p-3,
                                      -0x1.d0e2e2b44de01p-2, -0x1.6a09e667f3bcdp-1, -0x1.c83201d3d2c6dp-1,
                                      -0x1.f9b24942fe45cp-1};
    memset(powers, 0, sizeof powers);
    powers[0][0] = 1.0;
    powers[1][1] = 1.0;
    for (int j = 2; j < N_NODES; j++)
        for (int i = 0; i < N_NODES; i++)
            powers[j][i] = 2.0 * (i > 0 ? powers[j - 1][i - 1] : 0.0) - powers[j - 2][i];
    for (int q = 0; q < N_NODES; q++) {
        basis[0][q] = 1.0;
        basis[1][q] = x[q];
    }
    for (int j = 2; j < N_NODES; j++)
        for (int q = 0; q < N_NODES; q++) basis[j][q] = 2.0 * x[q] * basis[j - 1][q] - basis[j - 2][q];

    size_t total = (size_t)(n - 1) * (size_t)pieces * N_NODES;
    double *coef = calloc(total, sizeof *coef);
    if (!coef) return NULL;
    for (int j = 0; j < n - 1; j++) {
        double width = grid[j + 1] - grid[j];
        double half = 0.5 * width / (double)pieces;
        for (int i = 0; i < pieces; i++) {
            double start = grid[j] + width * (double)i / (double)pieces;
            double f[N_NODES], series[N_NODES];
            for (int q = 0; q < N_NODES; q++) f[q] = rbs_restitution_factor(start + (x[q] + 1.0) * half, wall);
            for (int d = 0; d < N_NODES; d++) {
                double sum = 0.0;
                for (int q = 0; q < N_NODES; q++) sum += f[q] * basis[d][q];
                series[d] = d == 0 ? sum / (double)N_NODES : sum * 2.0 / (double)N_NODES;
            }
            double *out = coef + ((size_t)j * (size_t)pieces + (size_t)i) * N_NODES;
            for (int e = 0; e < N_NODES; e++) {
                double sum = 0.0;
                for (int d = 0; d < N_NODES; d++) sum += series[d] * powers[d][e];
                out[e] = sum;
            }
        }
    }
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

/* surrogate.kernels.layout.work_arrays: the work rows (zero after their 19 values), the work's residual shapes
 * level-major, and the work's cell records (means, sds, 1/sds, the trapped particles' mean work) */
static int derive_work(rbs_table *t, const rbs_raw_cells *raw, size_t n_cells)
{
    const size_t C = (size_t)t->n_clusters, M = (size_t)t->n_dictionary, L1 = (size_t)t->n_levels;
    t->work_rows_len = n_cells * C * WORK_ROW_SIZE;
    t->work_rows = rbs_aligned_alloc(t->work_rows_len * sizeof *t->work_rows);
    t->work_dictionary_len = n_cells * N_WORK * L1 * M;
    t->work_dictionary = rbs_aligned_alloc(t->work_dictionary_len * sizeof *t->work_dictionary);
    t->work_cells_len = n_cells * WORK_CELL_SIZE;
    t->work_cells = malloc(t->work_cells_len * sizeof *t->work_cells);
    if (!t->work_rows || !t->work_dictionary || !t->work_cells) return RBS_ERR_MEMORY;
    memset(t->work_rows, 0, t->work_rows_len * sizeof *t->work_rows);
    for (size_t at = 0; at < n_cells * C; at++) {
        float *row = t->work_rows + at * WORK_ROW_SIZE;
        for (int w = 0; w < N_WORK; w++) {
            row[WORK_ROW_LOC + w] = raw->work_loc[at * N_WORK + w];
            row[WORK_ROW_SCALE + w] = raw->work_scale[at * N_WORK + w];
            row[WORK_ROW_SHAPE + w] = (float)raw->work_shape[at * N_WORK + w];
        }
        for (int k = 0; k < N_WORK_SLOPES; k++) row[WORK_ROW_SLOPE + k] = raw->work_slope[at * N_WORK_SLOPES + k];
    }
    for (size_t cw = 0; cw < n_cells * N_WORK; cw++)
        for (size_t i = 0; i < L1; i++)
            for (size_t m = 0; m < M; m++)
                t->work_dictionary[(cw * L1 + i) * M + m] = raw->work_dictionary[(cw * M + m) * L1 + i];
    for (size_t cell = 0; cell < n_cells; cell++) {
        double *r = t->work_cells + cell * WORK_CELL_SIZE;
        for (int w = 0; w < N_WORK; w++) {
            double sd = raw->work_std[cell * N_WORK + w];
            r[WORK_CELL_MEAN + w] = raw->work_mean[cell * N_WORK + w];
            r[WORK_CELL_SD + w] = sd;
            r[WORK_CELL_INV_SD + w] = sd > 0.0 ? 1.0 / sd : 0.0;
            r[WORK_CELL_TRAPPED + w] = raw->trapped_work[cell * N_WORK + w];
        }
    }
    t->has_work = 1;
    return RBS_OK;
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

    /* the wall law at the grid speeds and between them (surrogate.kernels.layout.kernel_data: table.wall.as_array) */
    const double *wall = t->direct_parameters + P_WALL;
    t->speed_restitution = malloc((size_t)t->n_speed * sizeof *t->speed_restitution);
    if (!t->speed_restitution) return RBS_ERR_MEMORY;
    for (int j = 0; j < t->n_speed; j++) t->speed_restitution[j] = rbs_restitution_factor(t->speed_m_s[j], wall);
    t->restitution_pieces = rbs_restitution_pieces(t->speed_m_s, t->n_speed, wall, &t->n_pieces,
                                                   &t->restitution_pieces_len);
    if (!t->restitution_pieces) return RBS_ERR_MEMORY;
    if (raw->work_loc && derive_work(t, raw, n_cells) != RBS_OK) return RBS_ERR_MEMORY;

    if (!all_finite(t->alpha1_axis, t->alpha1_axis_len)) *what = "alpha1_axis";
    else if (!all_finite(t->speed_axis, t->speed_axis_len)) *what = "speed_axis";
    else if (!all_finite(t->cells, t->cells_len)) *what = "cells (P(trapped), means, sds)";
    else if (!all_finite_f(t->clusters, t->clusters_len)) *what = "clusters (component rows)";
    else if (!all_finite_f(t->dictionary, t->dictionary_len)) *what = "dictionary (residual shapes)";
    else if (!all_finite(t->speed_restitution, (size_t)t->n_speed)) *what = "speed_restitution";
    else if (!all_finite(t->restitution_pieces, t->restitution_pieces_len)) *what = "restitution_pieces";
    else if (!all_finite_f(t->work_rows, t->work_rows_len)) *what = "work_rows";
    else if (!all_finite_f(t->work_dictionary, t->work_dictionary_len)) *what = "work_dictionary";
    else if (!all_finite(t->work_cells, t->work_cells_len)) *what = "work_cells";
    return *what ? RBS_ERR_FORMAT : RBS_OK;
}
