/*
 * polyhedron.c: a convex hull's mass properties (direct_model.polyhedron: mass_properties, monomial_integrals,
 * _fsum_mean; math.fsum) and a family's surface from its faces' normals (direct_model.registry._faces_to_triangles),
 * with the same operations in the same order as numpy does them elementwise, so that the loader finds the bits
 * the registry stored: shape_records.c compares a table's triangles and inertia with them.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#include <math.h>
#include <stdlib.h>

#include "polyhedron.h"

#define STACK_TRIANGLES (2 * MAX_STACK_VERTICES - 4)        /* the triangles of a hull kept on the stack */

/* CPython's math.fsum (Shewchuk's partials, then the round-half-even fix across partials) for finite values; the
 * partials are non-overlapping and one input adds at most one, so there are at most n of them (in p). */
double rbs_fsum(const double *x, size_t n, double *p)
{
    size_t used = 0;
    for (size_t k = 0; k < n; k++) {
        double value = x[k];
        size_t kept = 0;
        for (size_t j = 0; j < used; j++) {
            double y = p[j];
            if (fabs(value) < fabs(y)) {
                double swap = value;
                value = y;
                y = swap;
            }
            double hi = value + y, yr = hi - value, lo = y - yr;
            if (lo != 0.0) p[kept++] = lo;
            value = hi;
        }
        used = kept;
        if (value != 0.0) p[used++] = value;
    }
    double hi = 0.0, lo = 0.0;
    if (used > 0) {
        hi = p[--used];
        while (used > 0) {
            double top = hi, y = p[--used];
            hi = top + y;
            double yr = hi - top;
            lo = y - yr;
            if (lo != 0.0) break;
        }
        if (used > 0 && ((lo < 0.0 && p[used - 1] < 0.0) || (lo > 0.0 && p[used - 1] > 0.0))) {
            double y = lo * 2.0, sum = hi + y, yr = sum - hi;
            if (y == yr) hi = sum;
        }
    }
    return hi;
}

/* ∫ x^p y^q z^r dV (p + q + r <= 2) over the body the triangles bound, the corners' coordinates `v`
 * (direct_model.polyhedron.monomial_integrals for one exponent): per triangle det[p0 p1 p2] times the sum over
 * the maps of the coordinates to corners, in itertools.product's order; then math.fsum. `values` and `partials`:
 * room for n_triangles each. */
static double monomial(const double *v, const int32_t *triangles, int n_triangles, int p, int q, int r,
                       double *values, double *partials)
{
    int axes[2], k = 0;
    for (int i = 0; i < p; i++) axes[k++] = 0;
    for (int i = 0; i < q; i++) axes[k++] = 1;
    for (int i = 0; i < r; i++) axes[k++] = 2;
    for (int t = 0; t < n_triangles; t++) {
        const int32_t *own = triangles + 3 * t;
        const double *corner[3] = {v + 3 * own[0], v + 3 * own[1], v + 3 * own[2]};
        const double *p0 = corner[0], *p1 = corner[1], *p2 = corner[2];
        double c0 = p1[1] * p2[2] - p1[2] * p2[1];
        double c1 = p1[2] * p2[0] - p1[0] * p2[2];
        double c2 = p1[0] * p2[1] - p1[1] * p2[0];
        double six_volume = p0[0] * c0 + p0[1] * c1 + p0[2] * c2;
        double total = 0.0;
        if (k == 0) {
            total = total + 1.0 / 6.0;                      /* 0! 0! 0! / 3! */
        } else if (k == 1) {
            for (int a = 0; a < 3; a++) total = total + (1.0 / 24.0) * corner[a][axes[0]];     /* 1! / 4! */
        } else {
            for (int a = 0; a < 3; a++)
                for (int b = 0; b < 3; b++) {
                    double weight = (a == b ? 2.0 : 1.0) / 120.0;                       /* 2! or 1! 1!, / 5! */
                    total = total + weight * corner[a][axes[0]] * corner[b][axes[1]];
                }
        }
        values[t] = six_volume * total;
    }
    return rbs_fsum(values, (size_t)n_triangles, partials);
}

int rbs_hull_mass_properties(const double *vertices, int n_vertices, const int32_t *triangles, int n_triangles,
                             rbs_mass_properties *out)
{
    /* work space: the shifted vertices (3 n_vertices), a column of them (n_vertices), the triangles' values
     * (n_triangles) and fsum's partials (the larger count): on the stack for a hull of MAX_STACK_VERTICES vertices */
    double stack[4 * MAX_STACK_VERTICES + 2 * STACK_TRIANGLES], *shifted = stack, origin[3], first[3];
    size_t most = (size_t)(n_vertices > n_triangles ? n_vertices : n_triangles);
    size_t need = 4 * (size_t)n_vertices + (size_t)n_triangles + most;
    out->volume = NAN;
    if (need > sizeof stack / sizeof *stack && !(shifted = malloc(need * sizeof *shifted))) return -2;
    double *column = shifted + 3 * (size_t)n_vertices, *values = column + n_vertices, *partials = values + n_triangles;
    for (int c = 0; c < 3; c++) {                           /* _fsum_mean: an interior point */
        for (int i = 0; i < n_vertices; i++) column[i] = vertices[3 * i + c];
        origin[c] = rbs_fsum(column, (size_t)n_vertices, partials) / n_vertices;
    }
    for (int i = 0; i < n_vertices; i++)
        for (int c = 0; c < 3; c++) shifted[3 * i + c] = vertices[3 * i + c] - origin[c];
    double volume = monomial(shifted, triangles, n_triangles, 0, 0, 0, values, partials);
    for (int c = 0; c < 3; c++)
        first[c] = monomial(shifted, triangles, n_triangles, c == 0, c == 1, c == 2, values, partials);
    out->volume = volume;
    int status = volume > 0.0 ? 0 : -1;
    if (status == 0) {
        for (int c = 0; c < 3; c++) out->centroid[c] = origin[c] + first[c] / volume;
        for (int i = 0; i < n_vertices; i++)
            for (int c = 0; c < 3; c++) shifted[3 * i + c] = vertices[3 * i + c] - out->centroid[c];
        static const int second[6][3] = {{2, 0, 0}, {0, 2, 0}, {0, 0, 2}, {1, 1, 0}, {1, 0, 1}, {0, 1, 1}};
        double m[6];
        for (int e = 0; e < 6; e++)
            m[e] = monomial(shifted, triangles, n_triangles, second[e][0], second[e][1], second[e][2], values,
                            partials) / volume;
        const double cov[3][3] = {{m[0], m[3], m[4]}, {m[3], m[1], m[5]}, {m[4], m[5], m[2]}};
        double trace = m[0] + m[1] + m[2];
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++) out->inertia[i][j] = trace * (i == j ? 1.0 : 0.0) - cov[i][j];
    }
    if (shifted != stack) free(shifted);
    return status;
}

/* a row of a matrix-vector product as numpy's matmul sums it: from +0.0 (a zero of any sign sums to +0.0, which
 * decides atan2's ±π) */
static double dot(const double *a, const double *b)
{
    return 0.0 + a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

int rbs_faces_to_triangles(const double *vertices, int n_vertices, const double *normals, int n_normals,
                           int32_t *out, int max_triangles)
{
    /* work space: the heights and angles (doubles) and a face's indices (ints) of the vertices, on the stack for
     * MAX_STACK_VERTICES of them */
    double stack_real[2 * MAX_STACK_VERTICES], *height = stack_real;
    int stack_face[MAX_STACK_VERTICES], *face = stack_face;
    if (n_vertices > MAX_STACK_VERTICES) {
        if (!(height = malloc((size_t)n_vertices * (2 * sizeof *height + sizeof *face)))) return -2;
        face = (int *)(height + 2 * (size_t)n_vertices);
    }
    double *angle = height + (n_vertices > MAX_STACK_VERTICES ? n_vertices : MAX_STACK_VERTICES);
    int count = 0;
    for (int f = 0; f < n_normals && count >= 0; f++) {
        const double *normal = normals + 3 * f;
        double top = -INFINITY;
        for (int i = 0; i < n_vertices; i++) {
            const double *x = vertices + 3 * i;
            height[i] = dot(x, normal);
            if (height[i] > top) top = height[i];
        }
        int k = 0;
        for (int i = 0; i < n_vertices; i++)
            if (height[i] >= top - 1e-12) face[k++] = i;
        if (k < 3) continue;                                /* a face shrunk to a point or an edge (κ = 0) */
        double centre[3] = {0.0, 0.0, 0.0}, u[3], w[3];
        for (int j = 0; j < k; j++)
            for (int c = 0; c < 3; c++) centre[c] += vertices[3 * face[j] + c];
        for (int c = 0; c < 3; c++) {
            centre[c] /= k;
            u[c] = vertices[3 * face[0] + c] - centre[c];
        }
        w[0] = normal[1] * u[2] - normal[2] * u[1];
        w[1] = normal[2] * u[0] - normal[0] * u[2];
        w[2] = normal[0] * u[1] - normal[1] * u[0];
        for (int j = 0; j < k; j++) {
            double d[3];
            for (int c = 0; c < 3; c++) d[c] = vertices[3 * face[j] + c] - centre[c];
            angle[j] = atan2(dot(d, w), dot(d, u));
        }
        for (int j = 1; j < k; j++) {                       /* numpy.argsort by angle (distinct on a convex face) */
            double a = angle[j];
            int index = face[j], i = j - 1;
            for (; i >= 0 && angle[i] > a; i--) {
                angle[i + 1] = angle[i];
                face[i + 1] = face[i];
            }
            angle[i + 1] = a;
            face[i + 1] = index;
        }
        for (int j = 1; j + 1 < k && count >= 0; j++) {
            if (count >= max_triangles) {
                count = -1;
                break;
            }
            out[3 * count] = face[0];
            out[3 * count + 1] = face[j];
            out[3 * count + 2] = face[j + 1];
            count++;
        }
    }
    if (height != stack_real) free(height);
    return count;
}
