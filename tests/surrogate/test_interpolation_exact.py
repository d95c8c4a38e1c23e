"""The table path between grid points, checked exactly instead of statistically (docs/format.md, "Between grid
points"; surrogate.kernels.locate, gather, arithmetic).

A draw at α1 between grid points g_j < g_{j+1} has the weight w = (α1 − g_j)/(g_{j+1} − g_j) (likewise in |V⁻|);
it reads the upper neighbour's cell iff u[1] < w (u[2] < w_v in speed), and with ``scaled`` moves the drawn
state x to x' = m + (x − m_cell) σ/σ_cell, m and σ the cell means and standard deviations blended
(1 − w)·lo + w·hi, and to the incident speed by the restitution factor exp(−k V^p) at V. Each of these is a
deterministic function of the uniforms, so each is checked here to a few ulp (the exact counterparts of
tests/surrogate/test_law.py's interpolation mean and spread at 4 standard errors, which a weight biased by a
few percent passes). On the session's 3 × 3 table (α1 30, 60, 90°; 50, 150, 250 m/s).
"""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest

import surrogate
from data_schema.samples import STATUS_REBOUNDED
from surrogate.kernels import U_PER_DRAW, draw_velocity, grid_interval, locate
from surrogate.kernels.gather import gather_cell
from surrogate.kernels.layout import CELL_MEAN, CELL_SD, CELL_SIZE

EPS = np.finfo(np.float64).eps
# weights of the upper grid point tried in every interval: dyadic, not dyadic, near either end
WEIGHTS = (0.125, 0.25, 1 / 3, 0.5, 2 / 3, 0.875, 0.999)
SHAPE = "prism"


def _grids(table):
    data = table.kernel_data
    return ((data.alpha1_axis, np.asarray(table.alpha1_deg)), (data.speed_axis, np.asarray(table.speed_m_s)))


def _exact_weight(grid, j, x):
    """(x − g_j)/(g_{j+1} − g_j) in exact rational arithmetic."""
    return (Fraction(x) - Fraction(grid[j])) / (Fraction(grid[j + 1]) - Fraction(grid[j]))


def _ulps(got, exact):
    """|got − exact| in units of the spacing of doubles at exact."""
    return abs(Fraction(got) - exact) / Fraction(np.spacing(float(exact)) if exact != 0 else np.spacing(0.0))


def _uniforms(seed, n):
    """n rows of U_PER_DRAW uniforms, away from the edges the tests set themselves."""
    return np.random.default_rng(seed).uniform(0.01, 0.99, (n, U_PER_DRAW))


def _cell_number(table, shape, ia, iv):
    return (shape * table.kernel_data.n_alpha1 + ia) * table.kernel_data.n_speed + iv


def _moments(table):
    """(means, sds) of every cell, (n_cells, 6) each, state order (α2, β2, s, Ω_x, Ω_y, Ω_z)."""
    cells = table.kernel_data.cells.reshape(-1, CELL_SIZE)
    return cells[:, CELL_MEAN:CELL_MEAN + 6], cells[:, CELL_SD:CELL_SD + 6]


def test_the_weight_is_the_position_between_grid_points(small_table):
    """grid_interval gives the interval holding x and w within 2 ulp of (x − g_j)/(g_{j+1} − g_j) (one rounding
    of the inverse spacing, one of the product); at a node w is 0 exactly (1 at the last node); one double away
    from a node, w is within 2 ulp of its exact value next to 0 or 1."""
    for axis, grid in _grids(small_table):
        n = len(grid)
        for j in range(n - 1):
            xs = [grid[j] + w * (grid[j + 1] - grid[j]) for w in WEIGHTS]
            xs += [np.nextafter(grid[j], np.inf), np.nextafter(grid[j + 1], -np.inf)]
            for x in xs:
                got_j, got_w = grid_interval(axis, n, x)
                assert got_j == j, (grid, x)
                assert _ulps(got_w, _exact_weight(grid, j, x)) <= 2, (grid, x, got_w)
            assert grid_interval(axis, n, grid[j]) == (j, 0.0)
        assert grid_interval(axis, n, grid[-1]) == (n - 2, 1.0)


def test_the_upper_neighbour_is_drawn_iff_u_is_below_the_weight(small_table):
    """The neighbour choice's boundary sits exactly at the weight: u[1] one double below w_α draws the upper
    α1 neighbour, u[1] = w_α the lower (the same with u[2] and w_v in speed); the cell read is that neighbour's
    at the drawn speed."""
    data = small_table.kernel_data
    cdf = surrogate.mix_cdf(small_table, SHAPE)
    shape = small_table.shapes.index(SHAPE)
    (alpha_axis, alphas), (speed_axis, speeds) = _grids(small_table)
    u = _uniforms(1, 1)[0]
    for ja in range(len(alphas) - 1):
        for jv in range(len(speeds) - 1):
            for wa_target in WEIGHTS:
                for wv_target in WEIGHTS:
                    alpha1 = alphas[ja] + wa_target * (alphas[ja + 1] - alphas[ja])
                    speed = speeds[jv] + wv_target * (speeds[jv + 1] - speeds[jv])
                    wa = grid_interval(alpha_axis, len(alphas), alpha1)[1]
                    wv = grid_interval(speed_axis, len(speeds), speed)[1]
                    for u1, ia in ((np.nextafter(wa, 0.0), ja + 1), (wa, ja)):
                        for u2, iv in ((np.nextafter(wv, 0.0), jv + 1), (wv, jv)):
                            u[1], u[2] = u1, u2
                            drawn, below, got_wa, got_jv, got_wv, got_iv = locate(data, cdf, alpha1, speed, u)
                            assert (drawn, below) == (_cell_number(small_table, shape, ia, iv),
                                                      _cell_number(small_table, shape, ja, iv))
                            assert (got_wa, got_jv, got_wv, got_iv) == (wa, jv, wv, iv)


def _blend(lo, hi, w):
    """(1 − w)·lo + w·hi in exact arithmetic, rounded once."""
    return float((1 - w) * Fraction(lo) + w * Fraction(hi))


def test_the_moved_moments_are_the_blend_of_the_neighbours(small_table):
    """gather_cell's α1 terms, against the cells' statistics: m = (1 − w)·m_lo + w·m_hi and
    σ = (1 − w)·σ_lo + w·σ_hi, ratio σ/σ_cell, m_cell the drawn cell's mean, for every shape, α1 interval,
    grid speed and weight, whichever neighbour is drawn. Tolerance 8 ulp of max(|lo|, |hi|): the kernel's w
    (≤ 2 ulp, test above) and three roundings of the blend. The test has power: a weight off by 3·10⁻⁴ w(1 − w)
    (the grid's weight at each point moved by a hundredth of a 3 % bias) moves α2's m past the tolerance."""
    data = small_table.kernel_data
    means, sds = _moments(small_table)
    alphas, speeds = np.asarray(small_table.alpha1_deg), np.asarray(small_table.speed_m_s)
    u = _uniforms(2, 1)[0]
    for shape_name in small_table.shapes:
        cdf = surrogate.mix_cdf(small_table, shape_name)
        shape = small_table.shapes.index(shape_name)
        for ja in range(len(alphas) - 1):
            for iv, speed in enumerate(speeds):
                lo, hi = _cell_number(small_table, shape, ja, iv), _cell_number(small_table, shape, ja + 1, iv)
                for w_target in WEIGHTS:
                    alpha1 = alphas[ja] + w_target * (alphas[ja + 1] - alphas[ja])
                    w = _exact_weight(alphas, ja, alpha1)
                    for u1, here in ((0.0, hi), (0.999999, lo)):
                        u[1] = u1
                        cell = locate(data, cdf, alpha1, speed, u)
                        assert cell[0] == here
                        got_wa, got_wv, ratios, shifts, _, _ = gather_cell(data, cell)
                        assert got_wv == (1.0 if iv == len(speeds) - 1 else 0.0)     # a grid speed
                        where = (shape_name, alpha1, speed, u1)
                        for k in range(6):
                            tol = 8 * EPS * max(abs(sds[lo, k]), abs(sds[hi, k]))
                            sd = _blend(sds[lo, k], sds[hi, k], w)
                            if sds[here, k] > 0.0:
                                assert abs(ratios[k] * sds[here, k] - sd) <= tol + 2 * EPS * sd, (where, k)
                        for i, k in enumerate((0, 2, 5)):      # the shifted variables: α2, s, Ω_z
                            m_cell, m = shifts[2 * i], shifts[2 * i + 1]
                            assert m_cell == means[here, k], (where, k)
                            tol = 8 * EPS * max(abs(means[lo, k]), abs(means[hi, k]))
                            assert abs(m - _blend(means[lo, k], means[hi, k], w)) <= tol, (where, k, m)
                        bias = 0.0003 * float(w * (1 - w)) * abs(means[hi, 0] - means[lo, 0])
                        assert bias > 8 * EPS * max(abs(means[lo, 0]), abs(means[hi, 0])), where


def _state(vx, vy, vz):
    """(α2, β2, s) of a local-frame V⁺ (units of |V⁻|)."""
    s = math.sqrt(vx * vx + vy * vy + vz * vz)
    return math.atan2(vy, vx), math.asin(vz / s), s


def _folded(alpha2, beta2, s):
    """The reflection into the physical range the kernel applies after a move (docs/format.md)."""
    alpha2, s = abs(alpha2), abs(s)
    return (2 * math.pi - alpha2 if alpha2 > math.pi else alpha2, math.pi - beta2 if beta2 > math.pi / 2 else beta2,
            2 - s if s > 1 else s)


def test_a_scaled_draw_is_the_neighbour_s_draw_moved_to_the_blended_moments(small_table):
    """The whole draw between α1 grid points (at a grid speed): for the same uniforms, the draw at α1 is the
    drawn neighbour's draw at its own grid point moved variable by variable, x' = m + (x − m_cell) σ/σ_cell
    (β2, Ω_x, Ω_y only scaled), m and σ blended with the exact weight, folded back into the physical range,
    mirrored by u[11]. The node's state is recovered from its V⁺ with atan2 and asin, so the tolerance is
    1e-12 (units of |V⁻| and |V⁻|/a) rather than ulps."""
    data = small_table.kernel_data
    means, sds = _moments(small_table)
    alphas = np.asarray(small_table.alpha1_deg)
    speed, iv = 150.0, 1
    checked = 0
    for shape_name in small_table.shapes:
        cdf = surrogate.mix_cdf(small_table, shape_name)
        shape = small_table.shapes.index(shape_name)
        for ja in range(len(alphas) - 1):
            for w_target in (0.25, 1 / 3, 0.8):
                alpha1 = alphas[ja] + w_target * (alphas[ja + 1] - alphas[ja])
                w = _exact_weight(alphas, ja, alpha1)
                lo, hi = _cell_number(small_table, shape, ja, iv), _cell_number(small_table, shape, ja + 1, iv)
                m = [_blend(means[lo, k], means[hi, k], w) for k in range(6)]
                sd = [_blend(sds[lo, k], sds[hi, k], w) for k in range(6)]
                for u in _uniforms(3, 40):
                    for u1, ia, here in ((0.0, ja + 1, hi), (0.999999, ja, lo)):
                        u[1] = u1
                        got = draw_velocity(data, cdf, alpha1, speed, u, True)
                        node = draw_velocity(data, cdf, alphas[ia], speed, u, True)
                        assert got[0] == node[0]
                        if node[0] != STATUS_REBOUNDED:
                            continue
                        sign = -1.0 if u[11] < 0.5 else 1.0        # the mirror: β2, Ω_x, Ω_y change sign
                        alpha2, beta2, s = _state(*node[1:4])
                        x = (alpha2, sign * beta2, s, sign * node[4], sign * node[5], node[6])
                        ratio = [sd[k] / sds[here, k] if sds[here, k] > 0 else 1.0 for k in range(6)]
                        moved = [m[k] + (x[k] - means[here, k]) * ratio[k] if k in (0, 2, 5) else x[k] * ratio[k]
                                 for k in range(6)]
                        a2, b2, s2 = _folded(*moved[:3])
                        expected = (s2 * math.cos(b2) * math.cos(a2), s2 * math.cos(b2) * math.sin(a2),
                                    sign * s2 * math.sin(b2), sign * moved[3], sign * moved[4], moved[5])
                        np.testing.assert_allclose(got[1:], expected, rtol=1e-12, atol=1e-12,
                                                   err_msg=f"{shape_name} {alpha1} {u1} {u}")
                        checked += 1
    assert checked > 1800, checked


def test_a_stochastic_draw_is_the_drawn_neighbour_s_draw_bit_for_bit(small_table):
    """Without ``scaled``, a draw between grid points (α1 and |V⁻| both off the grid) is the draw of the
    neighbour cell u[1], u[2] pick, at that cell's grid point, bit for bit: the exact counterpart of
    test_law's weighted mean of the neighbours (stochastic)."""
    data = small_table.kernel_data
    alphas, speeds = np.asarray(small_table.alpha1_deg), np.asarray(small_table.speed_m_s)
    cdf = surrogate.mix_cdf(small_table, "mix")
    for u in _uniforms(4, 200):
        alpha1, speed = 30.0 + 60.0 * u[12], 50.0 + 200.0 * u[9]
        ja, wa = grid_interval(data.alpha1_axis, len(alphas), alpha1)
        jv, wv = grid_interval(data.speed_axis, len(speeds), speed)
        got = draw_velocity(data, cdf, alpha1, speed, u, False)
        node = draw_velocity(data, cdf, alphas[ja + (u[1] < wa)], speeds[jv + (u[2] < wv)], u, False)
        assert np.array(got).tobytes() == np.array(node).tobytes(), (alpha1, speed)


def test_the_speed_move_uses_the_restitution_factor_at_the_incident_speed(small_table):
    """Between grid speeds, the factors the speed move reads are exp(−k V^p) at the incident V (from the
    restitution pieces: within their 1e-12 accuracy, tests/surrogate/test_kernel_math.py) and, exactly, the
    factor stored for the drawn grid speed."""
    data = small_table.kernel_data
    k, p = 0.1, 0.61        # the wall the session's table is built with (the default preset's), checked here
    speeds = np.asarray(small_table.speed_m_s)
    assert data.speed_restitution.tolist() == [math.exp(-k * math.pow(v, p)) for v in speeds.tolist()]
    cdf = surrogate.mix_cdf(small_table, SHAPE)
    u = _uniforms(5, 1)[0]
    for jv in range(len(speeds) - 1):
        for w_target in WEIGHTS:
            speed = speeds[jv] + w_target * (speeds[jv + 1] - speeds[jv])
            for u2, iv in ((0.0, jv + 1), (0.999999, jv)):
                u[2] = u2
                cell = locate(data, cdf, 45.0, speed, u)
                *_, f_target, f_grid = gather_cell(data, cell)
                assert f_grid == data.speed_restitution[iv]
                assert abs(f_target - math.exp(-k * math.pow(speed, p))) <= 1e-12, (speed, f_target)


@pytest.mark.parametrize("axis", ["alpha1", "speed"])
def test_draws_are_continuous_at_a_node(small_table, axis):
    """One double below and above an interior node (60°, 150 m/s), the draw is the node's draw for the same
    uniforms: w → 1 below reads the node's cell with the moments (and, in speed, the restitution factor) of the
    node; w → 0 above reads it unmoved. Tolerance: a few ulp of the blended moments in α1; in speed the
    restitution pieces' 1e-12, times the few units a factor (1 + a(V))/(1 + a(V_j)) multiplies."""
    data = small_table.kernel_data
    cdf = surrogate.mix_cdf(small_table, "mix")
    alpha1, speed = 60.0, 150.0
    tol = 1e-13 if axis == "alpha1" else 1e-11
    for u in _uniforms(6, 300):
        node = draw_velocity(data, cdf, alpha1, speed, u, True)
        for side in (-np.inf, np.inf):
            at = (np.nextafter(alpha1, side), speed) if axis == "alpha1" else (alpha1, np.nextafter(speed, side))
            got = draw_velocity(data, cdf, *at, u, True)
            assert got[0] == node[0]
            np.testing.assert_allclose(got[1:], node[1:], rtol=0.0, atol=tol, err_msg=str((at, u)))
