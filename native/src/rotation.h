/*
 * rotation.h: torque-free motion of a rigid body (direct_model.rotation), the same operations in the same
 * order as the numba kernels, so the same bits:
 *
 *   rbs_rotation_init   the set-up of one flight into a parameter array (RBS_ROT_PARAMS_SIZE doubles, the
 *                       layout of direct_model.rotation, index for index)
 *   rbs_rotation_at     orientation R(t) (body -> lab) and lab angular velocity omega(t) at any time t
 *   rbs_carlson_rf      Carlson's R_F(x, y, z)
 *   rbs_carlson_rj      Carlson's R_J(x, y, z, p)
 *
 * Matrices are row-major 3x3 (x_lab = R x_body), as numba's arrays. No allocation, no global state.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#ifndef RBS_ROTATION_H
#define RBS_ROTATION_H

#define RBS_ROT_PARAMS_SIZE 93 /* direct_model.rotation.ROT_PARAMS_SIZE */

/* Precompute the torque-free motion (direct_model.rotation.rotation_init).
 *   K       principal values of the inertia tensor per unit mass along body axes 0, 1, 2 (positive)
 *   R0      rotation body -> lab at t = 0, row-major
 *   ell     angular momentum per unit mass in the lab frame (constant), possibly zero
 *   params  output, RBS_ROT_PARAMS_SIZE doubles; the Landen levels or theta terms beyond the stored count are not
 *           written */
void rbs_rotation_init(const double K[3], const double R0[9], const double ell[3], double *params);

/* R_out (row-major, body -> lab) and omega_out (lab frame) at time t (direct_model.rotation.rotation_at) */
void rbs_rotation_at(const double *params, double t, double R_out[9], double omega_out[3]);

/* Carlson's symmetric elliptic integrals (direct_model.rotation.carlson_rf, carlson_rj) */
double rbs_carlson_rf(double x, double y, double z);
double rbs_carlson_rj(double x, double y, double z, double p);

#endif
