"""Many particles on all threads: the pipeline (:mod:`surrogate.kernels.pipeline`) and the local draws in
parallel.

The rows are cut into chunks of CHUNK_ROWS (:mod:`surrogate.kernels.rng`); the
``*_rng`` kernels draw chunk j's uniforms from the xoshiro256+ state
``states[j]`` (:func:`surrogate.kernels.rng.chunk_states`), so the draws are the
same whatever the number of threads. Input shapes are checked before the
parallel loop (:mod:`surrogate.kernels.checks`).
"""

import numba

from surrogate.kernels.checks import check_local_rows, check_rows, check_states, check_uniforms
from surrogate.kernels.options import JIT
from surrogate.kernels.pipeline import (no_shape_out, no_shapes, no_state, no_uniforms, no_work, run_blocks,
                                       table_rebound_uniforms)
from surrogate.kernels.rng import CHUNK_ROWS, n_chunks
from surrogate.kernels.table_path import draw_local


@numba.njit(parallel=True, **JIT)
def table_rebound_parallel(data, mix_cdf, V, n, a, u, V_out, Omega_out, status, scaled=True):
    """:func:`surrogate.kernels.table_path.table_rebound` for every row (parallel over chunks of
    :func:`surrogate.kernels.pipeline.table_rebound_many`); u has shape (N, U_PER_DRAW)."""
    check_rows(V, n, a, V_out, Omega_out, status)
    check_uniforms(u, V.shape[0], "V")
    for j in numba.prange(n_chunks(V.shape[0])):
        lo, hi = _chunk(j, V.shape[0])
        _rebound_chunk(data, mix_cdf, V, n, a, u[lo:hi], no_state(), V_out, Omega_out, status, scaled, lo, hi)


@numba.njit(parallel=True, **JIT)
def table_rebound_parallel_rng(data, mix_cdf, V, n, a, states, V_out, Omega_out, status, scaled=True):
    """:func:`table_rebound_parallel` drawing its own uniforms: the rows of chunk j (CHUNK_ROWS rows) from a
    copy of the xoshiro256+ state ``states[j]`` (:func:`surrogate.kernels.rng.chunk_states`; ``states`` itself is
    not advanced), as :func:`surrogate.kernels.pipeline.table_rebound_many_rng` draws them (:func:`table_rebound_uniforms`).
    The draws are the same whatever the number of threads, and no (N, U_PER_DRAW) array of uniforms is
    held. ``states`` must have one row per chunk (ValueError)."""
    check_rows(V, n, a, V_out, Omega_out, status)
    check_states(states, V.shape[0])
    for j in numba.prange(states.shape[0]):
        lo, hi = _chunk(j, V.shape[0])
        _rebound_chunk(data, mix_cdf, V, n, a, no_uniforms(), states[j].copy(), V_out, Omega_out, status, scaled, lo, hi)


@numba.njit(inline="always", **JIT)
def _chunk(j, n_rows):
    """Rows [lo, hi) of chunk j."""
    return j * CHUNK_ROWS, min((j + 1) * CHUNK_ROWS, n_rows)


@numba.njit(**JIT)
def _rebound_chunk(data, mix_cdf, V, n, a, u, state, V_out, Omega_out, status, scaled, lo, hi):
    """:func:`surrogate.kernels.pipeline.table_rebound_many` on rows [lo, hi) with the uniforms ``u`` of those rows,
    or :func:`surrogate.kernels.pipeline.table_rebound_many_rng` with ``state``. Called, not inlined: numba's
    parallel passes then see one call in the loop, not the chunk's work (docs/design/test_time.md)."""
    run_blocks(data, mix_cdf, no_shapes(), V[lo:hi], n[lo:hi], a[lo:hi], u, state, V_out[lo:hi], Omega_out[lo:hi],
               status[lo:hi], no_shape_out(), no_work(), no_work(), scaled)


@numba.njit(parallel=True, **JIT)
def draw_local_parallel(data, mix_cdf, alpha1, speed, u, out, status, scaled=True):
    """:func:`draw_local` for every row (parallel): alpha1 and speed (N,), u (N, U_PER_DRAW), out (N, 6)
    (α2, β2, s, Ω_x, Ω_y, Ω_z), status (N,); a ValueError names an array of another shape."""
    check_local_rows(alpha1, speed, out, status)
    check_uniforms(u, alpha1.shape[0], "alpha1")
    for j in numba.prange(n_chunks(alpha1.shape[0])):
        lo, hi = _chunk(j, alpha1.shape[0])
        _draw_local_chunk(data, mix_cdf, alpha1, speed, u, 0, out, status, scaled, lo, hi)


@numba.njit(parallel=True, **JIT)
def draw_local_parallel_rng(data, mix_cdf, alpha1, speed, states, out, status, scaled=True):
    """:func:`draw_local_parallel` drawing its own uniforms, chunk by chunk as :func:`table_rebound_parallel_rng`
    (chunk j's are ``table_rebound_uniforms(states[j].copy(), rows)``)."""
    check_local_rows(alpha1, speed, out, status)
    check_states(states, alpha1.shape[0])
    for j in numba.prange(states.shape[0]):
        lo, hi = _chunk(j, alpha1.shape[0])
        _draw_local_chunk(data, mix_cdf, alpha1, speed, table_rebound_uniforms(states[j].copy(), hi - lo), lo, out,
                          status, scaled, lo, hi)


@numba.njit(inline="always", **JIT)
def _draw_local_chunk(data, mix_cdf, alpha1, speed, u, first, out, status, scaled, lo, hi):
    """:func:`draw_local` on rows [lo, hi), row i with the uniforms ``u[i - first]`` (a row of the whole array: a
    slice of ``u`` would compile :func:`draw_local` again for its layout)."""
    for i in range(lo, hi):
        st, a2, b2, s, wx, wy, wz = draw_local(data, mix_cdf, alpha1[i], speed[i], u[i - first], scaled)
        status[i] = st
        out[i, 0], out[i, 1], out[i, 2], out[i, 3], out[i, 4], out[i, 5] = a2, b2, s, wx, wy, wz
