/*
 * collision.c: one impulsive collision of a rigid body with the wall y = 0 and its work on the wall
 * (direct_model.collision: collide, wall_work, smallest_positive_root, _first_guess, _bracketed_root, _cubic,
 * _cubic_slope, _form). The same operations in the same order as the numba kernels: plain products and sums (no
 * fma), libm's sqrt, exp and pow.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#include <math.h>

#include "collision.h"
#include "pymath.h"
#include "wall.h"

#define MAX_ROOT_ITERATIONS 200     /* direct_model.collision._MAX_ROOT_ITERATIONS */

static inline double cubic(double c0, double c1, double c2, double c3, double x)
{
    return ((c3 * x + c2) * x + c1) * x + c0;
}

static inline double cubic_slope(double c1, double c2, double c3, double x)
{
    return (3.0 * c3 * x + 2.0 * c2) * x + c1;
}

/* a first guess of the root above lo (P(lo) <= 0, P rising after lo): the root of P's second-order expansion at
 * lo, P(lo) + P'(lo) d + P''(lo) d^2 / 2 (P(lo + d) = c3 d^3 >= 0 there, so it is above the root), or a Newton
 * step from lo where that has none; inf if neither exists */
static double first_guess(double c0, double c1, double c2, double c3, double lo)
{
    double p = cubic(c0, c1, c2, c3, lo);
    double slope = cubic_slope(c1, c2, c3, lo);
    double curvature = 6.0 * c3 * lo + 2.0 * c2;
    double disc = slope * slope - 2.0 * p * curvature;
    if (disc >= 0.0) {
        double denominator = slope + sqrt(disc);
        if (denominator > 0.0) return lo - 2.0 * p / denominator;
    }
    return slope > 0.0 ? lo - p / slope : INFINITY;
}

/* root of the cubic in [lo, hi] where it rises from <= 0 to >= 0: Newton steps from first_guess (the bracket's
 * midpoint if the guess is outside it), bisection whenever they leave the bracket, until P(x) is within the
 * rounding of its evaluation (|P(x)| <= 1e-15 sum |c_i| x^i, lo >= 0), the step or the bracket below 4e-16
 * relative; returns 1 if converged */
static int bracketed_root(double c0, double c1, double c2, double c3, double lo, double hi, double *root)
{
    double x = first_guess(c0, c1, c2, c3, lo);
    if (!(lo < x && x < hi)) x = 0.5 * (lo + hi);
    double a0 = 1e-15 * fabs(c0), a1 = 1e-15 * fabs(c1), a2 = 1e-15 * fabs(c2), a3 = 1e-15 * fabs(c3);
    for (int i = 0; i < MAX_ROOT_ITERATIONS; i++) {
        double fx = cubic(c0, c1, c2, c3, x);
        if (fabs(fx) <= cubic(a0, a1, a2, a3, x)) {
            *root = x;
            return 1;
        }
        if (fx < 0.0) lo = x;
        else hi = x;
        double slope = cubic_slope(c1, c2, c3, x), xn = 0.0;
        int step_ok = 0;
        if (slope > 0.0) {
            xn = x - fx / slope;
            step_ok = lo < xn && xn < hi;
        }
        if (!step_ok) xn = 0.5 * (lo + hi);
        if (fabs(xn - x) <= 4e-16 * fabs(xn) || hi - lo <= 4e-16 * hi) {
            *root = xn;
            return 1;
        }
        x = xn;
    }
    *root = x;
    return 0;
}

int rbs_smallest_positive_root(double c0, double c1, double c2, double c3, double *root, int *three)
{
    /* critical points of the cubic */
    double qa = 3.0 * c3, qb = 2.0 * c2, qc = c1;
    double disc = qb * qb - 4.0 * qa * qc;
    /* Cauchy bound on the roots' magnitude */
    double upper = 1.0 + py_max(fabs(c0), py_max(fabs(c1), fabs(c2))) / c3;
    *three = 0;
    if (disc <= 0.0) return bracketed_root(c0, c1, c2, c3, 0.0, upper, root);
    double sq = sqrt(disc);
    /* numerically stable quadratic roots */
    double t = -0.5 * (qb + (qb >= 0.0 ? sq : -sq));
    double r1 = t / qa, r2 = t != 0.0 ? qc / t : 0.0;
    double x1 = py_min(r1, r2), x2 = py_max(r1, r2);    /* P rises on (−∞, x1], falls on [x1, x2], rises after */
    if (x2 <= 0.0 || x1 <= 0.0)
        /* from P(0) < 0 the cubic falls, then rises once: a single positive root */
        return bracketed_root(c0, c1, c2, c3, py_max(x2, 0.0), upper, root);
    double p1 = cubic(c0, c1, c2, c3, x1);
    if (p1 >= 0.0) {
        double p2 = cubic(c0, c1, c2, c3, x2);
        int ok = bracketed_root(c0, c1, c2, c3, 0.0, x1, root);
        *three = p2 <= 0.0;
        return ok;
    }
    return bracketed_root(c0, c1, c2, c3, x2, upper, root);
}

/* pᵀ A q for a row-major 3 × 3 A */
static inline double form(const double *A, const double *p, const double *q)
{
    double acc = 0.0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) acc += p[i] * A[3 * i + j] * q[j];
    return acc;
}

int rbs_collide(const double V[3], const double W[3], const double r[3], const double Kinv[9], const double *wall,
                double dV[3], double dW[3])
{
    for (int k = 0; k < 3; k++) {
        dV[k] = 0.0;
        dW[k] = 0.0;
    }
    double rx = r[0], ry = r[1], rz = r[2];
    /* contact-point velocity V_c = V + W × r */
    double uc = V[0] + W[1] * rz - W[2] * ry;
    double vc = V[1] + W[2] * rx - W[0] * rz;
    double wc = V[2] + W[0] * ry - W[1] * rx;
    if (!(vc < 0.0)) return COLLISION_NOT_APPROACHING;
    double speed_c = sqrt(uc * uc + vc * vc + wc * wc);
    double a_nc = rbs_restitution(wall, speed_c, -vc / speed_c);
    double dvc = -(1.0 + a_nc) * vc;                   /* > 0 */
    double speed_p = sqrt(V[0] * V[0] + V[1] * V[1] + V[2] * V[2]);
    double rnorm = sqrt(rx * rx + ry * ry + rz * rz);
    double cos_g = 0.0;
    if (speed_p > 0.0 && rnorm > 0.0) cos_g = (rx * V[0] + ry * V[1] + rz * V[2]) / (rnorm * speed_p);
    double mu = rbs_friction_factor(wall, cos_g) / speed_c;

    /* G = I − [r]× K⁻¹ [r]×, G_ij = δ_ij + (r × e_i)·K⁻¹(r × e_j) */
    const double e0[3] = {0.0, rz, -ry}, e1[3] = {-rz, 0.0, rx}, e2[3] = {ry, -rx, 0.0};
    double g00 = 1.0 + form(Kinv, e0, e0);
    double g11 = 1.0 + form(Kinv, e1, e1);
    double g22 = 1.0 + form(Kinv, e2, e2);
    double g01 = form(Kinv, e0, e1);
    double g02 = form(Kinv, e0, e2);
    double g12 = form(Kinv, e1, e2);

    /* tangential system (1 + hλG_xx) x + hλG_xz z = rx(λ), hλG_zx x + (1 + hλG_zz) z = rz(λ) */
    double h = 0.5 * mu;
    double p = h * g00, q = h * g22, s = h * g02;
    double d1 = p + q, d2 = p * q - s * s;             /* det = 1 + d1 λ + d2 λ² */
    double rx1 = -mu * uc, rx2 = -0.5 * mu * g01;
    double rz1 = -mu * wc, rz2 = -0.5 * mu * g12;
    double x2 = rx2 + q * rx1 - s * rz1, x3 = q * rx2 - s * rz2;   /* det·x = rx1 λ + x2 λ² + x3 λ³ */
    double z2 = rz2 + p * rz1 - s * rx1, z3 = p * rz2 - s * rx2;   /* det·z = rz1 λ + z2 λ² + z3 λ³ */
    double c0 = -dvc;
    double c1 = g01 * rx1 + g12 * rz1 + g11 - dvc * d1;
    double c2 = g01 * x2 + g12 * z2 + g11 * d1 - dvc * d2;
    double c3 = g01 * x3 + g12 * z3 + g11 * d2;
    double lam;
    int multiple = 0, ok = 1;
    if (!(c3 > 0.0)) {
        /* frictionless limit (μ → 0): the cubic degenerates to a line */
        if (!(c1 > 0.0)) return COLLISION_FAILED;
        lam = dvc / c1;
    } else {
        ok = rbs_smallest_positive_root(c0, c1, c2, c3, &lam, &multiple);
    }
    if (!ok || !(lam > 0.0)) return COLLISION_FAILED;

    double det = 1.0 + d1 * lam + d2 * lam * lam;
    double bx = rx1 * lam + rx2 * lam * lam;
    double bz = rz1 * lam + rz2 * lam * lam;
    dV[0] = (bx * (1.0 + q * lam) - s * lam * bz) / det;
    dV[1] = lam;
    dV[2] = (bz * (1.0 + p * lam) - s * lam * bx) / det;
    /* K ΔΩ = r × ΔV */
    double tx = ry * dV[2] - rz * dV[1];
    double ty = rz * dV[0] - rx * dV[2];
    double tz = rx * dV[1] - ry * dV[0];
    for (int i = 0; i < 3; i++) dW[i] = Kinv[3 * i] * tx + Kinv[3 * i + 1] * ty + Kinv[3 * i + 2] * tz;
    return multiple ? COLLISION_MULTIPLE_ROOTS : COLLISION_OK;
}

void rbs_wall_work(const double V[3], const double W[3], const double r[3], const double dV[3], const double dW[3],
                   double *normal, double *tangential)
{
    double rx = r[0], ry = r[1], rz = r[2];
    double u0 = V[0] + W[1] * rz - W[2] * ry;
    double v0 = V[1] + W[2] * rx - W[0] * rz;
    double w0 = V[2] + W[0] * ry - W[1] * rx;
    double Vx = V[0] + dV[0], Vy = V[1] + dV[1], Vz = V[2] + dV[2];
    double Wx = W[0] + dW[0], Wy = W[1] + dW[1], Wz = W[2] + dW[2];
    double u1 = Vx + Wy * rz - Wz * ry;
    double v1 = Vy + Wz * rx - Wx * rz;
    double w1 = Vz + Wx * ry - Wy * rx;
    *normal = -(dV[1] * (v0 + v1)) * 0.5;
    *tangential = -(dV[0] * (u0 + u1) + dV[2] * (w0 + w1)) * 0.5;
}
