/*
 * shapes.c: the particle shapes of the direct model (direct_model.shapes: SHAPES, body_vertices,
 * bounding_radius).
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

double rbs_bounding_radius(int shape, double a, double b, double c, const double *verts, int nv)
{
    if (shape == RBS_ELLIPSOID) return py_max(a, py_max(b, c));
    double r2 = 0.0;
    for (int i = 0; i < nv; i++) {
        const double *v = verts + 3 * i;
        r2 = py_max(r2, v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    }
    return sqrt(r2);
}
