/*
 * fastmath.h: the inlined arithmetic of a draw and of the flight's phases that would otherwise call libm
 * (surrogate.kernels.fastmath, direct_model.elementary), with the same operations in the same order and fma()
 * wherever numba uses its fused multiply-add intrinsic, so the same bits:
 *
 *   rbs_sincos            (sin x, cos x): Cody–Waite reduction by π/2, Taylor polynomials
 *   rbs_atan2_q1          atan2(y, x) for x, y >= 0: nearest node atan c + Taylor series of atan z
 *   rbs_restitution_at    exp(−k V^p) between grid speeds from the table's polynomial pieces
 *   rbs_trunc             Python's int(x) of a float as numba compiles it on x86-64
 *
 * The constants are those of the Python modules, written as hexadecimal literals (exact).
 * Compile with -ffp-contract=off: a contracted a*b + c would not give numba's bits.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#ifndef RBS_FASTMATH_H
#define RBS_FASTMATH_H

#include <math.h>
#include <stdint.h>
#include <string.h>

#include "internal.h"

#if defined(__x86_64__) && defined(__SSE2__)
#include <emmintrin.h>
#endif

#define RBS_PI 0x1.921fb54442d18p+1             /* math.pi */
#define RBS_TWO_PI 0x1.921fb54442d18p+2         /* 2.0 * math.pi */
#define RBS_HALF_PI 0x1.921fb54442d18p+0        /* 0.5 * math.pi */
#define RBS_DEG_TO_RAD 0x1.1df46a2529d39p-6     /* math.pi / 180 (numba's math.radians) */
#define RBS_RAD_TO_DEG 0x1.ca5dc1a63c1f8p+5     /* 180 / math.pi (numba's math.degrees) */

#define RBS_HALF_PI_HI 0x1.921fb54442d18p+0     /* π/2 rounded to a double */
#define RBS_HALF_PI_LO 0x1.1a62633145c07p-54    /* π/2 − RBS_HALF_PI_HI */
#define RBS_TWO_OVER_PI 0x1.45f306dc9c883p-1    /* 2.0 / math.pi */

/* Python's int(x) for a float, as numba compiles it (fptosi): x86-64's cvttsd2si, which gives
 * INT64_MIN for NaN and out-of-range values; written out so the C is defined everywhere. */
RBS_INLINE int64_t rbs_trunc(double x)
{
#if defined(__x86_64__) && defined(__SSE2__)
    return _mm_cvttsd_si64(_mm_set_sd(x));      /* the instruction itself */
#else
    return (x > -0x1p63 && x < 0x1p63) ? (int64_t)x : INT64_MIN;
#endif
}

/* an index i (last >= 0) kept in [0, last]: i if it is there, else last (a negative i, INT64_MIN from
 * a NaN or out-of-range conversion included, is beyond last as unsigned: one compare, as the upper clamp
 * alone; surrogate.kernels.fastmath.clamp_index) */
RBS_INLINE int64_t rbs_clamp_index(int64_t i, int64_t last)
{
    return (uint64_t)i <= (uint64_t)last ? i : last;
}

/* the bits of a double (surrogate.kernels.fastmath.bits) */
RBS_INLINE uint64_t rbs_bits(double x)
{
    uint64_t b;
    memcpy(&b, &x, sizeof b);
    return b;
}

/* numba's min(a, b) and max(a, b) of floats: b if b < a (b > a) else a */
RBS_INLINE double rbs_fmin_py(double a, double b) { return b < a ? b : a; }
RBS_INLINE double rbs_fmax_py(double a, double b) { return b > a ? b : a; }

/* The reduced angle's sine s and cosine c and the multiple q of π/2 with x = r + q·π/2, |r| <= π/4
 * (Cody–Waite reduction, Taylor polynomials; direct_model.elementary.sincos) */
RBS_INLINE double rbs_sincos_reduced(double x, double *s, double *c)
{
    const double S3 = -0x1.5555555555555p-3, S5 = 0x1.1111111111111p-7, S7 = -0x1.a01a01a01a01ap-13,
                 S9 = 0x1.71de3a556c734p-19, S11 = -0x1.ae64567f544e4p-26, S13 = 0x1.6124613a86d09p-33,
                 S15 = -0x1.ae7f3e733b81fp-41;
    const double C2 = -0x1p-1, C4 = 0x1.5555555555555p-5, C6 = -0x1.6c16c16c16c17p-10, C8 = 0x1.a01a01a01a01ap-16,
                 C10 = -0x1.27e4fb7789f5cp-22, C12 = 0x1.1eed8eff8d898p-29, C14 = -0x1.93974a8c07c9dp-37,
                 C16 = 0x1.ae7f3e733b81fp-45;
    double q = floor(x * RBS_TWO_OVER_PI + 0.5);
    double r = (x - q * RBS_HALF_PI_HI) - q * RBS_HALF_PI_LO;
    double z = r * r;
    double p = fma(z, fma(z, fma(z, fma(z, fma(z, fma(z, S15, S13), S11), S9), S7), S5), S3);
    *s = fma(r * z, p, r);
    p = fma(z, fma(z, fma(z, fma(z, fma(z, fma(z, fma(z, C16, C14), C12), C10), C8), C6), C4), C2);
    *c = fma(z, p, 1.0);
    return q;
}

/* (sin x, cos x), |x| < 2^62: a few ulp for |x| <= 2π, plus about ulp(x)/2 beyond (direct_model.elementary.sincos) */
RBS_INLINE void rbs_sincos(double x, double *sin_x, double *cos_x)
{
    double s, c;
    int64_t quadrant = rbs_trunc(rbs_sincos_reduced(x, &s, &c)) & 3;
    int odd = (quadrant & 1) == 1;
    double sign = 1.0 - (double)(quadrant & 2);
    *sin_x = sign * (odd ? c : s);
    *cos_x = sign * (odd ? -s : c);
}

/* rbs_sincos written for SIMD loops: the quadrant q mod 4 taken in floating point (q − 4⌊q/4⌋, exact for
 * every finite q, as int(q) & 3 is) instead of an integer conversion AVX2 lacks; the same bits as
 * rbs_sincos for every finite x (and NaN where rbs_sincos gives NaN). */
RBS_INLINE void rbs_sincos_simd(double x, double *sin_x, double *cos_x)
{
    double s, c;
    double q = rbs_sincos_reduced(x, &s, &c);
    double quadrant = q - 4.0 * floor(q * 0.25);
    int odd = (quadrant == 1.0) | (quadrant == 3.0);
    double sign = quadrant >= 2.0 ? -1.0 : 1.0;
    *sin_x = sign * (odd ? c : s);
    *cos_x = sign * (odd ? -s : c);
}

/* atan z of the reduced argument of atan2(y, x), x, y >= 0: t = min/max, c = node/4 the nearest of 0, 1/4, …, 1
 * (node returned, as a double), z = (t − c)/(1 + c t), and whether y > x (surrogate.kernels.fastmath) */
RBS_INLINE double rbs_atan2_q1_reduced(double y, double x, int *swap, double *node)
{
    *swap = y > x;
    double lo = *swap ? x : y, hi = *swap ? y : x;
    *node = (lo > 0.125 * hi ? 1.0 : 0.0) + (lo > 0.375 * hi ? 1.0 : 0.0) + (lo > 0.625 * hi ? 1.0 : 0.0)
            + (lo > 0.875 * hi ? 1.0 : 0.0);
    double c = 0.25 * *node;
    double z = fma(-c, hi, lo) / fma(c, lo, hi);
    double w = z * z;
    double p = fma(w, fma(w, fma(w, fma(w, fma(w, fma(w, fma(w, -0x1.e1e1e1e1e1e1ep-5, 0x1.1111111111111p-4),
                                                          -0x1.3b13b13b13b14p-4), 0x1.745d1745d1746p-4),
                                     -0x1.c71c71c71c71cp-4), 0x1.2492492492492p-3), -0x1.999999999999ap-3),
                  0x1.5555555555555p-2);
    return fma(-z * w, p, z);
}

/* atan2(y, x) in radians for x >= 0, y >= 0, not both 0, to a few ulp (surrogate.kernels.fastmath.atan2_first_quadrant) */
RBS_INLINE double rbs_atan2_q1(double y, double x)
{
    static const double ATAN_AT_NODES[5] = {0.0, 0x1.f5b75f92c80ddp-3, 0x1.dac670561bb4fp-2, 0x1.4978fa3269ee1p-1,
                                            0x1.921fb54442d18p-1};
    int swap;
    double node;
    double atan_z = rbs_atan2_q1_reduced(y, x, &swap, &node);
    double angle = ATAN_AT_NODES[(int)node] + atan_z;
    return swap ? RBS_HALF_PI - angle : angle;
}

/* rbs_atan2_q1 written for SIMD loops (the node's atan by selects, not a table read): the same bits */
RBS_INLINE double rbs_atan2_q1_simd(double y, double x)
{
    int swap;
    double node;
    double atan_z = rbs_atan2_q1_reduced(y, x, &swap, &node);
    /* atan c by selects; one term is non-zero, so the sum is exact */
    double atan_c = ((node == 1.0 ? 0x1.f5b75f92c80ddp-3 : 0.0) + (node == 2.0 ? 0x1.dac670561bb4fp-2 : 0.0))
                  + ((node == 3.0 ? 0x1.4978fa3269ee1p-1 : 0.0) + (node == 4.0 ? 0x1.921fb54442d18p-1 : 0.0));
    double angle = atan_c + atan_z;
    return swap ? RBS_HALF_PI - angle : angle;
}

/* exp(−k V^p) at V = V_j + w (V_{j+1} − V_j), w in [0, 1], from the table's pieces (flat; n_pieces S
 * per interval, degree 9; surrogate.kernels.fastmath.restitution_at) */
RBS_INLINE double rbs_restitution_at(const double *pieces, int64_t n_pieces, int64_t j, double w)
{
    double t = w * (double)n_pieces;
    int64_t i = rbs_clamp_index(rbs_trunc(t), n_pieces - 1);
    double x = 2.0 * (t - (double)i) - 1.0;
    const double *piece = pieces + (j * n_pieces + i) * 10;
    double value = piece[9];
    for (int d = 8; d >= 0; d--) value = fma(value, x, piece[d]);
    return value;
}

#endif /* RBS_FASTMATH_H */
