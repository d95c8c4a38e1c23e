/*
 * shapes.c: the particle shapes of the direct model (direct_model.shapes: SHAPES, body_vertices;
 * direct_model.shape_arrays: family_shape_arrays, particle_body, _half_extents, bounding_radius). The same
 * operations in the same order as the numba kernels.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#include <math.h>
#include <string.h>

#include "pymath.h"
#include "shapes.h"

const char *const rbs_shape_names[RBS_N_FAMILIES] = {"ellipsoid", "prism", "cut_prism", "tetrahedron"};

int rbs_shape_code(const char *name)
{
    for (int k = 0; k < RBS_N_FAMILIES; k++)
        if (strcmp(name, rbs_shape_names[k]) == 0) return k;
    return -1;
}

static void put(double *out, int i, double x, double y, double z)
{
    out[3 * i] = x;
    out[3 * i + 1] = y;
    out[3 * i + 2] = z;
}

int rbs_body_vertices(int shape, double a, double b, double c, double kappa, double hand, double *out)
{
    if (shape == RBS_ELLIPSOID) return 0;
    if (shape == RBS_TETRAHEDRON) {
        double ch = c * hand;
        put(out, 0, a, b, ch);
        put(out, 1, a, -b, -ch);
        put(out, 2, -a, b, -ch);
        put(out, 3, -a, -b, ch);
        return 4;
    }
    static const double sign[2] = {-1.0, 1.0};
    int n = 0;
    for (int i = 0; i < 2; i++)
        for (int j = 0; j < 2; j++)
            for (int k = 0; k < 2; k++) {
                double sa = sign[i], sb = sign[j], sc = sign[k];
                if (shape == RBS_PRISM) {
                    put(out, n, sa * a, sb * b, sc * c);
                    n += 1;
                } else {
                    put(out, n, sa * a * (1.0 - kappa), sb * b, sc * c);
                    put(out, n + 1, sa * a, sb * b * (1.0 - kappa), sc * c);
                    put(out, n + 2, sa * a, sb * b, sc * c * (1.0 - kappa));
                    n += 3;
                }
            }
    return n;
}

void rbs_family_shapes_fill(int8_t *kind, int64_t *vertex_start, double *vertices, double *second_moments,
                            double *aspect, double *aspect_cdf, uint8_t *both_hands, double kappa,
                            const double law[4], const double law_cdf[2], const double kfac[RBS_N_FAMILIES])
{
    vertex_start[0] = 0;
    for (int code = 0; code < RBS_N_FAMILIES; code++) {
        double *rows = vertices + 3 * vertex_start[code];
        int n = 1;
        if (code == RBS_ELLIPSOID) {
            kind[code] = KIND_ELLIPSOID;
            rows[0] = rows[1] = rows[2] = 1.0;
        } else {
            kind[code] = KIND_POLYHEDRON;
            n = rbs_body_vertices(code, 1.0, 1.0, 1.0, kappa, 1.0, rows);
        }
        vertex_start[code + 1] = vertex_start[code] + n;
        for (int k = 0; k < 3; k++) second_moments[3 * code + k] = kfac[code];
        for (int k = 0; k < 4; k++) aspect[4 * code + k] = law[k];
        for (int k = 0; k < 2; k++) aspect_cdf[2 * code + k] = law_cdf[k];
        both_hands[code] = code == RBS_TETRAHEDRON;
    }
}

void rbs_half_extents(const double *unit, int64_t lo, int nv, double e[3])
{
    for (int k = 0; k < 3; k++) {
        double low = unit[3 * lo + k], high = low;
        for (int64_t i = lo + 1; i < lo + nv; i++) {
            low = py_min(low, unit[3 * i + k]);
            high = py_max(high, unit[3 * i + k]);
        }
        e[k] = 0.5 * (high - low);
    }
}

int rbs_particle_body(const rbs_shape_arrays *s, int shape, double ratio_ba, double ratio_cb, double hand,
                      double *verts, double K[3], double semi[3], double scale[3])
{
    int64_t lo = s->vertex_start[shape];
    int nv = (int)(s->vertex_start[shape + 1] - lo);
    const double *unit = s->vertices;
    if (isnan(s->aspect[4 * shape])) ratio_ba = ratio_cb = 1.0;
    double d[3] = {1.0, ratio_ba, ratio_ba * ratio_cb}, e[3];
    if (s->kind[shape] == KIND_ELLIPSOID) {
        nv = 0;
        for (int k = 0; k < 3; k++) e[k] = unit[3 * lo + k];
    } else if (s->half_extents) {
        for (int k = 0; k < 3; k++) e[k] = s->half_extents[3 * shape + k];
    } else {
        rbs_half_extents(unit, lo, nv, e);
    }
    for (int k = 0; k < 3; k++) e[k] = d[k] * e[k];
    double a = py_max(e[0], py_max(e[1], e[2])), f[3];
    for (int k = 0; k < 3; k++) {
        semi[k] = e[k] / a;
        f[k] = d[k] / a;
    }
    if (hand < 0.0) f[2] = -f[2];
    for (int k = 0; k < 3; k++) scale[k] = f[k];
    for (int i = 0; verts && i < nv; i++)
        for (int k = 0; k < 3; k++) verts[3 * i + k] = unit[3 * (lo + i) + k] * f[k];
    const double *m = s->second_moments + 3 * shape;
    double a2 = f[0] * f[0], b2 = f[1] * f[1], c2 = f[2] * f[2];
    if (m[0] == m[1] && m[1] == m[2]) { /* a family's: J/m = s (b² + c², a² + c², a² + b²) */
        K[0] = m[0] * (b2 + c2);
        K[1] = m[0] * (a2 + c2);
        K[2] = m[0] * (a2 + b2);
    } else {
        double m0 = m[0] * a2, m1 = m[1] * b2, m2 = m[2] * c2;
        K[0] = m1 + m2;
        K[1] = m0 + m2;
        K[2] = m0 + m1;
    }
    return nv;
}

double rbs_bounding_radius(int kind, const double semi[3], const double *verts, int nv)
{
    if (kind == KIND_ELLIPSOID) return py_max(semi[0], py_max(semi[1], semi[2]));
    double r2 = 0.0;
    for (int i = 0; i < nv; i++) {
        const double *v = verts + 3 * i;
        r2 = py_max(r2, v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    }
    return sqrt(r2);
}

int rbs_walked(const rbs_shape_arrays *s, int shape)
{
    return s->graph_start && s->kind[shape] == KIND_POLYHEDRON
           && s->vertex_start[shape + 1] - s->vertex_start[shape] > WALK_ABOVE;
}

void rbs_particle_hull(const rbs_shape_arrays *s, int shape, const double scale[3], rbs_hull *hull)
{
    int64_t lo = s->vertex_start[shape], n = s->vertex_start[shape + 1] - lo;
    *hull = (rbs_hull){s->vertices + 3 * lo, (int)n, {scale[0], scale[1], scale[2]}, s->graph_start + lo, s->graph,
                       s->starts + (int64_t)MAP_SIZE * shape, s->far + s->far_start[shape],
                       (int)(s->far_start[shape + 1] - s->far_start[shape])};
}
