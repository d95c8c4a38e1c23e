"""One draw from a table in the local frame: grid look-up, table reads, the chain, the move to the incident state.

These are plain functions over the arrays of a table (``table.kernel_data``,
a named tuple of flat arrays and their sizes, :class:`surrogate.table.KernelData`)
and pre-drawn uniforms. Every draw consumes exactly :data:`U_PER_DRAW`
uniforms from [0, 1)::

    u[0] shape from the mix        u[1] α1 neighbour       u[2] speed neighbour
    u[3] trapped or not            u[4] mixture component  u[5:11] the six chain variables
    u[11] mirror sign              u[12] in-wall axis at normal impact (:func:`surrogate.frame.impact_frame`)

Between grid points the sampler uses stochastic interpolation: the cell of the
neighbour at x_{j+1} is used with probability w = (x − x_j)/(x_{j+1} − x_j), as
Monte Carlo transport codes do between incident-energy points; a multimodal
law stays multimodal (no averaging of quantiles). By default (``scaled``) the
state drawn from the neighbour is then moved to the incident state:

* in α1, variable by variable, to the mean and standard deviation interpolated
  linearly between the two neighbouring α1 (like the unit-base interpolation
  of transport codes, which stretches a neighbour's secondary law to the
  interpolated range);
* in |V⁻|, by the wall's restitution law (:func:`_to_speed`), with a law that
  depends on the drawn cluster's collision regime: the velocity change and
  the spin of a rebound of one or two collisions scale with 1 + a(V), the
  normal rebound velocity of a longer one with a(V).

The hot path calls no libm function (:mod:`surrogate.trig`,
:mod:`surrogate.restitution`) and branches only where the outcome is
predictable (trapped, outside the grid); choices that vary from draw to draw
(neighbour cell, alias, regime, mirror sign, quadrant) are selects.

Frame and units: the model's lab frame (wall y = 0, normal +Y, impact plane
XY, α1 from the wall); angles in radians except α1 (degrees), V⁺ in units of
|V⁻|, Ω in units of |V⁻|/a. The global-frame kernels built on these are in
:mod:`surrogate.kernels`.
"""

import math

import numba
import numpy as np

from data_schema.samples import STATUS_REBOUNDED, STATUS_TRAPPED
from surrogate.fused import fma
from surrogate.jit import JIT, KERNEL
from surrogate.memory import load, prefetch
from surrogate.restitution import restitution_at
from surrogate.table import (AXIS_GRID, AXIS_INV_STEP, AXIS_ORIGIN, CELL_INV_SD, CELL_MEAN, CELL_P_TRAPPED, CELL_SD,
                             CELL_SIZE, ROW_ALIAS, ROW_ALIAS_PROB, ROW_LOC, ROW_REGIME, ROW_SCALE, ROW_SHAPE,
                             ROW_SIZE, ROW_SLOPE)
from surrogate.trig import sincos


U_PER_DRAW = 13


@numba.njit(inline="always", **JIT)
def locate(axis, n, x):
    """(j, w): grid interval [g_j, g_{j+1}] holding x and the weight of g_{j+1} (O(1)).

    ``axis`` is the record of an n-point grid (:func:`surrogate.table.axis_record`).
    Outside the grid, the nearest edge with weight 0 or 1; a one-point grid gives (0, 0).
    """
    if n == 1:
        return 0, 0.0
    inverse = AXIS_GRID + n     # where the inverse spacings start
    lookup = inverse + n - 1    # where the look-up indices start
    k = int((x - load(axis, AXIS_ORIGIN)) * load(axis, AXIS_INV_STEP))
    k = min(max(k, 0), axis.shape[0] - 1 - lookup)
    j = int(load(axis, lookup + k))
    j += (x >= load(axis, AXIS_GRID + j + 1)) & (j < n - 2)     # one-step correction, no branch to mispredict
    w = (x - load(axis, AXIS_GRID + j)) * load(axis, inverse + j)
    return j, min(max(w, 0.0), 1.0)


@numba.njit(inline="always", **JIT)
def _row(data, cell, c):
    """Offset in ``data.clusters`` of component c's row in cell number ``cell``."""
    return (cell * data.n_clusters + c) * ROW_SIZE


@numba.njit(inline="always", **JIT)
def _level(data, cell, k, i):
    """Offset in ``data.dictionary`` of level i of chain variable k's residual shapes in cell number ``cell``
    (the n_dictionary shapes follow)."""
    return ((cell * 6 + k) * data.n_levels + i) * data.n_dictionary


@numba.njit(inline="always", **JIT)
def _first_row(data, cell, u4):
    """(t, c, offset of row c): the component u4 picks in cell number ``cell`` before the alias table,
    c = ⌊t⌋ with t = u4 · n_clusters."""
    t = u4 * data.n_clusters
    c = min(int(t), data.n_clusters - 1)
    return t, c, _row(data, cell, c)


@numba.njit(inline="always", **JIT)
def _component(data, cell, u4):
    """Offset in ``data.clusters`` of the mixture component u4 draws in cell number ``cell``: Walker's
    alias table (one multiply, one floor, one compare; the alias sits in the row's first cache line)."""
    t, c, row = _first_row(data, cell, u4)
    alias = int(load(data.clusters, row + ROW_ALIAS))
    c = alias if t - c >= load(data.clusters, row + ROW_ALIAS_PROB) else c
    return _row(data, cell, c)


@numba.njit(inline="always", **JIT)
def _three(x, at, step):
    """x[at + j·step] for j = 0, 1, 2, as float64."""
    return np.float64(load(x, at)), np.float64(load(x, at + step)), np.float64(load(x, at + 2 * step))


@numba.njit(inline="always", **JIT)
def _six(x, at, step):
    """x[at + j·step] for j = 0 … 5, as float64."""
    return _three(x, at, step) + _three(x, at + 3 * step, step)


@numba.njit(inline="always", **JIT)
def _fifteen(x, at, step):
    """x[at + j·step] for j = 0 … 14, as float64 (the slopes of a component row)."""
    return _six(x, at, step) + _six(x, at + 6 * step, step) + _three(x, at + 12 * step, step)


@numba.njit(inline="always", **JIT)
def _quantile(data, cell, row, k, u):
    """loc + scale · S(u) of chain variable k in the component at offset ``row`` of cell number ``cell``: the
    residual shape S interpolated linearly between the levels i, i + 1 that u falls between (one multiply,
    one floor)."""
    r = data.clusters
    levels = data.n_levels - 1
    t = u * levels
    i = min(int(t), levels - 1)
    at = _level(data, cell, k, i) + int(load(r, row + ROW_SHAPE + k))
    lo, hi = np.float64(load(data.dictionary, at)), np.float64(load(data.dictionary, at + data.n_dictionary))
    return fma(np.float64(load(r, row + ROW_SCALE + k)), fma(t - i, hi - lo, lo), np.float64(load(r, row + ROW_LOC + k)))


@numba.njit(inline="always", **JIT)
def _quantiles(data, cell, row, u):
    """The residual quantiles (:func:`_quantile`) of the six chain variables at u[5:11]."""
    return (_quantile(data, cell, row, 0, u[5]), _quantile(data, cell, row, 1, u[6]),
            _quantile(data, cell, row, 2, u[7]), _quantile(data, cell, row, 3, u[8]),
            _quantile(data, cell, row, 4, u[9]), _quantile(data, cell, row, 5, u[10]))


@numba.njit(inline="always", **JIT)
def _chain(q, b):
    """The folded state (α2, |β2|, s, Ω_x, Ω_y, Ω_z) of one component from its residual quantiles ``q``.

    Chain variable k (α2, |β2|, s, Ω_z, Ω_x, Ω_y) is its residual quantile
    shifted by the component's slopes ``b`` on the variables already drawn
    (x_k on x_i at b[k(k−1)/2 + i]), then folded into the physical ranges
    (:func:`_folded`).
    """
    # each x_k gathers its terms in the order the x_i become available: one fused multiply-add after x_{k−1}
    x0 = q[0]
    x1 = fma(b[0], x0, q[1])
    x2 = fma(b[2], x1, fma(b[1], x0, q[2]))
    x3 = fma(b[5], x2, fma(b[4], x1, fma(b[3], x0, q[3])))
    x4 = fma(b[9], x3, fma(b[8], x2, fma(b[7], x1, fma(b[6], x0, q[4]))))
    x5 = fma(b[14], x4, fma(b[13], x3, fma(b[12], x2, fma(b[11], x1, fma(b[10], x0, q[5])))))
    return _folded(x0, x1, x2, x4, x5, x3)


@numba.njit(inline="always", **JIT)
def _folded(alpha2, beta2, s, wx, wy, wz):
    """The state (state order) reflected into the range of a rebound: α2 into [0, π], β2 below π/2, s into [0, 1].

    The linear shifts of the chain and of the α1 move can step outside by a
    hair (up to 4e-3 of the draws at a point between the grid points of a
    coarse 3 × 3 table, 1.5e-4 on the default table). Reflected at the edge, such a draw stays a rebound that
    leaves the wall (V⁺·n = s sin α2 cos β2 > 0) and gains no kinetic energy
    (s ≤ 1: tables are built with Ω⁻ = 0, so |V⁺| ≤ |V⁻|); a cap would put it
    on the edge, where s = 0 or β2 = π/2 gives V⁺·n = 0 and s = 1 an elastic
    rebound. β2 < 0 is left as drawn: it is a valid state (the mirror sign is
    drawn afterwards).
    """
    alpha2, s = abs(alpha2), abs(s)
    return (2.0 * math.pi - alpha2 if alpha2 > math.pi else alpha2, math.pi - beta2 if beta2 > 0.5 * math.pi else beta2,
            2.0 - s if s > 1.0 else s, wx, wy, wz)


@numba.njit(inline="always", **JIT)
def draw_folded(data, cell, u):
    """The folded state (α2, |β2|, s, Ω_x, Ω_y, Ω_z) of cell number ``cell`` from u[4:11], and its regime.

    Representation (data_schema.table): u[4] picks the mixture component with
    the Walker alias table (:func:`_component`), u[5:11] the residual
    quantiles (:func:`_quantiles`) of the chain (:func:`_chain`). Arrays are read by scalar indices
    only (no views, so no reference counting on the hot path).
    """
    r = data.clusters
    row = _component(data, cell, u[4])
    state = _chain(_quantiles(data, cell, row, u), _fifteen(r, row + ROW_SLOPE, 1))
    return state + (np.float64(load(r, row + ROW_REGIME)),)


@numba.njit(inline="always", **JIT)
def _alpha1_terms(data, below, wa, drawn):
    """What moves a state drawn from cell ``drawn`` to the incident α1: (ratio, m_cell, m), six-tuples in
    state order, for x' = m + (x − m_cell) · ratio (:func:`_moved`).

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
    sd = fma(wa, load(cells, hi + CELL_SD + k), (1.0 - wa) * load(cells, lo + CELL_SD + k))
    inv_sd = load(cells, here + CELL_INV_SD + k)
    mean = fma(wa, load(cells, hi + CELL_MEAN + k), (1.0 - wa) * load(cells, lo + CELL_MEAN + k))
    return sd * inv_sd if inv_sd > 0.0 else 1.0, load(cells, here + CELL_MEAN + k), mean


@numba.njit(inline="always", **JIT)
def _moved(state, terms):
    """The folded ``state`` of a draw moved to the incident α1 with the :func:`_alpha1_terms` ``terms``,
    variable by variable, like the unit-base interpolation of transport codes, then folded again. The
    centred variables (β2, Ω_x, Ω_y: mean 0 by the mirror symmetry) are only scaled."""
    return _folded(_shifted(state[0], terms[0]), state[1] * terms[1][0], _shifted(state[2], terms[2]),
                   state[3] * terms[3][0], state[4] * terms[4][0], _shifted(state[5], terms[5]))


@numba.njit(inline="always", **JIT)
def _shifted(x, term):
    """m + (x − m_cell) · ratio."""
    ratio, mean_cell, mean = term
    return fma(x - mean_cell, ratio, mean)


@numba.njit(inline="always", **JIT)
def _velocity(alpha2, beta2, s):
    """V⁺ (local frame, units of |V⁻|) of a rebound at (α2, β2) with speed ratio s."""
    sb, cb = sincos(beta2)
    sa, ca = sincos(alpha2)
    scb = s * cb
    return scb * ca, scb * sa, s * sb


@numba.njit(inline="always", **JIT)
def _restitution_factors(data, jv, wv, iv):
    """exp(−k V^p) at the incident speed V = V_jv + wv (V_jv+1 − V_jv) and at the drawn grid speed V_iv."""
    return restitution_at(data.restitution_pieces, data.n_pieces, jv, wv), np.float64(load(data.speed_restitution, iv))


@numba.njit(inline="always", **JIT)
def _to_speed(regime, f_target, f_grid, cos_alpha1, sin_alpha1, vx, vy, vz, wx, wy, wz):
    """A rebound drawn at grid speed V_iv, moved to the incident speed V; returns (vx, vy, vz, wx, wy, wz).

    ``f_target``, ``f_grid``: exp(−k V^p) at V and at V_iv
    (:func:`_restitution_factors`). Local frame, V⁺ in units of |V⁻|, Ω⁺ in
    units of |V⁻|/a. With a(V) = 1 − (1 − exp(−k V^p)) sin α1, the normal
    restitution of the wall law for a contact point moving like the centre
    of mass:

    * regime 0 (at most two collisions): the velocity change V⁺ − V⁻ and the
      spin Ω⁺ are multiplied by (1 + a(V))/(1 + a(V_iv)). For one
      frictionless collision this is exact: the impulse is (1 + a) times the
      incident normal velocity over the contact's effective inverse mass.
    * regime 1 (more collisions): the normal rebound velocity is multiplied
      by a(V)/a(V_iv), the rest kept (the last, slow contacts set it).

    Measured against the direct model between grid speeds 25–50 m/s apart
    (docs/design/table_representation.md): either law alone fails near
    normal impact for some shape (classifier accuracy up to 0.79), the pair
    by regime stays ≤ 0.54. A normal velocity the shift would reverse is
    reflected (the rebound must leave the wall).
    """
    a_target = 1.0 - (1.0 - f_target) * sin_alpha1
    a_grid = 1.0 - (1.0 - f_grid) * sin_alpha1
    # both laws computed, the regime's picked by selects: the regime varies from draw to draw, a branch
    # on it would be mispredicted often
    few = regime == 0.0
    f = (1.0 + a_target) / (1.0 + a_grid) if few else a_target / a_grid
    g = f if few else 1.0       # factor of the spin and of V⁺ − V⁻ off the normal
    vx_few, vy_few = fma(f, vx - cos_alpha1, cos_alpha1), abs(fma(f, vy + sin_alpha1, -sin_alpha1))
    return vx_few if few else vx, vy_few if few else vy * f, g * vz, g * wx, g * wy, g * wz


@numba.njit(inline="always", **JIT)
def _cell(data, mix_cdf, alpha1, speed, u):
    """The cell a draw reads: (drawn, below, wa, jv, wv, iv).

    Shape from u[0] and the mix; grid intervals (ja, jv) with the weights of
    their upper points (wa, wv); the neighbour cell (ia, iv) drawn with those
    weights from u[1], u[2] (stochastic interpolation). ``drawn`` is the
    number of cell (shape, ia, iv) (:class:`surrogate.table.KernelData`),
    ``below`` that of (shape, ja, iv), the lower α1 neighbour at the drawn speed.
    """
    shape = 0
    for k in range(mix_cdf.shape[0] - 1):     # the first k with u[0] < cdf[k], without data-dependent branches
        shape += u[0] >= mix_cdf[k]
    ja, wa = locate(data.alpha1_axis, data.n_alpha1, alpha1)
    jv, wv = locate(data.speed_axis, data.n_speed, speed)
    ia = ja + (u[1] < wa)       # integer + comparison: no branch to mispredict
    iv = jv + (u[2] < wv)
    below = (shape * data.n_alpha1 + ja) * data.n_speed + iv
    return below + (ia - ja) * data.n_speed, below, wa, jv, wv, iv


@numba.njit(inline="always", **JIT)
def draw_velocity(data, mix_cdf, alpha1, speed, u, scaled=True):
    """One reflected state at (α1 deg, |V⁻| m/s) as local-frame vectors.

    ``mix_cdf`` is the cumulative shape weights in the table's shape order
    (last entry 1). Returns (status, V⁺_x, V⁺_y, V⁺_z, Ω_x, Ω_y, Ω_z) with
    V⁺ in units of |V⁻| and Ω⁺ in units of |V⁻|/a; NaN for a trapped
    particle. Outside the table's grid the law at the nearest grid edge is used.

    Between grid points the cell of a neighbour is drawn with its
    interpolation weight (stochastic interpolation). With ``scaled`` the
    draw is then moved to the incident state: in α1 to the interpolated
    means and standard deviations (:func:`_moved`), in |V⁻| by the wall's
    restitution law (:func:`_to_speed`).
    """
    cell = _cell(data, mix_cdf, alpha1, speed, u)
    _hint_draw(data, cell, u)
    sin_a1, cos_a1 = sincos(math.radians(alpha1))
    return _draw_in_cell(data, cell, cos_a1, sin_a1, u, scaled)


@numba.njit(inline="always", **JIT)
def _draw_in_cell(data, cell, cos_alpha1, sin_alpha1, u, scaled):
    """:func:`draw_velocity` once its cell (:func:`_cell`) is known; α1 given by its cosine and sine."""
    drawn, below, wa, jv, wv, iv = cell
    if u[3] < load(data.cells, drawn * CELL_SIZE + CELL_P_TRAPPED):
        return STATUS_TRAPPED, np.nan, np.nan, np.nan, np.nan, np.nan, np.nan
    folded = draw_folded(data, drawn, u)
    state, regime = folded[:6], folded[6]
    if scaled and wa > 0.0:
        state = _moved(state, _alpha1_terms(data, below, wa, drawn))
    alpha2, beta2, s, wx, wy, wz = state
    vx, vy, vz = _velocity(alpha2, beta2, s)
    if scaled and wv > 0.0:
        f_target, f_grid = _restitution_factors(data, jv, wv, iv)
        vx, vy, vz, wx, wy, wz = _to_speed(regime, f_target, f_grid, cos_alpha1, sin_alpha1, vx, vy, vz, wx, wy, wz)
    return _mirrored(u[11], vx, vy, vz, wx, wy, wz)


@numba.njit(inline="always", **JIT)
def _mirrored(u, vx, vy, vz, wx, wy, wz):
    """(STATUS_REBOUNDED, state) with the mirror symmetry Z → −Z applied when u < 1/2."""
    mirror = -1.0 if u < 0.5 else 1.0
    return STATUS_REBOUNDED, vx, vy, mirror * vz, mirror * wx, mirror * wy, wz


@numba.njit(**KERNEL)
def draw_local(data, mix_cdf, alpha1, speed, u, scaled=True):
    """One reflected state at (α1 deg, |V⁻| m/s) in the local frame: (status, α2, β2, s, Ω_x, Ω_y, Ω_z).

    Angles in radians, s = |V⁺|/|V⁻|, Ω in units of |V⁻|/a; the state is NaN
    for a trapped particle. See :func:`draw_velocity` (same arguments).
    """
    status, vx, vy, vz, wx, wy, wz = draw_velocity(data, mix_cdf, alpha1, speed, u, scaled)
    if status != STATUS_REBOUNDED:
        return status, np.nan, np.nan, np.nan, np.nan, np.nan, np.nan
    s = math.sqrt(vx * vx + vy * vy + vz * vz)
    return status, math.atan2(vy, vx), math.asin(vz / s) if s > 0.0 else 0.0, s, wx, wy, wz


@numba.njit(inline="always", **JIT)
def _hint_draw(data, cell, u):
    """Cache hints (:func:`surrogate.memory.prefetch`) for the table reads of a draw in ``cell`` that
    the uniforms alone locate, so that they are all in flight at once: the component row u[4] picks
    (before its alias is resolved) and the residual-shape levels u[5:11] pick (the dictionary is
    level-major, so these lines do not depend on the row). Without them the row and then the
    dictionary would each wait for memory in turn. (Hints for the small arrays, the trapped
    probabilities and the moments, measured slower: they stay cached.)"""
    _hint_row(data, _first_row(data, cell[0], u[4])[2])
    _hint_levels(data, cell[0], u)


@numba.njit(inline="always", **JIT)
def _hint_row(data, row):
    """Cache hints for the component row at offset ``row``: its three cache lines (144 bytes, the start
    16-byte aligned)."""
    for j in range(0, ROW_SIZE, 16):
        prefetch(data.clusters, (row + j,))


@numba.njit(inline="always", **JIT)
def _hint_levels(data, drawn, u):
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
    """Cache hints for the two residual-shape levels of chain variable k that u picks (:func:`_quantile`)."""
    levels = data.n_levels - 1
    level = _level(data, drawn, k, min(int(u * levels), levels - 1))
    prefetch(data.dictionary, (level,))
    prefetch(data.dictionary, (level + data.n_dictionary,))
