"""Many particles on one thread: the draws of :func:`surrogate.kernels.particle.rebound` as a pipeline of blocks.

A per-particle draw is a chain of dependent steps (frame, cell, table reads,
arithmetic), and a table read waits for memory. :func:`rebound_many` and
:func:`rebound_many_rng` take BLOCK particles at a time through three
stages, so that one block's table reads are in flight while the blocks
before it are computed:

1. locate: impact frames (a SIMD loop), grid cells
   (:func:`surrogate.kernels.draw.locate`), cache hints for the component
   rows the uniforms pick;
2. resolve: the alias table of each row, cache hints for the component and
   its residual-shape levels;
3. draw: the table values gathered (:func:`surrogate.kernels.draw.gather_component`,
   :func:`~surrogate.kernels.draw.gather_cell`) into a scratch array, then
   :func:`surrogate.kernels.draw.arithmetic`, the function one particle
   calls, as one branch-free (SIMD) loop over the block: the same bits by
   construction.

The block scratch arrays are field-major (field f of particle b at
f · BLOCK + b): a compile-time stride, which the SIMD loops need. Input
shapes are checked before any work (ValueError naming the array).
"""

import numba
import numpy as np

from surrogate.kernels.draw import (U_PER_DRAW, arithmetic, component, first_row, gather_cell, gather_component,
                                    hint_levels, hint_row, locate)
from surrogate.kernels.frame import STATUS_INVALID, impact_frame, moves_into_wall, particle_ok, to_global, uniforms_ok
from surrogate.kernels.memory import load, load3, load6, load15
from surrogate.kernels.options import JIT, KERNEL
from surrogate.kernels.rng import fill_lanes, seed_lanes


BLOCK = 32      # particles whose table reads rebound_many puts in flight together


INDEX = 5       # integers per particle in rebound_many's index scratch (field f of particle b at f · BLOCK + b): the
                # cell (draw.locate), the component row


I_DRAWN, I_BELOW, I_JV, I_IV, I_ROW = 0, 1, 2, 3, 4
# Fields of rebound_many's scratch (float64, field f of particle b at f · BLOCK + b): what the arithmetic
# of a draw reads, so that it runs as one loop over the block on these arrays alone


G_VALID, G_ALPHA1, G_SPEED, G_COS, G_SIN, G_A, G_EX, G_EZ, G_N = 0, 1, 2, 3, 4, 5, 6, 9, 12    # frame


G_WA, G_WV, G_TRAPPED, G_MIRROR, G_REGIME, G_F_TARGET, G_F_GRID = 15, 16, 17, 18, 19, 20, 21   # weights, flags


G_Q, G_SLOPE = 22, 28          # draw.gather_component: residual quantiles (6) and slopes (15)


G_RATIO, G_SHIFT = 43, 49       # draw.gather_cell: 6 ratios; (m_cell, m) of α2, s, Ω_z (the others are centred)


G_OK = 55                       # particle_ok and uniforms_ok, applied with the result (frame.to_global)


G_FIELDS = 56


OUT_STATUS, OUT_V, OUT_OMEGA, OUT_FIELDS = 0, 1, 4, 7                           # the draws' results, same layout


@numba.njit(**JIT)
def rebound_many(data, mix_cdf, V, n, a, u, V_out, Omega_out, status, scaled=True):
    """:func:`surrogate.kernels.particle.rebound` for every row, one thread, by blocks of BLOCK particles.

    Same arguments as :func:`surrogate.kernels.parallel.rebound_parallel` and the same results, bit for
    bit, as calling :func:`surrogate.kernels.particle.rebound` row by row. Every array must have one row per
    particle (ValueError naming the first that has not); V, n and a are
    copied if they are not C-contiguous. Per block, each step a loop over
    the block whose iterations do not depend on each other (so the processor
    overlaps them):

    1. the impact frames, as one branch-free loop that the compiler turns
       into SIMD instructions (8 particles per instruction with AVX-512);
    2. the cells, with cache hints (:func:`surrogate.kernels.memory.prefetch`) for
       the component rows the uniforms pick;
    3. (a block later) the components, through the alias table on those
       rows, with hints for the resolved rows and the residual levels;
    4. (a block later) the table values every draw needs, copied into a
       scratch array;
    5. the arithmetic of the draws on that scratch, one branch-free SIMD loop.

    So the memory latencies of a whole block overlap, and each has a block's
    worth of work to arrive in.

    For a flow solver that collects its wall hits: call this from its
    ``@njit`` code on the hit arrays (or :func:`rebound_many_rng`, which
    draws the uniforms itself).
    """
    check_rows(V, n, a, V_out, Omega_out, status)
    check_uniforms(u, V.shape[0], "V")
    run_blocks(data, mix_cdf, V, n, a, u, no_state(), V_out, Omega_out, status, scaled)


@numba.njit(**JIT)
def rebound_many_rng(data, mix_cdf, V, n, a, state, V_out, Omega_out, status, scaled=True):
    """:func:`rebound_many` drawing the uniforms from the xoshiro256+ ``state`` ((4,) uint64,
    :func:`surrogate.kernels.rng.seed_state`), which it advances by one step.

    The uniforms come from BLOCK xoshiro256+ lanes seeded from ``state``
    (:func:`surrogate.kernels.rng.seed_lanes`): row b of every block of BLOCK rows
    from lane b (:func:`surrogate.kernels.rng.fill_lanes`, SIMD across the lanes).
    The results are the same, bit for bit, as ``rebound_many`` on the array
    :func:`rebound_uniforms` returns for the same state, without holding it
    (a block's uniforms are drawn when it enters the pipeline). Seeding the
    lanes costs about 0.1 µs per call, so call it on many rows at once.
    """
    check_state(state)
    check_rows(V, n, a, V_out, Omega_out, status)
    run_blocks(data, mix_cdf, V, n, a, no_uniforms(), state, V_out, Omega_out, status, scaled)


@numba.njit(**JIT)
def check_state(state):
    """ValueError unless ``state`` is one xoshiro256+ state: (4,) uint64, not all zero (the generator's
    fixed point; rbs_rebound_many_rng gives every row RBS_INVALID for it)."""
    if state.shape[0] != 4 or (state[0] | state[1] | state[2] | state[3]) == 0:
        raise ValueError("'state' must be one xoshiro256+ state, (4,) uint64 not all zero, as surrogate.seed_state "
                         "gives")


@numba.njit(**JIT)
def rebound_uniforms(state, n_rows):
    """The (n_rows, U_PER_DRAW) uniforms :func:`rebound_many_rng` draws from ``state`` for n_rows rows,
    advancing ``state`` as it does (for tests, and to replay a draw through :func:`rebound_many`)."""
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
    """The BLOCK xoshiro256+ lanes of :func:`rebound_many_rng` (:func:`surrogate.kernels.rng.seed_lanes` layout)."""
    return np.zeros(4 * BLOCK, dtype=np.uint64)


@numba.njit(**JIT)
def check_rows(V, n, a, V_out, Omega_out, status):
    """ValueError naming the first array of a block kernel's call that has not one row per particle, with
    its shape and the shape needed. Called before the parallel loops: a raise inside one keeps numba from
    running it in parallel."""
    rows = V.shape[0]
    for name, shape in (("V", V.shape), ("n", n.shape), ("V_out", V_out.shape), ("Omega_out", Omega_out.shape)):
        if shape[0] != rows or shape[1] != 3:
            raise ValueError(shape_error(name, shape, "(" + str(rows) + ", 3)"))
    for name, shape in (("a", a.shape), ("status", status.shape)):
        if shape[0] != rows:
            raise ValueError(shape_error(name, shape, "(" + str(rows) + ",)"))


@numba.njit(**JIT)
def check_uniforms(u, rows, first):
    """ValueError unless the uniforms ``u`` have shape (rows, U_PER_DRAW), rows = len(first)."""
    if u.shape[0] != rows or u.shape[1] != U_PER_DRAW:
        raise ValueError(shape_error("u", u.shape, "(" + str(rows) + ", " + str(U_PER_DRAW) + ")", first))


@numba.njit(**JIT)
def shape_error(name, shape, needed, first="V"):
    """The message of a shape error of the kernels over many particles: one row per particle, as many as
    the array ``first`` has."""
    text = ", ".join([str(x) for x in shape]) + ("," if len(shape) == 1 else "")
    return ("'" + name + "' has shape (" + text + "); needed " + needed
            + ": one row per particle, as many as " + first + " has")


@numba.njit(inline="always", **JIT)
def run_blocks(data, mix_cdf, V, n, a, u, state, V_out, Omega_out, status, scaled):
    """The pipeline (:func:`rebound_many` with ``u``, :func:`rebound_many_rng` with ``state``; the other
    argument empty: :func:`no_state`, :func:`no_uniforms`) with its scratch, V, n, a made C-contiguous
    (copied if they are not)."""
    _rebound_blocks(data, mix_cdf, np.ascontiguousarray(V), np.ascontiguousarray(n), np.ascontiguousarray(a), u,
                    state, V_out, Omega_out, status, scaled, *_block_scratch())


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
    """The scratch arrays of :func:`_rebound_blocks`, one slot per block in the pipeline: uniforms, index,
    gathered fields; the results of the block being drawn, and the random lanes."""
    return (np.zeros((STAGES, BLOCK * U_PER_DRAW)), np.zeros((STAGES, INDEX * BLOCK), dtype=np.int64),
            np.zeros((STAGES, G_FIELDS * BLOCK)), np.zeros(OUT_FIELDS * BLOCK), _lanes())


STAGES = 3      # blocks in rebound_many's pipeline: located, resolved, drawn


@numba.njit(**KERNEL)
def _rebound_blocks(data, mix_cdf, V, n, a, u, state, V_out, Omega_out, status, scaled, us, index, g, out, lanes):
    """:func:`rebound_many` (uniforms ``u``) or :func:`rebound_many_rng` (uniforms drawn from ``state``)
    with its scratch arrays (:func:`_block_scratch`).

    A pipeline of three blocks, so that a block's table reads have a whole
    step to arrive before they are used: while block k is located (its
    uniforms, steps 1, 2), block k − 1 has its components resolved (step 3)
    and block k − 2 is drawn (steps 4, 5).
    """
    if state.shape[0] == 4:
        seed_lanes(state, lanes)
    V_flat, n_flat = V.reshape(3 * V.shape[0]), n.reshape(3 * V.shape[0])
    n_blocks = (V.shape[0] + BLOCK - 1) // BLOCK
    for k in range(n_blocks + STAGES - 1):
        if k < n_blocks:
            j = k % STAGES
            _block_uniforms(u, state, lanes, k * BLOCK, min(BLOCK, V.shape[0] - k * BLOCK), us[j])
            _locate_block(data, mix_cdf, V_flat, n_flat, a, us[j], state.shape[0] != 4, k * BLOCK, index[j], g[j])
        if 1 <= k <= n_blocks:
            j = (k - 1) % STAGES
            _resolve_block(data, us[j], (k - 1) * BLOCK, V.shape[0], index[j], g[j])
        if k >= 2:
            j = (k - 2) % STAGES
            _draw_block(data, us[j], V_out, Omega_out, status, scaled, (k - 2) * BLOCK, index[j], g[j], out)


@numba.njit(inline="always", **JIT)
def _block_uniforms(u, state, lanes, start, m, ub):
    """The uniforms of the m rows from ``start`` into ``ub``, uniform k of row start + b at k · BLOCK + b:
    drawn from the ``lanes`` when ``state`` is a state (rebound_many_rng), else copied from ``u``."""
    if state.shape[0] == 4:
        fill_lanes(lanes, ub, BLOCK, U_PER_DRAW)
    else:
        for k in range(U_PER_DRAW):
            for b in range(m):
                ub[k * BLOCK + b] = u[start + b, k]


@numba.njit(inline="always", **JIT)
def _uniforms(ub, b):
    """The U_PER_DRAW uniforms of particle b of a block as a tuple, from the block's uniforms ``ub``
    (:func:`_block_uniforms`)."""
    return load6(ub, b, BLOCK) + load6(ub, 6 * BLOCK + b, BLOCK) + (np.float64(load(ub, 12 * BLOCK + b)),)


@numba.njit(inline="always", **JIT)
def _locate_block(data, mix_cdf, V, n, a, ub, given, start, index, g):
    """Steps 1 and 2 on the block of rows from ``start`` (their uniforms ``ub``, checked if ``given``):
    impact frames (SIMD), cells and cache hints. V and n flat, row after row: a compile-time stride, which keeps the SIMD loop
    free of run-time stride checks."""
    m = min(BLOCK, a.shape[0] - start)
    for b in range(m):      # no branch and no table read: SIMD across the block
        _frame(V, n, a, ub, given, start + b, g, b)
    for b in range(m):
        if _field(g, G_VALID, b) != 0.0:
            _cell_and_hints(data, mix_cdf, _uniforms(ub, b), index, g, b)
        else:
            _no_cell(index, g, b)
    for b in range(m):
        if _field(g, G_VALID, b) != 0.0:
            hint_row(data, _field(index, I_ROW, b))


@numba.njit(inline="always", **JIT)
def _resolve_block(data, ub, start, n_rows, index, g):
    """Step 3: each particle's component (the alias table read on the row hinted in step 2), and cache
    hints for its row (the same lines again unless the alias table redirected the draw) and its levels."""
    for b in range(min(BLOCK, n_rows - start)):
        if _field(g, G_VALID, b) != 0.0:
            row = component(data, _field(index, I_DRAWN, b), ub[4 * BLOCK + b])
            index[I_ROW * BLOCK + b] = row
            hint_row(data, row)
            hint_levels(data, _field(index, I_DRAWN, b), _uniforms(ub, b))


@numba.njit(inline="always", **JIT)
def _draw_block(data, ub, V_out, Omega_out, status, scaled, start, index, g, out):
    """Steps 4 and 5: gather the table values of every draw, draw (SIMD), store the results."""
    m = min(BLOCK, status.shape[0] - start)
    for b in range(m):
        if _field(g, G_VALID, b) != 0.0:
            _gather_component(data, _uniforms(ub, b), index, g, b)
    for b in range(m):      # no branch: SIMD across the block (invalid rows read cell 0, see _no_cell)
        _gather_cell(data, index, g, b)
    for b in range(m):      # no branch and no table read: SIMD across the block
        _arithmetic(g, out, b, scaled)
    for b in range(m):
        i = start + b
        if _field(g, G_VALID, b) != 0.0:
            status[i] = int(out[OUT_STATUS * BLOCK + b])
            for k in range(3):
                V_out[i, k], Omega_out[i, k] = out[(OUT_V + k) * BLOCK + b], out[(OUT_OMEGA + k) * BLOCK + b]
        else:       # what one particle's rebound returns for a row that does not move into the wall
            status[i] = STATUS_INVALID
            for k in range(3):
                V_out[i, k], Omega_out[i, k] = np.nan, np.nan


@numba.njit(inline="always", **JIT)
def _put3(g, field, b, values):
    """Fields ``field`` … ``field`` + 2 of particle b in a block scratch: the 3-tuple ``values`` (written out:
    a tuple indexed by a loop variable compiles to a jump table)."""
    g[field * BLOCK + b], g[(field + 1) * BLOCK + b], g[(field + 2) * BLOCK + b] = values


@numba.njit(inline="always", **JIT)
def _put6(g, field, b, values):
    """Fields ``field`` … ``field`` + 5 of particle b: the 6-tuple ``values``."""
    _put3(g, field, b, values[:3])
    _put3(g, field + 3, b, values[3:])


@numba.njit(inline="always", **JIT)
def _frame(V, n, a, ub, given, i, g, b):
    """Block step 1, row i as particle b (uniforms ``ub``, :func:`_block_uniforms`): validity and impact
    frame (computed for invalid rows too)."""
    Vi, ni = (V[3 * i], V[3 * i + 1], V[3 * i + 2]), (n[3 * i], n[3 * i + 1], n[3 * i + 2])
    alpha1, speed, cos_a1, sin_a1, ex, ez = impact_frame(Vi, ni, ub[12 * BLOCK + b])
    _put3(g, G_VALID, b, (1.0 if moves_into_wall(Vi, ni) else 0.0, alpha1, speed))
    # uniforms drawn from the lanes are in [0, 1): checked only when ``given`` (rebound_many), as many.c
    g[G_OK * BLOCK + b] = 1.0 if particle_ok(ni, a[i]) & (not given or uniforms_ok(_uniforms(ub, b))) else 0.0
    _put3(g, G_COS, b, (cos_a1, sin_a1, a[i]))
    _put3(g, G_EX, b, ex)
    _put3(g, G_EZ, b, ez)
    _put3(g, G_N, b, ni)


@numba.njit(inline="always", **JIT)
def _cell_and_hints(data, mix_cdf, u, index, g, b):
    """Block step 2 for particle b: its cell, and the cache hints its uniforms locate."""
    cell = locate(data, mix_cdf, _field(g, G_ALPHA1, b), _field(g, G_SPEED, b), u)
    index[I_ROW * BLOCK + b] = first_row(data, cell[0], u[4])[2]
    drawn, below, wa, jv, wv, iv = cell
    for field, value in ((I_DRAWN, drawn), (I_BELOW, below), (I_JV, jv), (I_IV, iv)):
        index[field * BLOCK + b] = value
    g[G_WA * BLOCK + b], g[G_WV * BLOCK + b] = wa, wv


@numba.njit(inline="always", **JIT)
def _no_cell(index, g, b):
    """Block step 2 for an invalid particle b: cell 0 at grid weights 0, so that the steps that run on
    every particle of a block read the table in range (their results for b are discarded)."""
    for k in range(INDEX):
        index[k * BLOCK + b] = 0
    g[G_WA * BLOCK + b], g[G_WV * BLOCK + b] = 0.0, 0.0


@numba.njit(inline="always", **JIT)
def _gather_component(data, u, index, g, b):
    """Block step 4 for particle b: what its draw reads from its component row
    (:func:`surrogate.kernels.draw.gather_component`) into the scratch."""
    q, slopes, regime, trapped, mirror = gather_component(data, _field(index, I_DRAWN, b), _field(index, I_ROW, b), u)
    _put3(g, G_TRAPPED, b, (trapped, mirror, regime))
    _put6(g, G_Q, b, q)
    _put6(g, G_SLOPE, b, slopes[:6])
    _put6(g, G_SLOPE + 6, b, slopes[6:12])
    _put3(g, G_SLOPE + 12, b, slopes[12:])


@numba.njit(inline="always", **JIT)
def _gather_cell(data, index, g, b):
    """Block step 4 for particle b: what its draw reads from its cell (:func:`surrogate.kernels.draw.gather_cell`)
    into the scratch (the weights wa, wv are there from step 2)."""
    cell = (_field(index, I_DRAWN, b), _field(index, I_BELOW, b), _field(g, G_WA, b), _field(index, I_JV, b),
            _field(g, G_WV, b), _field(index, I_IV, b))
    _, _, ratio, shift, f_target, f_grid = gather_cell(data, cell)
    g[G_F_TARGET * BLOCK + b], g[G_F_GRID * BLOCK + b] = f_target, f_grid
    _put6(g, G_RATIO, b, ratio)
    _put6(g, G_SHIFT, b, shift)


@numba.njit(inline="always", **JIT)
def _field(g, field, b):
    return load(g, field * BLOCK + b)


@numba.njit(inline="always", **JIT)
def _fields6(g, field, b):
    return load6(g, field * BLOCK + b, BLOCK)


@numba.njit(inline="always", **JIT)
def _arithmetic(g, out, b, scaled):
    """Block step 5 for particle b: :func:`surrogate.kernels.draw.arithmetic` on its gathered fields, in the
    order :func:`surrogate.kernels.draw.gather` gives them, then :func:`surrogate.kernels.frame.to_global`."""
    gathered = (_fields6(g, G_Q, b), load15(g, G_SLOPE * BLOCK + b, BLOCK), _field(g, G_REGIME, b),
                _field(g, G_TRAPPED, b), _field(g, G_MIRROR, b), _field(g, G_WA, b), _field(g, G_WV, b),
                _fields6(g, G_RATIO, b), _fields6(g, G_SHIFT, b), _field(g, G_F_TARGET, b), _field(g, G_F_GRID, b))
    status, vx, vy, vz, wx, wy, wz = arithmetic(gathered, _field(g, G_COS, b), _field(g, G_SIN, b), scaled)
    ex, n, ez = load3(g, G_EX * BLOCK + b, BLOCK), load3(g, G_N * BLOCK + b, BLOCK), load3(g, G_EZ * BLOCK + b, BLOCK)
    status, V_new, Omega_new = to_global(status, _field(g, G_OK, b) != 0.0, vx, vy, vz, wx, wy, wz,
                                         _field(g, G_SPEED, b), _field(g, G_A, b), ex, n, ez)
    out[OUT_STATUS * BLOCK + b] = status
    _put3(out, OUT_V, b, V_new)
    _put3(out, OUT_OMEGA, b, Omega_new)
