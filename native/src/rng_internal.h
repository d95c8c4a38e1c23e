/*
 * rng_internal.h: one xoshiro256+ step (Blackman & Vigna 2018), splitmix64, and the block lanes.
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#ifndef RBS_RNG_INTERNAL_H
#define RBS_RNG_INTERNAL_H

#include <stdint.h>

#include "fastmath.h"
#include "rebound_scatter.h"

#define RBS_GOLDEN 0x9E3779B97F4A7C15ull      /* splitmix64's increment */
#define RBS_KEY_BITS 0x7FFFFFFFFFFFFFFFull    /* a key's 63 bits: the top bit cleared (surrogate.kernels.rng._KEY_BITS) */

static inline uint64_t rbs_rotl(uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }

/* one xoshiro256+ step: the 64-bit output, s advanced */
static inline uint64_t rbs_next(uint64_t s[4])
{
    uint64_t result = s[0] + s[3];
    uint64_t t = s[1] << 17;
    s[2] ^= s[0];
    s[3] ^= s[1];
    s[1] ^= s[2];
    s[0] ^= s[3];
    s[2] ^= t;
    s[3] = rbs_rotl(s[3], 45);
    return result;
}

/* the top 53 bits times 2^-53 (surrogate.kernels.rng._step) */
static inline double rbs_uniform_of(uint64_t x)
{
    return (double)(int64_t)(x >> 11) * 0x1p-53;
}

static inline uint64_t rbs_splitmix64(uint64_t z)
{
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/* a uniform in [0, 1) that depends on the grain key and the slot only (surrogate.kernels.rng.grain_uniform) */
static inline double rbs_grain_uniform(uint64_t key, uint64_t slot)
{
    return rbs_uniform_of(rbs_splitmix64(rbs_splitmix64(key + RBS_GOLDEN) + (slot + 1) * RBS_GOLDEN));
}

/* A key of a hit's first `count` uniforms u: splitmix64 chained over their bits from `domain`, top bit cleared (an
 * int64 >= 0, as a grain key; surrogate.kernels.rng.hit_key). Each use of a hit's key has its own domain. */
static inline int64_t rbs_hit_key(const double *u, int count, uint64_t domain)
{
    uint64_t h = rbs_splitmix64(domain);
    for (int k = 0; k < count; k++) h = rbs_splitmix64(h + rbs_bits(u[k]) + RBS_GOLDEN);
    return (int64_t)(h & RBS_KEY_BITS);
}

/* a state that is not NULL and not all zero (xoshiro256+'s fixed point: all-zero words give 0 forever) */
static inline int rbs_rng_ok(const rbs_rng *rng)
{
    return rng != NULL && (rng->s[0] | rng->s[1] | rng->s[2] | rng->s[3]) != 0;
}

/* RBS_BLOCK lanes seeded from one step of rng (surrogate.kernels.rng.seed_lanes; word w of lane l at w·BLOCK + l) */
void rbs_lanes_seed(rbs_rng *rng, uint64_t lanes[4 * RBS_BLOCK]);

/* u[q·BLOCK + l] = the next uniform of lane l, q < RBS_U_PER_DRAW (surrogate.kernels.rng.fill_lanes) */
void rbs_lanes_fill(uint64_t lanes[4 * RBS_BLOCK], double *u);

#endif /* RBS_RNG_INTERNAL_H */
