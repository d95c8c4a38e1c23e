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
reads overlapped), :func:`rebound_batch` (parallel; :func:`rebound_batch_rng`
draws its uniforms), :func:`draw_local` and :func:`draw_velocity` (local
frame; :func:`draw_local_batch` and :func:`draw_local_batch_rng` parallel).

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
from surrogate.rng import ROWS_PER_STREAM, fill_uniforms, n_streams
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
def _residual(data, cell, row, k, u):
    """loc + scale · S(u) of chain variable k in the component at offset ``row`` of cell number ``cell``:
    multiply, floor, linear interpolation."""
    rows, dic = data.clusters, data.dictionary
    levels = data.n_levels - 1
    t = u * levels
    i = min(int(t), levels - 1)
    at = _level(data, cell, k, i) + int(load(rows, row + ROW_SHAPE + k))
    lo = load(dic, at)
    quantile = fma(t - i, load(dic, at + data.n_dictionary) - lo, lo)
    return fma(load(rows, row + ROW_SCALE + k), quantile, load(rows, row + ROW_LOC + k))


@numba.njit(inline="always", **JIT)
def draw_folded(data, cell, u):
    """The folded state (α2, |β2|, s, Ω_x, Ω_y, Ω_z) of cell number ``cell`` from u[4:11], and its regime.

    Representation (data_schema.table): u[4] picks the mixture component c with
    the Walker alias table (one multiply, one floor, one compare); then chain
    variable k (α2, |β2|, s, Ω_z, Ω_x, Ω_y) is the component's residual quantile
    function at u[5 + k], shifted by the component's slopes on the variables
    already drawn (x_k on x_i at ROW_SLOPE + k(k−1)/2 + i). α2 is reflected
    into [0, π] and |β2| capped at π/2 (the linear shifts can step outside by
    a hair, ~1e-4 of draws). Arrays are read by scalar indices only (no views,
    so no reference counting on the hot path).
    """
    r = data.clusters
    n_clusters = data.n_clusters
    t = u[4] * n_clusters
    c = min(int(t), n_clusters - 1)
    row = _row(data, cell, c)
    alias = int(load(r, row + ROW_ALIAS))           # same cache line: read it always, select without a branch
    c = alias if t - c >= load(r, row + ROW_ALIAS_PROB) else c
    row = _row(data, cell, c)
    b = row + ROW_SLOPE
    # each x_k gathers its terms in the order the x_i become available: one fused multiply-add after x_{k−1}
    x0 = _residual(data, cell, row, 0, u[5])
    x1 = fma(load(r, b), x0, _residual(data, cell, row, 1, u[6]))
    x2 = fma(load(r, b + 2), x1, fma(load(r, b + 1), x0, _residual(data, cell, row, 2, u[7])))
    x3 = fma(load(r, b + 5), x2, fma(load(r, b + 4), x1, fma(load(r, b + 3), x0, _residual(data, cell, row, 3, u[8]))))
    x4 = fma(load(r, b + 9), x3, fma(load(r, b + 8), x2, fma(load(r, b + 7), x1, fma(load(r, b + 6), x0,
                                                                    _residual(data, cell, row, 4, u[9])))))
    x5 = fma(load(r, b + 14), x4, fma(load(r, b + 13), x3, fma(load(r, b + 12), x2, fma(load(r, b + 11), x1, fma(
        load(r, b + 10), x0, _residual(data, cell, row, 5, u[10]))))))
    alpha2 = abs(x0)
    if alpha2 > math.pi:
        alpha2 = 2.0 * math.pi - alpha2
    return alpha2, min(x1, 0.5 * math.pi), max(x2, 0.0), x4, x5, x3, load(r, row + ROW_REGIME)


@numba.njit(inline="always", **JIT)
def _rescaled(data, below, wa, drawn, k, x, centred):
    """x drawn from cell number ``drawn``, moved to the moments interpolated in α1 between cell ``below``
    (the lower α1 neighbour, at the drawn speed) and the next one up.

    x' = m + (x − m_cell) σ/σ_cell with m, σ linear in α1 between the two
    cells' means and standard deviations of state variable k; ``centred``
    variables (β2, Ω_x, Ω_y: mean 0 by the mirror symmetry) are only scaled.
    """
    cells = data.cells
    lo, hi, here = below * CELL_SIZE + k, (below + data.n_speed) * CELL_SIZE + k, drawn * CELL_SIZE + k
    sd = fma(wa, load(cells, hi + CELL_SD), (1.0 - wa) * load(cells, lo + CELL_SD))
    inv_sd_cell = load(cells, here + CELL_INV_SD)
    ratio = sd * inv_sd_cell if inv_sd_cell > 0.0 else 1.0
    if centred:
        return x * ratio
    mean = fma(wa, load(cells, hi + CELL_MEAN), (1.0 - wa) * load(cells, lo + CELL_MEAN))
    return fma(x - load(cells, here + CELL_MEAN), ratio, mean)


@numba.njit(inline="always", **JIT)
def _to_speed(data, regime, jv, wv, cos_alpha1, sin_alpha1, iv, vx, vy, vz, wx, wy, wz):
    """A rebound drawn at grid speed V_iv, moved to incident speed V = V_jv + wv (V_jv+1 − V_jv); returns
    (vx, vy, vz, wx, wy, wz).

    Local frame, V⁺ in units of |V⁻|, Ω⁺ in units of |V⁻|/a. With
    a(V) = 1 − (1 − exp(−k V^p)) sin α1, the normal restitution of the wall
    law for a contact point moving like the centre of mass:

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
    reflected (the rebound must leave the wall). exp(−k V^p) comes from the
    table's polynomial pieces (:mod:`surrogate.restitution`).
    """
    a_target = 1.0 - (1.0 - restitution_at(data.restitution_pieces, data.n_pieces, jv, wv)) * sin_alpha1
    a_grid = 1.0 - (1.0 - load(data.speed_restitution, iv)) * sin_alpha1
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
    alpha2, beta2, s, wx, wy, wz, regime = draw_folded(data, drawn, u)
    if scaled and wa > 0.0:
        alpha2 = abs(_rescaled(data, below, wa, drawn, 0, alpha2, False))
        alpha2 = 2.0 * math.pi - alpha2 if alpha2 > math.pi else alpha2
        beta2 = min(_rescaled(data, below, wa, drawn, 1, beta2, True), 0.5 * math.pi)
        s = max(_rescaled(data, below, wa, drawn, 2, s, False), 0.0)
        wx = _rescaled(data, below, wa, drawn, 3, wx, True)
        wy = _rescaled(data, below, wa, drawn, 4, wy, True)
        wz = _rescaled(data, below, wa, drawn, 5, wz, False)
    sb, cb = sincos(beta2)
    sa, ca = sincos(alpha2)
    scb = s * cb
    vx, vy, vz = scb * ca, scb * sa, s * sb
    if scaled and wv > 0.0:
        vx, vy, vz, wx, wy, wz = _to_speed(data, regime, jv, wv, cos_alpha1, sin_alpha1, iv,
                                           vx, vy, vz, wx, wy, wz)
    mirror = -1.0 if u[11] < 0.5 else 1.0
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
    drawn = cell[0]
    c = min(int(u[4] * data.n_clusters), data.n_clusters - 1)
    row = _row(data, drawn, c)
    for j in range(0, ROW_SIZE, 16):   # the three cache lines of a 144-byte row (its start is 16-byte aligned)
        prefetch(data.clusters, (row + j,))
    levels = data.n_levels - 1
    for k in range(6):
        level = _level(data, drawn, k, min(int(u[5 + k] * levels), levels - 1))
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


BLOCK = 16      # particles whose table reads rebound_many puts in flight together
INDEX = 5       # integers per particle in rebound_many's index scratch
FRAME = 11      # floats per particle in rebound_many's frame scratch


@numba.njit(**JIT)
def rebound_many(data, mix_cdf, V, n, a, u, V_out, W_out, status, scaled=True):
    """:func:`rebound` for every row, one thread, with the table reads of BLOCK particles in flight at once.

    Same arguments as :func:`rebound_batch` and the same results, bit for bit,
    as calling :func:`rebound` row by row. A draw's table reads are located
    by its uniforms once its cell is known (the component row, the residual
    levels), except the row the alias table redirects to, which waits for the
    first row. :func:`rebound` requests them together for one particle; here
    they are requested for a block of particles (cache hints,
    :func:`surrogate.memory.prefetch`), then the redirected rows, and the
    draws then run on cached data, so the memory latencies of the whole
    block overlap. For a flow solver that collects its wall hits: call this
    from its ``@njit`` code on the hit arrays.
    """
    _rebound_blocks(data, mix_cdf, V, n, a, u, V_out, W_out, status, scaled,
                    np.empty((BLOCK, INDEX), dtype=np.int64), np.empty((BLOCK, FRAME)))


@numba.njit(**KERNEL)
def _rebound_blocks(data, mix_cdf, V, n, a, u, V_out, W_out, status, scaled, index, frame):
    """:func:`rebound_many` with its scratch arrays: ``index`` (BLOCK, INDEX) int64 holds validity and the
    cell (drawn, below, jv, iv; :func:`_cell`) of each particle of a block; ``frame`` (BLOCK, FRAME) |V⁻|,
    cos α1, sin α1, ex, ez, wa, wv."""
    rows = data.clusters
    n_clusters = data.n_clusters
    for start in range(0, V.shape[0], BLOCK):
        stop = min(start + BLOCK, V.shape[0])
        for b in range(stop - start):                 # 1: impact frame, cell, hint the reads u locates
            i = start + b
            index[b, 0] = _moves_into_wall(V[i], n[i])
            if not index[b, 0]:
                continue
            alpha1, speed, cos_a1, sin_a1, ex, ez = impact_frame(V[i], n[i], u[i, 12])
            cell = _cell(data, mix_cdf, alpha1, speed, u[i])
            _hint_draw(data, cell, u[i])
            drawn, below, wa, jv, wv, iv = cell
            index[b, 1], index[b, 2], index[b, 3], index[b, 4] = drawn, below, jv, iv
            frame[b, 0], frame[b, 1], frame[b, 2], frame[b, 9], frame[b, 10] = speed, cos_a1, sin_a1, wa, wv
            frame[b, 3], frame[b, 4], frame[b, 5] = ex
            frame[b, 6], frame[b, 7], frame[b, 8] = ez
        for b in range(stop - start):                 # 2: where the alias table redirects, hint that row
            if not index[b, 0]:
                continue
            drawn = index[b, 1]
            t = u[start + b, 4] * n_clusters
            c = min(int(t), n_clusters - 1)
            row = _row(data, drawn, c)
            if t - c >= load(rows, row + ROW_ALIAS_PROB):
                row = _row(data, drawn, int(load(rows, row + ROW_ALIAS)))
                for j in range(0, ROW_SIZE, 16):
                    prefetch(rows, (row + j,))
        for b in range(stop - start):                 # 3: the draws, on cached data
            i = start + b
            if not index[b, 0]:
                status[i] = rebound(data, mix_cdf, V[i], n[i], a[i], u[i], V_out[i], W_out[i], scaled)
                continue
            cell = (index[b, 1], index[b, 2], frame[b, 9], index[b, 3], frame[b, 10], index[b, 4])
            st, vx, vy, vz, wx, wy, wz = _draw_in_cell(data, cell, frame[b, 1], frame[b, 2], u[i], scaled)
            ex, ez = (frame[b, 3], frame[b, 4], frame[b, 5]), (frame[b, 6], frame[b, 7], frame[b, 8])
            V_new, W_new = _to_global(st, vx, vy, vz, wx, wy, wz, frame[b, 0], a[i], ex, n[i], ez)
            _store(V_new, W_new, V_out[i], W_out[i])
            status[i] = st


@numba.njit(parallel=True, **JIT)
def rebound_batch(data, mix_cdf, V, n, a, u, V_out, W_out, status, scaled=True):
    """:func:`rebound` for every row (parallel over chunks of :func:`rebound_many`); u has shape (N, U_PER_DRAW)."""
    for j in numba.prange(n_streams(V.shape[0])):
        lo, hi = _chunk(j, V.shape[0])
        _rebound_chunk(data, mix_cdf, V, n, a, u[lo:hi], V_out, W_out, status, scaled, lo, hi)


@numba.njit(parallel=True, **JIT)
def rebound_batch_rng(data, mix_cdf, V, n, a, states, V_out, W_out, status, scaled=True):
    """:func:`rebound_batch` drawing its own uniforms: the rows of chunk j (ROWS_PER_STREAM rows) from a
    copy of the xoshiro256+ state ``states[j]`` (:func:`surrogate.rng.stream_states`; ``states`` itself is
    not advanced), row after row. The draws are the same whatever the number of threads, and no
    (N, U_PER_DRAW) array of uniforms is held. ``states`` must have one row per chunk (ValueError)."""
    _check_streams(states, V.shape[0])
    for j in numba.prange(states.shape[0]):
        lo, hi = _chunk(j, V.shape[0])
        _rebound_chunk(data, mix_cdf, V, n, a, _stream_uniforms(states[j], hi - lo), V_out, W_out, status, scaled,
                       lo, hi)


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
def _stream_uniforms(state, rows):
    """(rows, U_PER_DRAW) uniforms from a copy of the xoshiro256+ ``state``, row after row."""
    u = np.empty((rows, U_PER_DRAW))
    fill_uniforms(state.copy(), u.reshape(rows * U_PER_DRAW))
    return u


@numba.njit(inline="always", **JIT)
def _rebound_chunk(data, mix_cdf, V, n, a, u, V_out, W_out, status, scaled, lo, hi):
    """:func:`rebound_many` on rows [lo, hi) with the uniforms ``u`` of those rows."""
    _rebound_blocks(data, mix_cdf, V[lo:hi], n[lo:hi], a[lo:hi], u, V_out[lo:hi], W_out[lo:hi], status[lo:hi],
                    scaled, np.empty((BLOCK, INDEX), dtype=np.int64), np.empty((BLOCK, FRAME)))


@numba.njit(parallel=True, **JIT)
def draw_local_batch(data, mix_cdf, alpha1, speed, u, out, status, scaled=True):
    """:func:`draw_local` for every row (parallel); out has shape (N, 6)."""
    for j in numba.prange(n_streams(alpha1.shape[0])):
        lo, hi = _chunk(j, alpha1.shape[0])
        _draw_local_chunk(data, mix_cdf, alpha1, speed, u[lo:hi], out, status, scaled, lo, hi)


@numba.njit(parallel=True, **JIT)
def draw_local_batch_rng(data, mix_cdf, alpha1, speed, states, out, status, scaled=True):
    """:func:`draw_local_batch` drawing its own uniforms, chunk by chunk as :func:`rebound_batch_rng`."""
    _check_streams(states, alpha1.shape[0])
    for j in numba.prange(states.shape[0]):
        lo, hi = _chunk(j, alpha1.shape[0])
        _draw_local_chunk(data, mix_cdf, alpha1, speed, _stream_uniforms(states[j], hi - lo), out, status, scaled,
                          lo, hi)


@numba.njit(inline="always", **JIT)
def _draw_local_chunk(data, mix_cdf, alpha1, speed, u, out, status, scaled, lo, hi):
    """:func:`draw_local` on rows [lo, hi) with the uniforms ``u`` of those rows."""
    for i in range(lo, hi):
        st, a2, b2, s, wx, wy, wz = draw_local(data, mix_cdf, alpha1[i], speed[i], u[i - lo], scaled)
        status[i] = st
        out[i, 0], out[i, 1], out[i, 2], out[i, 3], out[i, 4], out[i, 5] = a2, b2, s, wx, wy, wz
