"""A small, fast random source for numba solver loops: xoshiro256+ uniforms.

Drawing the :data:`surrogate.kernels.draw.U_PER_DRAW` uniforms of a rebound with
``np.random.random()`` inside numba costs about as much as the rebound
itself. xoshiro256+ (Blackman & Vigna 2018) produces a 53-bit uniform in a
few integer operations from a state of four 64-bit words that the caller
owns: one state per thread (or per particle stream) keeps a parallel solver
reproducible whatever the scheduling.

Words: a *stream* is one xoshiro256+ state and the uniforms it gives; the
pipeline (:func:`surrogate.kernels.pipeline.table_rebound_many_rng`) draws from
BLOCK *lanes*, streams seeded from the caller's state with splitmix64
(:func:`seed_lanes`) and stepped together as SIMD instructions
(:func:`fill_lanes`), since one stream's steps depend on each other; the
parallel kernels (:mod:`surrogate.kernels.parallel`) cut their rows into
*chunks* of :data:`CHUNK_ROWS`, chunk j drawn from its own stream
(:func:`chunk_states`), so their draws do not depend on the number of threads.

Usage from a solver's ``@njit`` loop::

    state = surrogate.seed_state(1234)               # NumPy side, (4,) uint64
    ...
    fill_uniforms(state, u)                          # inside numba: u[:] = next uniforms
    status, V_out, Omega_out = table_rebound(data, mix_cdf, V, n, a, u)

:func:`seed_state` with ``n_streams`` gives independent states (rows) from
one seed, through NumPy's ``SeedSequence``.
"""

from __future__ import annotations

import numba
import numpy as np

from data_schema import kernel_cache  # noqa: F401  (keys this module's kernels by their sources)
from surrogate.kernels.fastmath import bits

_53_BITS = 1.0 / 9007199254740992.0      # 2**-53
CHUNK_ROWS = 1024      # rows of a chunk: the unit of work of the parallel kernels, drawn from one stream


def seed_state(seed: int, n_streams: int | None = None) -> np.ndarray:
    """xoshiro256+ state(s) from an integer seed: (4,) uint64, or (n_streams, 4) independent rows.

    The words come from ``numpy.random.SeedSequence(seed)`` (spawned per
    stream), so nearby seeds give unrelated states; a state is never all zero.
    """
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise ValueError(f"The 'seed' parameter must be a non-negative int; got {seed!r}.")
    rows = 1 if n_streams is None else n_streams
    if isinstance(rows, bool) or not isinstance(rows, (int, np.integer)) or rows < 1:
        raise ValueError(f"The 'n_streams' parameter must be an integer >= 1; got {n_streams!r}.")
    children = np.random.SeedSequence(seed).spawn(rows)
    state = np.array([child.generate_state(4, np.uint64) for child in children], dtype=np.uint64)
    state[np.all(state == 0, axis=1), 0] = 1
    return state[0] if n_streams is None else state


@numba.njit(inline="always", cache=True, nogil=True)
def n_chunks(n_rows):
    """Chunks of CHUNK_ROWS rows (the last may be partial) in ``n_rows`` rows."""
    return (n_rows + CHUNK_ROWS - 1) // CHUNK_ROWS


def chunk_states(generator: np.random.Generator, n_rows: int) -> np.ndarray:
    """xoshiro256+ states for the chunks of ``n_rows`` draws: (⌈n_rows / CHUNK_ROWS⌉, 4) uint64, one per
    chunk of rows, drawn from ``generator`` (so a seeded Generator gives the same batch every time)."""
    state = generator.integers(0, np.iinfo(np.uint64).max, size=(n_chunks(int(n_rows)), 4), dtype=np.uint64,
                               endpoint=True)
    state[np.all(state == 0, axis=1), 0] = 1
    return state


@numba.njit(inline="always", cache=True, nogil=True)
def _rotl(x, k):
    return (x << np.uint64(k)) | (x >> np.uint64(64 - k))


@numba.njit(inline="always", cache=True, nogil=True)
def _next(s0, s1, s2, s3):
    """One xoshiro256+ step on the state words: (64-bit output, s0, s1, s2, s3)."""
    result = s0 + s3
    t = s1 << np.uint64(17)
    s2 ^= s0
    s3 ^= s1
    s1 ^= s2
    s0 ^= s3
    s2 ^= t
    s3 = _rotl(s3, 45)
    return result, s0, s1, s2, s3


@numba.njit(inline="always", cache=True, nogil=True)
def _step(s0, s1, s2, s3):
    """One xoshiro256+ step on the state words: (uniform in [0, 1) with 53 bits, s0, s1, s2, s3).

    The uniform is the output's top 53 bits times 2⁻⁵³, converted as a signed integer (exact below 2⁵³;
    the signed conversion is a single SIMD instruction, so :func:`fill_lanes` vectorises)."""
    result, s0, s1, s2, s3 = _next(s0, s1, s2, s3)
    return np.float64(np.int64(result >> np.uint64(11))) * _53_BITS, s0, s1, s2, s3


@numba.njit(inline="always", cache=True, nogil=True)
def next_uniform(state):
    """The next uniform in [0, 1) (53 bits) from a xoshiro256+ ``state`` (4,) uint64, updated in place; NaN
    for an all-zero state (not a xoshiro256+ state: it would give 0 forever), which every draw refuses."""
    if (state[0] | state[1] | state[2] | state[3]) == 0:
        return np.nan
    x, state[0], state[1], state[2], state[3] = _step(state[0], state[1], state[2], state[3])
    return x


@numba.njit(inline="always", cache=True, nogil=True)
def fill_uniforms(state, u):
    """u[:] = the next len(u) uniforms of ``state`` (see :func:`next_uniform`).

    The state words stay in registers for the whole fill and are stored once
    at the end (stepping ``state`` in place per uniform would store and reload
    them each time: the compiler cannot tell that u and state do not overlap). An all-zero state gives NaN
    (:func:`next_uniform`).
    """
    s0, s1, s2, s3 = state[0], state[1], state[2], state[3]
    if (s0 | s1 | s2 | s3) == 0:
        u[:] = np.nan
        return
    for k in range(u.shape[0]):
        u[k], s0, s1, s2, s3 = _step(s0, s1, s2, s3)
    state[0], state[1], state[2], state[3] = s0, s1, s2, s3


_GOLDEN = np.uint64(0x9E3779B97F4A7C15)     # splitmix64's increment


@numba.njit(inline="always", cache=True, nogil=True)
def _splitmix64(x):
    """splitmix64's output for the counter value x (Steele, Lea & Flood 2014)."""
    z = x
    z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
    z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    return z ^ (z >> np.uint64(31))


@numba.njit(inline="always", cache=True, nogil=True)
def hit_key(u, count, domain):
    """A key of a hit's first ``count`` uniforms ``u``: splitmix64 chained over their bits from ``domain``, top bit
    cleared (an int64 ≥ 0, as a grain key). Each use of a hit's key has its own ``domain``, so its keyed uniforms
    (:func:`grain_uniform`) are unrelated to another use's."""
    h = _splitmix64(domain)
    for k in range(count):
        h = _splitmix64(h + bits(np.float64(u[k])) + _GOLDEN)
    return np.int64(h & _KEY_BITS)


_KEY_BITS = np.uint64(0x7FFFFFFFFFFFFFFF)


@numba.njit(inline="always", cache=True, nogil=True)
def grain_uniform(key, slot):
    """A uniform in [0, 1) (53 bits) that depends on the grain key and the slot only, not on any stream.

    splitmix64 of the key, then splitmix64 of that plus (slot + 1)·γ: keys that differ by a multiple of γ
    still give unrelated uniforms. ``key`` a non-negative int64, ``slot`` a small non-negative integer.
    """
    x = _splitmix64(np.uint64(key) + _GOLDEN) + np.uint64(slot + 1) * _GOLDEN
    return np.float64(np.int64(_splitmix64(x) >> np.uint64(11))) * _53_BITS


@numba.njit(inline="always", cache=True, nogil=True)
def seed_lanes(state, lanes):
    """Seed L = len(lanes) // 4 xoshiro256+ lanes from ``state`` ((4,) uint64, advanced one step).

    ``lanes`` is word-major: word w of lane l at ``lanes[w * L + l]``. The
    words are splitmix64 of the counter x + (j + 1)·γ, j = 0 … 4L − 1, with x
    the next 64-bit output of ``state`` (the seeding the xoshiro authors
    recommend), so successive calls on one state give unrelated lanes.
    """
    x, state[0], state[1], state[2], state[3] = _next(state[0], state[1], state[2], state[3])
    for j in range(lanes.shape[0]):
        lanes[j] = _splitmix64(x + np.uint64(j + 1) * _GOLDEN)


@numba.njit(inline="always", cache=True, nogil=True)
def fill_lanes(lanes, u, n_lanes, count):
    """u[q · L + l] = the next uniform of lane l, for q < ``count`` and l < L = ``n_lanes`` (``lanes`` in
    the :func:`seed_lanes` layout, 4 L words).

    Each lane is a xoshiro256+ generator like :func:`next_uniform`. With
    ``n_lanes`` and ``count`` compile-time constants the loop over q unrolls
    and the loop over the lanes runs as SIMD instructions (L independent
    generators, a step one vector operation per 8 lanes): about four times
    cheaper per uniform than one stream, whose steps depend on each other.
    """
    for l in range(n_lanes):    # the lane's words stay in registers across its outputs; SIMD across lanes
        s0, s1, s2, s3 = lanes[l], lanes[n_lanes + l], lanes[2 * n_lanes + l], lanes[3 * n_lanes + l]
        for q in range(count):
            u[q * n_lanes + l], s0, s1, s2, s3 = _step(s0, s1, s2, s3)
        lanes[l], lanes[n_lanes + l], lanes[2 * n_lanes + l], lanes[3 * n_lanes + l] = s0, s1, s2, s3
