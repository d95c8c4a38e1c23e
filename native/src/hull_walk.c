/*
 * hull_walk.c: walks over a hull's vertex graph (direct_model.hull_walk: level, descend, band, walk_lowest,
 * walk_contact_sums, walk_farthest, nearer, map_cell, start_map, farthest_candidates; direct_model.polyhedron:
 * vertex_graph). The same operations in the same order as the numba kernels where they decide an answer; where
 * they decide only the speed (the start map, the descents' paths) too, so that both runtimes walk alike.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "hull_walk.h"
#include "pymath.h"

#define HASH 2654435761u /* direct_model.hull_walk._HASH, Knuth's multiplicative hash */

static int compare_int32(const void *a, const void *b)
{
    int32_t x = *(const int32_t *)a, y = *(const int32_t *)b;
    return (x > y) - (x < y);
}

int rbs_vertex_graph(const int32_t *triangles, int64_t nt, int n, int64_t **start, int32_t **graph)
{
    int64_t *at = calloc((size_t)n + 1, sizeof *at);
    int32_t *all = malloc((size_t)(6 * nt > 0 ? 6 * nt : 1) * sizeof *all);
    if (!at || !all) {
        free(at);
        free(all);
        return -1;
    }
    for (int64_t t = 0; t < 3 * nt; t++) at[triangles[t] + 1] += 2;      /* each corner: two edges of its triangle */
    for (int i = 0; i < n; i++) at[i + 1] += at[i];
    int64_t *fill = malloc((size_t)n * sizeof *fill);
    if (!fill) {
        free(at);
        free(all);
        return -1;
    }
    memcpy(fill, at, (size_t)n * sizeof *fill);
    for (int64_t t = 0; t < nt; t++)
        for (int k = 0; k < 3; k++) {
            int32_t a = triangles[3 * t + k], b = triangles[3 * t + (k + 1) % 3];
            all[fill[a]++] = b;
            all[fill[b]++] = a;
        }
    /* each list ascending without repeats (an edge is in two triangles), packed */
    int64_t kept = 0;
    for (int i = 0; i < n; i++) {
        int64_t lo = at[i], hi = at[i + 1];
        qsort(all + lo, (size_t)(hi - lo), sizeof *all, compare_int32);
        at[i] = kept;
        for (int64_t k = lo; k < hi; k++)
            if (k == lo || all[k] != all[k - 1]) all[kept++] = all[k];
    }
    at[n] = kept;
    free(fill);
    *start = at;
    *graph = all;
    return 0;
}

void rbs_start_map(const double *unit, int n, const int64_t *start, const int32_t *graph, int32_t *starts)
{
    static const double zero[3] = {0.0, 0.0, 0.0};
    const rbs_hull whole = {unit, n, {1.0, 1.0, 1.0}, start, graph, NULL, NULL, 0};
    int i = 0;
    for (int face = 0; face < 6; face++) {
        int axis = face / 2;
        double sign = face % 2 ? -1.0 : 1.0;
        for (int a = 0; a < MAP_CELLS; a++)
            for (int b = 0; b < MAP_CELLS; b++) {
                double w[3];
                w[axis] = sign;
                w[(axis + 1) % 3] = (a + 0.5) / MAP_CELLS * 2.0 - 1.0;
                w[(axis + 2) % 3] = (b + 0.5) / MAP_CELLS * 2.0 - 1.0;
                i = rbs_walk_descend(&whole, w, zero, 0.0, 0.0, 0.0, i, NULL);
                starts[(face * MAP_CELLS + a) * MAP_CELLS + b] = i;
            }
    }
}

typedef struct {
    double key[3];  /* |u|², u0² + u1², u0² */
    int32_t index;
} far_key;

/* |u|² descending, then the index ascending: numpy's stable argsort of −|u|² */
static int compare_far(const void *a, const void *b)
{
    const far_key *x = a, *y = b;
    if (x->key[0] != y->key[0]) return x->key[0] < y->key[0] ? 1 : -1;
    return (x->index > y->index) - (x->index < y->index);
}

int rbs_farthest_candidates(const double *unit, int n, int32_t *far)
{
    far_key *keys = malloc((size_t)(n > 0 ? n : 1) * sizeof *keys);
    if (!keys) return -1;
    for (int i = 0; i < n; i++) {
        const double *u = unit + 3 * i;
        double c = u[0] * u[0], b = c + u[1] * u[1];
        keys[i] = (far_key){{b + u[2] * u[2], b, c}, i};
    }
    qsort(keys, (size_t)n, sizeof *keys, compare_far);
    int count = 0;      /* far[0 .. count) the kept, in the order met: indices into keys */
    for (int m = 0; m < n; m++) {
        const double *x = keys[m].key;
        int beaten = 0;
        for (int k = 0; k < count && !beaten; k++) {
            const double *y = keys[far[k]].key;
            beaten = y[0] >= x[0] + FAR_MARGIN && y[1] >= x[1] + FAR_MARGIN && y[2] >= x[2] + FAR_MARGIN;
        }
        if (!beaten) far[count++] = m;
    }
    for (int k = 0; k < count; k++) far[k] = keys[far[k]].index;
    free(keys);
    qsort(far, (size_t)count, sizeof *far, compare_int32);
    return count;
}

int rbs_walk_descend(const rbs_hull *hl, const double g[3], const double d[3], double y, double v, double T, int i,
                     double *around)
{
    double best = rbs_walk_level(hl, g, d, y, v, T, i);
    for (;;) {
        int here = i;
        double low = INFINITY;
        for (int64_t k = hl->graph_start[here]; k < hl->graph_start[here + 1]; k++) {
            int j = hl->graph[k];
            double x = rbs_walk_level(hl, g, d, y, v, T, j);
            low = py_min(low, x);
            if (x < best) {
                i = j;
                best = x;
            }
        }
        if (i == here) {
            if (around) *around = low;
            return i;
        }
    }
}

/* the start map's cell of the direction w ≠ 0 (direct_model.hull_walk.map_cell) */
static int map_cell(double w0, double w1, double w2)
{
    double a0 = fabs(w0), a1 = fabs(w1), a2 = fabs(w2), top, x, y;
    int axis;
    if (a0 >= a1 && a0 >= a2) {
        axis = 0;
        top = w0;
        x = w1;
        y = w2;
    } else if (a1 >= a2) {
        axis = 1;
        top = w1;
        x = w2;
        y = w0;
    } else {
        axis = 2;
        top = w2;
        x = w0;
        y = w1;
    }
    int face = 2 * axis + (top < 0.0 ? 1 : 0);
    double big = fabs(top);
    if (!(big > 0.0)) return 0;
    double scale = 0.5 * MAP_CELLS / big;
    int i = (int)((x + big) * scale), j = (int)((y + big) * scale); /* |x|, |y| <= big: 0 .. MAP_CELLS */
    i = i < MAP_CELLS ? i : MAP_CELLS - 1;
    j = j < MAP_CELLS ? j : MAP_CELLS - 1;
    return (face * MAP_CELLS + i) * MAP_CELLS + j;
}

int rbs_walk_map_start(const rbs_hull *hl, const double direction[3])
{
    return hl->starts[map_cell(direction[0] * hl->scale[0], direction[1] * hl->scale[1],
                               direction[2] * hl->scale[2])];
}

int rbs_walk_nearer(const rbs_hull *hl, const double g[3], double y, const rbs_walk *w)
{
    double p[3];
    int mapped = rbs_walk_map_start(hl, g);
    return rbs_hull_height(hl, g, y, mapped, p) < rbs_hull_height(hl, g, y, w->start, p) ? mapped : w->start;
}

void rbs_walk_clear(rbs_walk *w)
{
    memset(w->slots, 0, sizeof w->slots);
}

int rbs_walk_band(const rbs_hull *hl, const double g[3], const double d[3], double y, double v, double T, double limit,
                  int start, rbs_walk *w)
{
    if (!(rbs_walk_level(hl, g, d, y, v, T, start) <= limit)) return -1;
    uint32_t slot = ((uint32_t)start * HASH) & (WALK_SLOTS - 1);
    w->slots[slot] = start + 1;
    w->where[0] = (int32_t)slot;
    w->members[0] = start;
    int n_met = 1, count = 1, head = 0, full = 0;
    while (head < count && !full) {
        int i = w->members[head++];
        for (int64_t k = hl->graph_start[i]; k < hl->graph_start[i + 1]; k++) {
            int32_t j = hl->graph[k];
            slot = ((uint32_t)j * HASH) & (WALK_SLOTS - 1);
            while (w->slots[slot] != 0 && w->slots[slot] != j + 1) slot = (slot + 1) & (WALK_SLOTS - 1);
            if (w->slots[slot] != 0) continue;
            if (n_met == WALK_ROOM) {
                full = 1; /* give up: the query scans */
                break;
            }
            w->slots[slot] = j + 1;
            w->where[n_met++] = (int32_t)slot;
            if (rbs_walk_level(hl, g, d, y, v, T, j) <= limit) w->members[count++] = j;
        }
    }
    for (int k = 0; k < n_met; k++) w->slots[w->where[k]] = 0;
    if (full) return -1;
    for (int k = 1; k < count; k++) { /* insertion sort: a band holds a few vertices */
        int32_t x = w->members[k];
        int m = k - 1;
        while (m >= 0 && w->members[m] > x) {
            w->members[m + 1] = w->members[m];
            m--;
        }
        w->members[m + 1] = x;
    }
    return count;
}

void rbs_walk_lowest(const rbs_hull *hl, const double g[3], double y, int start, rbs_walk *w, double *h_low, int *low)
{
    static const double zero[3] = {0.0, 0.0, 0.0};
    double around, p[3];
    int m = rbs_walk_descend(hl, g, zero, y, 0.0, 0.0, start, &around);
    double h_m = rbs_hull_height(hl, g, y, m, p), limit = h_m + WALK_BAND * (fabs(y) + rbs_hull_reach(g, hl->scale));
    *h_low = h_m;
    *low = m;
    if (around > limit) return; /* no neighbour as low: m is the answer */
    int count = rbs_walk_band(hl, g, zero, y, 0.0, 0.0, limit, m, w);
    *h_low = INFINITY;
    *low = -1;
    for (int k = 0; k < (count >= 0 ? count : hl->n); k++) {
        int i = rbs_walk_member(w, count, k);
        double h = rbs_hull_height(hl, g, y, i, p);
        if (h < *h_low) {
            *h_low = h;
            *low = i;
        }
    }
}

void rbs_walk_contact_sums(const rbs_hull *hl, const double g[3], const double d[3], double y, double v, double limit,
                           int low, rbs_walk *w, int *count, double sums[3], double *rate, int *best)
{
    int found = rbs_walk_band(hl, g, d, y, v, 0.0, limit + WALK_BAND * (fabs(y) + rbs_hull_reach(g, hl->scale)), low,
                              w);
    int n = 0, b = -1;
    double s0 = 0.0, s1 = 0.0, s2 = 0.0, r = 0.0, best_h = INFINITY, p[3];
    for (int k = 0; k < (found >= 0 ? found : hl->n); k++) {
        int i = rbs_walk_member(w, found, k);
        double h = rbs_hull_height(hl, g, y, i, p);
        if (h <= limit) {
            double h1 = v + (d[0] * p[0] + d[1] * p[1] + d[2] * p[2]);
            n += 1;
            s0 = s0 + p[0];
            s1 = s1 + p[1];
            s2 = s2 + p[2];
            r = r + h1;
            if (h1 < 0.0 && h < best_h) {
                b = i;
                best_h = h;
            }
        }
    }
    *count = n;
    sums[0] = s0;
    sums[1] = s1;
    sums[2] = s2;
    *rate = r;
    *best = b;
}

double rbs_walk_farthest(const rbs_hull *hl)
{
    double r2 = 0.0, p[3];
    for (int k = 0; k < hl->n_far; k++) {
        rbs_hull_vertex(hl, hl->far[k], p);
        r2 = py_max(r2, p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    }
    return r2;
}
