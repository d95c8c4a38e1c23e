/*
 * paths.h: the internal entry points of a hit, with the kernels' arguments (the public calls of rebound_scatter.h
 * take records): each path alone and the hit along a path. The public calls are made of them; the C test programs,
 * the bench programs (the static library) and the ctypes tests (librebound_scatter_testing.so) check them against
 * numba. Not exported by librebound_scatter.so.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#ifndef RBS_PATHS_H
#define RBS_PATHS_H

#include "internal.h"

/* table_path.c: the table path of one hit, global frame (surrogate.kernels.table_path.table_rebound; Ω⁻ = 0 is
 * assumed): RBS_OK, RBS_TRAPPED or RBS_INVALID (V not moving into the wall, n not a unit vector, a not finite and
 * > 0, a uniform outside [0, 1), a result not finite or not leaving the wall, a NULL pointer, a mix of another
 * table, an unknown interpolation: RBS_INTERPOLATION_*), V⁺ (m/s) and Ω⁺ (rad/s) NaN unless rebounded.
 * rbs_table_hit also gives the table shape drawn from the mix into *shape (−1 for RBS_INVALID) and the hit's work
 * on the wall drawn with the rebound (work.h: m²/s², a trapped draw its cell's trapped particles' mean) into
 * wall_work[0] (normal) and wall_work[1] (tangential), NaN from a table of format 4.0 and for RBS_INVALID. */
int rbs_table_rebound(const rbs_table *table, const rbs_mix *mix, const double V[3], const double n[3], double a,
                      const double u[RBS_U_PER_DRAW], int interpolation, double V_out[3], double Omega_out[3]);
int rbs_table_hit(const rbs_table *table, const rbs_mix *mix, const double V[3], const double n[3], double a,
                  const double u[RBS_U_PER_DRAW], int interpolation, double V_out[3], double Omega_out[3], int *shape,
                  double wall_work[2]);
/* table_path.c: the table path of a particle of the table's shape `shape`, u[0] not read
 * (surrogate.kernels.table_path.table_shape_rebound): as rbs_table_hit, RBS_INVALID also for a shape outside the
 * table's; the facet hits of a rough wall (wall_hit.c). */
int rbs_table_shape_hit(const rbs_table *table, int shape, const double V[3], const double n[3], double a,
                        const double u[RBS_U_PER_DRAW], int interpolation, double V_out[3], double Omega_out[3],
                        double wall_work[2]);

/* direct_path.c: the direct model for one hit, caller's frame (surrogate.kernels.direct_path.direct_rebound): `shape`
 * the index of the particle's shape in the table's direct shapes (the four families in code order, then the
 * table's other polyhedra in table order: t->direct_shapes), Ω⁻ in rad/s (exactly zero: the body starts touching
 * the wall), u RBS_U_PER_REBOUND uniforms in [0, 1) (direct_model.runtime: U_ORIENTATION, U_RATIOS, U_HAND,
 * U_AXIS). RBS_OK; RBS_TRAPPED or RBS_FAILED with NaN outputs; RBS_INVALID with NaN outputs for an input out of
 * range, a NULL pointer, a shape outside those. rbs_direct_hit also gives the
 * collisions of the rebound into *n_collisions (−1 for RBS_INVALID) and their work on the wall per unit particle mass
 * (m²/s², up to the trap or the failure; rbs_rebound_model_frame_counted's) into wall_work[0] (normal) and
 * wall_work[1] (tangential), NaN for RBS_INVALID. */
int rbs_direct_rebound(const rbs_table *table, int shape, const double V[3], const double Omega[3], const double n[3],
                       double a, const double u[RBS_U_PER_REBOUND], double V_out[3], double Omega_out[3]);
int rbs_direct_hit(const rbs_table *table, int shape, const double V[3], const double Omega[3], const double n[3],
                   double a, const double u[RBS_U_PER_REBOUND], double V_out[3], double Omega_out[3],
                   int *n_collisions, double wall_work[2]);

/* wall_hit.c: a hit along the path `path` (RBS_PATH_TABLE, RBS_PATH_DIRECT; surrogate.kernels.wall_hit.rebound_typed)
 * with its RBS_U_PER_DRAW uniforms u (a keyed hit's already keyed): RBS_INVALID and NaN for RBS_PATH_NONE or what
 * rbs_rebound refuses. The table shape into *shape, the direct path's collisions into *n_collisions (−1 if none)
 * and the hit's work on the wall into wall_work[0], wall_work[1] (m²/s², rbs_direct_hit's or rbs_table_hit's; NaN
 * for RBS_INVALID). */
int rbs_rebound_along(const rbs_table *table, const rbs_mix *mix, int path, const double V[3], const double Omega[3],
                      const double n[3], double a, const double u[RBS_U_PER_DRAW], int interpolation, double V_out[3],
                      double Omega_out[3], int *shape, int *n_collisions, double wall_work[2]);

/* grain.c: out = u with the slots a grain key fixes replaced by the key's uniforms: u[0] (the shape) always, and
 * with `direct` the direct model's proportions and hand, u[1 + U_RATIOS], u[2 + U_RATIOS], u[1 + U_HAND]
 * (surrogate.kernels.grain.keyed_uniforms); key >= 0. */
void rbs_keyed_uniforms(int64_t key, const double u[RBS_U_PER_DRAW], int direct, double out[RBS_U_PER_DRAW]);

#endif /* RBS_PATHS_H */
