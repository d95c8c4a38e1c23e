"""The work of a table draw on the wall (docs/model.md §4.7; docs/design/table_representation.md, "The work on
the wall"): W_n and W_t, m²/s² per unit particle mass, jointly with the rebound the table path drew.

A table of format 4.1 continues each component's chain with two work variables (data_schema.table.WORK_NAMES):
the rotational energy fraction r = E_Ω⁺/E⁻ and the root of the normal share ν = √(W_n/(W_n + W_t)), each its
residual quantile plus slopes on the chain variables of the draw (and r). The work is then what the drawn
rebound's energy leaves, W = W_n + W_t = E⁻ (1 − s² − r) with E⁻ = |V⁻|²/2 (tables are built with Ω⁻ = 0) and
s = |V⁺|/|V⁻| of the rebound returned, so energy is conserved draw by draw whatever the move between grid
points; at the drawn grid speed W_n = ν² W. The root, because near grazing incidence W_n is a thousandth of W and
follows the normal velocity: its root is nearly linear in the state, as the chain needs. Between grid points r
and ν move with the draw: in α1 to their interpolated means and standard deviations, like the state. In |V⁻|
the spin of a regime-0 draw scales by g (:func:`surrogate.kernels.arithmetic.speed_factors`), so r by g²; W_n/E⁻
and W_t/E⁻ at the grid speed move as one collision's at the wall law's normal restitution a
(:func:`surrogate.kernels.arithmetic.restitutions`), W_n by (1 − a(V)²)/(1 − a(V_j)²) (its normal work
½ m_eff v_c²(1 − a²)) and W_t by (1 + a(V))/(1 + a(V_j)) (friction's work follows the normal impulse), and then
each changes by the least relative amount that closes W (:func:`closed_normal`): the larger part, W_t near
grazing and W_n near normal impact, takes most of the difference. A trapped draw does its cell's trapped
particles' mean work.

Random numbers: the two residual uniforms are keyed uniforms (:func:`surrogate.kernels.rng.grain_uniform`) of a
hash of the hit's own uniforms (:func:`work_key`), so the work takes nothing of the caller's stream: a rebound
is the same bits with or without it.
"""

import numba
import numpy as np

from data_schema.samples import STATUS_INVALID, STATUS_REBOUNDED, STATUS_TRAPPED
from data_schema.table import N_CHAIN, N_WORK
from direct_model.elementary import fma
from surrogate.kernels.arithmetic import (NAN6, OUT_S2, OUT_STATUS, _chain, arithmetic, at_alpha1, restitutions,
                                         speed_factors, speed_ratio_squared)
from surrogate.kernels.block import field, uniforms
from surrogate.kernels.draw import U_PER_DRAW
from surrogate.kernels.fastmath import clamp_index
from surrogate.kernels.frame import FRAME_SIN, FRAME_SPEED, is_valid
from surrogate.kernels.gather import gather, gathered_at, is_trapped, moved_term
from surrogate.kernels.layout import (WORK_CELL_INV_SD, WORK_CELL_MEAN, WORK_CELL_SD, WORK_CELL_SIZE,
                                      WORK_CELL_TRAPPED, WORK_ROW_LOC, WORK_ROW_SCALE, WORK_ROW_SHAPE, WORK_ROW_SIZE,
                                      WORK_ROW_SLOPE, ROW_SIZE)
from surrogate.kernels.locate import I_DRAWN, I_ROW, cell_at, component
from surrogate.kernels.memory import load, prefetch
from surrogate.kernels.options import JIT, KERNEL
from surrogate.kernels.rng import grain_uniform, hit_key

_WORK_DOMAIN = np.uint64(0xBB67AE8584CAA73B)    # the work keys' start: unrelated to the facet keys'


@numba.njit(inline="always", **JIT)
def work_key(u):
    """The work key of a hit of uniforms ``u`` (its U_PER_DRAW): :func:`surrogate.kernels.rng.hit_key` from
    _WORK_DOMAIN."""
    return hit_key(u, U_PER_DRAW, _WORK_DOMAIN)


@numba.njit(inline="always", **JIT)
def _level_at(data, cell, w, u):
    """Offset in ``data.work_dictionary`` of the level of work variable w that u picks in cell number ``cell``, and
    the interpolation parameter there (t − i of :func:`_work_quantile`)."""
    levels = data.n_levels - 1
    t = u * levels
    i = clamp_index(int(t), levels - 1)
    return ((cell * N_WORK + w) * data.n_levels + i) * data.n_dictionary, t - i


@numba.njit(inline="always", **JIT)
def hint_work(data, drawn, row, u):
    """Cache hints (:func:`surrogate.kernels.memory.prefetch`) for the work's table reads of a draw with uniforms
    ``u`` from the component at offset ``row`` of ``data.clusters`` (before its alias, or after) in cell number
    ``drawn``: its work row and the levels its two keyed uniforms pick, so that they are in flight with the
    rebound's reads."""
    if data.has_work:
        at = row // ROW_SIZE * WORK_ROW_SIZE
        prefetch(data.work_rows, (at,))
        prefetch(data.work_rows, (at + WORK_ROW_SIZE - 1,))
        key = work_key(u)
        for w in range(N_WORK):
            level = _level_at(data, drawn, w, grain_uniform(key, w))[0]
            prefetch(data.work_dictionary, (level,))
            prefetch(data.work_dictionary, (level + data.n_dictionary,))


@numba.njit(inline="always", **JIT)
def _work_quantile(data, cell, row, w, u):
    """loc + scale · S(u) of work variable w in the component at offset ``row`` of ``data.work_rows`` in cell
    number ``cell`` (as :func:`surrogate.kernels.gather._quantile`, from the work's own dictionary)."""
    r = data.work_rows
    level, dt = _level_at(data, cell, w, u)
    at = level + int(load(r, row + WORK_ROW_SHAPE + w))
    lo = np.float64(load(data.work_dictionary, at))
    hi = np.float64(load(data.work_dictionary, at + data.n_dictionary))
    return fma(np.float64(load(r, row + WORK_ROW_SCALE + w)), fma(dt, hi - lo, lo),
               np.float64(load(r, row + WORK_ROW_LOC + w)))


@numba.njit(inline="always", **JIT)
def _root_share(nu):
    """ν reflected into [0, 1] (the chain's linear shifts can step outside by a hair, as the state's)."""
    nu = abs(nu)
    return 2.0 - nu if nu > 1.0 else nu


@numba.njit(inline="always", **JIT)
def work_variables(data, cell, row, x, key):
    """(r, ν) of the component at offset ``row`` of ``data.clusters`` in cell number ``cell``, given the draw's
    chain variables x (chain order) and its work key: each work variable's residual quantile plus its slopes on
    x (and r), folded (r ≥ 0, ν in [0, 1])."""
    rows, at = data.work_rows, row // ROW_SIZE * WORK_ROW_SIZE     # the component's work row
    r = _work_quantile(data, cell, at, 0, grain_uniform(key, 0))
    nu = _work_quantile(data, cell, at, 1, grain_uniform(key, 1))
    for j in range(N_CHAIN):
        r = fma(np.float64(load(rows, at + WORK_ROW_SLOPE + j)), x[j], r)
        nu = fma(np.float64(load(rows, at + WORK_ROW_SLOPE + N_CHAIN + j)), x[j], nu)
    nu = fma(np.float64(load(rows, at + WORK_ROW_SLOPE + 2 * N_CHAIN)), r, nu)
    return abs(r), _root_share(nu)


@numba.njit(inline="always", **JIT)
def drawn_work(data, cell, row, gathered, status, s2, sin_alpha1, speed, key, scaled):
    """(W_n, W_t), m²/s², of a table draw in ``cell`` (:func:`surrogate.kernels.locate.locate`) from the component
    at offset ``row`` of ``data.clusters`` with the ``gathered`` values (:func:`surrogate.kernels.gather.gather`),
    that returned ``status`` and s² = |V⁺|²/|V⁻|² ``s2``, at sin α1 and |V⁻| = ``speed`` m/s, with its work key
    (module doc); NaN for a table without the work or a draw neither rebounded nor trapped. ``row`` and
    ``gathered`` are read for a rebound only."""
    if not data.has_work or (status != STATUS_REBOUNDED and status != STATUS_TRAPPED):
        return np.nan, np.nan
    drawn, below, wa, jv, wv, iv = cell
    if status == STATUS_TRAPPED:
        return trapped_work(data, drawn, speed)
    q, slopes, regime, _, _, _, _, _, _, f_target, f_grid = gathered
    state = _chain(q, slopes)
    r, nu = work_variables(data, drawn, row, (state[0], state[1], state[2], state[5], state[3], state[4]), key)
    if scaled and wa > 0.0:
        lo, hi, here = below * WORK_CELL_SIZE, (below + data.n_speed) * WORK_CELL_SIZE, drawn * WORK_CELL_SIZE
        r_term = moved_term(data.work_cells, lo, hi, here, wa, WORK_CELL_MEAN, WORK_CELL_SD, WORK_CELL_INV_SD)
        nu_term = moved_term(data.work_cells, lo + 1, hi + 1, here + 1, wa, WORK_CELL_MEAN, WORK_CELL_SD,
                              WORK_CELL_INV_SD)
        r = abs(fma(r - r_term[1], r_term[0], r_term[2]))
        nu = _root_share(fma(nu - nu_term[1], nu_term[0], nu_term[2]))
    normal, tangential = nu * nu, (1.0 - nu) * (1.0 + nu)     # the shares of W at the drawn grid speed: ν², 1 − ν²
    energy = 0.5 * speed * speed
    if scaled and wv > 0.0:
        # between grid speeds each part moves as one collision's, W_n ∝ 1 − a² and W_t ∝ λ ∝ 1 + a (units of E⁻),
        # then both change by the least relative amount that closes the moved rebound's energy
        s0 = at_alpha1(gathered, scaled)[2]         # s at the drawn grid speed
        grid_total = _positive(1.0 - s0 * s0 - r)
        g = speed_factors(regime, f_target, f_grid, sin_alpha1)[2]
        a_target, a_grid = restitutions(f_target, f_grid, sin_alpha1)
        r *= g * g
        total = _positive(1.0 - s2 - r)
        moved_n = normal * grid_total * ((1.0 - a_target) * (1.0 + a_target) / ((1.0 - a_grid) * (1.0 + a_grid)))
        moved_t = tangential * grid_total * ((1.0 + a_target) / (1.0 + a_grid))
        if moved_n * moved_n + moved_t * moved_t > 0.0:
            work_n = closed_normal(moved_n, moved_t, total)
            return energy * work_n, energy * (total - work_n)
    total = _positive(1.0 - s2 - r)
    weights = normal + tangential
    if not weights > 0.0:
        return 0.0, 0.0
    return energy * (total * normal / weights), energy * (total * tangential / weights)


@numba.njit(inline="always", **JIT)
def closed_normal(normal, tangential, total):
    """W_n of the pair (W_n, W_t) = (``normal``, ``tangential``) (≥ 0, not both 0) changed to sum to ``total``
    (≥ 0) by the least relative change of each: the difference split in proportion to their squares, so the
    larger part takes most of it; W_n kept in [0, total]."""
    squares = normal * normal + tangential * tangential
    work_n = normal + (total - normal - tangential) * (normal * normal / squares)
    work_n = work_n if work_n > 0.0 else 0.0
    return work_n if work_n < total else total


@numba.njit(inline="always", **JIT)
def _positive(x):
    """x if x > 0, else 0."""
    return x if x > 0.0 else 0.0


@numba.njit(inline="always", **JIT)
def trapped_work(data, drawn, speed):
    """(W_n, W_t), m²/s², of a trapped draw in cell number ``drawn`` at |V⁻| = ``speed`` m/s: its cell's trapped
    particles' mean."""
    at, energy = drawn * WORK_CELL_SIZE + WORK_CELL_TRAPPED, 0.5 * speed * speed
    return energy * load(data.work_cells, at), energy * load(data.work_cells, at + 1)


@numba.njit(**KERNEL)
def draw_with_work(data, cell, cos_alpha1, sin_alpha1, speed, u, scaled):
    """:func:`surrogate.kernels.draw.draw_in_cell` of one particle with uniforms ``u`` at |V⁻| = ``speed`` m/s, and
    its work on the wall (:func:`drawn_work`) from the same component and gathered values: (status, V⁺ (3, units
    of |V⁻|), Ω⁺ (3, units of |V⁻|/a), W_n, W_t (m²/s²))."""
    drawn = cell[0]
    if is_trapped(data, drawn, u[3]):
        work = trapped_work(data, drawn, speed) if data.has_work else (np.nan, np.nan)
        return (STATUS_TRAPPED,) + NAN6 + work
    row = component(data, drawn, u[4])
    gathered = gather(data, cell, row, u)
    status, vx, vy, vz, wx, wy, wz = arithmetic(gathered, cos_alpha1, sin_alpha1, scaled)
    work_n, work_t = drawn_work(data, cell, row, gathered, status, speed_ratio_squared(vx, vy, vz), sin_alpha1,
                                speed, work_key(u), scaled)
    return status, vx, vy, vz, wx, wy, wz, work_n, work_t


@numba.njit(**KERNEL)
def hint_work_block(data, ub, m, fr, index):
    """Cache hints for the work's reads (:func:`hint_work`) of the m particles of a resolved block (uniforms ``ub``,
    frame records ``fr``, cell records ``index``)."""
    for b in range(m):
        if is_valid(fr, b):
            hint_work(data, field(index, I_DRAWN, b), field(index, I_ROW, b), uniforms(ub, b))


@numba.njit(**KERNEL)
def work_block(data, ub, m, fr, index, weights, g, out, work_n, work_t, start, scaled):
    """The pipeline's stage after the arithmetic (:mod:`surrogate.kernels.pipeline`): the work on the wall
    (:func:`drawn_work`) of the m particles of a drawn block (uniforms ``ub``, frame records ``fr``, cell
    records ``index`` and ``weights``, gathered records ``g``, results ``out``), into rows start … start + m − 1
    of ``work_n`` and ``work_t`` (m²/s²): the bits :func:`draw_with_work` gives each particle."""
    for b in range(m):
        status = int(field(out, OUT_STATUS, b)) if is_valid(fr, b) else STATUS_INVALID
        work = (np.nan, np.nan)
        if data.has_work and (status == STATUS_REBOUNDED or status == STATUS_TRAPPED):
            work = drawn_work(data, cell_at(index, weights, b), field(index, I_ROW, b), gathered_at(g, b), status,
                              field(out, OUT_S2, b), field(fr, FRAME_SIN, b), field(fr, FRAME_SPEED, b),
                              work_key(uniforms(ub, b)), scaled)
        work_n[start + b], work_t[start + b] = work
