/*
 * flight.h: free flight between collisions and the search for the next contact (direct_model.flight). Frame:
 * the model's lab frame (wall y = 0, normal +Y); lengths in units of a, velocities in m/s, times in a/(m/s).
 * Arrays row-major: verts and r_all n × 3, R 3 × 3 body → lab.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#ifndef RBS_FLIGHT_H
#define RBS_FLIGHT_H

#include <math.h>

#include "hull_walk.h"
#include "internal.h"
#include "pymath.h"
#include "shapes.h"

/* search outcomes (direct_model.flight: SEARCH_CONTACT, SEARCH_ESCAPED, SEARCH_STALLED) */
#define SEARCH_CONTACT 0    /* a point touches the wall (within contact_tol) and approaches it */
#define SEARCH_ESCAPED 1    /* the body can never reach the wall again */
#define SEARCH_STALLED 2    /* max_steps reached without a decision */

/* The body: kind KIND_ELLIPSOID (semi its semi-axes) or KIND_POLYHEDRON (verts its nv vertices), Rb its bounding
 * radius (shapes.h, rbs_particle_body). */

/* bounds (ω, |ω̇|, |ω̈|) on the angular velocity and its rates during a flight (direct_model.flight._rate_bounds) */
RBS_INLINE void rbs_rate_bounds(const double K[3], const double ell[3], const double W[3], double *w, double *wdot,
                                double *wddot)
{
    double kmin = py_min(K[0], py_min(K[1], K[2]));
    double kmax = py_max(K[0], py_max(K[1], K[2]));
    double l2 = ell[0] * ell[0] + ell[1] * ell[1] + ell[2] * ell[2];
    double two_t = py_max(ell[0] * W[0] + ell[1] * W[1] + ell[2] * W[2], 0.0);
    *w = py_min(sqrt(l2) / kmin, sqrt(two_t / kmin));
    *wdot = 0.5 * (kmax - kmin) * *w * *w / kmin;
    *wddot = (kmax - kmin) * *w * *wdot / kmin;
}

/* Bounds M on |h''| and M3 on |h'''| of any candidate point's height during a flight, K principal J/m (a²), ell =
 * L/m and W = Ω (lab) at any instant of it (direct_model.flight: curvature_bound, jerk_bound). Inline: a flight's
 * set-up takes both, and the compiler computes their rbs_rate_bounds once. */
RBS_INLINE double rbs_curvature_bound(int kind, const double semi[3], double Rb, const double K[3],
                                      const double ell[3], const double W[3])
{
    double w, wdot, wddot;
    rbs_rate_bounds(K, ell, W, &w, &wdot, &wddot);
    if (kind == KIND_ELLIPSOID) {
        double amax = py_max(semi[0], py_max(semi[1], semi[2]));
        double amin = py_min(semi[0], py_min(semi[1], semi[2]));
        return amax * amax * w * w / amin + amax * (wdot + w * w);
    }
    return (wdot + w * w) * Rb;
}

RBS_INLINE double rbs_jerk_bound(int kind, const double semi[3], double Rb, const double K[3], const double ell[3],
                                 const double W[3])
{
    double w, wdot, wddot;
    rbs_rate_bounds(K, ell, W, &w, &wdot, &wddot);
    double g3 = wddot + 3.0 * w * wdot + w * w * w;
    if (kind == KIND_ELLIPSOID) {
        double amax = py_max(semi[0], py_max(semi[1], semi[2]));
        double amin = py_min(semi[0], py_min(semi[1], semi[2]));
        return 6.0 * amax * amax * w * (wdot + w * w) / amin + amax * g3
               + 6.0 * amax * amax * amax * w * w * w / (amin * amin);
    }
    return g3 * Rb;
}

/* The lab's normal seen from the body and how it turns (direct_model.flight.turning): g = Rᵀ e_y, ġ and g̈ (a vertex
 * p has h'' = g̈·p), from the orientation R, the lab Ω W and the principal J/m K. */
void rbs_turning(const double R[9], const double W[3], const double K[3], double g[3], double d[3], double a[3]);

/* Heights h[i] (units of a) and rates h1[i] of the candidate lowest points at orientation R, lab angular velocity W,
 * centre height y and vertical velocity v: every vertex (body frame, verts), or the ellipsoid's support point,
 * written into verts[0..2]; curv receives what gives a point's curvature h'': g̈ (a vertex p has h'' = g̈·p), or the
 * ellipsoid's h'' in curv[0]. Returns their number (direct_model.flight.lowest_points). */
int rbs_lowest_points(int kind, double *verts, int nv, const double semi[3], const double K[3], const double R[9],
                      const double W[3], double y, double v, double *h, double *h1, double curv[3]);

/* Advance a flight from its start (t = 0) to the next collision or to escape (direct_model.flight.find_contact):
 * K, ell its principal J/m and ℓ = L/m (lab), M, M3 its bounds, params its rotation (filled here by
 * rbs_rotation_init when first needed), y0 and v its centre height (a) at t = 0 and vertical velocity (m/s); R, W
 * on entry at t = 0, on return at the returned time *t; rc the contact point from the centroid (lab) for a
 * contact; h, h1 work space of nv points (at least one), curv of 3. hull: a hull walked over its vertex graph
 * (hull_walk.h; verts, h and h1 are not read; walk its work space, rbs_walk_clear'ed before a rebound's first search,
 * its start the vertex a descent to the lowest may start from, on return the last lowest), or NULL: the candidates
 * are scanned; the same steps and bits either way. Returns a SEARCH_* code, the search steps taken into *n_steps. */
int rbs_find_contact(int kind, double *verts, int nv, const double semi[3], double Rb, const double K[3],
                     const double ell[3], double M, double M3, double *params, double y0, double v, double contact_tol,
                     double set_tol, long long max_steps, double *t, double R[9], double W[3], double *h,
                     double *h1, double curv[3], double rc[3], long long *n_steps, const rbs_hull *hull,
                     rbs_walk *walk);

#endif /* RBS_FLIGHT_H */
