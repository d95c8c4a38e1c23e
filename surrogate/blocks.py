"""Many particles on one thread: the draws of :func:`surrogate.kernels.rebound` as a pipeline of blocks.

A per-particle draw is a chain of dependent steps (frame, cell, table reads,
arithmetic), and a table read waits for memory. :func:`rebound_many` and
:func:`rebound_many_rng` take BLOCK particles at a time through three
stages, so that one block's table reads are in flight while the blocks
before it are computed:

1. locate: impact frames (a SIMD loop), grid cells, cache hints for the
   component rows the uniforms pick;
2. resolve: the alias table of each row, cache hints for the component and
   its residual-shape levels;
3. draw: the table values gathered into a scratch array, then the arithmetic
   of every draw as one branch-free (SIMD) loop over the block, the same
   operations in the same order as the per-particle kernel, so the same bits.

The block scratch arrays are field-major (field f of particle b at
f · BLOCK + b): a compile-time stride, which the SIMD loops need. Input
shapes are checked before any work (ValueError naming the array).
"""

import numba
import numpy as np

from data_schema.samples import STATUS_TRAPPED
from surrogate.draw import (U_PER_DRAW, _alpha1_terms, _cell, _chain, _component, _fifteen, _first_row, _hint_levels,
                            _hint_row, _mirrored, _moved, _quantiles, _restitution_factors, _six, _three, _to_speed,
                            _velocity)
from surrogate.frame import STATUS_INVALID, _moves_into_wall, _to_global, impact_frame
from surrogate.jit import JIT, KERNEL
from surrogate.memory import load
from surrogate.rng import fill_lanes, seed_lanes
from surrogate.table import CELL_P_TRAPPED, CELL_SIZE, ROW_REGIME, ROW_SLOPE


BLOCK = 32      # particles whose table reads rebound_many puts in flight together


INDEX = 5       # integers per particle in rebound_many's index scratch (field f of particle b at f · BLOCK + b): the
                # cell (_cell), the component row


I_DRAWN, I_BELOW, I_JV, I_IV, I_ROW = 0, 1, 2, 3, 4
# Fields of rebound_many's scratch (float64, field f of particle b at f · BLOCK + b): what the arithmetic
# of a draw reads, so that it runs as one loop over the block on these arrays alone


G_VALID, G_ALPHA1, G_SPEED, G_COS, G_SIN, G_A, G_EX, G_EZ, G_N = 0, 1, 2, 3, 4, 5, 6, 9, 12    # frame


G_WA, G_WV, G_TRAPPED, G_MIRROR, G_REGIME, G_F_TARGET, G_F_GRID = 15, 16, 17, 18, 19, 20, 21   # weights, flags


G_Q, G_SLOPE = 22, 28          # _chain's residual quantiles (6) and slopes (15)


G_RATIO, G_SHIFT = 43, 49       # _alpha1_terms: 6 ratios; (m_cell, m) of α2, s, Ω_z (the others are centred)


G_FIELDS = 55


OUT_STATUS, OUT_V, OUT_W, OUT_FIELDS = 0, 1, 4, 7                           # the draws' results, same layout


@numba.njit(**JIT)
def rebound_many(data, mix_cdf, V, n, a, u, V_out, W_out, status, scaled=True):
    """:func:`surrogate.kernels.rebound` for every row, one thread, by blocks of BLOCK particles.

    Same arguments as :func:`surrogate.batch.rebound_batch` and the same results, bit for bit,
    as calling :func:`surrogate.kernels.rebound` row by row. Every array must have one row per
    particle (ValueError naming the first that has not); V, n and a are
    copied if they are not C-contiguous. Per block, each step a loop over
    the block whose iterations do not depend on each other (so the processor
    overlaps them):

    1. the impact frames, as one branch-free loop that the compiler turns
       into SIMD instructions (8 particles per instruction with AVX-512);
    2. the cells, with cache hints (:func:`surrogate.memory.prefetch`) for
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
    _check_rows(V, n, a, V_out, W_out, status)
    _check_uniforms(u, V.shape[0], "V")
    _run_blocks(data, mix_cdf, V, n, a, u, _no_state(), V_out, W_out, status, scaled)


@numba.njit(**JIT)
def rebound_many_rng(data, mix_cdf, V, n, a, state, V_out, W_out, status, scaled=True):
    """:func:`rebound_many` drawing the uniforms from the xoshiro256+ ``state`` ((4,) uint64,
    :func:`surrogate.rng.seed_state`), which it advances by one step.

    The uniforms come from BLOCK xoshiro256+ lanes seeded from ``state``
    (:func:`surrogate.rng.seed_lanes`): row b of every block of BLOCK rows
    from lane b (:func:`surrogate.rng.fill_lanes`, SIMD across the lanes).
    The results are the same, bit for bit, as ``rebound_many`` on the array
    :func:`rebound_uniforms` returns for the same state, without holding it
    (a block's uniforms are drawn when it enters the pipeline). Seeding the
    lanes costs about 0.1 µs per call, so call it on many rows at once.
    """
    if state.shape[0] != 4:
        raise ValueError("'state' must be one xoshiro256+ state, (4,) uint64, as surrogate.rng.seed_state gives")
    _check_rows(V, n, a, V_out, W_out, status)
    _run_blocks(data, mix_cdf, V, n, a, _no_uniforms(), state, V_out, W_out, status, scaled)


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
    """The BLOCK xoshiro256+ lanes of :func:`rebound_many_rng` (:func:`surrogate.rng.seed_lanes` layout)."""
    return np.zeros(4 * BLOCK, dtype=np.uint64)


@numba.njit(**JIT)
def _check_rows(V, n, a, V_out, W_out, status):
    """ValueError naming the first array of a block kernel's call that has not one row per particle, with
    its shape and the shape needed. Called before the parallel loops: a raise inside one keeps numba from
    running it in parallel."""
    rows = V.shape[0]
    for name, shape in (("V", V.shape), ("n", n.shape), ("V_out", V_out.shape), ("W_out", W_out.shape)):
        if shape[0] != rows or shape[1] != 3:
            raise ValueError(_shape_error(name, shape, "(" + str(rows) + ", 3)"))
    for name, shape in (("a", a.shape), ("status", status.shape)):
        if shape[0] != rows:
            raise ValueError(_shape_error(name, shape, "(" + str(rows) + ",)"))


@numba.njit(**JIT)
def _check_uniforms(u, rows, first):
    """ValueError unless the uniforms ``u`` have shape (rows, U_PER_DRAW), rows = len(first)."""
    if u.shape[0] != rows or u.shape[1] != U_PER_DRAW:
        raise ValueError(_shape_error("u", u.shape, "(" + str(rows) + ", " + str(U_PER_DRAW) + ")", first))


@numba.njit(**JIT)
def _shape_error(name, shape, needed, first="V"):
    """The message of a shape error of the kernels over many particles: one row per particle, as many as
    the array ``first`` has."""
    text = ", ".join([str(x) for x in shape]) + ("," if len(shape) == 1 else "")
    return ("'" + name + "' has shape (" + text + "); needed " + needed
            + ": one row per particle, as many as " + first + " has")


@numba.njit(inline="always", **JIT)
def _run_blocks(data, mix_cdf, V, n, a, u, state, V_out, W_out, status, scaled):
    """:func:`_rebound_blocks` with its scratch, V, n, a made C-contiguous (copied if they are not)."""
    _rebound_blocks(data, mix_cdf, np.ascontiguousarray(V), np.ascontiguousarray(n), np.ascontiguousarray(a), u,
                    state, V_out, W_out, status, scaled, *_block_scratch())


@numba.njit(inline="always", **JIT)
def _no_state():
    """The ``state`` argument of :func:`_rebound_blocks` when the uniforms are given (no state)."""
    return np.zeros(0, dtype=np.uint64)


@numba.njit(inline="always", **JIT)
def _no_uniforms():
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
def _rebound_blocks(data, mix_cdf, V, n, a, u, state, V_out, W_out, status, scaled, us, index, g, out, lanes):
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
            _locate_block(data, mix_cdf, V_flat, n_flat, a, us[j], k * BLOCK, index[j], g[j])
        if 1 <= k <= n_blocks:
            j = (k - 1) % STAGES
            _resolve_block(data, us[j], (k - 1) * BLOCK, V.shape[0], index[j], g[j])
        if k >= 2:
            j = (k - 2) % STAGES
            _draw_block(data, us[j], V_out, W_out, status, scaled, (k - 2) * BLOCK, index[j], g[j], out)


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
    return _six(ub, b, BLOCK) + _six(ub, 6 * BLOCK + b, BLOCK) + (np.float64(load(ub, 12 * BLOCK + b)),)


@numba.njit(inline="always", **JIT)
def _locate_block(data, mix_cdf, V, n, a, ub, start, index, g):
    """Steps 1 and 2 on the block of rows from ``start`` (their uniforms ``ub``): impact frames (SIMD),
    cells and cache hints. V and n flat, row after row: a compile-time stride, which keeps the SIMD loop
    free of run-time stride checks."""
    m = min(BLOCK, a.shape[0] - start)
    for b in range(m):      # no branch and no table read: SIMD across the block
        _frame(V, n, a, ub, start + b, g, b)
    for b in range(m):
        if _field(g, G_VALID, b) != 0.0:
            _cell_and_hints(data, mix_cdf, _uniforms(ub, b), index, g, b)
        else:
            _no_cell(index, g, b)
    for b in range(m):
        if _field(g, G_VALID, b) != 0.0:
            _hint_row(data, _field(index, I_ROW, b))


@numba.njit(inline="always", **JIT)
def _resolve_block(data, ub, start, n_rows, index, g):
    """Step 3: each particle's component (the alias table read on the row hinted in step 2), and cache
    hints for its row (the same lines again unless the alias table redirected the draw) and its levels."""
    for b in range(min(BLOCK, n_rows - start)):
        if _field(g, G_VALID, b) != 0.0:
            row = _component(data, _field(index, I_DRAWN, b), ub[4 * BLOCK + b])
            index[I_ROW * BLOCK + b] = row
            _hint_row(data, row)
            _hint_levels(data, _field(index, I_DRAWN, b), _uniforms(ub, b))


@numba.njit(inline="always", **JIT)
def _draw_block(data, ub, V_out, W_out, status, scaled, start, index, g, out):
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
                V_out[i, k], W_out[i, k] = out[(OUT_V + k) * BLOCK + b], out[(OUT_W + k) * BLOCK + b]
        else:       # what rebound returns for a row that does not move into the wall
            status[i] = STATUS_INVALID
            for k in range(3):
                V_out[i, k], W_out[i, k] = np.nan, np.nan


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
def _frame(V, n, a, ub, i, g, b):
    """Block step 1, row i as particle b (uniforms ``ub``, :func:`_block_uniforms`): validity and impact
    frame (computed for invalid rows too)."""
    Vi, ni = (V[3 * i], V[3 * i + 1], V[3 * i + 2]), (n[3 * i], n[3 * i + 1], n[3 * i + 2])
    alpha1, speed, cos_a1, sin_a1, ex, ez = impact_frame(Vi, ni, ub[12 * BLOCK + b])
    _put3(g, G_VALID, b, (1.0 if _moves_into_wall(Vi, ni) else 0.0, alpha1, speed))
    _put3(g, G_COS, b, (cos_a1, sin_a1, a[i]))
    _put3(g, G_EX, b, ex)
    _put3(g, G_EZ, b, ez)
    _put3(g, G_N, b, ni)


@numba.njit(inline="always", **JIT)
def _cell_and_hints(data, mix_cdf, u, index, g, b):
    """Block step 2 for particle b: its cell, and the cache hints its uniforms locate."""
    cell = _cell(data, mix_cdf, _field(g, G_ALPHA1, b), _field(g, G_SPEED, b), u)
    index[I_ROW * BLOCK + b] = _first_row(data, cell[0], u[4])[2]
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
    """Block step 4 for particle b: what its draw reads from its component row (:func:`surrogate.draw.draw_folded`) and
    the residual shapes, with the flags its uniforms set (trapped, mirror)."""
    drawn, row = _field(index, I_DRAWN, b), _field(index, I_ROW, b)
    r = data.clusters
    trapped = u[3] < load(data.cells, drawn * CELL_SIZE + CELL_P_TRAPPED)
    _put3(g, G_TRAPPED, b, (1.0 if trapped else 0.0, u[11], np.float64(load(r, row + ROW_REGIME))))
    _put6(g, G_Q, b, _quantiles(data, drawn, row, u))
    _put6(g, G_SLOPE, b, _six(r, row + ROW_SLOPE, 1))
    _put6(g, G_SLOPE + 6, b, _six(r, row + ROW_SLOPE + 6, 1))
    _put3(g, G_SLOPE + 12, b, _three(r, row + ROW_SLOPE + 12, 1))


@numba.njit(inline="always", **JIT)
def _gather_cell(data, index, g, b):
    """Block step 4 for particle b: the α1 move (:func:`_alpha1_terms`) and the restitution factors."""
    drawn, below = _field(index, I_DRAWN, b), _field(index, I_BELOW, b)
    jv, iv = _field(index, I_JV, b), _field(index, I_IV, b)
    g[G_F_TARGET * BLOCK + b], g[G_F_GRID * BLOCK + b] = _restitution_factors(data, jv, _field(g, G_WV, b), iv)
    t = _alpha1_terms(data, below, _field(g, G_WA, b), drawn)
    _put6(g, G_RATIO, b, (t[0][0], t[1][0], t[2][0], t[3][0], t[4][0], t[5][0]))
    _put6(g, G_SHIFT, b, t[0][1:] + t[2][1:] + t[5][1:])


@numba.njit(inline="always", **JIT)
def _field(g, field, b):
    return load(g, field * BLOCK + b)


@numba.njit(inline="always", **JIT)
def _fields6(g, field, b):
    return _six(g, field * BLOCK + b, BLOCK)


@numba.njit(inline="always", **JIT)
def _pick6(c, x, y):
    """x if c else y for two 6-tuples, element by element (selects, which vectorise)."""
    return (x[0] if c else y[0], x[1] if c else y[1], x[2] if c else y[2], x[3] if c else y[3],
            x[4] if c else y[4], x[5] if c else y[5])


@numba.njit(inline="always", **JIT)
def _arithmetic(g, out, b, scaled):
    """Block step 5: :func:`surrogate.draw._draw_in_cell` and :func:`_to_global` for particle b on its gathered
    fields, the same operations in the same order (so the same bits), with every branch a select."""
    state = _chain(_fields6(g, G_Q, b), _fifteen(g, G_SLOPE * BLOCK + b, BLOCK))
    wa, wv = _field(g, G_WA, b), _field(g, G_WV, b)
    ratio, shift = _fields6(g, G_RATIO, b), _fields6(g, G_SHIFT, b)
    terms = ((ratio[0], shift[0], shift[1]), (ratio[1], 0.0, 0.0), (ratio[2], shift[2], shift[3]),
             (ratio[3], 0.0, 0.0), (ratio[4], 0.0, 0.0), (ratio[5], shift[4], shift[5]))
    state = _pick6(scaled and wa > 0.0, _moved(state, terms), state)
    vx, vy, vz = _velocity(state[0], state[1], state[2])
    cos_a1, sin_a1 = _field(g, G_COS, b), _field(g, G_SIN, b)
    local = (vx, vy, vz, state[3], state[4], state[5])
    moved = _to_speed(_field(g, G_REGIME, b), _field(g, G_F_TARGET, b), _field(g, G_F_GRID, b), cos_a1, sin_a1,
                      vx, vy, vz, state[3], state[4], state[5])
    vx, vy, vz, wx, wy, wz = _pick6(scaled and wv > 0.0, moved, local)
    status, vx, vy, vz, wx, wy, wz = _mirrored(_field(g, G_MIRROR, b), vx, vy, vz, wx, wy, wz)
    status = STATUS_TRAPPED if _field(g, G_TRAPPED, b) > 0.5 else status
    ex, n, ez = (_three(g, G_EX * BLOCK + b, BLOCK), _three(g, G_N * BLOCK + b, BLOCK),
                 _three(g, G_EZ * BLOCK + b, BLOCK))
    V_new, W_new = _to_global(status, vx, vy, vz, wx, wy, wz, _field(g, G_SPEED, b), _field(g, G_A, b), ex, n, ez)
    out[OUT_STATUS * BLOCK + b] = status
    _put3(out, OUT_V, b, V_new)
    _put3(out, OUT_W, b, W_new)
