"""The C free flight (native/src/rotation.c) gives the bits of direct_model.rotation.

For random and adversarial bodies and states in every mode -- static (ell = 0), steady (ell along a
principal axis, including the middle one; a sphere; an axisymmetric body spinning in its degenerate
plane), general (Jacobi's theta series and the Landen chain with both forms of the third-kind integral,
axisymmetric and nearly axisymmetric bodies,
inertias and momenta scaled by 1e+-40), the separatrix (exactly, and within the rounding of R0^T ell) and
states next to it (k' down to 1e-19) -- the whole parameter array of rbs_rotation_init equals that of
rotation_init bit for bit, and R and omega of rbs_rotation_at equal those of rotation_at at times from 0 to
1e12 periods, negative, and beyond the int64 range of the period count. Carlson's R_F and R_J equal numba's
on random arguments. The largest ulp difference is printed (run with -s) and must be 0. At t = +-inf or NaN
both give NaN where the other does, the sign bit of a NaN may differ (which operand of a commutative
operation the compilers put first decides which NaN the x86 instruction passes on); the count is printed.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from tests.helpers import python_side as py
from tests.helpers.states import max_ulp

STATES_PER_KIND = 400
PREFILL = -7.25     # both parameter arrays start with it: the entries rotation_init leaves alone must agree too


def _rotation(rng):
    """A random rotation matrix (uniform quaternion)."""
    w, x, y, z = rng.standard_normal(4)
    s = 2.0 / (w * w + x * x + y * y + z * z)
    return np.array([[1 - s * (y * y + z * z), s * (x * y - w * z), s * (x * z + w * y)],
                     [s * (x * y + w * z), 1 - s * (x * x + z * z), s * (y * z - w * x)],
                     [s * (x * z - w * y), s * (y * z + w * x), 1 - s * (x * x + y * y)]])


def _signed_permutation(rng):
    """A proper rotation permuting the axes with signs (exact: R0^T ell has no rounding)."""
    while True:
        R = np.eye(3)[rng.permutation(3)] * rng.choice([-1.0, 1.0], 3)[:, None]
        if np.linalg.det(R) > 0:
            return R


HARMONIC_ENDS = ((1.0, 3.0), (1.0, 7.0), (3.0, 5.0), (2.0, 6.0))   # their harmonic means are exact doubles


def _harmonic_body(rng):
    """Principal values (lo, mid, hi) with mid the harmonic mean of lo and hi, so (hi - mid) lo =
    (mid - lo) hi: with m_mid arbitrary and |m_lo| = |m_hi| (squares exact) the state lies exactly on the
    separatrix (L^2 = 2E K_mid)."""
    lo, hi = HARMONIC_ENDS[rng.integers(len(HARMONIC_ENDS))]
    mid = 2.0 * lo * hi / (lo + hi)
    scale = 2.0 ** int(rng.integers(-20, 21))
    return lo * scale, mid * scale, hi * scale


def _place(values, order):
    """Values (lo, mid, hi) put on the body axes ``order`` (order[i] = body axis of value i)."""
    out = np.empty(3)
    out[list(order)] = values
    return out


def _states(kind, rng, count):
    """(K, R0, ell) triples of one kind (module docstring)."""
    out = []
    for _ in range(count):
        R0 = _rotation(rng)
        K = np.exp(rng.uniform(-2.0, 2.0, 3))
        m = rng.standard_normal(3) * math.exp(rng.uniform(-3.0, 3.0))
        if kind == "general":
            pass
        elif kind == "scaled":
            K *= 10.0 ** rng.uniform(-40.0, 40.0)
            m *= 10.0 ** rng.uniform(-40.0, 40.0)
        elif kind == "static":
            m = rng.choice([0.0, -0.0], 3)
        elif kind == "steady_axis":
            axis = rng.integers(0, 3)
            m = np.zeros(3)
            m[axis] = rng.choice([-1.0, 1.0]) * math.exp(rng.uniform(-3.0, 3.0))
            if rng.random() < 0.3:
                R0 = _signed_permutation(rng)
            if rng.random() < 0.3:      # the middle axis (unstable, stays put)
                K = _place(np.sort(K), np.roll([0, 1, 2], -int(axis) + 1))
        elif kind == "sphere":
            K[:] = K[0]
        elif kind == "axisymmetric_plane":
            unique = rng.integers(0, 3)
            K[[i for i in range(3) if i != unique]] = K[(unique + 1) % 3]
            m[unique] = 0.0
        elif kind == "axisymmetric":
            unique = rng.integers(0, 3)
            K[[i for i in range(3) if i != unique]] = K[(unique + 1) % 3]
        elif kind == "nearly_axisymmetric":
            unique = rng.integers(0, 3)
            pair = [i for i in range(3) if i != unique]
            K[pair[1]] = K[pair[0]] * (1.0 + 10.0 ** rng.uniform(-15.0, -6.0) * rng.choice([-1.0, 1.0]))
        elif kind in ("separatrix", "separatrix_rounded", "near_separatrix"):
            order = rng.permutation(3)
            K = _place(_harmonic_body(rng), order)
            lo = rng.choice([-1.0, 1.0]) * math.ldexp(float(rng.integers(1, 2 ** 20)), -10)
            mid = rng.standard_normal()
            hi = rng.choice([-1.0, 1.0]) * abs(lo)
            if kind == "near_separatrix":   # |m_hi| a few ulps off; |m_lo| / |m_mid| down to 2^-44, above the
                hi = hi * (1.0 + rng.choice([-1.0, 1.0]) * rng.integers(1, 5) * 2.0 ** -52)   # 16 eps snap
                scale = 2.0 ** -int(rng.integers(0, 45))
                lo, hi = lo * scale, hi * scale
            m = _place((lo, mid, hi), order)
            if kind != "separatrix_rounded":
                R0 = _signed_permutation(rng)
        else:
            raise ValueError(kind)
        out.append((K, np.ascontiguousarray(R0), R0 @ m))
    return out


KINDS = ("general", "scaled", "static", "steady_axis", "sphere", "axisymmetric_plane", "axisymmetric",
         "nearly_axisymmetric", "separatrix", "separatrix_rounded", "near_separatrix")
MODES = {"general": {2.0, 4.0}, "static": {0.0}, "steady_axis": {1.0}, "sphere": {1.0}, "axisymmetric_plane": {1.0},
         "axisymmetric": {2.0}, "nearly_axisymmetric": {2.0, 4.0}, "separatrix": {3.0}, "near_separatrix": {2.0}}


def _times(rng, params):
    """Times over a flight: 0, within a period, many periods, 1e12 periods, negative, and so far out that
    the period count leaves the int64 range; plus the non-finite ones."""
    mode = params[0]
    if mode == 1.0:
        period = 2.0 * math.pi / math.sqrt(float(np.sum(params[10:13] ** 2)))
    elif mode == 2.0:
        period = params[21] / abs(params[19])
    elif mode == 3.0:
        period = 1.0 / abs(params[19])
    elif mode == 4.0:
        period = math.pi / abs(params[46])
    else:
        period = 1.0
    spans = [0.0, 1e-3, 0.5, 1.0, 10.0, 1e3, 1e6, 1e12]
    t = [0.0, period, -period] + [s * period * rng.uniform(-1.0, 1.0) for s in spans]
    return t + [period * 1e20 * rng.uniform(0.5, 1.0), math.inf, -math.inf, math.nan]


def _same(a, b):
    """Bit-identical, NaN meeting NaN counted equal (their payloads are compared separately)."""
    a, b = np.asarray(a), np.asarray(b)
    nan = np.isnan(a) & np.isnan(b)
    return bool(np.array_equal(np.where(nan, 0.0, a).view(np.uint64), np.where(nan, 0.0, b).view(np.uint64)))


@pytest.mark.parametrize("kind", KINDS)
def test_rotation_bit_identical(native, kind):
    """rbs_rotation_init's whole parameter array and rbs_rotation_at's R and omega equal numba's."""
    rng = np.random.default_rng(KINDS.index(kind) + 2027)
    worst_params = worst_at = 0.0
    modes, differ, nan_payloads = set(), [], 0
    for K, R0, ell in _states(kind, rng, STATES_PER_KIND):
        p_py, p_c = np.full(py.ROT_PARAMS_SIZE, PREFILL), np.full(py.ROT_PARAMS_SIZE, PREFILL)
        py.rotation_init(K, R0, ell, p_py)
        native.rotation_init(K, R0, ell, p_c)
        modes.add(float(p_py[0]))
        worst_params = max(worst_params, max_ulp(p_py, p_c))
        if not _same(p_py, p_c):
            differ.append(("params", K, R0, ell))
            continue
        for t in _times(rng, p_py):
            R_py, w_py = np.empty((3, 3)), np.empty(3)
            py.rotation_at(p_py, t, R_py, w_py)
            R_c, w_c = native.rotation_at(p_c, t)
            worst_at = max(worst_at, max_ulp(R_py, R_c), max_ulp(w_py, w_c))
            if not (_same(R_py, R_c) and _same(w_py, w_c)):
                differ.append(("at", K, R0, ell, t))
            nan_payloads += int(not np.array_equal(np.concatenate([R_py.ravel(), w_py]).view(np.uint64),
                                                   np.concatenate([R_c.ravel(), w_c]).view(np.uint64)))
    print(f"\n{kind}: modes {sorted(modes)}, largest ulp difference: params {worst_params:g}, R and omega "
          f"{worst_at:g}; {nan_payloads} evaluation(s) with other NaN bits")
    assert not differ, f"{len(differ)} differ, first {differ[0]}"
    assert worst_params == 0.0 and worst_at == 0.0
    if kind in MODES:
        assert modes == MODES[kind], modes


def test_states_cover_both_climbs_of_the_landen_chain(native):
    """The states of the test above include both forms of the third-kind integral (beta <= 1 and > 1),
    Landen chains of at most 7 levels (the climb in homogeneous coordinates) and of more (one division per
    level), and k' from above 1e-9 down to below 1e-18 next to the separatrix. (k' cannot go much lower:
    |m_lo| stays above 16 eps L, or the state counts as a steady rotation, and |m_hi| - |m_lo| is at least an
    ulp; both bound |H|, so k'^2, from below.)"""
    levels, forms, k_prime = set(), set(), []
    for kind in ("general", "near_separatrix"):
        rng = np.random.default_rng(KINDS.index(kind) + 2027)
        for K, R0, ell in _states(kind, rng, STATES_PER_KIND):
            params = np.full(py.ROT_PARAMS_SIZE, PREFILL)
            native.rotation_init(K, R0, ell, params)
            levels.add(int(params[43]))
            forms.add(float(params[29]))
            if kind == "near_separatrix":
                k_prime.append(0.5 * params[45 + 24])      # 1 - k_1 = 2 k' / (1 + k') ~ 2 k'
    print(f"\nLanden levels {sorted(levels)}; next to the separatrix k' from {min(k_prime):.1e} to {max(k_prime):.1e}")
    assert min(levels) <= 7 < max(levels), levels
    assert forms == {0.0, 1.0}, forms
    assert min(k_prime) < 1e-18 and max(k_prime) > 1e-9


def test_states_cover_both_forms_of_the_theta_series(native):
    """The general states of the bit test above take the theta mode with w through theta_4 (beta <= k) and
    through theta_1 (beta > k), a hundred or more of each."""
    rng = np.random.default_rng(KINDS.index("general") + 2027)
    reflected = []
    for K, R0, ell in _states("general", rng, STATES_PER_KIND):
        params = np.full(py.ROT_PARAMS_SIZE, PREFILL)
        native.rotation_init(K, R0, ell, params)
        if params[0] == 4.0:
            reflected.append(params[90])
    assert reflected.count(0.0) >= 100 and reflected.count(1.0) >= 100, reflected


def test_carlson_bit_identical(native):
    """R_F and R_J on random arguments over 1e+-30, with one of x, y, z zero, equal arguments, p near x."""
    rng = np.random.default_rng(7)
    n = 20000
    args = np.exp(rng.uniform(-69.0, 69.0, (n, 4)))
    args[: n // 8, rng.integers(0, 3)] = 0.0
    args[n // 8: n // 4, 1] = args[n // 8: n // 4, 0]
    args[n // 4: 3 * n // 8, 3] = args[n // 4: 3 * n // 8, 0] * (1.0 + 1e-9 * rng.standard_normal(n // 8))
    rf_py = np.array([py.carlson_rf(*a[:3]) for a in args])
    rf_c = np.array([native.internal.rbs_carlson_rf(*a[:3]) for a in args])
    rj_py = np.array([py.carlson_rj(*a) for a in args])
    rj_c = np.array([native.internal.rbs_carlson_rj(*a) for a in args])
    ulp = max(max_ulp(rf_py, rf_c), max_ulp(rj_py, rj_c))
    print(f"\nCarlson R_F, R_J over {n} arguments: largest ulp difference {ulp:g}")
    assert ulp == 0.0 and _same(rf_py, rf_c) and _same(rj_py, rj_c)


def test_rotation_init_ends_on_nan_inertia(native):
    """A NaN principal value ends the AGM loop at once in both (its exit test is written so that NaN exits),
    with NaN motion and the same parameters."""
    K, ell = np.array([1.0, np.nan, 2.0]), np.array([0.3, 0.4, 0.5])
    params, params_py = np.full(py.ROT_PARAMS_SIZE, PREFILL), np.full(py.ROT_PARAMS_SIZE, PREFILL)
    native.rotation_init(K, np.eye(3), ell, params)
    py.rotation_init(K, np.eye(3), ell, params_py)
    assert params[0] == 2.0 and _same(params, params_py)
    R, omega = native.rotation_at(params, 1.0)
    assert np.isnan(R).any() and np.isnan(omega).any()
