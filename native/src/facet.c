/*
 * facet.c: the facets of a rough wall (surrogate.kernels.facet; docs/model.md §12).
 *
 * The facet normal is the mean normal n rotated in the hit's impact frame (ex, n, ez) by γx about ez and γz about
 * ex, n_f = −sin γx ex + cos γx cos γz n + cos γx sin γz ez, with γx, γz ~ N(0, Δγ²) and a facet seen along V⁻ with
 * probability ∝ p = cos α1 sin γx + sin α1 cos γx cos γz (the shadow effect): drawn by rejection from the proposal
 * N(γz) · N(γx) (cos α1 |γx| + sin α1), a mixture of a normal and a two-sided Rayleigh law for γx. The same
 * operations in the same order as numba (no contraction: CMakeLists.txt), libm's log1p as numba calls it.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#include <math.h>

#include "facet.h"
#include "fastmath.h"
#include "frame.h"
#include "rng_internal.h"

#define FACET_DOMAIN 0x6A09E667F3BCC909ull     /* the facet keys' start (surrogate.kernels.facet._FACET_DOMAIN) */
#define SQRT_2_OVER_PI 0x1.9884533d43651p-1    /* math.sqrt(2.0 / math.pi): E|γx| / Δγ */

int64_t rbs_facet_key(const double u[RBS_U_PER_DRAW])
{
    return rbs_hit_key(u, RBS_U_PER_DRAW, FACET_DOMAIN);
}

/* the radius of a Box–Muller pair, sqrt(−2 ln(1 − u)), u in [0, 1): a standard Rayleigh deviate */
static inline double normal_radius(double u)
{
    return sqrt(-2.0 * log1p(-u));
}

/* the keyed uniform of `key` at `slot` */
static inline double keyed(int64_t key, int64_t slot)
{
    return rbs_grain_uniform((uint64_t)key, (uint64_t)slot);
}

RBS_HOT int rbs_facet_normal(const double V[3], const double n[3], double roughness_deg, int64_t key, int64_t *slot,
                             double facet[3])
{
    const double spread = roughness_deg * RBS_DEG_TO_RAD;
    int64_t s = *slot;
    rbs_frame f;
    rbs_impact_frame(V, n, keyed(key, s), &f);
    s += 1;
    const double cos_a1 = f.cos_alpha1, sin_a1 = f.sin_alpha1;
    const double flat = sin_a1, tilted = cos_a1 * spread * SQRT_2_OVER_PI;     /* the proposal's two weights */
    for (int draw = 0; draw < RBS_MAX_FACET_DRAWS; draw++) {
        double u0 = keyed(key, s), u1 = keyed(key, s + 1), u2 = keyed(key, s + 2);
        double u3 = keyed(key, s + 3), u4 = keyed(key, s + 4), u5 = keyed(key, s + 5);
        s += RBS_U_PER_FACET;
        double r = spread * normal_radius(u1), gx, sin_c, cz;
        if (u0 * (flat + tilted) < flat) {
            double cos_c;
            rbs_sincos(RBS_TWO_PI * u2, &sin_c, &cos_c);
            gx = r * cos_c;
        } else {
            gx = u2 < 0.5 ? r : -r;
        }
        rbs_sincos(RBS_TWO_PI * u4, &sin_c, &cz);
        double gz = spread * normal_radius(u3) * cz;
        double sin_x, cos_x, sin_z, cos_z;
        rbs_sincos(gx, &sin_x, &cos_x);
        rbs_sincos(gz, &sin_z, &cos_z);
        double seen = cos_a1 * sin_x + sin_a1 * cos_x * cos_z;
        if (u5 * (cos_a1 * fabs(gx) + sin_a1) < seen) {
            double tilt = cos_x * cos_z, along = cos_x * sin_z;
            for (int k = 0; k < 3; k++) facet[k] = tilt * n[k] - sin_x * f.ex[k] + along * f.ez[k];
            *slot = s;
            return 1;
        }
    }
    for (int k = 0; k < 3; k++) facet[k] = n[k];
    *slot = s;
    return 0;
}
