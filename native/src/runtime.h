/*
 * runtime.h: the direct model at run time (direct_model.runtime): one particle's whole rebound in the model's
 * frame from RBS_U_PER_REBOUND uniforms and the parameter array P_* (direct_model.runtime.model_parameters).
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#ifndef RBS_RUNTIME_H
#define RBS_RUNTIME_H

#include "rebound_scatter.h"
#include "shapes.h"
#include "wall.h"

/* layout of the parameter array (float64; direct_model.runtime: P_ASPECT_MEAN ... P_WALL, N_PARAMS) */
#define P_ASPECT_MEAN 0     /* the aspect-ratio law (b/a and c/b): mean, sd, low, high */
#define P_ASPECT_SD 1
#define P_ASPECT_LOW 2
#define P_ASPECT_HIGH 3
#define P_CDF_LOW 4         /* Φ((low − mean)/sd), Φ((high − mean)/sd): the law's CDF bounds */
#define P_CDF_HIGH 5
#define P_KAPPA 6
#define P_N_MAX 7
#define P_CONTACT_TOL 8     /* units of a */
#define P_SET_TOL 9         /* units of a */
#define P_MAX_STEPS 10      /* search steps per flight */
#define P_KFAC 11           /* second-moment factor s per shape code, 11..14 */
#define P_WALL (P_KFAC + RBS_N_FAMILIES)       /* one factor per family code, as direct_model.runtime derives it */
#define N_PARAMS (P_WALL + WALL_ARRAY_SIZE)    /* the wall's array (wall.h, layout W_*), zero after its own values */

/* the uniforms of one rebound (direct_model.runtime: U_PER_REBOUND; U_ORIENTATION, U_RATIOS, U_HAND, U_AXIS) */
#define RBS_U_PER_REBOUND 7
#define U_ORIENTATION 0
#define U_RATIOS 3
#define U_HAND 5
#define U_AXIS 6

/* Φ⁻¹(p) for p in (0, 1): Wichura's AS 241 (direct_model.runtime.normal_quantile) */
double rbs_normal_quantile(double p);

/* the quantile at u in [0, 1) of the aspect-ratio law (mean, sd, low, high) with CDF bounds cdf = (Φ_low, Φ_high), in
 * [low, high] (direct_model.runtime.aspect_ratio) */
double rbs_aspect_ratio(const double law[4], const double cdf[2], double u);

/* q = a unit quaternion (w, x, y, z) uniform on S³ from three uniforms (Shoemake;
 * direct_model.runtime.uniform_quaternion) */
void rbs_uniform_quaternion(double u0, double u1, double u2, double q[4]);

/* One particle's whole rebound in the model's frame (direct_model.runtime.rebound_model_frame): params the
 * P_* array, shape the index of the particle's shape in `shapes` (0 .. shapes->n_shapes − 1), incident velocity
 * (vt, vn, 0) m/s (vn < 0), angular velocity (wx, wy, wz) in (m/s)/a (all zero: the body starts touching the
 * wall), u RBS_U_PER_REBOUND uniforms. V⁺ (m/s) into V and Ω⁺ ((m/s)/a) into W; returns RBS_OK (rebounded),
 * RBS_TRAPPED or RBS_FAILED (also, with no collision, when the work space of a hull of more than
 * MAX_STACK_VERTICES vertices cannot be allocated). */
int rbs_rebound_model_frame(const double *params, const rbs_shape_arrays *shapes, int shape, double vt, double vn,
                            double wx, double wy, double wz, const double *u, double V[3], double W[3]);

/* rbs_rebound_model_frame, the collisions of the rebound into *n_collisions (up to the trap) and their work on the
 * wall per unit particle mass (m²/s², normal then tangential; rbs_body_rebound's, up to the trap or the failure, 0
 * without a collision) into wall_work[0], wall_work[1] (direct_model.runtime.rebound_model_frame's
 * wall_work_normal, wall_work_tangential) */
int rbs_rebound_model_frame_counted(const double *params, const rbs_shape_arrays *shapes, int shape, double vt,
                                    double vn, double wx, double wy, double wz, const double *u, double V[3],
                                    double W[3], long long *n_collisions, double wall_work[2]);

#endif /* RBS_RUNTIME_H */
