/*
 * flight.h: free flight between collisions and the search for the next contact (direct_model.flight). Frame:
 * the model's lab frame (wall y = 0, normal +Y); lengths in units of a, velocities in m/s, times in a/(m/s).
 * Arrays row-major: verts and r_all n × 3, R 3 × 3 body → lab.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#ifndef RBS_FLIGHT_H
#define RBS_FLIGHT_H

/* search outcomes (direct_model.flight: SEARCH_CONTACT, SEARCH_ESCAPED, SEARCH_STALLED) */
#define SEARCH_CONTACT 0    /* a point touches the wall (within contact_tol) and approaches it */
#define SEARCH_ESCAPED 1    /* the body can never reach the wall again */
#define SEARCH_STALLED 2    /* max_steps reached without a decision */

/* Bound M on |h''| of any body point's height during a flight, K principal J/m (a²), ell = L/m and W = Ω
 * (lab) at any instant of it (direct_model.flight.curvature_bound). */
double rbs_curvature_bound(int shape, const double semi[3], double Rb, const double K[3], const double ell[3],
                           const double W[3]);

/* Heights h[i] (units of a) and lab offsets r_all[i] of the candidate lowest points at centre height y:
 * every vertex, or the ellipsoid's support point; returns their number (direct_model.flight.lowest_points). */
int rbs_lowest_points(int shape, const double *verts, int nv, const double semi[3], const double R[9], double y,
                      double *h, double *r_all);

/* Advance the flight from time t to the next collision or to escape (direct_model.flight.find_contact):
 * params the flight's rotation (rbs_rotation_init), y0 and v its centre height (a) at its t = 0 and vertical
 * velocity (m/s); R, W on entry at time t, on return at the returned time *t; rc the contact point from the
 * centroid (lab) for a contact; h, r_all work space of MAX_VERTICES points. Returns a SEARCH_* code, the
 * search steps taken into *n_steps. */
int rbs_find_contact(int shape, const double *verts, int nv, const double semi[3], double Rb, double M,
                     const double *params, double y0, double v, double contact_tol, double set_tol, long long max_steps,
                     double *t, double R[9], double W[3], double *h, double *r_all, double rc[3], long long *n_steps);

#endif /* RBS_FLIGHT_H */
