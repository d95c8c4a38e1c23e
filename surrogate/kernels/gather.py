"""Stage 2 of a draw, gather: every table value it needs, once its cell and component row are located
(:mod:`surrogate.kernels.locate`). The component's residual quantiles and slopes, its collision regime, the
trapped outcome (:func:`gather_component`); the moments and the restitution factors that move the draw to the
incident state (:func:`gather_cell`); both as one tuple, the gathered record (:func:`gather`).

Its block form (:mod:`surrogate.kernels.block`) is the G_* fields of a float64
array, in the order of the tuple; :func:`gather_block` is this stage for a
block of the pipeline (:mod:`surrogate.kernels.pipeline`).
"""

import numba
import numpy as np

from direct_model.elementary import fma
from surrogate.kernels.block import BLOCK, field, fields6, put3, put6, uniforms
from surrogate.kernels.fastmath import clamp_index, restitution_at
from surrogate.kernels.frame import is_valid
from surrogate.kernels.layout import (CELL_INV_SD, CELL_MEAN, CELL_P_TRAPPED, CELL_SD, CELL_SIZE, ROW_LOC, ROW_REGIME,
                                      ROW_SCALE, ROW_SHAPE, ROW_SLOPE)
from surrogate.kernels.locate import I_DRAWN, I_ROW, cell_at, level_offset
from surrogate.kernels.memory import load, load15
from surrogate.kernels.options import JIT, KERNEL


@numba.njit(inline="always", **JIT)
def _quantile(data, cell, row, k, u):
    """loc + scale · S(u) of chain variable k in the component at offset ``row`` of cell number ``cell``: the
    residual shape S interpolated linearly between the levels i, i + 1 that u falls between (one multiply,
    one floor)."""
    r = data.clusters
    levels = data.n_levels - 1
    t = u * levels
    i = clamp_index(int(t), levels - 1)
    at = level_offset(data, cell, k, i) + int(load(r, row + ROW_SHAPE + k))
    lo, hi = np.float64(load(data.dictionary, at)), np.float64(load(data.dictionary, at + data.n_dictionary))
    return fma(np.float64(load(r, row + ROW_SCALE + k)), fma(t - i, hi - lo, lo), np.float64(load(r, row + ROW_LOC + k)))


@numba.njit(inline="always", **JIT)
def _quantiles(data, cell, row, u):
    """The residual quantiles (:func:`_quantile`) of the six chain variables at u[5:11]."""
    return (_quantile(data, cell, row, 0, u[5]), _quantile(data, cell, row, 1, u[6]),
            _quantile(data, cell, row, 2, u[7]), _quantile(data, cell, row, 3, u[8]),
            _quantile(data, cell, row, 4, u[9]), _quantile(data, cell, row, 5, u[10]))


@numba.njit(inline="always", **JIT)
def _alpha1_terms(data, below, wa, drawn):
    """What moves a state drawn from cell ``drawn`` to the incident α1: (ratio, m_cell, m), six-tuples in
    state order, for x' = m + (x − m_cell) · ratio (:func:`surrogate.kernels.arithmetic._moved`).

    m and σ are interpolated linearly in α1 (weight wa of the upper
    neighbour) between cell ``below`` and the next α1 up, at the drawn speed;
    ratio = σ/σ_cell (1 where σ_cell = 0) and m_cell are those of cell
    ``drawn``. With wa = 0 the cell above is not read (``below`` may be in
    the last α1 row).
    """
    cells = data.cells
    lo, here = below * CELL_SIZE, drawn * CELL_SIZE
    hi = (below + data.n_speed) * CELL_SIZE if wa > 0.0 else lo
    return (_three_terms(cells, lo, hi, here, wa, 0) + _three_terms(cells, lo, hi, here, wa, 3))


@numba.njit(inline="always", **JIT)
def _three_terms(cells, lo, hi, here, wa, k):
    """:func:`_alpha1_terms` of state variables k, k + 1, k + 2 as (ratio, m_cell, m) triples."""
    return (_term(cells, lo, hi, here, wa, k), _term(cells, lo, hi, here, wa, k + 1),
            _term(cells, lo, hi, here, wa, k + 2))


@numba.njit(inline="always", **JIT)
def _term(cells, lo, hi, here, wa, k):
    """(ratio, m_cell, m) of state variable k (:func:`_alpha1_terms`)."""
    return moved_term(cells, lo + k, hi + k, here + k, wa, CELL_MEAN, CELL_SD, CELL_INV_SD)


@numba.njit(inline="always", **JIT)
def moved_term(cells, lo, hi, here, wa, at_mean, at_sd, at_inv_sd):
    """(ratio, m_cell, m) of a variable whose mean, sd and 1/sd sit at offsets ``at_*`` from a cell record's
    start in ``cells``: the records of the α1 below (``lo``), above (``hi``) and the drawn cell (``here``)
    (:func:`_alpha1_terms`)."""
    sd = fma(wa, load(cells, hi + at_sd), (1.0 - wa) * load(cells, lo + at_sd))
    inv_sd = load(cells, here + at_inv_sd)
    mean = fma(wa, load(cells, hi + at_mean), (1.0 - wa) * load(cells, lo + at_mean))
    return sd * inv_sd if inv_sd > 0.0 else 1.0, load(cells, here + at_mean), mean


@numba.njit(inline="always", **JIT)
def restitution_factors(data, jv, wv, iv):
    """The wall's restitution factor f (exp(−k V^p) for the exponential law) at the incident speed
    V = V_jv + wv (V_jv+1 − V_jv) and at the drawn grid speed V_iv."""
    return restitution_at(data.restitution_pieces, data.n_pieces, jv, wv), np.float64(load(data.speed_restitution, iv))


@numba.njit(inline="always", **JIT)
def is_trapped(data, drawn, u3):
    """Whether u[3] draws the trapped outcome in cell number ``drawn``."""
    return u3 < load(data.cells, drawn * CELL_SIZE + CELL_P_TRAPPED)


@numba.njit(inline="always", **JIT)
def gather_component(data, drawn, row, u):
    """What a draw reads from its component (at offset ``row`` in cell number ``drawn``,
    :func:`surrogate.kernels.locate.component`):
    (residual quantiles at u[5:11], the 15 slopes, regime, trapped flag (1.0 or 0.0), mirror uniform u[11])."""
    r = data.clusters
    trapped = 1.0 if is_trapped(data, drawn, u[3]) else 0.0
    return (_quantiles(data, drawn, row, u), load15(r, row + ROW_SLOPE, 1), np.float64(load(r, row + ROW_REGIME)),
            trapped, u[11])


@numba.njit(inline="always", **JIT)
def gather_cell(data, cell):
    """What a draw reads from its cell and the grid to move it to the incident state: (wa, wv, the six α1
    ratios, (m_cell, m) of α2, s and Ω_z (:func:`_alpha1_terms`; the other variables are centred), the
    restitution factors at the incident and the drawn speed)."""
    drawn, below, wa, jv, wv, iv = cell
    f_target, f_grid = restitution_factors(data, jv, wv, iv)
    t = _alpha1_terms(data, below, wa, drawn)
    return (wa, wv, (t[0][0], t[1][0], t[2][0], t[3][0], t[4][0], t[5][0]), t[0][1:] + t[2][1:] + t[5][1:],
            f_target, f_grid)


@numba.njit(inline="always", **JIT)
def gather(data, cell, row, u):
    """Every table value a draw in ``cell`` (:func:`surrogate.kernels.locate.locate`) with component ``row`` needs:
    :func:`gather_component` + :func:`gather_cell`, the arguments of :func:`surrogate.kernels.arithmetic.arithmetic`."""
    return gather_component(data, cell[0], row, u) + gather_cell(data, cell)


# -- the gathered record of a block ------------------------------------------------------------------

G_Q, G_SLOPE, G_REGIME, G_TRAPPED, G_MIRROR = 0, 6, 21, 22, 23     # gather_component: 6 quantiles, 15 slopes, ...
G_WA, G_WV, G_RATIO, G_SHIFT, G_F_TARGET, G_F_GRID = 24, 25, 26, 32, 38, 39     # gather_cell: ..., 6 ratios, 6 shifts
GATHERED_FIELDS = 40


@numba.njit(inline="always", **JIT)
def gathered_at(g, b):
    """Particle b's gathered record, as :func:`gather` returns it."""
    return (fields6(g, G_Q, b), load15(g, G_SLOPE * BLOCK + b, BLOCK), field(g, G_REGIME, b), field(g, G_TRAPPED, b),
            field(g, G_MIRROR, b), field(g, G_WA, b), field(g, G_WV, b), fields6(g, G_RATIO, b),
            fields6(g, G_SHIFT, b), field(g, G_F_TARGET, b), field(g, G_F_GRID, b))


@numba.njit(**KERNEL)
def gather_block(data, ub, m, fr, index, weights, g):
    """Stage 2 for the m particles of a located block (uniforms ``ub``, frame records ``fr``, cell records
    ``index``, ``weights``): their gathered records into ``g``."""
    for b in range(m):
        if is_valid(fr, b):
            _put_component(g, b, gather_component(data, field(index, I_DRAWN, b), field(index, I_ROW, b),
                                                  uniforms(ub, b)))
    for b in range(m):      # no branch: SIMD across the block (invalid rows read cell 0)
        _put_cell_values(g, b, gather_cell(data, cell_at(index, weights, b)))


@numba.njit(inline="always", **JIT)
def _put_component(g, b, values):
    q, slopes, regime, trapped, mirror = values
    put6(g, G_Q, b, q)
    put6(g, G_SLOPE, b, slopes[:6])
    put6(g, G_SLOPE + 6, b, slopes[6:12])
    put3(g, G_SLOPE + 12, b, slopes[12:])
    put3(g, G_REGIME, b, (regime, trapped, mirror))


@numba.njit(inline="always", **JIT)
def _put_cell_values(g, b, values):
    wa, wv, ratio, shift, f_target, f_grid = values
    g[G_WA * BLOCK + b], g[G_WV * BLOCK + b] = wa, wv
    put6(g, G_RATIO, b, ratio)
    put6(g, G_SHIFT, b, shift)
    g[G_F_TARGET * BLOCK + b], g[G_F_GRID * BLOCK + b] = f_target, f_grid
