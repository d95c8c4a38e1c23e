/*
 * frame.h: the impact frame of a hit and the way back to the global frame (surrogate/frame.py).
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

/* a·b of two 3-vectors, the same bits wherever it is inlined (surrogate.kernels.frame._dot) */
RBS_INLINE double rbs_dot(double a0, double a1, double a2, double b0, double b1, double b2)
{
    return fma(a0, b0, fma(a1, b1, a2 * b2));
}

/* V·n < 0 and V finite */
RBS_INLINE int rbs_moves_into_wall(const double *V, const double *n)
{
    return rbs_dot(V[0], V[1], V[2], n[0], n[1], n[2]) < 0.0 && isfinite(V[0] + V[1] + V[2]);
}

typedef struct rbs_frame {
    double alpha1;          /* deg */
    double speed;           /* |V⁻|, m/s */
    double cos_alpha1, sin_alpha1;
    double ex[3], ez[3];
} rbs_frame;

/* The impact frame of V on a wall of unit normal n (surrogate.kernels.frame.impact_frame); at normal impact
 * (tangential part <= 1e-12 |V|) ex is uniform in the wall plane, from u_axis. */
RBS_INLINE void rbs_impact_frame(const double *V, const double *n, double u_axis, rbs_frame *f)
{
    double vn = rbs_dot(V[0], V[1], V[2], n[0], n[1], n[2]);
    double tx = fma(-vn, n[0], V[0]), ty = fma(-vn, n[1], V[1]), tz = fma(-vn, n[2], V[2]);
    double vt = sqrt(fma(tx, tx, fma(ty, ty, tz * tz)));
    double speed = sqrt(fma(vn, vn, vt * vt));
    double ex0, ex1, ex2;
    if (vt > 1e-12 * speed) {
        double inv = 1.0 / vt;
        ex0 = tx * inv;
        ex1 = ty * inv;
        ex2 = tz * inv;
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
    double inv_speed = 1.0 / speed;
    f->alpha1 = rbs_atan2_q1(-vn, vt) * RBS_RAD_TO_DEG;
    f->speed = speed;
    f->cos_alpha1 = vt * inv_speed;
    f->sin_alpha1 = -vn * inv_speed;
}

/* A local draw x = (vx, vy, vz, wx, wy, wz) (units |V⁻|, |V⁻|/a) as V⁺ (m/s) and Ω⁺ (rad/s) in the
 * frame (ex, n, ez); NaN unless rebounded (surrogate.kernels.frame.to_global). */
RBS_INLINE void rbs_to_global(int status, const double x[6], double speed, double a, const double *ex,
                                 const double *n, const double *ez, double *V_out, double *Omega_out)
{
    if (status != RBS_REBOUNDED) {
        for (int k = 0; k < 3; k++) V_out[k] = Omega_out[k] = NAN;
        return;
    }
    double w = speed / a;
    for (int k = 0; k < 3; k++) {
        V_out[k] = speed * rbs_dot(x[0], x[1], x[2], ex[k], n[k], ez[k]);
    }
    for (int k = 0; k < 3; k++) {
        Omega_out[k] = w * rbs_dot(x[3], x[4], x[5], ex[k], n[k], ez[k]);
    }
}

#endif /* RBS_FRAME_H */
