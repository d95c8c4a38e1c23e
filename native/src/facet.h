/*
 * facet.h: the facets of a rough wall (surrogate.kernels.facet: facet_key, facet_normal; docs/model.md §12): under
 * each hit, the mean wall tilted at random, drawn from keyed uniforms of the hit's facet key.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#ifndef RBS_FACET_H
#define RBS_FACET_H

#include <stdint.h>

#include "rebound_scatter.h"

#define RBS_MAX_FACET_DRAWS 64      /* draws of one facet (surrogate.kernels.facet.MAX_FACET_DRAWS) */
#define RBS_U_PER_FACET 6           /* keyed uniforms of one draw (surrogate.kernels.facet.U_PER_FACET) */

/* The facet key of a hit of uniforms u: rng_internal.h's rbs_hit_key from the facet keys' domain
 * (surrogate.kernels.facet.facet_key). */
int64_t rbs_facet_key(const double u[RBS_U_PER_DRAW]);

/* A facet under the hit V (m/s) on the mean wall of unit normal n, roughness Δγ = roughness_deg > 0, from the keyed
 * uniforms of `key` numbered from *slot (surrogate.kernels.facet.facet_normal): 1 and the facet's unit normal into
 * facet (V·facet < 0), or 0 and n after RBS_MAX_FACET_DRAWS draws kept none. *slot is advanced past the uniforms
 * used: one for the impact frame's axis at normal impact, then RBS_U_PER_FACET per draw. */
int rbs_facet_normal(const double V[3], const double n[3], double roughness_deg, int64_t key, int64_t *slot,
                     double facet[3]);

#endif /* RBS_FACET_H */
