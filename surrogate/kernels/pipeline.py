"""Many particles on one thread: the draws of :func:`surrogate.kernels.table_path.table_rebound` as a pipeline of blocks.

A per-particle draw is a chain of dependent steps (frame, cell, table reads,
arithmetic), and a table read waits for memory. :func:`table_rebound_many` and
:func:`table_rebound_many_rng` take BLOCK particles at a time
(:mod:`surrogate.kernels.block`) through the stages of a draw, each stage's
block form a step of the pipeline, so that one block's table reads are in
flight while the blocks before it are computed. This module only schedules:
while block k is located (:func:`surrogate.kernels.locate.locate_block`),
block k − 1 has its components resolved
(:func:`surrogate.kernels.locate.resolve_block`) and block k − 2 is gathered
and drawn (:func:`surrogate.kernels.gather.gather_block`,
:func:`surrogate.kernels.arithmetic.arithmetic_block`). Input shapes are
checked before any work (:mod:`surrogate.kernels.checks`).
"""

import numba
import numpy as np

from surrogate.kernels.arithmetic import OUT_FIELDS, arithmetic_block
from surrogate.kernels.block import BLOCK, field
from surrogate.kernels.checks import check_rows, check_state, check_uniforms
from surrogate.kernels.draw import U_PER_DRAW
from surrogate.kernels.frame import FRAME_FIELDS
from surrogate.kernels.gather import GATHERED_FIELDS, gather_block
from surrogate.kernels.locate import I_DRAWN, INDEX_FIELDS, WEIGHT_FIELDS, locate_block, resolve_block
from surrogate.kernels.options import JIT, KERNEL
from surrogate.kernels.rng import fill_lanes, seed_lanes
from surrogate.kernels.work import hint_work_block, work_block

STAGES = 3      # blocks in the pipeline: located, resolved, drawn


@numba.njit(**JIT)
def table_rebound_many(data, mix_cdf, V, n, a, u, V_out, Omega_out, status, scaled=True):
    """:func:`surrogate.kernels.table_path.table_rebound` for every row, one thread, by blocks of BLOCK particles.

    Same arguments as :func:`surrogate.kernels.parallel.table_rebound_parallel` and the same results, bit for
    bit, as calling :func:`surrogate.kernels.table_path.table_rebound` row by row. Every array must have one row per
    particle (ValueError naming the first that has not); V, n and a are
    copied if they are not C-contiguous. Each stage is a loop over the
    block whose iterations do not depend on each other (so the processor
    overlaps them), the impact frames and the arithmetic branch-free SIMD
    loops: the memory latencies of a whole block overlap, and each has a
    block's worth of work to arrive in.

    For a flow solver that collects its wall hits: call this from its
    ``@njit`` code on the hit arrays (or :func:`table_rebound_many_rng`, which
    draws the uniforms itself).
    """
    check_rows(V, n, a, V_out, Omega_out, status)
    check_uniforms(u, V.shape[0], "V")
    run_blocks(data, mix_cdf, no_shapes(), V, n, a, u, no_state(), V_out, Omega_out, status, no_shape_out(),
               no_work(), no_work(), scaled)


@numba.njit(**JIT)
def table_rebound_many_rng(data, mix_cdf, V, n, a, state, V_out, Omega_out, status, scaled=True):
    """:func:`table_rebound_many` drawing the uniforms from the xoshiro256+ ``state`` ((4,) uint64,
    :func:`surrogate.kernels.rng.seed_state`), which it advances by one step.

    The uniforms come from BLOCK xoshiro256+ lanes seeded from ``state``
    (:func:`surrogate.kernels.rng.seed_lanes`): row b of every block of BLOCK rows
    from lane b (:func:`surrogate.kernels.rng.fill_lanes`, SIMD across the lanes).
    The results are the same, bit for bit, as ``table_rebound_many`` on the array
    :func:`table_rebound_uniforms` returns for the same state, without holding it
    (a block's uniforms are drawn when it enters the pipeline). Seeding the
    lanes costs about 0.1 µs per call, so call it on many rows at once.
    """
    check_state(state)
    check_rows(V, n, a, V_out, Omega_out, status)
    run_blocks(data, mix_cdf, no_shapes(), V, n, a, no_uniforms(), state, V_out, Omega_out, status, no_shape_out(),
               no_work(), no_work(), scaled)


@numba.njit(**JIT)
def table_rebound_uniforms(state, n_rows):
    """The (n_rows, U_PER_DRAW) uniforms :func:`table_rebound_many_rng` draws from ``state`` for n_rows rows,
    advancing ``state`` as it does (for tests, and to replay a draw through :func:`table_rebound_many`)."""
    lanes, u = _lanes(), np.empty((n_rows, U_PER_DRAW))
    seed_lanes(state, lanes)
    ub = np.empty(BLOCK * U_PER_DRAW)
    for start in range(0, n_rows, BLOCK):
        fill_lanes(lanes, ub, BLOCK, U_PER_DRAW)
        for b in range(min(BLOCK, n_rows - start)):
            for k in range(U_PER_DRAW):
                u[start + b, k] = ub[k * BLOCK + b]
    return u


@numba.njit(inline="always", **JIT)
def _lanes():
    """The BLOCK xoshiro256+ lanes of :func:`table_rebound_many_rng` (:func:`surrogate.kernels.rng.seed_lanes` layout)."""
    return np.zeros(4 * BLOCK, dtype=np.uint64)


@numba.njit(inline="always", **JIT)
def run_blocks(data, mix_cdf, shapes, V, n, a, u, state, V_out, Omega_out, status, shape_out, work_n, work_t,
               scaled):
    """The pipeline (:func:`table_rebound_many` with ``u``, :func:`table_rebound_many_rng` with ``state``; the other
    argument empty: :func:`no_state`, :func:`no_uniforms`) with its scratch, V, n, a made C-contiguous
    (copied if they are not). ``shapes``: each row's shape index in the table, or SHAPE_FROM_MIX
    (:func:`surrogate.kernels.locate.row_shape`); empty (:func:`no_shapes`): every row's from the mix.
    ``shape_out``: (rows,) int32, each row's shape index (that of a row that does not move into its wall is
    meaningless), or empty (:func:`no_shape_out`): not written. ``work_n``, ``work_t``: (rows,) float64, each
    row's work on the wall W_n, W_t in m²/s² (:func:`surrogate.kernels.work.work_block`), or both empty
    (:func:`no_work`): not computed."""
    _rebound_blocks(data, mix_cdf, shapes, np.ascontiguousarray(V), np.ascontiguousarray(n),
                    np.ascontiguousarray(a), u, state, V_out, Omega_out, status, shape_out, work_n, work_t, scaled,
                    *_block_scratch())


@numba.njit(inline="always", **JIT)
def no_shapes():
    """The ``shapes`` argument of :func:`run_blocks` when every row's shape is drawn from the mix."""
    return np.zeros(0, dtype=np.int64)


@numba.njit(inline="always", **JIT)
def no_shape_out():
    """The ``shape_out`` argument of :func:`run_blocks` when the rows' shapes are not wanted."""
    return np.zeros(0, dtype=np.int32)


@numba.njit(inline="always", **JIT)
def no_work():
    """The ``work_n`` and ``work_t`` arguments of :func:`run_blocks` when the work on the wall is not wanted."""
    return np.zeros(0)


@numba.njit(inline="always", **JIT)
def no_state():
    """The ``state`` argument of :func:`_rebound_blocks` when the uniforms are given (no state)."""
    return np.zeros(0, dtype=np.uint64)


@numba.njit(inline="always", **JIT)
def no_uniforms():
    """The ``u`` argument of :func:`_rebound_blocks` when it draws the uniforms (no rows)."""
    return np.zeros((0, U_PER_DRAW))


@numba.njit(inline="always", **JIT)
def _block_scratch():
    """The scratch arrays of :func:`_rebound_blocks`: per block in the pipeline its uniforms, frame records and
    cell records (index, weights); the gathered records and the results of the block being drawn; the random
    lanes."""
    return (np.zeros((STAGES, BLOCK * U_PER_DRAW)), np.zeros((STAGES, FRAME_FIELDS * BLOCK)),
            np.zeros((STAGES, INDEX_FIELDS * BLOCK), dtype=np.int64), np.zeros((STAGES, WEIGHT_FIELDS * BLOCK)),
            np.zeros(GATHERED_FIELDS * BLOCK), np.zeros(OUT_FIELDS * BLOCK), _lanes())


@numba.njit(**KERNEL)
def _rebound_blocks(data, mix_cdf, shapes, V, n, a, u, state, V_out, Omega_out, status, shape_out, work_n, work_t,
                    scaled, us, fr, index, weights, g, out, lanes):
    """:func:`table_rebound_many` (uniforms ``u``) or :func:`table_rebound_many_rng` (uniforms drawn from ``state``)
    with its scratch arrays (:func:`_block_scratch`): a pipeline of STAGES blocks, so that a block's table
    reads have a whole step to arrive before they are used."""
    if state.shape[0] == 4:
        seed_lanes(state, lanes)
    rows = V.shape[0]
    V_flat, n_flat = V.reshape(3 * rows), n.reshape(3 * rows)
    n_blocks = (rows + BLOCK - 1) // BLOCK
    for k in range(n_blocks + STAGES - 1):
        if k < n_blocks:
            j, start = k % STAGES, k * BLOCK
            _block_uniforms(u, state, lanes, start, min(BLOCK, rows - start), us[j])
            locate_block(data, mix_cdf, shapes, V_flat, n_flat, a, us[j], state.shape[0] != 4, start,
                         min(BLOCK, rows - start), fr[j], index[j], weights[j])
            for b in range(min(BLOCK, rows - start) if shape_out.shape[0] > 0 else 0):
                shape_out[start + b] = field(index[j], I_DRAWN, b) // (data.n_alpha1 * data.n_speed)
        if 1 <= k <= n_blocks:
            j, start = (k - 1) % STAGES, (k - 1) * BLOCK
            resolve_block(data, us[j], min(BLOCK, rows - start), fr[j], index[j])
            if work_n.shape[0] > 0:
                hint_work_block(data, us[j], min(BLOCK, rows - start), fr[j], index[j])
        if k >= 2:
            j, start = (k - 2) % STAGES, (k - 2) * BLOCK
            gather_block(data, us[j], min(BLOCK, rows - start), fr[j], index[j], weights[j], g)
            arithmetic_block(g, fr[j], out, V_out, Omega_out, status, start, min(BLOCK, rows - start), scaled)
            if work_n.shape[0] > 0:
                work_block(data, us[j], min(BLOCK, rows - start), fr[j], index[j], weights[j], g, out, work_n, work_t,
                           start, scaled)


@numba.njit(inline="always", **JIT)
def _block_uniforms(u, state, lanes, start, m, ub):
    """The uniforms of the m rows from ``start`` into ``ub``, uniform k of row start + b at k · BLOCK + b:
    drawn from the ``lanes`` when ``state`` is a state (table_rebound_many_rng), else copied from ``u``."""
    if state.shape[0] == 4:
        fill_lanes(lanes, ub, BLOCK, U_PER_DRAW)
    else:
        for k in range(U_PER_DRAW):
            for b in range(m):
                ub[k * BLOCK + b] = u[start + b, k]
