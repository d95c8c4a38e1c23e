"""Stage 1 of a draw, locate: where in the table it reads. The cell (:func:`locate`: shape, grid intervals,
the neighbour drawn with its interpolation weight), the component row in it (:func:`component`, Walker's
alias table) and cache hints for those reads (:func:`hint`).

The cell record is (drawn, below, wa, jv, wv, iv) (:func:`locate`); its block
form (:mod:`surrogate.kernels.block`) is the I_* fields of an int64 array
``index`` with the component row, and the W_* fields of a float64 array
``weights``. :func:`locate_block` and :func:`resolve_block` are this stage
for a block of the pipeline (:mod:`surrogate.kernels.pipeline`).
"""

import numba
import numpy as np

from data_schema.table import N_CHAIN
from surrogate.kernels.block import BLOCK, field, uniforms
from surrogate.kernels.fastmath import clamp_index
from surrogate.kernels.frame import FRAME_ALPHA1, FRAME_SPEED, frame_block, is_valid
from surrogate.kernels.layout import (AXIS_GRID, AXIS_INV_STEP, AXIS_ORIGIN, FLOAT32_PER_CACHE_LINE, ROW_ALIAS,
                                      ROW_ALIAS_PROB, ROW_SIZE)
from surrogate.kernels.memory import load, prefetch
from surrogate.kernels.options import JIT, KERNEL


@numba.njit(inline="always", **JIT)
def grid_interval(axis, n, x):
    """(j, w): grid interval [g_j, g_{j+1}] holding x and the weight of g_{j+1} (O(1)).

    ``axis`` is the record of an n-point grid (:func:`surrogate.kernels.layout.axis_record`).
    Outside the grid, the nearest edge with weight 0 or 1; a one-point grid gives (0, 0).
    """
    if n == 1:
        return 0, 0.0
    inverse = AXIS_GRID + n     # where the inverse spacings start
    lookup = inverse + n - 1    # where the look-up indices start
    last = axis.shape[0] - 1 - lookup
    # capped before the conversion: a huge x (or NaN) would convert to INT64_MIN, which the lower clamp sends
    # to the first point, an interior cell for x above the grid
    t = (x - load(axis, AXIS_ORIGIN)) * load(axis, AXIS_INV_STEP)
    k = max(int(t if t < last else np.float64(last)), 0)
    j = int(load(axis, lookup + k))
    j += (x >= load(axis, AXIS_GRID + j + 1)) & (j < n - 2)     # one-step correction, no branch to mispredict
    w = (x - load(axis, AXIS_GRID + j)) * load(axis, inverse + j)
    return j, min(max(w, 0.0), 1.0)


SHAPE_FROM_MIX = -1    # a per-particle shape index (``shapes`` of the many-particle kernels): drawn from the mix


@numba.njit(inline="always", **JIT)
def mix_shape(mix_cdf, u0):
    """The shape drawn from the mix with the uniform u0: the first k with u0 < mix_cdf[k]."""
    shape = 0
    for k in range(mix_cdf.shape[0] - 1):     # without data-dependent branches
        shape += u0 >= mix_cdf[k]
    return shape


@numba.njit(**JIT)
def mix_shapes(mix_cdf, u0):
    """:func:`mix_shape` for each uniform of u0 (N,): (N,) int64 shape indices, table order."""
    shapes = np.empty(u0.shape[0], dtype=np.int64)
    for i in range(u0.shape[0]):
        shapes[i] = mix_shape(mix_cdf, u0[i])
    return shapes


@numba.njit(inline="always", **JIT)
def row_shape(mix_cdf, shapes, i, u0):
    """The shape of row i: ``shapes[i]`` where given (≥ 0), else drawn from the mix with u0 (``shapes`` empty:
    every row's is). u0 is that row's u[0], consumed either way, so the streams stay aligned."""
    given = shapes.shape[0] > 0 and shapes[i] != SHAPE_FROM_MIX
    return shapes[i] if given else mix_shape(mix_cdf, u0)


@numba.njit(inline="always", **JIT)
def locate(data, mix_cdf, alpha1, speed, u):
    """The cell a draw reads: (drawn, below, wa, jv, wv, iv), its shape drawn from the mix with u[0]
    (:func:`locate_in_shape`)."""
    return locate_in_shape(data, mix_shape(mix_cdf, u[0]), alpha1, speed, u)


@numba.njit(inline="always", **JIT)
def locate_in_shape(data, shape, alpha1, speed, u):
    """The cell a draw of the shape ``shape`` (its index in the table) reads: (drawn, below, wa, jv, wv, iv).

    Grid intervals (ja, jv) with the weights of
    their upper points (wa, wv); the neighbour cell (ia, iv) drawn with those
    weights from u[1], u[2] (stochastic interpolation). ``drawn`` is the
    number of cell (shape, ia, iv) (:class:`surrogate.kernels.layout.KernelData`),
    ``below`` that of (shape, ja, iv), the lower α1 neighbour at the drawn speed.
    """
    ja, wa = grid_interval(data.alpha1_axis, data.n_alpha1, alpha1)
    jv, wv = grid_interval(data.speed_axis, data.n_speed, speed)
    ia = ja + (u[1] < wa)       # integer + comparison: no branch to mispredict
    iv = jv + (u[2] < wv)
    below = (shape * data.n_alpha1 + ja) * data.n_speed + iv
    return below + (ia - ja) * data.n_speed, below, wa, jv, wv, iv


@numba.njit(inline="always", **JIT)
def _row(data, cell, c):
    """Offset in ``data.clusters`` of component c's row in cell number ``cell``."""
    return (cell * data.n_clusters + c) * ROW_SIZE


@numba.njit(inline="always", **JIT)
def level_offset(data, cell, k, i):
    """Offset in ``data.dictionary`` of level i of chain variable k's residual shapes in cell number ``cell``
    (the n_dictionary shapes follow)."""
    return ((cell * N_CHAIN + k) * data.n_levels + i) * data.n_dictionary


@numba.njit(inline="always", **JIT)
def first_row(data, cell, u4):
    """(t, c, offset of row c): the component u4 picks in cell number ``cell`` before the alias table,
    c = ⌊t⌋ with t = u4 · n_clusters."""
    t = u4 * data.n_clusters
    c = clamp_index(int(t), data.n_clusters - 1)
    return t, c, _row(data, cell, c)


@numba.njit(inline="always", **JIT)
def component(data, cell, u4):
    """Offset in ``data.clusters`` of the mixture component u4 draws in cell number ``cell``: Walker's
    alias table (one multiply, one floor, one compare; the alias sits in the row's first cache line)."""
    t, c, row = first_row(data, cell, u4)
    alias = int(load(data.clusters, row + ROW_ALIAS))
    c = alias if t - c >= load(data.clusters, row + ROW_ALIAS_PROB) else c
    return _row(data, cell, c)


@numba.njit(inline="always", **JIT)
def hint(data, cell, u):
    """Cache hints (:func:`surrogate.kernels.memory.prefetch`) for the table reads of a draw in ``cell`` that
    the uniforms alone locate, so that they are all in flight at once: the component row u[4] picks
    (before its alias is resolved) and the residual-shape levels u[5:11] pick (the dictionary is
    level-major, so these lines do not depend on the row). The trapped probabilities and the moments are
    small and stay cached."""
    hint_row(data, first_row(data, cell[0], u[4])[2])
    hint_levels(data, cell[0], u)


@numba.njit(inline="always", **JIT)
def hint_row(data, row):
    """Cache hints for the component row at offset ``row``: its three cache lines (144 bytes, the start
    16-byte aligned)."""
    for j in range(0, ROW_SIZE, FLOAT32_PER_CACHE_LINE):
        prefetch(data.clusters, (row + j,))


@numba.njit(inline="always", **JIT)
def hint_levels(data, drawn, u):
    """Cache hints for the residual-shape levels u[5:11] pick in cell number ``drawn`` (two per variable;
    ``u`` a row of uniforms or a tuple)."""
    _hint_level(data, drawn, 0, u[5])
    _hint_level(data, drawn, 1, u[6])
    _hint_level(data, drawn, 2, u[7])
    _hint_level(data, drawn, 3, u[8])
    _hint_level(data, drawn, 4, u[9])
    _hint_level(data, drawn, 5, u[10])


@numba.njit(inline="always", **JIT)
def _hint_level(data, drawn, k, u):
    """Cache hints for the two residual-shape levels of chain variable k that u picks
    (:func:`surrogate.kernels.gather._quantile`)."""
    levels = data.n_levels - 1
    level = level_offset(data, drawn, k, clamp_index(int(u * levels), levels - 1))
    prefetch(data.dictionary, (level,))
    prefetch(data.dictionary, (level + data.n_dictionary,))


# -- the cell record of a block ----------------------------------------------------------------------

I_DRAWN, I_BELOW, I_JV, I_IV, I_ROW = 0, 1, 2, 3, 4     # int64 fields: the cell's integers, the component row
INDEX_FIELDS = 5
W_A, W_V = 0, 1                                         # float64 fields: the cell's weights wa, wv
WEIGHT_FIELDS = 2


@numba.njit(inline="always", **JIT)
def cell_at(index, weights, b):
    """Particle b's cell record (drawn, below, wa, jv, wv, iv), as :func:`locate` returns it."""
    return (field(index, I_DRAWN, b), field(index, I_BELOW, b), field(weights, W_A, b), field(index, I_JV, b),
            field(weights, W_V, b), field(index, I_IV, b))


@numba.njit(**KERNEL)
def locate_block(data, mix_cdf, shapes, V, n, a, ub, given, start, m, fr, index, weights):
    """Stage 1 for the m rows from ``start`` (their uniforms ``ub``, checked if ``given``; their shapes
    :func:`row_shape`): the frame records ``fr`` (:func:`surrogate.kernels.frame.frame_block`), the cells, and
    cache hints for the component rows the uniforms pick (before the alias table)."""
    frame_block(V, n, a, ub, given, start, m, fr)
    for b in range(m):
        if is_valid(fr, b):
            u = uniforms(ub, b)
            _put_cell(data, row_shape(mix_cdf, shapes, start + b, u[0]), field(fr, FRAME_ALPHA1, b),
                      field(fr, FRAME_SPEED, b), u, index, weights, b)
        else:
            _no_cell(index, weights, b)
    for b in range(m):
        if is_valid(fr, b):
            hint_row(data, field(index, I_ROW, b))


@numba.njit(inline="always", **JIT)
def _put_cell(data, shape, alpha1, speed, u, index, weights, b):
    """Particle b's cell in the shape ``shape`` and the row u[4] picks in it before the alias table."""
    cell = locate_in_shape(data, shape, alpha1, speed, u)
    index[I_ROW * BLOCK + b] = first_row(data, cell[0], u[4])[2]
    drawn, below, wa, jv, wv, iv = cell
    for f, value in ((I_DRAWN, drawn), (I_BELOW, below), (I_JV, jv), (I_IV, iv)):
        index[f * BLOCK + b] = value
    weights[W_A * BLOCK + b], weights[W_V * BLOCK + b] = wa, wv


@numba.njit(inline="always", **JIT)
def _no_cell(index, weights, b):
    """Cell 0 at grid weights 0 for a particle b that does not move into its wall, so that the steps that run
    on every particle of a block read the table in range (their results for b are discarded)."""
    for f in range(INDEX_FIELDS):
        index[f * BLOCK + b] = 0
    weights[W_A * BLOCK + b], weights[W_V * BLOCK + b] = 0.0, 0.0


@numba.njit(**KERNEL)
def resolve_block(data, ub, m, fr, index):
    """Stage 1, a block later: each particle's component (the alias table read on the row hinted in
    :func:`locate_block`), and cache hints for its row (the same lines again unless the alias table
    redirected the draw) and its residual-shape levels."""
    for b in range(m):
        if is_valid(fr, b):
            row = component(data, field(index, I_DRAWN, b), ub[4 * BLOCK + b])
            index[I_ROW * BLOCK + b] = row
            hint_row(data, row)
            hint_levels(data, field(index, I_DRAWN, b), uniforms(ub, b))
