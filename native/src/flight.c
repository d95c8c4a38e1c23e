/*
 * flight.c: the search for the next contact of a free flight (direct_model.flight: safe_step, pass_over_bound,
 * may_reach, taylor_root, lowest_points, choose_contact, find_contact); the bounds it takes are flight.h's, the
 * flight itself rotation.c's. The same operations in the same order as the numba kernels (plain products and
 * sums, libm's sqrt).
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#include <math.h>

#include "flight.h"
#include "hull_walk.h"
#include "pymath.h"
#include "rebound_scatter.h"
#include "rotation.h"
#include "shapes.h"

#define HORIZON 4.0 /* direct_model.flight.HORIZON */
#define REFINE 3    /* direct_model.flight.REFINE */
/* above this many vertices pass_over_bound starts the pass: from 12 here, 24 in numba
 * (direct_model.flight.PASS_OVER_ABOVE), where each compiler's scan pays for it (the same bits either way) */
#define PASS_OVER_ABOVE 12

/* first τ >= 0 where h + hdot τ − ½Mτ² reaches 0 (h < 0 taken as 0; M of any sign); inf if never */
static double safe_step(double h, double hdot, double M)
{
    if (h < 0.0) h = 0.0;
    double disc = hdot * hdot + 2.0 * M * h;
    if (hdot <= 0.0) {
        if (disc < 0.0) return INFINITY;
        double den = sqrt(disc) - hdot;
        return den > 0.0 ? 2.0 * h / den : 0.0;
    }
    if (M <= 0.0) return INFINITY;
    return (hdot + sqrt(disc)) / M;
}

/* T at least the second smallest safe step of the n points: the larger of the safe steps of point low and of the
 * lowest other point; INFINITY for a single point */
static double pass_over_bound(const double *h, const double *h1, int n, int low, double M)
{
    int second = -1;
    double h_next = INFINITY;
    for (int i = 0; i < n; i++)
        if (i != low && h[i] < h_next) {
            second = i;
            h_next = h[i];
        }
    if (second < 0) return INFINITY;
    return py_max(safe_step(h[low], h1[low], M), safe_step(h[second], h1[second], M));
}

/* 0 only if safe_step(h, hdot, M) is surely above T (> 0, finite): h + hdot T' − ½MT'² > 0 at T' = T(1 + 1e-12)
 * + 1e-300 beyond its round-off; 1 for NaN */
static int may_reach(double h, double hdot, double M, double T)
{
    if (h < 0.0) h = 0.0;
    T = T * (1.0 + 1e-12) + 1e-300;
    double q = h + (hdot - 0.5 * M * T) * T;
    return !(q > 1e-14 * (h + fabs(hdot) * T + 0.5 * M * T * T));
}

/* root nearest 0 of h + hdot s + ½hddot s² (Newton's −h/hdot where it has none) */
static double taylor_root(double h, double hdot, double hddot)
{
    double disc = hdot * hdot - 2.0 * h * hddot;
    if (disc < 0.0) return -h / hdot;
    return -2.0 * h / (hdot + copysign(sqrt(disc), hdot));
}

void rbs_turning(const double R[9], const double W[3], const double K[3], double g[3], double d[3], double a[3])
{
    double g0 = R[3], g1 = R[4], g2 = R[5];
    double w0 = R[0] * W[0] + R[3] * W[1] + R[6] * W[2]; /* ω = Rᵀ Ω */
    double w1 = R[1] * W[0] + R[4] * W[1] + R[7] * W[2];
    double w2 = R[2] * W[0] + R[5] * W[1] + R[8] * W[2];
    double m0 = K[0] * w0, m1 = K[1] * w1, m2 = K[2] * w2;
    double e0 = (m1 * w2 - m2 * w1) / K[0]; /* ω̇ = K⁻¹ (K ω) × ω */
    double e1 = (m2 * w0 - m0 * w2) / K[1];
    double e2 = (m0 * w1 - m1 * w0) / K[2];
    double d0 = g1 * w2 - g2 * w1, d1 = g2 * w0 - g0 * w2, d2 = g0 * w1 - g1 * w0; /* ġ = g × ω */
    g[0] = g0;
    g[1] = g1;
    g[2] = g2;
    d[0] = d0;
    d[1] = d1;
    d[2] = d2;
    a[0] = d1 * w2 - d2 * w1 + (g1 * e2 - g2 * e1); /* g̈ = ġ × ω + g × ω̇ */
    a[1] = d2 * w0 - d0 * w2 + (g2 * e0 - g0 * e2);
    a[2] = d0 * w1 - d1 * w0 + (g0 * e1 - g1 * e0);
}

int rbs_lowest_points(int kind, double *verts, int nv, const double semi[3], const double K[3], const double R[9],
                      const double W[3], double y, double v, double *h, double *h1, double curv[3])
{
    double g[3], d[3], a[3];
    rbs_turning(R, W, K, g, d, a);
    double g0 = g[0], g1 = g[1], g2 = g[2], d0 = d[0], d1 = d[1], d2 = d[2], a0 = a[0], a1 = a[1], a2 = a[2];
    if (kind == KIND_ELLIPSOID) {
        double u0 = semi[0] * g0, u1 = semi[1] * g1, u2 = semi[2] * g2;
        double sigma = sqrt(u0 * u0 + u1 * u1 + u2 * u2);
        double q0 = semi[0] * u0, q1 = semi[1] * u1, q2 = semi[2] * u2; /* A² g */
        verts[0] = -q0 / sigma;
        verts[1] = -q1 / sigma;
        verts[2] = -q2 / sigma;
        double phi1 = 2.0 * (q0 * d0 + q1 * d1 + q2 * d2);
        double phi2 = 2.0 * (semi[0] * semi[0] * d0 * d0 + semi[1] * semi[1] * d1 * d1 + semi[2] * semi[2] * d2 * d2
                             + (q0 * a0 + q1 * a1 + q2 * a2));
        h[0] = y - sigma;
        h1[0] = v - 0.5 * phi1 / sigma;
        curv[0] = (0.25 * phi1 * phi1 / (sigma * sigma) - 0.5 * phi2) / sigma;
        return 1;
    }
    for (int i = 0; i < nv; i++) {
        double p0 = verts[3 * i], p1 = verts[3 * i + 1], p2 = verts[3 * i + 2];
        h[i] = y + (g0 * p0 + g1 * p1 + g2 * p2);
        h1[i] = v + (d0 * p0 + d1 * p1 + d2 * p2);
    }
    curv[0] = a0;
    curv[1] = a1;
    curv[2] = a2;
    return nv;
}

/* curvature h'' of candidate point i from rbs_lowest_points' curv (direct_model.flight.curvature) */
static double curvature(int kind, const double *verts, int i, const double curv[3])
{
    if (kind == KIND_ELLIPSOID) return curv[0];
    return curv[0] * verts[3 * i] + curv[1] * verts[3 * i + 1] + curv[2] * verts[3 * i + 2];
}

/* choose_contact's choice from the contact set's sums (count points, Σp, Σh') and its lowest approaching point best
 * at q (−1: none): the centroid if it approaches, else q, into rc (lab); 0 if neither (direct_model.flight.
 * contact_point) */
static int contact_point(int count, const double sums[3], double rate, int best, const double q[3], const double *R,
                         double *rc)
{
    double p0 = sums[0], p1 = sums[1], p2 = sums[2];
    if (!(count > 1 && rate < 0.0)) {
        if (best < 0) return 0;
        p0 = q[0];
        p1 = q[1];
        p2 = q[2];
        count = 1;
    }
    p0 = p0 / (double)count;
    p1 = p1 / (double)count;
    p2 = p2 / (double)count;
    for (int k = 0; k < 3; k++) rc[k] = R[3 * k] * p0 + R[3 * k + 1] * p1 + R[3 * k + 2] * p2;
    return 1;
}

/* the contact point among touching candidates into rc (lab); 0 if none approaches (the points within set_tol of
 * the lowest form the contact set: their centroid if it approaches, else the lowest approaching point of the set) */
static int choose_contact(int n, const double *verts, const double *h, const double *h1, const double *R,
                          double set_tol, double *rc)
{
    double hmin = INFINITY;
    for (int i = 0; i < n; i++) hmin = py_min(hmin, h[i]);
    int count = 0, best = -1;
    double sums[3] = {0.0, 0.0, 0.0}, rate = 0.0, best_h = INFINITY;
    for (int i = 0; i < n; i++) {
        if (h[i] <= hmin + set_tol) {
            count += 1;
            for (int k = 0; k < 3; k++) sums[k] = sums[k] + verts[3 * i + k];
            rate = rate + h1[i];
            if (h1[i] < 0.0 && h[i] < best_h) {
                best = i;
                best_h = h[i];
            }
        }
    }
    return contact_point(count, sums, rate, best, verts + 3 * (best > 0 ? best : 0), R, rc);
}

/* the scan's loop over the safe steps (flight.c, rbs_find_contact) for one point: a point whose safe step surely
 * exceeds the second smallest so far (or T, at least the final second smallest) changes neither */
static void take_step(double h, double h1, double M, double T, int i, double *tau, double *tau_other, int *b)
{
    double bound = py_min(T, *tau_other);
    if (bound < INFINITY && !may_reach(h, h1, M, bound)) return;
    double tau_i = safe_step(h, h1, M);
    if (tau_i < *tau) {
        *tau_other = *tau;
        *tau = tau_i;
        *b = i;
    } else {
        *tau_other = py_min(*tau_other, tau_i);
    }
}

/* the two smallest safe steps met, t[0] <= t[1], and their vertices i[], after vertex j (not i[0] nor i[1])
 * (direct_model.flight._tighten) */
static void tighten(const rbs_hull *hl, const double g[3], const double d[3], double y, double v, double M, int j,
                    double t[2], int i[2])
{
    double p[3];
    double h = rbs_hull_height(hl, g, y, j, p), h1 = v + (d[0] * p[0] + d[1] * p[1] + d[2] * p[2]);
    if (t[1] < INFINITY && !may_reach(h, h1, M, t[1])) return;
    double tj = safe_step(h, h1, M);
    if (tj < t[0]) {
        t[1] = t[0];
        i[1] = i[0];
        t[0] = tj;
        i[0] = j;
    } else if (tj < t[1]) {
        t[1] = tj;
        i[1] = j;
    }
}

/* (tau, tau_other, b) of a walked hull's vertices (direct_model.flight.walk_safe_steps): the bound T from the
 * lowest, its neighbours and the vertices around the lowest of the level h + T'h', then the walk of T's band in
 * index order */
static void walk_safe_steps(const rbs_hull *hl, const double g[3], const double d[3], double y, double v, double M,
                            int low, rbs_walk *w, double *tau, double *tau_other, int *b)
{
    double p[3], t[2] = {INFINITY, INFINITY};
    int i[2] = {low, -1};
    {
        double h = rbs_hull_height(hl, g, y, low, p);
        t[0] = safe_step(h, v + (d[0] * p[0] + d[1] * p[1] + d[2] * p[2]), M);
    }
    for (int64_t k = hl->graph_start[low]; k < hl->graph_start[low + 1]; k++) tighten(hl, g, d, y, v, M, hl->graph[k],
                                                                                       t, i);
    int m = low;
    for (int round = 0; round < REFINE && t[1] < INFINITY; round++) {
        double before = t[1], Tp = t[1] * (1.0 + 1e-12) + 1e-300;
        const double e[3] = {g[0] + Tp * d[0], g[1] + Tp * d[1], g[2] + Tp * d[2]};
        int mapped = rbs_walk_map_start(hl, e);
        int start = rbs_walk_level(hl, g, d, y, v, Tp, mapped) < rbs_walk_level(hl, g, d, y, v, Tp, m) ? mapped : m;
        int last = m;
        m = rbs_walk_descend(hl, g, d, y, v, Tp, start, NULL);
        if (m == last) break;
        for (int64_t k = hl->graph_start[m] - 1; k < hl->graph_start[m + 1]; k++) {
            int j = k < hl->graph_start[m] ? m : hl->graph[k]; /* m, then its neighbours */
            if (j != i[0] && j != i[1]) tighten(hl, g, d, y, v, M, j, t, i);
        }
        if (!(t[1] < before)) break;
    }
    double T = t[1];
    int count = -1;
    if (T < INFINITY) {
        double Tp = T * (1.0 + 1e-12) + 1e-300;
        double size = fabs(y) + rbs_hull_reach(g, hl->scale) + (fabs(v) + rbs_hull_reach(d, hl->scale)) * Tp
                      + 0.5 * fabs(M) * Tp * Tp;
        count = rbs_walk_band(hl, g, d, y, v, Tp, 0.5 * M * Tp * Tp + WALK_BAND * size, i[0], w);
    }
    *tau = *tau_other = INFINITY;
    *b = -1;
    for (int k = 0; k < (count >= 0 ? count : hl->n); k++) {
        int j = rbs_walk_member(w, count, k);
        double h = rbs_hull_height(hl, g, y, j, p);
        take_step(h, v + (d[0] * p[0] + d[1] * p[1] + d[2] * p[2]), M, T, j, tau, tau_other, b);
    }
}

/* (h, h', h'') of candidate b: from the scan's arrays, or computed for vertex b of a walked hull
 * (direct_model.flight.point_state) */
static void point_state(const rbs_hull *hl, int kind, const double *verts, const double *h, const double *h1,
                        const double curv[3], const double g[3], const double d[3], double y, double v, int b,
                        double state[3])
{
    if (hl) {
        double p[3];
        rbs_hull_vertex(hl, b, p);
        state[0] = y + (g[0] * p[0] + g[1] * p[1] + g[2] * p[2]);
        state[1] = v + (d[0] * p[0] + d[1] * p[1] + d[2] * p[2]);
        state[2] = curv[0] * p[0] + curv[1] * p[1] + curv[2] * p[2];
        return;
    }
    state[0] = h[b];
    state[1] = h1[b];
    state[2] = curvature(kind, verts, b, curv);
}

int rbs_find_contact(int kind, double *verts, int nv, const double semi[3], double Rb, const double K[3],
                     const double ell[3], double M, double M3, double *params, double y0, double v, double contact_tol,
                     double set_tol, long long max_steps, double *t_out, double R[9], double W[3], double *h,
                     double *h1, double curv[3], double rc[3], long long *n_steps, const rbs_hull *hull,
                     rbs_walk *walk)
{
    int b = -1;                 /* the binding point of the last step */
    double t = 0.0;
    double t_lo = 0.0;          /* latest time known to precede any contact */
    double t_hi = INFINITY;     /* a time past the contact of point b, once a step overshoots */
    double g[3] = {0.0, 0.0, 0.0}, d[3] = {0.0, 0.0, 0.0}; /* a walk's view of the normal and its turn */
    for (long long step = 0; step < max_steps; step++) {
        if (step > 0) {
            if (step == 1) rbs_rotation_init(K, R, ell, params);
            rbs_rotation_at(params, t, R, W);
        }
        double y = y0 + v * t;
        double hmin = INFINITY;
        int n = nv, low = 0;
        if (hull) {
            rbs_turning(R, W, K, g, d, curv);
            rbs_walk_lowest(hull, g, y, rbs_walk_nearer(hull, g, y, walk), walk, &hmin, &low);
            walk->start = low;
        } else {
            n = rbs_lowest_points(kind, verts, nv, semi, K, R, W, y, v, h, h1, curv);
            for (int i = 0; i < n; i++)
                if (h[i] < hmin) {
                    hmin = h[i];
                    low = i;
                }
        }
        *n_steps = step + 1;
        *t_out = t;
        if (-contact_tol <= hmin && hmin <= contact_tol) {
            int touching;
            if (hull) {
                int count, best;
                double sums[3], rate, q[3];
                rbs_walk_contact_sums(hull, g, d, y, v, hmin + set_tol, low, walk, &count, sums, &rate, &best);
                rbs_hull_vertex(hull, best > 0 ? best : 0, q);
                touching = contact_point(count, sums, rate, best, q, R, rc);
            } else {
                touching = choose_contact(n, verts, h, h1, R, set_tol, rc);
            }
            if (touching) return SEARCH_CONTACT;
        }
        double state[3] = {0.0, 0.0, 0.0}; /* b's height, rate and curvature: set before their reads */
        if (hmin < -contact_tol || t_hi < INFINITY) {
            /* bracket [t_lo, t_hi] in which only point b reaches the wall, monotonically: safeguarded
             * second-order Newton on its height */
            if (b < 0) b = low; /* below the wall at the start: no bracket, the budget ends it */
            point_state(hull, kind, verts, h, h1, curv, g, d, y, v, b, state);
            if (state[0] < 0.0) t_hi = t;
            else t_lo = t;
            double t_new = t + taylor_root(state[0], state[1], state[2]);
            t = t_lo < t_new && t_new < t_hi ? t_new : 0.5 * (t_lo + t_hi);
            continue;
        }
        if (v > 0.0 && y > Rb) return SEARCH_ESCAPED;
        /* the smallest and second smallest safe steps are at most T: points that surely take longer are passed */
        double tau = INFINITY, tau_other = INFINITY;
        int found = -1;
        if (hull) {
            walk_safe_steps(hull, g, d, y, v, M, low, walk, &tau, &tau_other, &found);
        } else {
            double T = n > PASS_OVER_ABOVE ? pass_over_bound(h, h1, n, low, M) : INFINITY;
            for (int i = 0; i < n; i++) take_step(h[i], h1[i], M, T, i, &tau, &tau_other, &found);
        }
        if (found >= 0) b = found;
        if (0.0 < tau && tau < INFINITY) {
            /* b's longer step from its exact curvature, valid up to the horizon */
            point_state(hull, kind, verts, h, h1, curv, g, d, y, v, b, state);
            double horizon = py_min(tau_other, HORIZON * tau);
            tau = py_max(tau, py_min(horizon, safe_step(state[0], state[1], py_min(M, M3 * horizon / 3.0 - state[2]))));
        }
        if (v > 0.0 && tau >= (Rb - y) / v) return SEARCH_ESCAPED;
        if (!(0.0 < tau && tau < INFINITY)) return SEARCH_STALLED;
        /* second-order Newton step of b where it is safe: no other point can reach the wall first, and b
         * approaches monotonically */
        if (state[1] < 0.0) {
            double t_newton = taylor_root(state[0], state[1], state[2]);
            if (tau < t_newton && t_newton < tau_other
                && (state[1] + M * t_newton < 0.0 || state[1] + (state[2] + 0.5 * M3 * t_newton) * t_newton < 0.0))
                tau = t_newton;
        }
        t_lo = t;
        t += tau;
    }
    *n_steps = max_steps;
    *t_out = t;
    return SEARCH_STALLED;
}
