"""Numba kernels of the runtime sampler: O(1) work per reflected state.

These are plain functions over the arrays of a table (``table.kernel_data``, a
named tuple of flat arrays and their sizes) and pre-drawn uniforms, so a flow
solver can call them from its own ``@njit`` loop. Every draw consumes exactly
:data:`U_PER_DRAW` uniforms from [0, 1)::

    u[0] shape from the mix        u[1] α1 neighbour       u[2] speed neighbour
    u[3] trapped or not            u[4] mixture component  u[5:11] the six chain variables
    u[11] mirror sign              u[12] in-wall axis at normal impact

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

Entry points: :func:`rebound_tuple` (one particle, global frame, vectors as
tuples: the form for a solver's per-hit loop), :func:`rebound` (the same on
(3,) arrays), :func:`rebound_many` (many particles, one thread, their table
reads overlapped; :func:`rebound_many_rng` draws their uniforms from 32 SIMD
lanes, :func:`rebound_uniforms` returns those), :func:`rebound_batch`
(parallel; :func:`rebound_batch_rng` draws its uniforms), :func:`draw_local`
and :func:`draw_velocity` (local frame; :func:`draw_local_batch` and
:func:`draw_local_batch_rng` parallel).

The hot path calls no libm function (:mod:`surrogate.trig`,
:mod:`surrogate.restitution`) and branches only where the outcome is
predictable (trapped, outside the grid); choices that vary from draw to draw
(neighbour cell, alias, regime, mirror sign, quadrant) are selects.

Frames and units: the local frame is the model's lab frame (wall y = 0,
normal +Y, impact plane XY, α1 from the wall); angles in radians except α1
(degrees), Ω in units of |V⁻|/a locally. The global kernel returns V⁺ in m/s
and Ω⁺ in rad/s.
"""

import math

import numba
import numpy as np

from data_schema.samples import STATUS_REBOUNDED, STATUS_TRAPPED
from surrogate.fused import fma
from surrogate.memory import load, prefetch
from surrogate.restitution import restitution_at
from surrogate.rng import ROWS_PER_STREAM, fill_lanes, n_streams, seed_lanes
from surrogate.table import (AXIS_GRID, AXIS_INV_STEP, AXIS_ORIGIN, CELL_INV_SD, CELL_MEAN, CELL_P_TRAPPED, CELL_SD,
                             CELL_SIZE, ROW_ALIAS, ROW_ALIAS_PROB, ROW_LOC, ROW_REGIME, ROW_SCALE, ROW_SHAPE,
                             ROW_SIZE, ROW_SLOPE)
from surrogate.trig import atan2_first_quadrant, sincos

U_PER_DRAW = 13
STATUS_INVALID = -1     # returned by :func:`rebound` for an incident state that does not hit the wall
JIT = dict(cache=True, nogil=True, fastmath=False, error_model="numpy")
# The per-particle kernels allocate nothing, so they are compiled without numba's reference
# counting (_nrt=False): with it, every array taken from the table tuple or sliced from a row
# costs an atomic increment and decrement that numba cannot prune across branches (measured:
# the cell look-up alone 83 ns with, 15 ns without). Callers keep their own reference counting.
KERNEL = dict(JIT, _nrt=False)


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
    (x_k on x_i at b[k(k−1)/2 + i]). α2 is reflected into [0, π] and |β2|
    capped at π/2 (the linear shifts can step outside by a hair, ~1e-4 of
    draws).
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
    """α2 reflected into [0, π], β2 capped at π/2, s at 0 (state order)."""
    alpha2 = abs(alpha2)
    return 2.0 * math.pi - alpha2 if alpha2 > math.pi else alpha2, min(beta2, 0.5 * math.pi), max(s, 0.0), wx, wy, wz


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
    means and standard deviations (:func:`_rescaled`), in |V⁻| by the wall's
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
def impact_frame(V, n, u_axis):
    """Impact frame of V on a wall of unit normal n.

    ex is the direction of the tangential part of V (uniform in the wall plane,
    from ``u_axis``, at normal impact: tangential part below 1e-12 |V|); the
    frame is (ex, n, ez = ex × n). Returns (α1 in degrees, |V|, cos α1, sin α1,
    ex, ez) with ex and ez as 3-tuples.
    """
    vn = _dot(V, n)
    tx, ty, tz = fma(-vn, n[0], V[0]), fma(-vn, n[1], V[1]), fma(-vn, n[2], V[2])
    vt = math.sqrt(fma(tx, tx, fma(ty, ty, tz * tz)))
    speed = math.sqrt(fma(vn, vn, vt * vt))
    if vt > 1e-12 * speed:
        inv = 1.0 / vt
        ex0, ex1, ex2 = tx * inv, ty * inv, tz * inv
    else:
        # orthonormal basis (p, q) of the wall plane: p = n × e_k with e_k the axis least aligned with n
        if abs(n[0]) <= abs(n[1]) and abs(n[0]) <= abs(n[2]):
            px, py, pz = 0.0, n[2], -n[1]
        elif abs(n[1]) <= abs(n[2]):
            px, py, pz = -n[2], 0.0, n[0]
        else:
            px, py, pz = n[1], -n[0], 0.0
        pn = math.sqrt(px * px + py * py + pz * pz)
        px, py, pz = px / pn, py / pn, pz / pn
        qx, qy, qz = n[1] * pz - n[2] * py, n[2] * px - n[0] * pz, n[0] * py - n[1] * px
        s, c = sincos(2.0 * math.pi * u_axis)
        ex0, ex1, ex2 = c * px + s * qx, c * py + s * qy, c * pz + s * qz
    ez = (ex1 * n[2] - ex2 * n[1], ex2 * n[0] - ex0 * n[2], ex0 * n[1] - ex1 * n[0])
    inv_speed = 1.0 / speed
    return (math.degrees(atan2_first_quadrant(-vn, vt)), speed, vt * inv_speed, -vn * inv_speed, (ex0, ex1, ex2), ez)


@numba.njit(**KERNEL)
def rebound(data, mix_cdf, V, n, a, u, V_out, W_out, scaled=True):
    """Reflected state of one particle in the global frame; returns the status.

    Parameters
    ----------
    data : ``table.kernel_data``.
    mix_cdf : cumulative shape weights (table shape order).
    V : (3,) incident velocity, m/s; must move into the wall (V·n < 0).
    n : (3,) unit wall normal pointing into the gas (not checked here).
    a : particle half-size (half its largest extent), m.
    u : (U_PER_DRAW,) uniforms in [0, 1).
    V_out, W_out : (3,) outputs: V⁺ in m/s and Ω⁺ in rad/s (NaN unless rebounded).
    scaled : between grid points, move the draw to the incident state
        (default; :func:`draw_velocity`); False: plain stochastic interpolation.

    Returns STATUS_REBOUNDED, STATUS_TRAPPED, or STATUS_INVALID when V does not
    move into the wall (V·n ≥ 0, zero or non-finite). The impact frame is ex
    (tangential direction of V), n, ez = ex × n; the local draw is rotated back
    into the global frame. The mirror symmetry of the model is applied with a
    random sign inside :func:`draw_velocity`. An α1 or |V⁻| outside the table's
    grid uses the law at the nearest grid edge (check ``table.alpha1_range``
    and ``table.speed_range`` beforehand if that matters).
    """
    status, V_new, W_new = _rebound(data, mix_cdf, V, n, a, u, scaled)
    _store(V_new, W_new, V_out, W_out)
    return status


@numba.njit(**KERNEL)
def rebound_tuple(data, mix_cdf, V, n, a, u, scaled=True):
    """:func:`rebound` returning its outputs: (status, V⁺, Ω⁺), V⁺ in m/s and Ω⁺ in rad/s as 3-tuples.

    V and n may be 3-tuples or (3,) arrays. For a solver loop over particle
    arrays, passing ``(V[i, 0], V[i, 1], V[i, 2])`` rather than the row
    ``V[i]`` creates no array view, so the loop does no reference counting
    (numba's atomic counts on views cost tens of ns per call: bench_sampler.py, (b) and its variant).
    """
    return _rebound(data, mix_cdf, V, n, a, u, scaled)


_NAN3 = (np.nan, np.nan, np.nan)     # the V⁺ and Ω⁺ of a draw that did not rebound


@numba.njit(inline="always", **JIT)
def _rebound(data, mix_cdf, V, n, a, u, scaled):
    """:func:`rebound_tuple`."""
    if not _moves_into_wall(V, n):
        return STATUS_INVALID, _NAN3, _NAN3
    alpha1, speed, cos_a1, sin_a1, ex, ez = impact_frame(V, n, u[12])
    cell = _cell(data, mix_cdf, alpha1, speed, u)
    _hint_draw(data, cell, u)
    status, vx, vy, vz, wx, wy, wz = _draw_in_cell(data, cell, cos_a1, sin_a1, u, scaled)
    V_new, W_new = _to_global(status, vx, vy, vz, wx, wy, wz, speed, a, ex, n, ez)
    return status, V_new, W_new


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


@numba.njit(inline="always", **JIT)
def _moves_into_wall(V, n):
    """V·n < 0 and V finite."""
    return _dot(V, n) < 0.0 and math.isfinite(V[0] + V[1] + V[2])


@numba.njit(inline="always", **JIT)
def _dot(a, b):
    """a·b of two 3-vectors (tuples or arrays), the same bits wherever it is inlined."""
    return fma(a[0], b[0], fma(a[1], b[1], a[2] * b[2]))


@numba.njit(inline="always", **JIT)
def _store(V_new, W_new, V_out, W_out):
    for k in range(3):
        V_out[k] = V_new[k]
        W_out[k] = W_new[k]


@numba.njit(inline="always", **JIT)
def _to_global(status, vx, vy, vz, wx, wy, wz, speed, a, ex, n, ez):
    """A local draw (units |V⁻|, |V⁻|/a) as (V⁺ in m/s, Ω⁺ in rad/s) in the frame (ex, n, ez), 3-tuples;
    NaN unless rebounded."""
    if status != STATUS_REBOUNDED:
        return _NAN3, _NAN3
    w = speed / a
    v, o = (vx, vy, vz), (wx, wy, wz)
    return ((speed * _dot(v, (ex[0], n[0], ez[0])), speed * _dot(v, (ex[1], n[1], ez[1])),
             speed * _dot(v, (ex[2], n[2], ez[2]))),
            (w * _dot(o, (ex[0], n[0], ez[0])), w * _dot(o, (ex[1], n[1], ez[1])), w * _dot(o, (ex[2], n[2], ez[2]))))


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
    """:func:`rebound` for every row, one thread, by blocks of BLOCK particles.

    Same arguments as :func:`rebound_batch` and the same results, bit for bit,
    as calling :func:`rebound` row by row. Every array must have one row per
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
def _check_local_rows(alpha1, speed, out, status):
    """ValueError naming the first array of a local-frame batch that has not one row per incident state."""
    rows = alpha1.shape[0]
    for name, shape in (("speed", speed.shape), ("status", status.shape)):
        if shape[0] != rows:
            raise ValueError(_shape_error(name, shape, "(" + str(rows) + ",)", "alpha1"))
    if out.shape[0] != rows or out.shape[1] != 6:
        raise ValueError(_shape_error("out", out.shape, "(" + str(rows) + ", 6)", "alpha1"))


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
    """Block step 4 for particle b: what its draw reads from its component row (:func:`draw_folded`) and
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
    """Block step 5: :func:`_draw_in_cell` and :func:`_to_global` for particle b on its gathered fields, the
    same operations in the same order (so the same bits), with every branch a select."""
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


@numba.njit(parallel=True, **JIT)
def rebound_batch(data, mix_cdf, V, n, a, u, V_out, W_out, status, scaled=True):
    """:func:`rebound` for every row (parallel over chunks of :func:`rebound_many`); u has shape (N, U_PER_DRAW)."""
    _check_rows(V, n, a, V_out, W_out, status)
    _check_uniforms(u, V.shape[0], "V")
    for j in numba.prange(n_streams(V.shape[0])):
        lo, hi = _chunk(j, V.shape[0])
        _rebound_chunk(data, mix_cdf, V, n, a, u[lo:hi], _no_state(), V_out, W_out, status, scaled, lo, hi)


@numba.njit(parallel=True, **JIT)
def rebound_batch_rng(data, mix_cdf, V, n, a, states, V_out, W_out, status, scaled=True):
    """:func:`rebound_batch` drawing its own uniforms: the rows of chunk j (ROWS_PER_STREAM rows) from a
    copy of the xoshiro256+ state ``states[j]`` (:func:`surrogate.rng.stream_states`; ``states`` itself is
    not advanced), as :func:`rebound_many_rng` draws them (:func:`rebound_uniforms`). The draws are the
    same whatever the number of threads, and no (N, U_PER_DRAW) array of uniforms is held. ``states`` must
    have one row per chunk (ValueError)."""
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


@numba.njit(inline="always", **JIT)
def _chunk(j, n_rows):
    """Rows [lo, hi) of chunk j of a batch."""
    return j * ROWS_PER_STREAM, min((j + 1) * ROWS_PER_STREAM, n_rows)


@numba.njit(inline="always", **JIT)
def _rebound_chunk(data, mix_cdf, V, n, a, u, state, V_out, W_out, status, scaled, lo, hi):
    """:func:`rebound_many` on rows [lo, hi) with the uniforms ``u`` of those rows, or
    :func:`rebound_many_rng` with ``state``."""
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
