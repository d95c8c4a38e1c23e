/*
 * wall.h: the wall law of one collision (direct_model.wall: restitution, friction_factor), wall = (k, p, q) as
 * direct_model.wall.WallMaterial.as_array gives it. libm's exp and pow, as numba calls them.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#ifndef RBS_WALL_H
#define RBS_WALL_H

#include <math.h>

/* normal restitution a_nc of the contact point, contact_speed in m/s: 1 − [1 − exp(−k |V_c|^p)] sin */
static inline double rbs_restitution(const double *wall, double contact_speed, double sin_impact)
{
    return 1.0 - (1.0 - exp(-wall[0] * pow(contact_speed, wall[1]))) * sin_impact;
}

/* friction factor C_f = exp(q cos γ) */
static inline double rbs_friction_factor(const double *wall, double cos_gamma)
{
    return exp(wall[2] * cos_gamma);
}

#endif /* RBS_WALL_H */
