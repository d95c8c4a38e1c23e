/*
 * body_rebound.h: a whole rebound of the direct model, free flights and collisions alternating
 * (direct_model.body_rebound). Frame: the model's lab frame (wall y = 0, normal +Y); lengths in units of a,
 * velocities in m/s, angular velocities in (m/s)/a. Matrices row-major 3 × 3.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#ifndef RBS_BODY_REBOUND_H
#define RBS_BODY_REBOUND_H

#include "hull_walk.h"

/* R = the rotation matrix of the quaternion q = (w, x, y, z), normalised here
 * (direct_model.body_rebound.quaternion_to_matrix) */
void rbs_quaternion_to_matrix(const double q[4], double R[9]);

/* One particle's rebound (direct_model.body_rebound.body_rebound without history). The body as rbs_particle_body
 * gives it (shapes.h): kind, its nv vertices verts (at most MAX_HULL_VERTICES; the ellipsoid's support point is
 * written into verts[0..2], so at least one row), its half-extents semi, principal J/m K (a²) and bounding
 * radius Rb; R0 body → lab at the start, V0 (m/s) and W0 ((m/s)/a) incident, wall the wall array (wall.h, layout
 * W_*), n_max collisions allowed, contact_tol and set_tol (units of a), max_steps per flight; V, W receive the state
 * after the last collision. Returns RBS_OK (rebounded), RBS_TRAPPED or RBS_FAILED; the collisions and search steps into
 * *n_collisions, *n_steps, and, where wall_work is not NULL, the work of the collisions on the wall per unit particle
 * mass (m²/s², rbs_wall_work summed in their order from 0: BodyRebound's wall_work_normal, wall_work_tangential) into
 * wall_work[0] (normal) and wall_work[1] (tangential). The heights and rates of the vertices on the stack up to
 * MAX_STACK_VERTICES, above in one malloc (RBS_FAILED with no collision, no step and no work if it fails). */
int rbs_body_rebound(int kind, double *verts, int nv, const double semi[3], const double K[3], double Rb,
                     const double R0[9], const double V0[3], const double W0[3], const double *wall, long long n_max,
                     double contact_tol, double set_tol, long long max_steps, double V[3], double W[3],
                     long long *n_collisions, long long *n_steps, double wall_work[2]);

/* rbs_body_rebound with the caller's work space, h and h1 each with room for max(nv, 1) values; or, with hull not
 * NULL, the body a hull walked over its vertex graph (hull_walk.h: verts, h and h1 are not read). */
int rbs_body_rebound_in(int kind, double *verts, int nv, const double semi[3], const double K[3], double Rb,
                        const double R0[9], const double V0[3], const double W0[3], const double *wall,
                        long long n_max, double contact_tol, double set_tol, long long max_steps, double V[3],
                        double W[3], long long *n_collisions, long long *n_steps, double wall_work[2], double *h,
                        double *h1, const rbs_hull *hull);

#endif /* RBS_BODY_REBOUND_H */
