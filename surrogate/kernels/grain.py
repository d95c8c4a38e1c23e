"""Grain keys: a particle that keeps its grain from one wall hit to the next (docs/model.md §11).

A grain key is an int64 ≥ 0 per particle (the caller's: e.g. from its seed and the particle's ids,
:func:`grain_key`). The random properties of the grain are pure functions of the key and the shape mix: each is
drawn from a keyed uniform (:func:`surrogate.kernels.rng.grain_uniform`) of its slot instead of from the
caller's stream,

    SLOT_SHAPE      the shape from the mix              (the draw's u[0])
    SLOT_RATIO_BA   b/a, for a shape of random proportions  (the draw's u[1 + U_RATIOS])
    SLOT_RATIO_CB   c/b                                  (the draw's u[2 + U_RATIOS])
    SLOT_HAND       the hand of a shape drawn in both hands (the draw's u[1 + U_HAND])

and everything else (the orientation at impact, the table's law, the impact frame) stays random per hit from
the caller's uniforms. Which path honours what: the table holds each shape's law over its random proportions
and hands, so under the table path a key fixes the shape only; under the direct path it fixes the shape, the
proportions and the hand. A hit still consumes U_PER_DRAW uniforms of the caller's stream whatever the path,
keyed or not: the keyed slots' uniforms are drawn and ignored, so streams stay aligned. NO_KEY (−1): no key,
today's draws and bits.
"""

import numba
import numpy as np

from direct_model.runtime import U_HAND, U_RATIOS, aspect_ratio
from surrogate.kernels.locate import SHAPE_FROM_MIX, mix_shape
from surrogate.kernels.options import JIT
from surrogate.kernels.rng import _GOLDEN, _splitmix64, grain_uniform

NO_KEY = -1
SLOT_SHAPE, SLOT_RATIO_BA, SLOT_RATIO_CB, SLOT_HAND = 0, 1, 2, 3
_KEY_BITS = np.uint64(0x7FFFFFFFFFFFFFFF)      # a key's 63 bits: the top bit cleared, so the key is ≥ 0


@numba.njit(inline="always", **JIT)
def keyed_uniforms(key, u, direct, out):
    """out[:U_PER_DRAW] = a draw's uniforms ``u`` with the slots the key ``key`` (≥ 0) fixes replaced by its
    keyed uniforms: u[0] (the shape) always; with ``direct`` (the direct path) also the direct model's
    proportions and hand, u[1 + U_RATIOS], u[2 + U_RATIOS], u[1 + U_HAND] (:func:`key_model_uniforms` of
    u[1:]). ``out`` may be ``u``."""
    for k in range(out.shape[0]):
        out[k] = u[k]
    out[0] = grain_uniform(key, SLOT_SHAPE)
    if direct:
        key_model_uniforms(key, out[1:])


@numba.njit(inline="always", **JIT)
def key_model_uniforms(key, u):
    """The direct model's uniforms ``u`` (U_PER_REBOUND, :mod:`direct_model.runtime`) of a grain of key ``key``
    (≥ 0): u[U_RATIOS], u[U_RATIOS + 1] (b/a, c/b) and u[U_HAND] replaced in place by the key's."""
    u[U_RATIOS] = grain_uniform(key, SLOT_RATIO_BA)
    u[U_RATIOS + 1] = grain_uniform(key, SLOT_RATIO_CB)
    u[U_HAND] = grain_uniform(key, SLOT_HAND)


@numba.njit(**JIT)
def keyed_shapes(mix_cdf, shapes, keys):
    """Each row's table shape index as the kernels over many rows take it (``shapes`` of
    :func:`surrogate.kernels.wall_hit.rebound_parallel_rng`): ``shapes[i]`` where given (≥ 0), else the shape
    of key ``keys[i]`` drawn from the mix (:func:`grain_shape`) where it has one (≥ 0), else SHAPE_FROM_MIX.
    ``shapes`` and ``keys`` (N,) int64 or empty; returns a new (N,) int64 array, empty if both are."""
    rows = keys.shape[0] if keys.shape[0] > 0 else shapes.shape[0]
    out = np.empty(rows, dtype=np.int64)
    for i in range(rows):
        given = shapes.shape[0] > 0 and shapes[i] != SHAPE_FROM_MIX
        keyed = keys.shape[0] > 0 and keys[i] >= 0
        out[i] = shapes[i] if given else grain_shape(mix_cdf, keys[i]) if keyed else SHAPE_FROM_MIX
    return out


@numba.njit(inline="always", **JIT)
def grain_shape(mix_cdf, key):
    """The table shape index of grain ``key`` (≥ 0) in the mix ``mix_cdf``: the draw's shape with u[0] keyed."""
    return mix_shape(mix_cdf, grain_uniform(key, SLOT_SHAPE))


@numba.njit(**JIT)
def grain_properties(shape_arrays, model_shape, key):
    """(b/a, c/b, hand) of grain ``key`` (≥ 0) of the direct model's shape ``model_shape`` (its index in
    ``shape_arrays``, −1 for none): the proportions and hand the direct path gives that grain on every hit
    (:func:`direct_model.runtime.rebound_model_frame` with the keyed uniforms). NaN for what the key does not
    draw: the proportions of a shape of fixed proportions, the hand of a shape of one hand, all three for no
    direct shape."""
    if model_shape < 0:
        return np.nan, np.nan, np.nan
    law, cdf = shape_arrays.aspect[model_shape], shape_arrays.aspect_cdf[model_shape]
    ratio_ba, ratio_cb = np.nan, np.nan
    if not np.isnan(law[0]):
        ratio_ba = aspect_ratio(law, cdf, grain_uniform(key, SLOT_RATIO_BA))
        ratio_cb = aspect_ratio(law, cdf, grain_uniform(key, SLOT_RATIO_CB))
    hand = np.nan
    if shape_arrays.both_hands[model_shape] != 0:
        hand = 1.0 if grain_uniform(key, SLOT_HAND) < 0.5 else -1.0
    return ratio_ba, ratio_cb, hand


@numba.njit(**JIT)
def grain_table(shape_arrays, model_shapes, mix_cdf, shapes, keys, shape_out, properties_out):
    """For each key of ``keys`` (N,) int64 ≥ 0: its table shape index into ``shape_out`` (N,) (``shapes[i]``
    where given, as :func:`keyed_shapes`) and its (b/a, c/b, hand) into ``properties_out`` (N, 3)
    (:func:`grain_properties`; ``model_shapes`` the table's shapes' indices in ``shape_arrays``)."""
    shape_out[:] = keyed_shapes(mix_cdf, shapes, keys)
    for i in range(keys.shape[0]):
        ba, cb, hand = grain_properties(shape_arrays, model_shapes[shape_out[i]], keys[i])
        properties_out[i, 0], properties_out[i, 1], properties_out[i, 2] = ba, cb, hand


@numba.njit(**JIT)
def grain_key(words):
    """The grain key of each column of ``words`` (M ≥ 1, N) uint64, the seed then the ids: splitmix64 chained,
    h = splitmix64(seed + γ), then h = splitmix64(h + id + γ) for each id of the column in turn, and the key is h
    with its top bit cleared (an int64 ≥ 0). Returns (N,) int64. Unrelated keys for unrelated ids, the same key
    for the same (seed, ids) everywhere: a solver derives a particle's key from (seed, rank of origin, id)."""
    keys = np.empty(words.shape[1], dtype=np.int64)
    for j in range(words.shape[1]):
        h = _splitmix64(words[0, j] + _GOLDEN)
        for m in range(1, words.shape[0]):
            h = _splitmix64(h + words[m, j] + _GOLDEN)
        keys[j] = np.int64(h & _KEY_BITS)
    return keys
