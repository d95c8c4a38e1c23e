/*
 * collision.h: one impulsive collision of a rigid body with the wall y = 0 and its work on the wall
 * (direct_model.collision). Frame:
 * the model's lab frame (wall y = 0, normal +Y), velocities in m/s, lengths in units of a, angular velocities
 * in (m/s)/a.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#ifndef RBS_COLLISION_H
#define RBS_COLLISION_H

/* outcomes (direct_model.collision: COLLISION_OK, COLLISION_MULTIPLE_ROOTS, COLLISION_NOT_APPROACHING,
 * COLLISION_FAILED) */
#define COLLISION_OK 0
#define COLLISION_MULTIPLE_ROOTS 1      /* resolved with the smallest positive root */
#define COLLISION_NOT_APPROACHING 2     /* v_c⁻ >= 0: no collision, nothing changed */
#define COLLISION_FAILED 3              /* the root finder did not converge, nothing changed */

/* Smallest positive root of c3 λ³ + c2 λ² + c1 λ + c0, c0 < 0 < c3 (direct_model.collision.smallest_positive_root):
 * *root, *three (three positive roots), returns 1 if converged. */
int rbs_smallest_positive_root(double c0, double c1, double c2, double c3, double *root, int *three);

/* One collision at the contact point r (from the centre of mass, units of a) of a body with velocity V (m/s)
 * and angular velocity W ((m/s)/a), Kinv the inverse of K = J/m in the lab frame (1/a², row-major 3 × 3),
 * wall the wall array (wall.h, layout W_*): dV, dW the changes of V and W (zero unless OK or MULTIPLE_ROOTS); returns a COLLISION_*
 * code (direct_model.collision.collide). */
int rbs_collide(const double V[3], const double W[3], const double r[3], const double Kinv[9], const double *wall,
                double dV[3], double dW[3]);

/* The work of one collision on the wall per unit particle mass, m²/s² (direct_model.collision.wall_work): V, W and r
 * as rbs_collide's (before the collision), dV, dW its changes; *normal = −Δv (v_c⁻ + v_c⁺)/2 and *tangential =
 * −(Δu (u_c⁻ + u_c⁺) + Δw (w_c⁻ + w_c⁺))/2 with V_c⁻ = V + W × r, V_c⁺ = (V + dV) + (W + dW) × r: each >= 0 up to
 * round-off, their sum the kinetic energy the collision takes. */
void rbs_wall_work(const double V[3], const double W[3], const double r[3], const double dV[3], const double dW[3],
                   double *normal, double *tangential);

#endif /* RBS_COLLISION_H */
