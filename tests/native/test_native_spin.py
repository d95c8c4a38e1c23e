"""Every wall hit answered in C: rbs_rebound_path and rbs_rebound (uniforms given, or drawn from an rbs_rng) give
the paths and the bits of surrogate.kernels.wall_hit (rebound_path, rebound) for the same uniforms.

Over random incident states (over and beyond the table's grid, the hostile ones of tests.helpers.states.incident_states)
with Ω⁻ zero, below the spin tolerance, at it, above it, large, and NaN or infinite, under the three methods:
the path, the status and V⁺, Ω⁺ of C equal numba's (0 ulp), and rbs_result says the path that answered; the paths
follow the rule (checked here on the states' own numbers, away from the edges); where the table answers under auto,
the table path's bits. Hostile arguments (NULL pointers, a mix of another table, unknown methods and
interpolations, bad Ω⁻, no uniforms, a NULL or all-zero rng) give RBS_INVALID and NaN, never a crash.
"""

from __future__ import annotations

import ctypes

import numpy as np
import pytest

from tests.helpers import python_side as py
from tests.helpers.native_library import (INTERPOLATION_SCALED, INTERPOLATION_STOCHASTIC, INVALID, METHOD_AUTO,
                                          METHOD_DIRECT, METHOD_TABLE, PATH_DIRECT, PATH_NONE, PATH_TABLE, Options,
                                          Result, Rng, hit, options, ref)
from tests.helpers.states import incident_states, max_ulp, uniforms

AUTO, TABLE, DIRECT = METHOD_AUTO, METHOD_TABLE, METHOD_DIRECT
SCALED, STOCHASTIC = INTERPOLATION_SCALED, INTERPOLATION_STOCHASTIC

COUNT = 2500        # states per method: the direct path runs the model (microseconds each, twice)
METHODS = {"auto": AUTO, "table": TABLE, "direct": DIRECT}
# spin kinds: Ω⁻ = 0, |Ω⁻|a/|V⁻| = tolerance/2, = tolerance, = 2 tolerance, uniform in [0.01, 1.5], non-finite
ZERO, BELOW, AT, ABOVE, LARGE, HOSTILE = range(6)


def _spins(rng, V, a):
    """Ω⁻ (rad/s) of each state and its kind: random directions, |Ω⁻| a/|V⁻| set by the kind."""
    count = len(a)
    kind = rng.integers(0, 6, count)
    ratio = np.select([kind == BELOW, kind == AT, kind == ABOVE, kind == LARGE],
                      [0.5 * py.SPIN_TOLERANCE, py.SPIN_TOLERANCE, 2.0 * py.SPIN_TOLERANCE,
                       rng.uniform(0.01, 1.5, count)], 0.0)
    axis = rng.standard_normal((count, 3))
    axis /= np.linalg.norm(axis, axis=1)[:, None]
    with np.errstate(all="ignore"):
        omega = (ratio * np.linalg.norm(V, axis=1) / a)[:, None] * axis
    hostile = kind == HOSTILE
    omega[hostile] = 1.0
    omega[hostile, rng.integers(0, 3, hostile.sum())] = rng.choice([np.nan, np.inf, -np.inf], hostile.sum())
    return np.ascontiguousarray(omega), kind


def _incidence(V, n):
    """α1 (deg) and |V⁻| (m/s) of each state, NumPy's arithmetic."""
    with np.errstate(all="ignore"):
        speed = np.linalg.norm(V, axis=1)
        alpha1 = np.degrees(np.arcsin(np.clip(-np.einsum("ij,ij->i", V, n) / speed, -1.0, 1.0)))
    return alpha1, speed


@pytest.fixture(scope="module")
def spin_case(table_pair):
    """The table pair, a weighted mix over every shape of the table, states, spins and uniforms."""
    table, native_table = table_pair
    shapes = list(table.shapes)
    weights = dict(zip(shapes, np.arange(1.0, len(shapes) + 1) / np.arange(1.0, len(shapes) + 1).sum()))
    mix = native_table.mix(weights)
    V, omega, kind, n, a, u = spin_states(table)
    return table, native_table, mix, py.mix_cdf(table, weights), V, omega, kind, n, a, u


def spin_states(table):
    """COUNT incident states (tests.helpers.states.incident_states, over and beyond the grid), spins, uniforms.

    Speeds below 1e-6 or above 1e6 m/s are moved to the grid's top speed: numba's direct model does not
    return at |V⁻| = 1e-160 m/s (it stays in direct_model.rotation.rotation_init; C answers RBS_FAILED
    there), and test_native_bits covers those speeds on the table path."""
    rng = np.random.default_rng(28)
    (v_lo, v_hi) = table.speed_range
    V, n, a = incident_states(rng, COUNT, (0.0, 90.0), (0.3 * v_lo, 1.5 * v_hi))
    with np.errstate(over="ignore"):
        speed = np.linalg.norm(V, axis=1)
    extreme = np.isfinite(speed) & (speed > 0.0) & ((speed < 1e-6) | (speed > 1e6))
    V[extreme] *= (v_hi / speed[extreme])[:, None]
    omega, kind = _spins(rng, V, a)
    u = uniforms(rng, COUNT, hostile=0.01)
    return V, omega, kind, n, a, u


def _numba(table, cdf, V, omega, n, a, u, method, scaled=True):
    return py.rebound(table.kernel_data, table.direct_parameters, table.shape_arrays, table.model_shapes, cdf,
                      tuple(V), tuple(omega), tuple(n), a, u, method, scaled)


@pytest.mark.parametrize("method", sorted(METHODS))
def test_paths_and_bits_equal_numba(spin_case, method):
    """rbs_rebound_path and rbs_rebound = numba's rebound_path and rebound; rbs_result names the path that answered
    (rbs_rebound_path's), the shape the mix gave (u[0]) and, on the table path, no collision count; an invalid hit
    names no path and no shape."""
    table, native_table, mix, cdf, V, omega, kind, n, a, u = spin_case
    code = METHODS[method]
    paths, status = np.empty(COUNT, dtype=int), np.empty(COUNT, dtype=int)
    worst = 0.0
    for i in range(COUNT):
        paths[i] = native_table.rebound_path(V[i], omega[i], n[i], a[i], code)
        assert paths[i] == py.rebound_path(table.kernel_data, tuple(V[i]), tuple(omega[i]), tuple(n[i]), a[i],
                                           code), i
        result, _ = native_table.hit(mix, V[i], omega[i], n[i], a[i], u[i], method=code)
        st, v, w = result.status, np.array(result.V[:]), np.array(result.Omega[:])
        mine = _numba(table, cdf, V[i], omega[i], n[i], a[i], u[i], code)
        # the whole record, field by field: numba's Hit is rbs_result (the wall work: either path's, the table's
        # drawn with its rebound; NaN for an invalid hit)
        assert (st, result.path, result.shape, result.n_collisions) == mine[:4], (i, result, mine)
        work = np.array([result.wall_work_normal, result.wall_work_tangential])
        assert work.tobytes() == np.array([mine.wall_work_normal, mine.wall_work_tangential]).tobytes(), i
        assert np.isnan(work).all() == (st == INVALID), (i, work)
        worst = max(worst, max_ulp(v, np.array(mine.V)), max_ulp(w, np.array(mine.Omega)))
        status[i] = st
        if st == INVALID:
            assert (result.path, result.shape, result.n_collisions) == (PATH_NONE, -1, -1), i
        else:
            assert result.path == paths[i] and result.shape == py.mix_shape(cdf, u[i][0]), i
            assert (result.n_collisions == -1) == (result.path == PATH_TABLE), (i, result.n_collisions)
    print(f"\n{method}: paths table {np.sum(paths == PATH_TABLE)}, direct {np.sum(paths == PATH_DIRECT)}, invalid "
          f"{np.sum(paths == INVALID)}; statuses {np.unique(status, return_counts=True)}; largest ulp difference "
          f"{worst}")
    assert worst == 0.0
    valid = paths != INVALID
    assert np.all(~valid[kind == HOSTILE]) and np.all(status[kind == HOSTILE] == INVALID)
    expected = {"table": PATH_TABLE, "direct": PATH_DIRECT}.get(method)
    if expected is not None:
        assert np.all(paths[valid] == expected)
    # both paths rebound, in numbers
    assert np.sum((status == py.STATUS_REBOUNDED) & (paths == (PATH_TABLE if method == "table" else PATH_DIRECT))) \
        > 0.4 * COUNT


def test_auto_picks_the_path_by_spin_and_grid(spin_case):
    """Below the tolerance and inside the grid: the table; above it or outside the grid: the direct model
    (away from the grid's edges by 1e-9, where NumPy's α1 and |V⁻| could fall on the other side)."""
    table, native_table, mix, cdf, V, omega, kind, n, a, u = spin_case
    alpha1, speed = _incidence(V, n)
    (a_lo, a_hi), (v_lo, v_hi) = table.alpha1_range, table.speed_range
    eps = 1e-9
    inside = (alpha1 > a_lo * (1 + eps)) & (alpha1 < a_hi * (1 - eps)) & (speed > v_lo * (1 + eps)) & \
        (speed < v_hi * (1 - eps))
    outside = (alpha1 < a_lo * (1 - eps)) | (alpha1 > a_hi * (1 + eps)) | (speed < v_lo * (1 - eps)) | \
        (speed > v_hi * (1 + eps))
    paths = np.array([native_table.rebound_path(V[i], omega[i], n[i], a[i], AUTO) for i in range(COUNT)])
    valid = paths != INVALID
    cases = {"no spin, inside": valid & inside & (kind == ZERO), "below, inside": valid & inside & (kind == BELOW),
             "above, inside": valid & inside & (kind == ABOVE), "large": valid & (kind == LARGE),
             "no spin, outside": valid & outside & (kind == ZERO)}
    assert min(c.sum() for c in cases.values()) >= 20, {k: int(c.sum()) for k, c in cases.items()}
    assert np.all(paths[cases["no spin, inside"] | cases["below, inside"]] == PATH_TABLE)
    assert np.all(paths[cases["above, inside"] | cases["large"] | cases["no spin, outside"]] == PATH_DIRECT)
    # at the tolerance itself either path may answer (rounding of |Ω⁻|): C and numba agree there (above)
    at = valid & inside & (kind == AT)
    assert at.sum() >= 20


def test_table_path_is_the_table_s_draw_bit_for_bit(spin_case):
    """Where auto takes the table, and always under table, the answer is that of the table path alone (the
    test-only library's rbs_table_rebound, Ω⁻ not given) with the same uniforms, both interpolations."""
    table, native_table, mix, cdf, V, omega, kind, n, a, u = spin_case
    checked = 0
    for interpolation in (SCALED, STOCHASTIC):
        for i in range(COUNT):
            for method in (AUTO, TABLE):
                if native_table.rebound_path(V[i], omega[i], n[i], a[i], method) != PATH_TABLE:
                    continue
                st, v, w = native_table.rebound(mix, V[i], omega[i], n[i], a[i], u[i], method=method,
                                                interpolation=interpolation)
                st_t, v_t, w_t = _table_path_alone(native_table, mix, V[i], n[i], a[i], u[i], interpolation)
                assert st == st_t and max_ulp(v, v_t) == 0 and max_ulp(w, w_t) == 0, (i, method)
                checked += 1
    assert checked > COUNT


def _table_path_alone(native_table, mix, V, n, a, u, interpolation):
    """(status, V⁺, Ω⁺) of the test-only library's rbs_table_rebound: the table path without the path decision."""
    arrays = [np.ascontiguousarray(x, dtype=np.float64) for x in (V, n, u)]
    V_out, W_out = np.full(3, 7.0), np.full(3, 7.0)
    status = native_table.lib.internal.rbs_table_rebound(native_table.handle, mix.pointer, arrays[0].ctypes.data,
                                                         arrays[1].ctypes.data, float(a), arrays[2].ctypes.data,
                                                         interpolation, V_out.ctypes.data, W_out.ctypes.data)
    return status, V_out, W_out


def test_rng_form_draws_thirteen_uniforms_whatever_the_path(spin_case, native):
    """rbs_rebound with hit.rng (hit.u NULL) = rbs_rng_fill of 13 uniforms, then rbs_rebound with them, keyed or
    not; the stream advances by 13 per hit whatever the path and the status (invalid hits too)."""
    table, native_table, mix, cdf, V, omega, kind, n, a, u = spin_case
    state = py.seed_state(2811)
    for i in range(0, COUNT, 5):
        for method in METHODS.values():
            u_i, after = native.fill(state, 13)
            st, v, w, advanced = native_table.rebound(mix, V[i], omega[i], n[i], a[i], state=state, method=method)
            st_u, v_u, w_u = native_table.rebound(mix, V[i], omega[i], n[i], a[i], u_i, method=method)
            assert np.array_equal(advanced, after), i
            assert st == st_u and max_ulp(v, v_u) == 0 and max_ulp(w, w_u) == 0, i
            state = advanced


def test_hit_u_is_taken_before_hit_rng(spin_case, native):
    """A hit given both uniforms and an rng takes the uniforms and leaves the rng alone."""
    table, native_table, mix, cdf, V, omega, kind, n, a, u = spin_case
    state = py.seed_state(2812)
    for i in range(0, COUNT, 50):
        for method in METHODS.values():
            rng = Rng((ctypes.c_uint64 * 4)(*map(int, state)))
            h, kept = hit(V[i], omega[i], n[i], a[i], u[i], rng)
            result = Result()
            assert native.c.rbs_rebound(native_table.handle, mix.pointer, ref(h), ref(options(method)),
                                        ref(result)) == result.status
            st, v, w = native_table.rebound(mix, V[i], omega[i], n[i], a[i], u[i], method=method)
            assert result.status == st and max_ulp(np.array(result.V[:]), v) == 0, i
            assert max_ulp(np.array(result.Omega[:]), w) == 0, i
            assert list(rng.s) == [int(x) for x in state], i


def _raw_rebound(c, table_handle, mix_pointer, h, opts, result=True):
    """rbs_rebound on raw records: (returned status, the result record, prefilled with 7.0, or None)."""
    out = Result(status=77, path=77, shape=77, n_collisions=77) if result else None
    if out is not None:
        out.V[:], out.Omega[:] = [7.0] * 3, [7.0] * 3
    st = c.rbs_rebound(table_handle, mix_pointer, ref(h), ref(opts), ref(out))
    return st, out


def test_hostile_arguments_give_invalid_and_nan(spin_case, native, small_table_path, grain_table_path):
    table, native_table, mix, cdf, V, omega, kind, n, a, u = spin_case
    c, h = native.c, native_table.handle
    with np.errstate(over="ignore"):
        i = int(np.flatnonzero((kind == LARGE) & (np.linalg.norm(V, axis=1) > 0))[0])
    Vi, Wi, ni, ui = (np.ascontiguousarray(x, dtype=np.float64) for x in (V[i], omega[i], n[i], u[i]))
    assert native_table.rebound_path(Vi, Wi, ni, a[i], AUTO) in (PATH_TABLE, PATH_DIRECT)
    good, kept = hit(Vi, Wi, ni, a[i], ui)
    assert _raw_rebound(c, h, mix.pointer, good, None)[0] != INVALID     # the good arguments are good
    no_uniforms, _ = hit(Vi, Wi, ni, a[i])
    # mixes of another table: of the grain table (2 shapes), and of another rbs_table of the same file
    other_tables = [native.table(grain_table_path), native.table(small_table_path)]
    other_mixes = [t.mix() for t in other_tables]
    cases = {"NULL table": (None, mix.pointer, good, None), "NULL mix": (h, None, good, None),
             "NULL hit": (h, mix.pointer, None, None), "no u and no rng": (h, mix.pointer, no_uniforms, None),
             "method 3": (h, mix.pointer, good, Options(method=3)),
             "method -1": (h, mix.pointer, good, Options(method=-1)),
             "interpolation 5": (h, mix.pointer, good, Options(interpolation=5)),
             "interpolation -1": (h, mix.pointer, good, Options(interpolation=-1)),
             "mix of another table": (h, other_mixes[0].pointer, good, None),
             "mix of another rbs_table of the same file": (h, other_mixes[1].pointer, good, None)}
    for label, args in cases.items():
        st, result = _raw_rebound(c, *args)
        assert st == result.status == INVALID, (label, st, result.status)
        assert np.isnan(result.V[:]).all() and np.isnan(result.Omega[:]).all(), label
        assert (result.path, result.shape) == (PATH_NONE, -1), label
    st, _ = _raw_rebound(c, h, mix.pointer, good, None, result=False)
    assert st == INVALID, "NULL result"
    for bad in (np.nan, np.inf, -np.inf):
        for k in range(3):
            W_bad = Wi.copy()
            W_bad[k] = bad
            for method in METHODS.values():
                assert native_table.rebound_path(Vi, W_bad, ni, a[i], method) == PATH_NONE
                st, v, w = native_table.rebound(mix, Vi, W_bad, ni, a[i], ui, method=method)
                assert st == INVALID and np.isnan(v).all() and np.isnan(w).all(), (bad, k, method)
    assert c.rbs_rebound_path(None, ref(good), None) == PATH_NONE
    assert c.rbs_rebound_path(h, None, None) == PATH_NONE
    for method in (3, -1):
        assert c.rbs_rebound_path(h, ref(good), ref(Options(method=method))) == PATH_NONE
    # a NULL or all-zero rng (u NULL): invalid, the state untouched
    for rng in (None, Rng()):
        h_rng, _ = hit(Vi, Wi, ni, a[i], rng=rng)
        st, result = _raw_rebound(c, h, mix.pointer, h_rng, None)
        assert st == INVALID and np.isnan(result.V[:]).all() and np.isnan(result.Omega[:]).all()
        assert rng is None or list(rng.s) == [0, 0, 0, 0]
    del kept
    for t in other_tables:
        t.close()
