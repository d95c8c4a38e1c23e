/*
 * frame.h: the impact frame of a hit and the way back to the global frame (surrogate.kernels.frame).
 *
 * The frame of a hit is (ex, n, ez): ex the direction of the tangential part of V⁻, n the wall's unit
 * normal (into the gas), ez = ex × n. Local draws live in it (α1 from the wall, impact plane spanned by
 * ex and n); rbs_to_global turns a local draw into V⁺ (m/s) and Ω⁺ (rad/s) in the caller's frame.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#ifndef RBS_FRAME_H
#define RBS_FRAME_H

#include "fastmath.h"
#include "internal.h"

/* a·b of two 3-vectors, the same bits wherever it is inlined (surrogate.kernels.frame.dot) */
RBS_INLINE double rbs_dot(double a0, double a1, double a2, double b0, double b1, double b2)
{
    return fma(a0, b0, fma(a1, b1, a2 * b2));
}

/* x finite: x − x is 0 only for finite x (a compare, which SIMD loops take, where isfinite is a call) */
RBS_INLINE int rbs_finite(double x)
{
    return x - x == 0.0;
}

/* V·n < 0 and V finite: a particle that hits the wall (else RBS_INVALID at once) */
RBS_INLINE int rbs_moves_into_wall(double V0, double V1, double V2, double n0, double n1, double n2)
{
    return (rbs_dot(V0, V1, V2, n0, n1, n2) < 0.0) & rbs_finite(V0 + V1 + V2);
}

/* (1 ∓ RBS_NORMAL_TOLERANCE)²: the bounds of n·n, so the unit check needs no square root */
#define RBS_NORMAL_MIN2 ((1.0 - RBS_NORMAL_TOLERANCE) * (1.0 - RBS_NORMAL_TOLERANCE))
#define RBS_NORMAL_MAX2 ((1.0 + RBS_NORMAL_TOLERANCE) * (1.0 + RBS_NORMAL_TOLERANCE))

/* The rest of what a draw needs of its particle (surrogate.kernels.frame.particle_ok): | |n| − 1 | <=
 * RBS_NORMAL_TOLERANCE (as (1 ∓ tolerance)² bounds on n·n) and a finite and > 0. Checked with the result
 * (rbs_to_global), not before the draw: the table reads stay in range whatever the particle. */
RBS_INLINE int rbs_particle_ok(double n0, double n1, double n2, double a)
{
    double nn = rbs_dot(n0, n1, n2, n0, n1, n2);
    return (nn >= RBS_NORMAL_MIN2) & (nn <= RBS_NORMAL_MAX2) & (a > 0.0) & rbs_finite(a);
}

#define RBS_ONE_BITS 0x3ff0000000000000ull     /* the bits of 1.0 */

/* The RBS_U_PER_DRAW uniforms u[0], u[stride], ... all in [+0, 1) (NaN and −0 are not;
 * surrogate.kernels.frame.uniforms_ok): on the bits, b | (bits(1) − 1 − b) has its top bit clear exactly
 * then, so the test is an OR over the uniforms (SIMD), not two compares each. Checked with the result: the
 * table indices are clamped into the drawn cell, so the draw reads in range whatever the uniforms, and
 * what it draws from bad ones is discarded. */
RBS_INLINE int rbs_uniforms_ok(const double *u, size_t stride)
{
    uint64_t bad = 0;
    for (int k = 0; k < RBS_U_PER_DRAW; k++) {
        uint64_t b = rbs_bits(u[k * stride]);
        bad |= b | (RBS_ONE_BITS - 1 - b);
    }
    return (bad >> 63) == 0;
}

/* V⁺ (m/s) and Ω⁺ (rad/s) that may be reported as a rebound (surrogate.kernels.frame.rebound_ok): all
 * finite, and V⁺ leaving the wall (V⁺·n > 0); what overflows or underflows on extreme inputs is not. */
RBS_INLINE int rbs_rebound_ok(const double *V, const double *W, const double *n)
{
    return rbs_finite(V[0]) & rbs_finite(V[1]) & rbs_finite(V[2]) & rbs_finite(W[0]) & rbs_finite(W[1])
           & rbs_finite(W[2]) & (rbs_dot(V[0], V[1], V[2], n[0], n[1], n[2]) > 0.0);
}

/* a tangential speed at or below this fraction of |V| is normal impact: ex drawn in the wall plane
 * (surrogate.kernels.frame.NORMAL_IMPACT) */
#define RBS_NORMAL_IMPACT 1e-12

/* The parts of V on a wall of unit normal n that the impact frame is built on (surrogate.kernels.frame.incidence) */
typedef struct rbs_incidence_parts {
    double vn;              /* V·n, m/s */
    double t[3];            /* the tangential part V − (V·n) n, m/s */
    double vt;              /* its length, m/s */
    double speed;           /* |V⁻|, m/s */
} rbs_incidence_parts;

RBS_INLINE rbs_incidence_parts rbs_incidence(const double *V, const double *n)
{
    rbs_incidence_parts p;
    p.vn = rbs_dot(V[0], V[1], V[2], n[0], n[1], n[2]);
    p.t[0] = fma(-p.vn, n[0], V[0]);
    p.t[1] = fma(-p.vn, n[1], V[1]);
    p.t[2] = fma(-p.vn, n[2], V[2]);
    p.vt = sqrt(fma(p.t[0], p.t[0], fma(p.t[1], p.t[1], p.t[2] * p.t[2])));
    p.speed = sqrt(fma(p.vn, p.vn, p.vt * p.vt));
    return p;
}

/* α1 in degrees from the wall, from V·n and the tangential speed (surrogate.kernels.frame.incidence_angle) */
RBS_INLINE double rbs_incidence_angle(double vn, double vt)
{
    return rbs_atan2_q1(-vn, vt) * RBS_RAD_TO_DEG;
}

typedef struct rbs_frame {
    double alpha1;          /* deg */
    double speed;           /* |V⁻|, m/s */
    double cos_alpha1, sin_alpha1;
    double ex[3], ez[3];
} rbs_frame;

/* The impact frame of V on a wall of unit normal n (surrogate.kernels.frame.impact_frame); at normal impact
 * (tangential part <= RBS_NORMAL_IMPACT |V|) ex is uniform in the wall plane, from u_axis. */
RBS_INLINE void rbs_impact_frame(const double *V, const double *n, double u_axis, rbs_frame *f)
{
    rbs_incidence_parts in = rbs_incidence(V, n);
    double ex0, ex1, ex2;
    if (in.vt > RBS_NORMAL_IMPACT * in.speed) {
        double inv = 1.0 / in.vt;
        ex0 = in.t[0] * inv;
        ex1 = in.t[1] * inv;
        ex2 = in.t[2] * inv;
    } else {
        /* orthonormal basis (p, q) of the wall plane: p = n × e_k with e_k the axis least aligned with n */
        double px, py, pz;
        if (fabs(n[0]) <= fabs(n[1]) && fabs(n[0]) <= fabs(n[2])) {
            px = 0.0; py = n[2]; pz = -n[1];
        } else if (fabs(n[1]) <= fabs(n[2])) {
            px = -n[2]; py = 0.0; pz = n[0];
        } else {
            px = n[1]; py = -n[0]; pz = 0.0;
        }
        double pn = sqrt(px * px + py * py + pz * pz);
        px = px / pn;
        py = py / pn;
        pz = pz / pn;
        double qx = n[1] * pz - n[2] * py, qy = n[2] * px - n[0] * pz, qz = n[0] * py - n[1] * px;
        double s, c;
        rbs_sincos(RBS_TWO_PI * u_axis, &s, &c);
        ex0 = c * px + s * qx;
        ex1 = c * py + s * qy;
        ex2 = c * pz + s * qz;
    }
    f->ex[0] = ex0;
    f->ex[1] = ex1;
    f->ex[2] = ex2;
    f->ez[0] = ex1 * n[2] - ex2 * n[1];
    f->ez[1] = ex2 * n[0] - ex0 * n[2];
    f->ez[2] = ex0 * n[1] - ex1 * n[0];
    double inv_speed = 1.0 / in.speed;
    f->alpha1 = rbs_incidence_angle(in.vn, in.vt);
    f->speed = in.speed;
    f->cos_alpha1 = in.vt * inv_speed;
    f->sin_alpha1 = -in.vn * inv_speed;
}

/* A local draw x = (vx, vy, vz, wx, wy, wz) (units |V⁻|, |V⁻|/a) as V⁺ (m/s) and Ω⁺ (rad/s) in the
 * frame (ex, n, ez); returns the status: RBS_INVALID unless `ok` (the particle's and the uniforms' checks)
 * and, for a rebound, rbs_rebound_ok. NaN unless rebounded (surrogate.kernels.frame.to_global). */
RBS_INLINE int rbs_to_global(int status, int ok, const double x[6], double speed, double a, const double *ex,
                                const double *n, const double *ez, double *V_out, double *Omega_out)
{
    double V[3], W[3];
    double w = speed / a;
    for (int k = 0; k < 3; k++) V[k] = speed * rbs_dot(x[0], x[1], x[2], ex[k], n[k], ez[k]);
    for (int k = 0; k < 3; k++) W[k] = w * rbs_dot(x[3], x[4], x[5], ex[k], n[k], ez[k]);
    ok &= status != RBS_OK || rbs_rebound_ok(V, W, n);
    status = ok ? status : RBS_INVALID;
    for (int k = 0; k < 3; k++) {
        V_out[k] = status == RBS_OK ? V[k] : NAN;
        Omega_out[k] = status == RBS_OK ? W[k] : NAN;
    }
    return status;
}

/* The frame records of a block of RBS_BLOCK particles (pipeline.c), field-major: particle b at [b] */
typedef struct rbs_frames {
    double Vin[3][RBS_BLOCK], valid[RBS_BLOCK], ok[RBS_BLOCK], normal[RBS_BLOCK], alpha1[RBS_BLOCK], speed[RBS_BLOCK],
        cos_a1[RBS_BLOCK], sin_a1[RBS_BLOCK], a[RBS_BLOCK], ex[3][RBS_BLOCK], ez[3][RBS_BLOCK], n[3][RBS_BLOCK];
} rbs_frames;

/* The frame records of the m rows from `start` (surrogate.kernels.frame.frame_block): validity
 * (rbs_moves_into_wall; `ok`: rbs_particle_ok and, if `given`, rbs_uniforms_ok) and impact frame of every row
 * (rbs_impact_frame, the same operations), on the rows copied field-major (rows past the end: V = 0,
 * n = e_y, a = 1, invalid); u their uniforms */
RBS_INLINE void rbs_frame_block(const double *V, const double *n, const double *a, size_t start, size_t m,
                                const double u[RBS_U_PER_DRAW][RBS_BLOCK], int given, rbs_frames *k)
{
    for (size_t b = 0; b < RBS_BLOCK; b++) {
        size_t i = start + b;
        int here = b < m;
        for (int j = 0; j < 3; j++) {
            k->Vin[j][b] = here ? V[3 * i + j] : 0.0;
            k->n[j][b] = here ? n[3 * i + j] : (j == 1 ? 1.0 : 0.0);
        }
        k->a[b] = here ? a[i] : 1.0;
    }
    for (size_t b = 0; b < RBS_BLOCK; b++) {       /* branch-free: SIMD across the block */
        double V0 = k->Vin[0][b], V1 = k->Vin[1][b], V2 = k->Vin[2][b];
        double n0 = k->n[0][b], n1 = k->n[1][b], n2 = k->n[2][b];
        double vn = rbs_dot(V0, V1, V2, n0, n1, n2);
        k->valid[b] = rbs_moves_into_wall(V0, V1, V2, n0, n1, n2) ? 1.0 : 0.0;
        /* uniforms drawn from the lanes are in [0, 1): checked only when `given` (rbs_draw_many with hits.u) */
        k->ok[b] = rbs_particle_ok(n0, n1, n2, k->a[b]) & (!given || rbs_uniforms_ok(&u[0][b], RBS_BLOCK)) ? 1.0 : 0.0;
        double tx = fma(-vn, n0, V0), ty = fma(-vn, n1, V1), tz = fma(-vn, n2, V2);
        double vt = sqrt(fma(tx, tx, fma(ty, ty, tz * tz)));
        double speed = sqrt(fma(vn, vn, vt * vt));
        double inv = 1.0 / vt;
        k->ex[0][b] = tx * inv;
        k->ex[1][b] = ty * inv;
        k->ex[2][b] = tz * inv;
        k->normal[b] = vt > RBS_NORMAL_IMPACT * speed ? 0.0 : 1.0;
        double inv_speed = 1.0 / speed;
        k->alpha1[b] = rbs_atan2_q1_simd(-vn, vt) * RBS_RAD_TO_DEG;
        k->speed[b] = speed;
        k->cos_a1[b] = vt * inv_speed;
        k->sin_a1[b] = -vn * inv_speed;
    }
    for (size_t b = 0; b < RBS_BLOCK; b++) {       /* normal impact (rare): the in-wall direction from u[12] */
        if (k->normal[b] != 0.0) {
            rbs_frame f;
            const double Vi[3] = {k->Vin[0][b], k->Vin[1][b], k->Vin[2][b]};
            const double ni[3] = {k->n[0][b], k->n[1][b], k->n[2][b]};
            rbs_impact_frame(Vi, ni, u[12][b], &f);
            for (int j = 0; j < 3; j++) k->ex[j][b] = f.ex[j];
        }
    }
    for (size_t b = 0; b < RBS_BLOCK; b++) {
        double ex0 = k->ex[0][b], ex1 = k->ex[1][b], ex2 = k->ex[2][b];
        double n0 = k->n[0][b], n1 = k->n[1][b], n2 = k->n[2][b];
        k->ez[0][b] = ex1 * n2 - ex2 * n1;
        k->ez[1][b] = ex2 * n0 - ex0 * n2;
        k->ez[2][b] = ex0 * n1 - ex1 * n0;
    }
}

#endif /* RBS_FRAME_H */
