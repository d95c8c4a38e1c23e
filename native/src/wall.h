/*
 * wall.h: the wall law of one collision (direct_model.wall: restitution, tabulated_restitution, node_weight,
 * friction_factor). `wall` is the kernels' wall array of direct_model.wall.Wall.as_array (layout W_*): the family's
 * code and q, then the exponential family's k, p, or the tabulated family's node counts, speed nodes, sine nodes
 * and a_nc (row-major: speed, then sine). libm's exp and pow, as numba calls them; every blend rounds as numba's
 * because the library is compiled without contraction (CMakeLists.txt: -ffp-contract=off).
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#ifndef RBS_WALL_H
#define RBS_WALL_H

#include <math.h>

/* layout of the wall array (direct_model.wall: W_FAMILY ... W_NODES, MAX_CONTACT_SPEEDS, MAX_CONTACT_SINES,
 * WALL_ARRAY_SIZE, EXPONENTIAL_CODE) */
#define W_FAMILY 0          /* the family's code: EXPONENTIAL_CODE or TABULATED_CODE */
#define W_Q 1               /* q of C_f = exp(q cos γ), every family's */
#define W_K 2               /* the exponential family's k, p */
#define W_P 3
#define W_N_SPEEDS 2        /* the tabulated family's node counts ns, nz, then its nodes and a_nc from W_NODES */
#define W_N_SINES 3
#define W_NODES 4
#define MAX_CONTACT_SPEEDS 16
#define MAX_CONTACT_SINES 16
#define MAX_CONTACT_VALUES 256      /* MAX_CONTACT_SPEEDS · MAX_CONTACT_SINES: the a_nc of the most nodes */
#define WALL_ARRAY_SIZE (W_NODES + MAX_CONTACT_SPEEDS + MAX_CONTACT_SINES + MAX_CONTACT_VALUES)
#define EXPONENTIAL_CODE 0  /* direct_model.wall.WALL_FAMILIES' codes */
#define TABULATED_CODE 1

_Static_assert(MAX_CONTACT_VALUES == MAX_CONTACT_SPEEDS * MAX_CONTACT_SINES, "a_nc at every node of the most nodes");

/* Of the `count` increasing nodes wall[first .. first + count): the index (from first) of the node at or below x into
 * *lo and of the next into *hi; returns the weight of the next, 0 below the first node and 1 above the last
 * (direct_model.wall.node_weight) */
static inline double rbs_node_weight(const double *wall, int first, int count, double x, int *lo, int *hi)
{
    if (count == 1) {
        *lo = *hi = 0;
        return 0.0;
    }
    int i = 0;
    while (i < count - 2 && wall[first + i + 1] <= x) i++;
    double w = (x - wall[first + i]) / (wall[first + i + 1] - wall[first + i]);
    if (w < 0.0)
        w = 0.0;
    else if (w > 1.0)
        w = 1.0;
    *lo = i;
    *hi = i + 1;
    return w;
}

/* a_nc of the tabulated family: bilinear between the nodes, contact_speed in m/s
 * (direct_model.wall.tabulated_restitution) */
static inline double rbs_tabulated_restitution(const double *wall, double contact_speed, double sin_impact)
{
    int ns = (int)wall[W_N_SPEEDS], nz = (int)wall[W_N_SINES];
    int sines = W_NODES + ns, values = W_NODES + ns + nz;
    int i0, i1, j0, j1;
    double ws = rbs_node_weight(wall, W_NODES, ns, contact_speed, &i0, &i1);
    double wz = rbs_node_weight(wall, sines, nz, sin_impact, &j0, &j1);
    double low = (1.0 - wz) * wall[values + i0 * nz + j0] + wz * wall[values + i0 * nz + j1];
    double high = (1.0 - wz) * wall[values + i1 * nz + j0] + wz * wall[values + i1 * nz + j1];
    return (1.0 - ws) * low + ws * high;
}

/* normal restitution a_nc of the contact point, contact_speed in m/s (direct_model.wall.restitution): the exponential
 * family's 1 − [1 − exp(−k |V_c|^p)] sin, else the tabulated family's */
static inline double rbs_restitution(const double *wall, double contact_speed, double sin_impact)
{
    if (wall[W_FAMILY] == EXPONENTIAL_CODE)
        return 1.0 - (1.0 - exp(-wall[W_K] * pow(contact_speed, wall[W_P]))) * sin_impact;
    return rbs_tabulated_restitution(wall, contact_speed, sin_impact);
}

/* friction factor C_f = exp(q cos γ) (direct_model.wall.friction_factor) */
static inline double rbs_friction_factor(const double *wall, double cos_gamma)
{
    return exp(wall[W_Q] * cos_gamma);
}

#endif /* RBS_WALL_H */
