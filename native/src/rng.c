/*
 * rng.c: xoshiro256+ uniforms (surrogate.kernels.rng) and their seeding.
 *
 * rbs_rng_seed / rbs_rng_seed_stream repeat numpy's SeedSequence (numpy/random/bit_generator.pyx): the
 * seed's 32-bit words (and, for stream k, the spawn key (k,)) hashed into a pool of four 32-bit words,
 * from which generate_state(4, uint64) draws the state, as surrogate.seed_state does. The block
 * kernels' lanes are seeded with splitmix64 from one step of the caller's state (surrogate.kernels.rng.seed_lanes).
 *
 * Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
 */
#include <math.h>
#include <string.h>

#include "internal.h"
#include "rng_internal.h"

/* ------------------------------------------------------------------------- SeedSequence */

#define INIT_A 0x43b0d7e5u
#define MULT_A 0x931e8875u
#define INIT_B 0x8b51f9ddu
#define MULT_B 0x58f38dedu
#define MIX_MULT_L 0xca01f9ddu
#define MIX_MULT_R 0x4973f715u
#define XSHIFT 16
#define POOL_SIZE 4

static uint32_t hashmix(uint32_t value, uint32_t *hash_const)
{
    value ^= *hash_const;
    *hash_const *= MULT_A;
    value *= *hash_const;
    value ^= value >> XSHIFT;
    return value;
}

static uint32_t mix(uint32_t x, uint32_t y)
{
    uint32_t result = MIX_MULT_L * x - MIX_MULT_R * y;
    result ^= result >> XSHIFT;
    return result;
}

/* numpy's _int_to_uint32_array: 0 → [0], else the 32-bit words, least significant first */
static int int_words(uint64_t n, uint32_t *words)
{
    int count = 0;
    if (n == 0) words[count++] = 0;
    while (n > 0) {
        words[count++] = (uint32_t)(n & 0xffffffffu);
        n >>= 32;
    }
    return count;
}

/* SeedSequence(seed, spawn_key=(k,)).generate_state(4, uint64) */
static void seed_sequence_state(uint64_t seed, uint64_t k, uint64_t out[4])
{
    uint32_t entropy[8], pool[POOL_SIZE], hash_const = INIT_A;
    int n = int_words(seed, entropy);
    while (n < POOL_SIZE) entropy[n++] = 0;      /* run entropy padded to the pool size: a spawn key follows */
    n += int_words(k, entropy + n);
    for (int i = 0; i < POOL_SIZE; i++) pool[i] = hashmix(i < n ? entropy[i] : 0u, &hash_const);
    for (int src = 0; src < POOL_SIZE; src++)
        for (int dst = 0; dst < POOL_SIZE; dst++)
            if (src != dst) pool[dst] = mix(pool[dst], hashmix(pool[src], &hash_const));
    for (int src = POOL_SIZE; src < n; src++)
        for (int dst = 0; dst < POOL_SIZE; dst++) pool[dst] = mix(pool[dst], hashmix(entropy[src], &hash_const));
    uint32_t words[8], h = INIT_B;
    for (int i = 0; i < 8; i++) {
        uint32_t value = pool[i % POOL_SIZE];
        value ^= h;
        h *= MULT_B;
        value *= h;
        value ^= value >> XSHIFT;
        words[i] = value;
    }
    for (int i = 0; i < 4; i++) out[i] = (uint64_t)words[2 * i] | ((uint64_t)words[2 * i + 1] << 32);
}

void rbs_rng_seed_stream(rbs_rng *rng, uint64_t seed, uint64_t k)
{
    if (!rng) return;
    seed_sequence_state(seed, k, rng->s);
    if ((rng->s[0] | rng->s[1] | rng->s[2] | rng->s[3]) == 0) rng->s[0] = 1;
}

void rbs_rng_seed(rbs_rng *rng, uint64_t seed)
{
    rbs_rng_seed_stream(rng, seed, 0);      /* seed_state(seed) is SeedSequence(seed).spawn(1)[0] */
}

/* ------------------------------------------------------------------------- uniforms */

double rbs_rng_uniform(rbs_rng *rng)
{
    return rbs_rng_ok(rng) ? rbs_uniform_of(rbs_next(rng->s)) : NAN;
}

/* NaN into u[0..count) (u may be NULL): the uniforms of a NULL or all-zero state, which every draw refuses */
static void nan_fill(double *u, size_t count)
{
    if (u)
        for (size_t k = 0; k < count; k++) u[k] = NAN;
}

void rbs_rng_fill(rbs_rng *rng, double *u, size_t count)
{
    if (!u || !rbs_rng_ok(rng)) {
        nan_fill(u, count);
        return;
    }
    uint64_t s[4] = {rng->s[0], rng->s[1], rng->s[2], rng->s[3]};
    for (size_t k = 0; k < count; k++) u[k] = rbs_uniform_of(rbs_next(s));
    memcpy(rng->s, s, sizeof s);
}

void rbs_lanes_seed(rbs_rng *rng, uint64_t lanes[4 * RBS_BLOCK])
{
    uint64_t x = rbs_next(rng->s);
    for (uint64_t j = 0; j < 4 * RBS_BLOCK; j++) lanes[j] = rbs_splitmix64(x + (j + 1) * RBS_GOLDEN);
}

RBS_HOT void rbs_lanes_fill(uint64_t lanes[4 * RBS_BLOCK], double *u)
{
    uint64_t *w0 = lanes, *w1 = lanes + RBS_BLOCK, *w2 = lanes + 2 * RBS_BLOCK, *w3 = lanes + 3 * RBS_BLOCK;
    for (int q = 0; q < RBS_U_PER_DRAW; q++) {
        for (int l = 0; l < RBS_BLOCK; l++) {        /* one step of every lane: independent, so a SIMD loop */
            uint64_t s[4] = {w0[l], w1[l], w2[l], w3[l]};
            u[q * RBS_BLOCK + l] = rbs_uniform_of(rbs_next(s));
            w0[l] = s[0];
            w1[l] = s[1];
            w2[l] = s[2];
            w3[l] = s[3];
        }
    }
}

void rbs_draw_many_uniforms(rbs_rng *rng, size_t count, double *u)
{
    uint64_t lanes[4 * RBS_BLOCK];
    double ub[RBS_BLOCK * RBS_U_PER_DRAW];
    if (!u || !rbs_rng_ok(rng)) {
        nan_fill(u, count * RBS_U_PER_DRAW);
        return;
    }
    rbs_lanes_seed(rng, lanes);
    for (size_t start = 0; start < count; start += RBS_BLOCK) {
        rbs_lanes_fill(lanes, ub);
        size_t m = count - start < RBS_BLOCK ? count - start : RBS_BLOCK;
        for (size_t b = 0; b < m; b++)
            for (int k = 0; k < RBS_U_PER_DRAW; k++) u[(start + b) * RBS_U_PER_DRAW + k] = ub[k * RBS_BLOCK + b];
    }
}
