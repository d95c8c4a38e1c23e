"""Many particles on all threads: the block kernels (:mod:`surrogate.blocks`) and the local draws in parallel.

The rows are cut into chunks of ROWS_PER_STREAM (:mod:`surrogate.rng`); the
``*_rng`` kernels draw chunk j's uniforms from the xoshiro256+ state
``states[j]`` (:func:`surrogate.rng.stream_states`), so the draws are the
same whatever the number of threads. Input shapes are checked before the
parallel loop (ValueError naming the array): a raise inside a prange loop
would keep numba from running it in parallel.
"""

import numba

from surrogate.blocks import (_check_rows, _check_uniforms, _no_state, _no_uniforms, _run_blocks, _shape_error,
                             rebound_uniforms)
from surrogate.draw import draw_local
from surrogate.jit import JIT
from surrogate.rng import ROWS_PER_STREAM, n_streams


@numba.njit(parallel=True, **JIT)
def rebound_batch(data, mix_cdf, V, n, a, u, V_out, W_out, status, scaled=True):
    """:func:`surrogate.kernels.rebound` for every row (parallel over chunks of
    :func:`surrogate.blocks.rebound_many`); u has shape (N, U_PER_DRAW)."""
    _check_rows(V, n, a, V_out, W_out, status)
    _check_uniforms(u, V.shape[0], "V")
    for j in numba.prange(n_streams(V.shape[0])):
        lo, hi = _chunk(j, V.shape[0])
        _rebound_chunk(data, mix_cdf, V, n, a, u[lo:hi], _no_state(), V_out, W_out, status, scaled, lo, hi)


@numba.njit(parallel=True, **JIT)
def rebound_batch_rng(data, mix_cdf, V, n, a, states, V_out, W_out, status, scaled=True):
    """:func:`rebound_batch` drawing its own uniforms: the rows of chunk j (ROWS_PER_STREAM rows) from a
    copy of the xoshiro256+ state ``states[j]`` (:func:`surrogate.rng.stream_states`; ``states`` itself is
    not advanced), as :func:`surrogate.blocks.rebound_many_rng` draws them (:func:`rebound_uniforms`).
    The draws are the same whatever the number of threads, and no (N, U_PER_DRAW) array of uniforms is
    held. ``states`` must have one row per chunk (ValueError)."""
    _check_rows(V, n, a, V_out, W_out, status)
    _check_streams(states, V.shape[0])
    for j in numba.prange(states.shape[0]):
        lo, hi = _chunk(j, V.shape[0])
        _rebound_chunk(data, mix_cdf, V, n, a, _no_uniforms(), states[j].copy(), V_out, W_out, status, scaled, lo, hi)


@numba.njit(**JIT)
def _check_streams(states, n_rows):
    if states.shape[0] != n_streams(n_rows) or states.shape[1] != 4:
        raise ValueError("'states' must hold one xoshiro256+ state (4 words) per ROWS_PER_STREAM rows, as "
                         "surrogate.rng.stream_states(generator, n_rows) gives")


@numba.njit(**JIT)
def _check_local_rows(alpha1, speed, out, status):
    """ValueError naming the first array of a local-frame batch that has not one row per incident state."""
    rows = alpha1.shape[0]
    for name, shape in (("speed", speed.shape), ("status", status.shape)):
        if shape[0] != rows:
            raise ValueError(_shape_error(name, shape, "(" + str(rows) + ",)", "alpha1"))
    if out.shape[0] != rows or out.shape[1] != 6:
        raise ValueError(_shape_error("out", out.shape, "(" + str(rows) + ", 6)", "alpha1"))


@numba.njit(inline="always", **JIT)
def _chunk(j, n_rows):
    """Rows [lo, hi) of chunk j of a batch."""
    return j * ROWS_PER_STREAM, min((j + 1) * ROWS_PER_STREAM, n_rows)


@numba.njit(inline="always", **JIT)
def _rebound_chunk(data, mix_cdf, V, n, a, u, state, V_out, W_out, status, scaled, lo, hi):
    """:func:`surrogate.blocks.rebound_many` on rows [lo, hi) with the uniforms ``u`` of those rows, or
    :func:`surrogate.blocks.rebound_many_rng` with ``state``."""
    _run_blocks(data, mix_cdf, V[lo:hi], n[lo:hi], a[lo:hi], u, state, V_out[lo:hi], W_out[lo:hi], status[lo:hi],
                scaled)


@numba.njit(parallel=True, **JIT)
def draw_local_batch(data, mix_cdf, alpha1, speed, u, out, status, scaled=True):
    """:func:`draw_local` for every row (parallel): alpha1 and speed (N,), u (N, U_PER_DRAW), out (N, 6)
    (α2, β2, s, Ω_x, Ω_y, Ω_z), status (N,); a ValueError names an array of another shape."""
    _check_local_rows(alpha1, speed, out, status)
    _check_uniforms(u, alpha1.shape[0], "alpha1")
    for j in numba.prange(n_streams(alpha1.shape[0])):
        lo, hi = _chunk(j, alpha1.shape[0])
        _draw_local_chunk(data, mix_cdf, alpha1, speed, u[lo:hi], out, status, scaled, lo, hi)


@numba.njit(parallel=True, **JIT)
def draw_local_batch_rng(data, mix_cdf, alpha1, speed, states, out, status, scaled=True):
    """:func:`draw_local_batch` drawing its own uniforms, chunk by chunk as :func:`rebound_batch_rng`
    (chunk j's are ``rebound_uniforms(states[j].copy(), rows)``)."""
    _check_local_rows(alpha1, speed, out, status)
    _check_streams(states, alpha1.shape[0])
    for j in numba.prange(states.shape[0]):
        lo, hi = _chunk(j, alpha1.shape[0])
        _draw_local_chunk(data, mix_cdf, alpha1, speed, rebound_uniforms(states[j].copy(), hi - lo), out, status,
                          scaled, lo, hi)


@numba.njit(inline="always", **JIT)
def _draw_local_chunk(data, mix_cdf, alpha1, speed, u, out, status, scaled, lo, hi):
    """:func:`draw_local` on rows [lo, hi) with the uniforms ``u`` of those rows."""
    for i in range(lo, hi):
        st, a2, b2, s, wx, wy, wz = draw_local(data, mix_cdf, alpha1[i], speed[i], u[i - lo], scaled)
        status[i] = st
        out[i, 0], out[i, 1], out[i, 2], out[i, 3], out[i, 4], out[i, 5] = a2, b2, s, wx, wy, wz
