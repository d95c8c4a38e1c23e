"""The law of one draw, in three public stages: :func:`locate`, :func:`gather`, :func:`arithmetic`.

1. :func:`locate` — the cell a draw reads: the shape from the mix, the grid
   intervals of α1 and |V⁻| (:func:`grid_interval`) and the neighbour drawn
   with its interpolation weight;
2. :func:`gather` — every table value the draw needs (the component the alias
   table picks, its residual quantiles and slopes, the moments and the
   restitution factors that move it to the incident state), as a tuple;
   :func:`hint` requests its cache lines ahead;
3. :func:`arithmetic` — the reflected state from those values alone, with
   every choice a select, so the block pipeline runs it as a SIMD loop
   (:mod:`surrogate.kernels.pipeline`) and one particle
   (:mod:`surrogate.kernels.particle`) calls the same function: the two give
   the same bits by construction.

These are plain functions over the arrays of a table (``table.kernel_data``,
:class:`surrogate.kernels.layout.KernelData`) and pre-drawn uniforms. Every
draw consumes exactly :data:`U_PER_DRAW` uniforms from [0, 1)::

    u[0] shape from the mix        u[1] α1 neighbour       u[2] speed neighbour
    u[3] trapped or not            u[4] mixture component  u[5:11] the six chain variables
    u[11] mirror sign              u[12] in-wall axis at normal impact (:func:`surrogate.kernels.frame.impact_frame`)

Between grid points the sampler uses stochastic interpolation: the cell of the
neighbour at x_{j+1} is used with probability w = (x − x_j)/(x_{j+1} − x_j), as
Monte Carlo transport codes do between incident-energy points; a multimodal
law stays multimodal (no averaging of quantiles). By default (``scaled``) the
state drawn from the neighbour is then moved to the incident state:

* in α1, variable by variable, to the mean and standard deviation interpolated
  linearly between the two neighbouring α1 (like the unit-base interpolation
  of transport codes, which stretches a neighbour's secondary law to the
  interpolated range);
* in |V⁻|, by the wall's restitution law (:func:`to_speed`), with a law that
  depends on the drawn cluster's collision regime: the velocity change and
  the spin of a rebound of one or two collisions scale with 1 + a(V), the
  normal rebound velocity of a longer one with a(V).

The hot path calls no libm function (:mod:`surrogate.kernels.fastmath`) and
branches only where the outcome is predictable (trapped, outside the grid);
choices that vary from draw to draw (neighbour cell, alias, regime, mirror
sign, quadrant) are selects.

Frame and units: the model's lab frame (wall y = 0, normal +Y, impact plane
XY, α1 from the wall); angles in radians except α1 (degrees), V⁺ in units of
|V⁻|, Ω in units of |V⁻|/a.
"""

import math

import numba
import numpy as np

from data_schema.samples import STATUS_REBOUNDED, STATUS_TRAPPED
from data_schema.table import N_CHAIN
from surrogate.kernels.fastmath import clamp_index, fma, restitution_at, sincos
from surrogate.kernels.frame import STATUS_INVALID, rebound_ok, uniforms_ok
from surrogate.kernels.layout import (AXIS_GRID, AXIS_INV_STEP, AXIS_ORIGIN, CELL_INV_SD, CELL_MEAN, CELL_P_TRAPPED,
                                      CELL_SD, CELL_SIZE, FLOAT32_PER_CACHE_LINE, ROW_ALIAS, ROW_ALIAS_PROB, ROW_LOC,
                                      ROW_REGIME, ROW_SCALE, ROW_SHAPE, ROW_SIZE, ROW_SLOPE)
from surrogate.kernels.memory import load, load15, prefetch
from surrogate.kernels.options import JIT, KERNEL


U_PER_DRAW = 13


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


@numba.njit(inline="always", **JIT)
def _row(data, cell, c):
    """Offset in ``data.clusters`` of component c's row in cell number ``cell``."""
    return (cell * data.n_clusters + c) * ROW_SIZE


@numba.njit(inline="always", **JIT)
def _level(data, cell, k, i):
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
def _quantile(data, cell, row, k, u):
    """loc + scale · S(u) of chain variable k in the component at offset ``row`` of cell number ``cell``: the
    residual shape S interpolated linearly between the levels i, i + 1 that u falls between (one multiply,
    one floor)."""
    r = data.clusters
    levels = data.n_levels - 1
    t = u * levels
    i = clamp_index(int(t), levels - 1)
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
    hair for a rare draw (docs/format.md, "The stored law of a cell").
    Reflected at the edge, such a draw stays a rebound that
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
def restitution_factors(data, jv, wv, iv):
    """exp(−k V^p) at the incident speed V = V_jv + wv (V_jv+1 − V_jv) and at the drawn grid speed V_iv."""
    return restitution_at(data.restitution_pieces, data.n_pieces, jv, wv), np.float64(load(data.speed_restitution, iv))


@numba.njit(inline="always", **JIT)
def to_speed(regime, f_target, f_grid, cos_alpha1, sin_alpha1, vx, vy, vz, wx, wy, wz):
    """A rebound drawn at grid speed V_iv, moved to the incident speed V; returns (vx, vy, vz, wx, wy, wz).

    ``f_target``, ``f_grid``: exp(−k V^p) at V and at V_iv
    (:func:`restitution_factors`). Local frame, V⁺ in units of |V⁻|, Ω⁺ in
    units of |V⁻|/a. With a(V) = 1 − (1 − exp(−k V^p)) sin α1, the normal
    restitution of the wall law for a contact point moving like the centre
    of mass:

    * regime 0 (at most two collisions): the velocity change V⁺ − V⁻ and the
      spin Ω⁺ are multiplied by (1 + a(V))/(1 + a(V_iv)). For one
      frictionless collision this is exact: the impulse is (1 + a) times the
      incident normal velocity over the contact's effective inverse mass.
    * regime 1 (more collisions): the normal rebound velocity is multiplied
      by a(V)/a(V_iv), the rest kept (the last, slow contacts set it).

    One law per regime because neither alone follows the direct model near
    normal impact for every shape (docs/design/table_representation.md). A
    normal velocity the shift would reverse is reflected (the rebound must
    leave the wall).
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


# -- stage 1: locate -------------------------------------------------------------

@numba.njit(inline="always", **JIT)
def locate(data, mix_cdf, alpha1, speed, u):
    """The cell a draw reads: (drawn, below, wa, jv, wv, iv).

    Shape from u[0] and the mix; grid intervals (ja, jv) with the weights of
    their upper points (wa, wv); the neighbour cell (ia, iv) drawn with those
    weights from u[1], u[2] (stochastic interpolation). ``drawn`` is the
    number of cell (shape, ia, iv) (:class:`surrogate.kernels.layout.KernelData`),
    ``below`` that of (shape, ja, iv), the lower α1 neighbour at the drawn speed.
    """
    shape = 0
    for k in range(mix_cdf.shape[0] - 1):     # the first k with u[0] < cdf[k], without data-dependent branches
        shape += u[0] >= mix_cdf[k]
    ja, wa = grid_interval(data.alpha1_axis, data.n_alpha1, alpha1)
    jv, wv = grid_interval(data.speed_axis, data.n_speed, speed)
    ia = ja + (u[1] < wa)       # integer + comparison: no branch to mispredict
    iv = jv + (u[2] < wv)
    below = (shape * data.n_alpha1 + ja) * data.n_speed + iv
    return below + (ia - ja) * data.n_speed, below, wa, jv, wv, iv


# -- stage 2: gather --------------------------------------------------------------

@numba.njit(inline="always", **JIT)
def is_trapped(data, drawn, u3):
    """Whether u[3] draws the trapped outcome in cell number ``drawn``."""
    return u3 < load(data.cells, drawn * CELL_SIZE + CELL_P_TRAPPED)


@numba.njit(inline="always", **JIT)
def gather_component(data, drawn, row, u):
    """What a draw reads from its component (at offset ``row`` in cell number ``drawn``, :func:`component`):
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
    """Every table value a draw in ``cell`` (:func:`locate`) with component ``row`` needs:
    :func:`gather_component` + :func:`gather_cell`, the arguments of :func:`arithmetic`."""
    return gather_component(data, cell[0], row, u) + gather_cell(data, cell)


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
    """Cache hints for the two residual-shape levels of chain variable k that u picks (:func:`_quantile`)."""
    levels = data.n_levels - 1
    level = _level(data, drawn, k, clamp_index(int(u * levels), levels - 1))
    prefetch(data.dictionary, (level,))
    prefetch(data.dictionary, (level + data.n_dictionary,))


# -- stage 3: arithmetic ----------------------------------------------------------

@numba.njit(inline="always", **JIT)
def arithmetic(gathered, cos_alpha1, sin_alpha1, scaled):
    """The reflected state from the values :func:`gather` returns, at cos α1, sin α1:
    (status, V⁺_x, V⁺_y, V⁺_z, Ω_x, Ω_y, Ω_z), local frame, V⁺ in units of |V⁻|, Ω in units of |V⁻|/a;
    NaN and STATUS_TRAPPED when trapped.

    The chain (:func:`_chain`), then with ``scaled`` the move to the incident α1 when wa > 0
    (:func:`_moved`) and to the incident speed when wv > 0 (:func:`to_speed`), then the mirror sign.
    No table read and no branch (every choice a select), so a loop of it over a block of particles runs
    as SIMD instructions.
    """
    q, slopes, regime, trapped, mirror, wa, wv, ratio, shift, f_target, f_grid = gathered
    state = _chain(q, slopes)
    terms = ((ratio[0], shift[0], shift[1]), (ratio[1], 0.0, 0.0), (ratio[2], shift[2], shift[3]),
             (ratio[3], 0.0, 0.0), (ratio[4], 0.0, 0.0), (ratio[5], shift[4], shift[5]))
    state = _pick6(scaled and wa > 0.0, _moved(state, terms), state)
    vx, vy, vz = _velocity(state[0], state[1], state[2])
    local = (vx, vy, vz, state[3], state[4], state[5])
    moved = to_speed(regime, f_target, f_grid, cos_alpha1, sin_alpha1, vx, vy, vz, state[3], state[4], state[5])
    vx, vy, vz, wx, wy, wz = _pick6(scaled and wv > 0.0, moved, local)
    status, vx, vy, vz, wx, wy, wz = _mirrored(mirror, vx, vy, vz, wx, wy, wz)
    out = _pick6(trapped > 0.5, _NAN6, (vx, vy, vz, wx, wy, wz))
    return (STATUS_TRAPPED if trapped > 0.5 else status,) + out


_NAN6 = (np.nan, np.nan, np.nan, np.nan, np.nan, np.nan)


@numba.njit(inline="always", **JIT)
def _pick6(c, x, y):
    """x if c else y for two 6-tuples, element by element (selects, which vectorise)."""
    return (x[0] if c else y[0], x[1] if c else y[1], x[2] if c else y[2], x[3] if c else y[3],
            x[4] if c else y[4], x[5] if c else y[5])


@numba.njit(inline="always", **JIT)
def _mirrored(u, vx, vy, vz, wx, wy, wz):
    """(STATUS_REBOUNDED, state) with the mirror symmetry Z → −Z applied when u < 1/2."""
    mirror = -1.0 if u < 0.5 else 1.0
    return STATUS_REBOUNDED, vx, vy, mirror * vz, mirror * wx, mirror * wy, wz


# -- one draw in the local frame -----------------------------------------------------

@numba.njit(inline="always", **JIT)
def draw_in_cell(data, cell, cos_alpha1, sin_alpha1, u, scaled):
    """:func:`draw_velocity` once its cell (:func:`locate`) is known and its reads hinted; α1 given by its
    cosine and sine. A trapped draw reads nothing more."""
    drawn = cell[0]
    if is_trapped(data, drawn, u[3]):
        return (STATUS_TRAPPED,) + _NAN6
    return arithmetic(gather(data, cell, component(data, drawn, u[4]), u), cos_alpha1, sin_alpha1, scaled)


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
    restitution law (:func:`to_speed`).
    """
    cell = locate(data, mix_cdf, alpha1, speed, u)
    hint(data, cell, u)
    sin_a1, cos_a1 = sincos(math.radians(alpha1))
    return draw_in_cell(data, cell, cos_a1, sin_a1, u, scaled)


@numba.njit(inline="always", **JIT)
def local_ok(alpha1, speed):
    """A local incident state a draw takes: α1 in (0, 90] deg, |V⁻| finite and > 0 m/s."""
    return alpha1 > 0.0 and alpha1 <= 90.0 and speed > 0.0 and math.isfinite(speed)


@numba.njit(**KERNEL)
def draw_local(data, mix_cdf, alpha1, speed, u, scaled=True):
    """One reflected state at (α1 deg, |V⁻| m/s) in the local frame: (status, α2, β2, s, Ω_x, Ω_y, Ω_z).

    Angles in radians, s = |V⁺|/|V⁻|, Ω in units of |V⁻|/a; the state is NaN
    for a trapped particle. See :func:`draw_velocity` (same arguments).
    STATUS_INVALID (and NaN) for α1 outside (0, 90] or NaN, |V⁻| not finite
    and > 0, a uniform outside [0, 1), or a draw that is not a finite rebound
    leaving the wall (as rbs_draw_local).
    """
    if not local_ok(alpha1, speed):
        return STATUS_INVALID, np.nan, np.nan, np.nan, np.nan, np.nan, np.nan
    status, vx, vy, vz, wx, wy, wz = draw_velocity(data, mix_cdf, alpha1, speed, u, scaled)
    ok = uniforms_ok(u) & ((status != STATUS_REBOUNDED) | rebound_ok((vx, vy, vz), (wx, wy, wz), (0.0, 1.0, 0.0)))
    status = status if ok else STATUS_INVALID
    if status != STATUS_REBOUNDED:
        return status, np.nan, np.nan, np.nan, np.nan, np.nan, np.nan
    s = math.sqrt(vx * vx + vy * vy + vz * vz)
    return status, math.atan2(vy, vx), math.asin(vz / s) if s > 0.0 else 0.0, s, wx, wy, wz
