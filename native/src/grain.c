/*
 * grain.c: grain keys (surrogate.kernels.grain: keyed_uniforms, grain_shape, grain_properties, grain_key): a
 * particle's shape, proportions and hand as pure functions of its key and the shape mix, each from a keyed
 * uniform (rng_internal.h: rbs_grain_uniform, surrogate.kernels.rng.grain_uniform) of its slot.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#include <math.h>
#include <string.h>

#include "locate.h"
#include "paths.h"
#include "records.h"
#include "rng_internal.h"

/* the slots of a grain's keyed uniforms (surrogate.kernels.grain: SLOT_SHAPE, SLOT_RATIO_BA, SLOT_RATIO_CB,
 * SLOT_HAND) */
enum { SLOT_SHAPE = 0, SLOT_RATIO_BA = 1, SLOT_RATIO_CB = 2, SLOT_HAND = 3 };

#define KEY_BITS 0x7FFFFFFFFFFFFFFFull    /* a key's 63 bits: the top bit cleared (surrogate.kernels.grain._KEY_BITS) */

void rbs_keyed_uniforms(int64_t key, const double u[RBS_U_PER_DRAW], int direct, double out[RBS_U_PER_DRAW])
{
    memcpy(out, u, RBS_U_PER_DRAW * sizeof(double));
    out[0] = rbs_grain_uniform((uint64_t)key, SLOT_SHAPE);
    if (direct) {
        out[1 + U_RATIOS] = rbs_grain_uniform((uint64_t)key, SLOT_RATIO_BA);
        out[2 + U_RATIOS] = rbs_grain_uniform((uint64_t)key, SLOT_RATIO_CB);
        out[1 + U_HAND] = rbs_grain_uniform((uint64_t)key, SLOT_HAND);
    }
}

int rbs_grain_info(const rbs_table *t, const rbs_mix *mix, int64_t key, rbs_grain *grain)
{
    if (!t || !mix || mix->table != t || !RBS_RECORD_OK(grain, rbs_grain) || key < 0)
        return RBS_INVALID;
    int shape = (int)rbs_mix_shape(rbs_mix_cdf(mix), mix->n_shapes, rbs_grain_uniform((uint64_t)key, SLOT_SHAPE));
    int direct_shape = t->model_shape[shape];
    grain->shape = shape;
    grain->ratio_ba = grain->ratio_cb = grain->hand = NAN;
    if (direct_shape < 0)
        return RBS_OK;
    const rbs_shape_arrays *s = &t->direct_shapes;
    const double *law = s->aspect + 4 * direct_shape, *cdf = s->aspect_cdf + 2 * direct_shape;
    if (!isnan(law[0])) {       /* fixed proportions: no quantile of NaN (no FE_INVALID) */
        grain->ratio_ba = rbs_aspect_ratio(law, cdf, rbs_grain_uniform((uint64_t)key, SLOT_RATIO_BA));
        grain->ratio_cb = rbs_aspect_ratio(law, cdf, rbs_grain_uniform((uint64_t)key, SLOT_RATIO_CB));
    }
    if (s->both_hands[direct_shape])
        grain->hand = rbs_grain_uniform((uint64_t)key, SLOT_HAND) < 0.5 ? 1.0 : -1.0;
    return RBS_OK;
}

int64_t rbs_grain_key(uint64_t seed, uint64_t id1, uint64_t id2)
{
    uint64_t h = rbs_splitmix64(seed + RBS_GOLDEN);
    h = rbs_splitmix64(h + id1 + RBS_GOLDEN);
    h = rbs_splitmix64(h + id2 + RBS_GOLDEN);
    return (int64_t)(h & KEY_BITS);
}
