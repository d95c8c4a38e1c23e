/*
 * flight.c: the search for the next contact of a free flight (direct_model.flight: curvature_bound, safe_step,
 * point_height_rate, lowest_points, choose_contact, find_contact); the flight itself is rotation.c's. The same
 * operations in the same order as the numba kernels (plain products and sums, libm's sqrt).
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#include <math.h>

#include "flight.h"
#include "pymath.h"
#include "rebound_scatter.h"
#include "rotation.h"
#include "shapes.h"

double rbs_curvature_bound(int shape, const double semi[3], double Rb, const double K[3], const double ell[3],
                           const double W[3])
{
    double kmin = py_min(K[0], py_min(K[1], K[2]));
    double kmax = py_max(K[0], py_max(K[1], K[2]));
    double l2 = ell[0] * ell[0] + ell[1] * ell[1] + ell[2] * ell[2];
    double two_t = py_max(ell[0] * W[0] + ell[1] * W[1] + ell[2] * W[2], 0.0);
    double w = py_min(sqrt(l2) / kmin, sqrt(two_t / kmin));
    if (w == 0.0) return 0.0;
    double wdot = 0.5 * (kmax - kmin) * w * w / kmin;
    if (shape == RBS_ELLIPSOID) {
        double amax = py_max(semi[0], py_max(semi[1], semi[2]));
        double amin = py_min(semi[0], py_min(semi[1], semi[2]));
        return 2.0 * amax * amax * w * w / amin + amax * (wdot + w * w);
    }
    return (wdot + w * w) * Rb;
}

/* time until h + hdot τ − ½Mτ² first reaches 0 (h >= 0); inf if never */
static double safe_step(double h, double hdot, double M)
{
    if (h < 0.0) h = 0.0;
    if (hdot <= 0.0) {
        double den = sqrt(hdot * hdot + 2.0 * M * h) - hdot;
        return den > 0.0 ? 2.0 * h / den : 0.0;
    }
    if (M == 0.0) return INFINITY;
    return (hdot + sqrt(hdot * hdot + 2.0 * M * h)) / M;
}

/* height rate dh/dt of the body point at r (lab, from the centroid): v + (Ω × r)_y */
static inline double point_height_rate(double v, const double *W, const double *r)
{
    return v + W[2] * r[0] - W[0] * r[2];
}

int rbs_lowest_points(int shape, const double *verts, int nv, const double semi[3], const double R[9], double y,
                      double *h, double *r_all)
{
    if (shape == RBS_ELLIPSOID) {
        double u0 = R[3] * semi[0], u1 = R[4] * semi[1], u2 = R[5] * semi[2];
        double sigma = sqrt(u0 * u0 + u1 * u1 + u2 * u2);
        double b0 = -semi[0] * u0 / sigma, b1 = -semi[1] * u1 / sigma, b2 = -semi[2] * u2 / sigma;
        for (int k = 0; k < 3; k++) r_all[k] = R[3 * k] * b0 + R[3 * k + 1] * b1 + R[3 * k + 2] * b2;
        h[0] = y + r_all[1];
        return 1;
    }
    for (int i = 0; i < nv; i++) {
        const double *p = verts + 3 * i;
        for (int k = 0; k < 3; k++) r_all[3 * i + k] = R[3 * k] * p[0] + R[3 * k + 1] * p[1] + R[3 * k + 2] * p[2];
        h[i] = y + r_all[3 * i + 1];
    }
    return nv;
}

/* the contact point among touching candidates into rc; 0 if none approaches (the points within set_tol of the
 * lowest form the contact set: their centroid if it approaches, else the lowest approaching point of the set) */
static int choose_contact(int n, const double *h, const double *r_all, double v, const double *W, double set_tol,
                          double *rc)
{
    double hmin = INFINITY;
    for (int i = 0; i < n; i++) hmin = py_min(hmin, h[i]);
    int count = 0, best = -1;
    double best_h = INFINITY;
    rc[0] = rc[1] = rc[2] = 0.0;
    for (int i = 0; i < n; i++) {
        if (h[i] <= hmin + set_tol) {
            count += 1;
            for (int k = 0; k < 3; k++) rc[k] += r_all[3 * i + k];
            if (point_height_rate(v, W, r_all + 3 * i) < 0.0 && h[i] < best_h) {
                best = i;
                best_h = h[i];
            }
        }
    }
    for (int k = 0; k < 3; k++) rc[k] = rc[k] / (double)count;
    if (count > 1 && point_height_rate(v, W, rc) < 0.0) return 1;
    if (best < 0) return 0;
    for (int k = 0; k < 3; k++) rc[k] = r_all[3 * best + k];
    return 1;
}

int rbs_find_contact(int shape, const double *verts, int nv, const double semi[3], double Rb, double M,
                     const double *params, double y0, double v, double contact_tol, double set_tol, long long max_steps,
                     double *t_io, double R[9], double W[3], double *h, double *r_all, double rc[3], long long *n_steps)
{
    int b = -1;                 /* the binding point of the last step */
    double t = *t_io;
    double t_lo = t;            /* latest time known to precede any contact */
    double t_hi = INFINITY;     /* a time past the contact of point b, once a Newton step overshoots */
    for (long long step = 0; step < max_steps; step++) {
        if (step > 0) rbs_rotation_at(params, t, R, W);
        double y = y0 + v * t;
        int n = rbs_lowest_points(shape, verts, nv, semi, R, y, h, r_all);
        double hmin = INFINITY;
        for (int i = 0; i < n; i++) hmin = py_min(hmin, h[i]);
        *n_steps = step + 1;
        *t_io = t;
        if (-contact_tol <= hmin && hmin <= contact_tol && choose_contact(n, h, r_all, v, W, set_tol, rc))
            return SEARCH_CONTACT;
        if (hmin < -contact_tol || t_hi < INFINITY) {
            /* bracket [t_lo, t_hi] in which only point b reaches the wall, monotonically: safeguarded Newton
             * on its height (numba's index −1, the last point of the work space, before any binding point) */
            int bi = b < 0 ? b + MAX_VERTICES : b;
            if (h[bi] < 0.0) t_hi = t;
            else t_lo = t;
            double t_new = t - h[bi] / point_height_rate(v, W, r_all + 3 * bi);
            t = t_lo < t_new && t_new < t_hi ? t_new : 0.5 * (t_lo + t_hi);
            continue;
        }
        if (v > 0.0 && y > Rb) return SEARCH_ESCAPED;
        double tau = INFINITY, tau_other = INFINITY;
        for (int i = 0; i < n; i++) {
            double tau_i = safe_step(h[i], point_height_rate(v, W, r_all + 3 * i), M);
            if (tau_i < tau) {
                tau_other = tau;
                tau = tau_i;
                b = i;
            } else {
                tau_other = py_min(tau_other, tau_i);
            }
        }
        if (v > 0.0 && tau >= (Rb - y) / v) return SEARCH_ESCAPED;
        if (!(0.0 < tau && tau < INFINITY)) return SEARCH_STALLED;
        /* Newton step of the binding point where it is safe: no other point can reach the wall first, and b
         * approaches monotonically */
        double rate_b = point_height_rate(v, W, r_all + 3 * b);
        if (rate_b < 0.0) {
            double t_newton = h[b] / -rate_b;
            if (t_newton < tau_other && t_newton * M < -rate_b) tau = py_max(tau, t_newton);
        }
        t_lo = t;
        t += tau;
    }
    *n_steps = max_steps;
    *t_io = t;
    return SEARCH_STALLED;
}
