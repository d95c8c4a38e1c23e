"""Every wall hit answered in C: rbs_rebound_path, rbs_rebound and rbs_rebound_rng give the paths and
the bits of surrogate.kernels.wall_hit (rebound_path, rebound) for the same uniforms.

Over random incident states (over and beyond the table's grid, the hostile ones of tests.helpers.states.incident_states)
with Ω⁻ zero, below the spin tolerance, at it, above it, large, and NaN or infinite, under the three methods:
the path, the status and V⁺, Ω⁺ of C equal numba's (0 ulp); the paths follow the rule (checked here on the
states' own numbers, away from the edges); where the table answers under auto, the table path's bits. Hostile
arguments (NULL pointers, unknown methods, bad Ω⁻, a NULL or all-zero rng) give RBS_INVALID and NaN, never a
crash.
"""

from __future__ import annotations

import ctypes

import numpy as np
import pytest

from tests.helpers import python_side as py
from tests.helpers.native_library import (AUTO, DIRECT, INVALID, PATH_DIRECT, PATH_TABLE, SCALED, STOCHASTIC, TABLE, Mix,
                                          Rng, _ptr)
from tests.helpers.states import incident_states, max_ulp, uniforms

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
    assert table.direct_parameters is not None, "the small table must record the direct model's parameters"
    shapes = list(table.shapes)
    weights = dict(zip(shapes, np.arange(1.0, len(shapes) + 1) / np.arange(1.0, len(shapes) + 1).sum()))
    code, mix, message = native_table.mix_from_weights(weights)
    assert code == 0, message
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
    table, native_table, mix, cdf, V, omega, kind, n, a, u = spin_case
    code = METHODS[method]
    paths, status = np.empty(COUNT, dtype=int), np.empty(COUNT, dtype=int)
    worst = 0.0
    for i in range(COUNT):
        paths[i] = native_table.rebound_path(V[i], omega[i], n[i], a[i], code)
        assert paths[i] == py.rebound_path(table.kernel_data, tuple(V[i]), tuple(omega[i]), tuple(n[i]), a[i],
                                           code), i
        st, v, w = native_table.rebound(mix, V[i], omega[i], n[i], a[i], u[i], code)
        st_py, v_py, w_py = _numba(table, cdf, V[i], omega[i], n[i], a[i], u[i], code)
        assert st == st_py, (i, st, st_py)
        worst = max(worst, max_ulp(v, np.array(v_py)), max_ulp(w, np.array(w_py)))
        status[i] = st
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


def test_table_path_is_rbs_table_rebound_bit_for_bit(spin_case):
    """Where auto takes the table, and always under table, the answer is rbs_table_rebound's with the same
    uniforms (both interpolations)."""
    table, native_table, mix, cdf, V, omega, kind, n, a, u = spin_case
    checked = 0
    for interpolation in (SCALED, STOCHASTIC):
        for i in range(COUNT):
            for method in (AUTO, TABLE):
                if native_table.rebound_path(V[i], omega[i], n[i], a[i], method) != PATH_TABLE:
                    continue
                st, v, w = native_table.rebound(mix, V[i], omega[i], n[i], a[i], u[i], method, interpolation)
                st_t, v_t, w_t = native_table.table_rebound(mix, V[i], n[i], a[i], u[i], interpolation)
                assert st == st_t and max_ulp(v, v_t) == 0 and max_ulp(w, w_t) == 0, (i, method)
                checked += 1
    assert checked > COUNT


def test_rng_form_draws_thirteen_uniforms_whatever_the_path(spin_case, native):
    """rbs_rebound_rng = rbs_rng_fill of 13 uniforms, then rbs_rebound; the stream advances by 13 per
    hit whatever the path and the status (invalid hits too)."""
    table, native_table, mix, cdf, V, omega, kind, n, a, u = spin_case
    state = py.seed_state(2811)
    for i in range(0, COUNT, 5):
        for method in METHODS.values():
            u_i, after = native.fill(state, 13)
            st, v, w, advanced = native_table.rebound_rng(mix, V[i], omega[i], n[i], a[i], state, method)
            st_u, v_u, w_u = native_table.rebound(mix, V[i], omega[i], n[i], a[i], u_i, method)
            assert np.array_equal(advanced, after), i
            assert st == st_u and max_ulp(v, v_u) == 0 and max_ulp(w, w_u) == 0, i
            state = advanced


def test_the_0x_name_rbs_rebound_spin_is_rbs_rebound_rng(spin_case):
    """rbs_rebound_spin, kept for programs written against 0.x: rbs_rebound_rng's statuses and bits, its stream
    advanced alike, under every method."""
    table, native_table, mix, cdf, V, omega, kind, n, a, u = spin_case
    state = py.seed_state(2812)
    for i in range(0, COUNT, 25):
        for method in METHODS.values():
            new = native_table.rebound_rng(mix, V[i], omega[i], n[i], a[i], state, method)
            old = native_table.rebound_rng(mix, V[i], omega[i], n[i], a[i], state, method, symbol="rbs_rebound_spin")
            assert new[0] == old[0], (i, method)
            assert all(np.array_equal(x.view(np.uint64), y.view(np.uint64)) for x, y in zip(new[1:], old[1:])), i
            state = new[3]


def test_hostile_arguments_give_invalid_and_nan(spin_case, native):
    table, native_table, mix, cdf, V, omega, kind, n, a, u = spin_case
    c, h = native.c, native_table.handle
    with np.errstate(over="ignore"):
        i = int(np.flatnonzero((kind == LARGE) & (np.linalg.norm(V, axis=1) > 0))[0])
    Vi, Wi, ni, ui = (np.ascontiguousarray(x, dtype=np.float64) for x in (V[i], omega[i], n[i], u[i]))
    assert native_table.rebound_path(Vi, Wi, ni, a[i], AUTO) in (PATH_TABLE, PATH_DIRECT)

    def rebound(table_handle, mix_arg, V_, W_, n_, a_, u_, method, interpolation=SCALED, outputs=True):
        out = (np.full(3, 7.0), np.full(3, 7.0))
        st = c.rbs_rebound(table_handle, mix_arg, V_, W_, n_, ctypes.c_double(a_), u_, method, interpolation,
                           _ptr(out[0]) if outputs else None, _ptr(out[1]) if outputs else None)
        return st, out

    mix_ref = ctypes.byref(mix)
    good = (_ptr(Vi), _ptr(Wi), _ptr(ni), a[i], _ptr(ui))
    wrong_mix = Mix(mix.n_shapes + 1, mix.cdf)
    cases = {"NULL table": (None, mix_ref, *good, AUTO), "NULL mix": (h, None, *good, AUTO),
             "NULL V": (h, mix_ref, None, *good[1:], AUTO), "NULL Omega": (h, mix_ref, good[0], None, *good[2:], AUTO),
             "NULL n": (h, mix_ref, *good[:2], None, *good[3:], AUTO), "NULL u": (h, mix_ref, *good[:4], None, AUTO),
             "method 3": (h, mix_ref, *good, 3), "method -1": (h, mix_ref, *good, -1),
             "mix of another shape count": (h, ctypes.byref(wrong_mix), *good, AUTO)}
    for label, args in cases.items():
        st, (v, w) = rebound(*args)
        assert st == INVALID and np.isnan(v).all() and np.isnan(w).all(), label
    st, (v, w) = rebound(h, mix_ref, *good, AUTO, interpolation=5)
    assert st == INVALID and np.isnan(v).all(), "unknown interpolation"
    st, _ = rebound(h, mix_ref, *good, AUTO, outputs=False)
    assert st == INVALID, "NULL outputs"
    for bad in (np.nan, np.inf, -np.inf):
        for k in range(3):
            W_bad = Wi.copy()
            W_bad[k] = bad
            for method in METHODS.values():
                assert native_table.rebound_path(Vi, W_bad, ni, a[i], method) == INVALID
                st, v, w = native_table.rebound(mix, Vi, W_bad, ni, a[i], ui, method)
                assert st == INVALID and np.isnan(v).all() and np.isnan(w).all(), (bad, k, method)
    assert c.rbs_rebound_path(None, _ptr(Vi), _ptr(Wi), _ptr(ni), ctypes.c_double(a[i]), AUTO) == INVALID
    assert c.rbs_rebound_path(h, _ptr(Vi), None, _ptr(ni), ctypes.c_double(a[i]), AUTO) == INVALID
    # a NULL or all-zero rng: invalid, the state untouched
    for rng in (None, ctypes.byref(Rng())):
        out = (np.empty(3), np.empty(3))
        st = c.rbs_rebound_rng(h, mix_ref, _ptr(Vi), _ptr(Wi), _ptr(ni), ctypes.c_double(a[i]), rng, AUTO, SCALED,
                               _ptr(out[0]), _ptr(out[1]))
        assert st == INVALID and np.isnan(out[0]).all() and np.isnan(out[1]).all()
