"""Tests of tablegen.rotation: exact (elliptic-function) torque-free rigid-body rotation.

References used here, all written independently of the module under test:

* ``dop853_reference``: scipy's DOP853 (rtol = atol = 1e-13) on Euler's equations
  ``dm/dt = m x (m/K)`` together with ``dR/dt = R [m/K]x``, many bodies at once.
* ``taylor_reference``: a Taylor-series integrator of the same equations in x87 long
  double (eps = 1.1e-19).  Near the separatrix the problem itself is ill conditioned (a
  relative change ``e`` of the invariants shifts the orbit by ~ ``e / delta`` per
  passage, ``delta`` the relative distance to the separatrix), so a double-precision
  integrator cannot check the 1e-7 requirement there; long double can.
* closed forms: steady rotation, regular precession of an axisymmetric body,
  Landau-Lifshitz period ``4 K(k) / nu``, mpmath's Jacobi functions and scipy's Carlson
  integrals.
"""

import math

import mpmath
import numba
import numpy as np
import pytest
import scipy.special as sps
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scipy.integrate import solve_ivp

from tablegen import rotation as rot
from tablegen._jit import JIT
from tablegen.rotation import ROT_PARAMS_SIZE, rotation_at, rotation_init


# --------------------------------------------------------------------------------------
# helpers
# --------------------------------------------------------------------------------------
def quat_to_matrix(q):
    """Rotation matrix of the (normalised) quaternion q = (w, x, y, z)."""
    w, x, y, z = np.asarray(q, dtype=float) / np.linalg.norm(q)
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ])


def random_rotation(rng):
    return quat_to_matrix(rng.normal(size=4))


def axis_rotation(axis, angle):
    """Rodrigues' rotation about the unit vector ``axis``."""
    a = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    ax = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + math.sin(angle) * ax + (1 - math.cos(angle)) * ax @ ax


def body_momentum(R0, ell):
    """R0^T ell evaluated in the same order as the module (so both start from the same
    rounded data -- it matters only near the separatrix)."""
    return np.array([R0[0, j] * ell[0] + R0[1, j] * ell[1] + R0[2, j] * ell[2]
                     for j in range(3)])


def evaluate(K, R0, ell, times):
    """R(t) and omega(t) from the module at the given times."""
    params = np.zeros(ROT_PARAMS_SIZE)
    rotation_init(np.asarray(K, float), np.asarray(R0, float), np.asarray(ell, float), params)
    Rs = np.zeros((len(times), 3, 3))
    ws = np.zeros((len(times), 3))
    for i, t in enumerate(times):
        rotation_at(params, float(t), Rs[i], ws[i])
    return Rs, ws


def landau_period(K, mb):
    """Nutation period 4 K(k) / |nu| from Landau & Lifshitz eq. (37.10) (double precision)."""
    order = np.argsort(K, kind="stable")
    I = np.asarray(K, float)[order]
    n = np.asarray(mb, float)[order]
    l2 = n @ n
    two_e = np.sum(n * n / I)
    if l2 < two_e * I[1]:
        I = I[::-1]
    nu = math.sqrt(abs(I[2] - I[1]) * abs(l2 - two_e * I[0]) / (I[0] * I[1] * I[2]))
    kp2 = 1.0 - abs(I[1] - I[0]) * abs(two_e * I[2] - l2) / (abs(I[2] - I[1]) * abs(l2 - two_e * I[0]))
    return 4.0 * sps.ellipkm1(kp2) / nu


def dop853_reference(K, R0, mb, tmax, taus, batch=25):
    """DOP853 reference for many bodies at once: R (nb, nt, 3, 3), m (nb, nt, 3).

    Body b is integrated in the scaled time tau = t / tmax[b] in [0, 1], so that all
    bodies of a batch need similar steps; outputs at t = taus * tmax[b] (dense output).
    """
    nb = len(K)
    Rout = np.zeros((nb, len(taus), 3, 3))
    mout = np.zeros((nb, len(taus), 3))
    for lo in range(0, nb, batch):
        sl = slice(lo, min(lo + batch, nb))
        k = K[sl]
        scale = tmax[sl][:, None]
        nbb = len(k)

        def rhs(_tau, y, k=k, scale=scale, nbb=nbb):
            y = y.reshape(nbb, 12)
            R = y[:, :9].reshape(nbb, 3, 3)
            m = y[:, 9:]
            w = m / k
            dR = np.cross(R, w[:, None, :]).reshape(nbb, 9)  # rows of R [w]x: row x w
            dm = np.cross(m, w)
            return (scale * np.concatenate([dR, dm], axis=1)).ravel()

        y0 = np.concatenate([R0[sl].reshape(nbb, 9), mb[sl]], axis=1).ravel()
        sol = solve_ivp(rhs, (0.0, taus[-1]), y0, method="DOP853", rtol=1e-13, atol=1e-13,
                        t_eval=taus)
        assert sol.success
        y = sol.y.T.reshape(len(taus), nbb, 12).transpose(1, 0, 2)
        Rout[sl] = y[..., :9].reshape(nbb, len(taus), 3, 3)
        mout[sl] = y[..., 9:]
    return Rout, mout


def taylor_reference(K, R0, mb, tmax, taus, order=30, tol=1e-21):
    """Taylor-series integration in x87 long double, many bodies at once.

    Euler's equations are quadratic, so the Taylor coefficients follow from Cauchy
    products: ``(n+1) m_{n+1} = sum_i m_i x w_{n-i}``, ``(n+1) R_{n+1} = sum_i R_i [w_{n-i}]x``
    with ``w_j = m_j / K``.  The step is chosen from the last two coefficients
    (Jorba & Zou, Exp. Math. 14 (2005)) so that the truncation is ~ tol.  Time is scaled
    per body as in ``dop853_reference``.
    """
    ld = np.longdouble
    nb = len(K)
    k = np.asarray(K, ld)
    m = np.asarray(mb, ld) * np.asarray(tmax, ld)[:, None]  # scaled: dm/dtau = tmax dm/dt
    k_scaled = k  # w = m_scaled / K = tmax * omega
    R = np.asarray(R0, ld).copy()
    lmag = np.sqrt(np.sum(m * m, axis=1))
    mc = np.zeros((order + 1, nb, 3), ld)
    wc = np.zeros((order + 1, nb, 3), ld)
    Rc = np.zeros((order + 1, nb, 3, 3), ld)
    Rout = np.zeros((nb, len(taus), 3, 3))
    mout = np.zeros((nb, len(taus), 3))
    tau = ld(0.0)
    for io, target in enumerate(taus):
        target = ld(target)
        while tau < target:
            mc[0] = m
            Rc[0] = R
            wc[0] = m / k_scaled
            for n in range(order):
                mc[n + 1] = np.cross(mc[: n + 1], wc[n::-1]).sum(axis=0) / (n + 1)
                wc[n + 1] = mc[n + 1] / k_scaled
                Rc[n + 1] = np.cross(Rc[: n + 1], wc[n::-1][:, :, None, :]).sum(axis=0) / (n + 1)
            h = target - tau
            for j in (order, order - 1):
                size = max(np.max(np.abs(mc[j]) / lmag[:, None]), np.max(np.abs(Rc[j])))
                if size > 0:
                    h = min(h, (ld(tol) / size) ** (ld(1.0) / j))
            mm = mc[order].copy()
            RR = Rc[order].copy()
            for n in range(order - 1, -1, -1):
                mm = mc[n] + h * mm
                RR = Rc[n] + h * RR
            m, R = mm, RR
            tau = target if h == target - tau else tau + h
        Rout[:, io] = R.astype(float)
        mout[:, io] = (m / np.asarray(tmax, ld)[:, None]).astype(float)
    return Rout, mout


def near_separatrix_state(K, delta, rng):
    """Unit body momentum with L^2 - 2E K_mid = -delta (so 2T K_mid = L^2 (1 + delta))."""
    order = np.argsort(K, kind="stable")
    I = K[order]
    ra = (I[1] - I[0]) / I[0]
    rc = (I[2] - I[1]) / I[2]
    c2 = rng.uniform(0.1, 0.8) * (1.0 - abs(delta)) / (1.0 + rc / ra)
    a2 = (c2 * rc + delta) / ra
    n_sorted = np.sqrt([a2, 1.0 - a2 - c2, c2]) * rng.choice([-1.0, 1.0], 3)
    n = np.empty(3)
    n[order] = n_sorted
    return n


# --------------------------------------------------------------------------------------
# special functions
# --------------------------------------------------------------------------------------
def test_carlson_integrals_against_scipy():
    rng = np.random.default_rng(1)
    for _ in range(300):
        x, y, z = rng.uniform(0.0, 3.0, 3) * 10.0 ** rng.uniform(-3, 3)
        p = rng.uniform(1e-3, 5.0)
        if rng.random() < 0.3:
            x = 0.0
        assert rot.carlson_rf(x, y, z) == pytest.approx(sps.elliprf(x, y, z), rel=1e-14)
        assert rot.carlson_rj(x, y, z, p) == pytest.approx(sps.elliprj(x, y, z, p), rel=1e-14)
    # large p (beta >> 1 in the module) and tiny y (k' -> 0)
    for y, p in [(1e-20, 1e12), (1e-12, 2.0), (0.5, 1e8)]:
        assert rot.carlson_rj(0.0, y, 1.0, p) == pytest.approx(sps.elliprj(0.0, y, 1.0, p), rel=1e-14)


@pytest.mark.parametrize("kp2", [1.0, 1.0 - 1e-14, 0.5, 1e-3, 1e-10, 1e-20, 1e-200, 5e-324])
def test_jacobi_functions_against_mpmath(kp2):
    """sn, cn, dn from the stored Landen chain on [-K, K] vs mpmath, and K(k).

    The argument u ~ K carries a rounding error ~ eps K, hence tolerances ~ eps (K + 10);
    dn >= k' must keep full *relative* accuracy (it is the small component of the body
    angular momentum near the separatrix).
    """
    with mpmath.workdps(40 - int(math.log10(kp2))):
        m_mp = 1 - mpmath.mpf(kp2)
        params = np.zeros(ROT_PARAMS_SIZE)
        kk = rot._landen_chain(math.sqrt(float(m_mp)), math.sqrt(kp2), params)
        assert kk == pytest.approx(float(mpmath.ellipk(m_mp)), rel=4e-15)
        tol = 2.5e-16 * (kk + 10.0)
        for u in np.linspace(-kk, kk, 25):
            s, c, d = rot._landen_sncndn(u * params[rot._I_WSCALE], params)
            ref = [float(mpmath.ellipfun(f, u, m_mp)) for f in ("sn", "cn", "dn")]
            assert abs(s - ref[0]) < tol
            assert abs(c - ref[1]) < tol
            assert abs(d - ref[2]) < 6.0 * tol * ref[2]


# --------------------------------------------------------------------------------------
# comparison with the numerical integration of Euler's equations
# --------------------------------------------------------------------------------------
def random_bodies(n, rng):
    """K (unsorted, with ties and near-ties), R0, ell for n bodies, mixed cases."""
    K = rng.uniform(0.1, 1.0, (n, 3))
    kind = rng.integers(0, 6, n)
    for b in range(n):
        i, j, l = rng.permutation(3)
        if kind[b] == 1:  # axisymmetric, either pair
            K[b, j] = K[b, i]
        elif kind[b] == 2:  # nearly axisymmetric
            K[b, j] = K[b, i] * (1.0 + rng.choice([-1, 1]) * 10.0 ** rng.uniform(-12, -6))
        elif kind[b] == 3:  # sphere
            K[b, :] = K[b, i]
    mdir = rng.normal(size=(n, 3))
    near_axis = kind == 4  # close to the axis of least or largest inertia
    for b in np.flatnonzero(near_axis):
        # (near the middle axis the problem is ill conditioned, DOP853 fails there:
        # covered by test_near_separatrix_matches_long_double_taylor)
        a = rng.choice([np.argmin(K[b]), np.argmax(K[b])])
        mdir[b] *= 10.0 ** rng.uniform(-8, -3)
        mdir[b, a] = rng.choice([-1.0, 1.0])
    mdir /= np.linalg.norm(mdir, axis=1)[:, None]
    lmag = 10.0 ** rng.uniform(-2, 3, n)  # huge and small scales
    R0 = np.array([random_rotation(rng) for _ in range(n)])
    ell = np.einsum("bij,bj->bi", R0, mdir * lmag[:, None])
    return K, R0, ell


def test_matches_dop853_for_random_bodies():
    """R and omega agree with DOP853 to 1e-9 over several rotation / nutation periods.

    Tolerance reasoning: DOP853 at rtol = atol = 1e-13 has a global error of a few 1e-12
    here (error per step ~1e-13 relative, ~1e3 steps, plus the dense output of order 7);
    the closed form is accurate to ~1e-13 (phase error ~ eps * rate * t).  1e-9 leaves a
    wide margin yet catches any wrong formula (those give O(1) errors) and loss of
    accuracy in the degenerate branches.  Random states can lie close to the separatrix,
    where the reference itself loses ~ 1e-13 / delta; with 300 states delta > ~1e-3.
    """
    rng = np.random.default_rng(20240611)
    n = 300
    K, R0, ell = random_bodies(n, rng)
    mb = np.array([body_momentum(R0[b], ell[b]) for b in range(n)])
    lmag = np.linalg.norm(ell, axis=1)
    t_rot = 2.0 * np.pi * np.median(K, axis=1) / lmag
    t_nut = np.array([landau_period(K[b], mb[b]) if np.ptp(K[b]) > 0 else np.inf
                      for b in range(n)])
    tmax = 4.0 * np.minimum(np.maximum(t_rot, np.nan_to_num(t_nut, posinf=0.0)), 10.0 * t_rot)
    taus = np.linspace(0.0, 1.0, 9)
    Rref, mref = dop853_reference(K, R0, mb, tmax, taus)
    err_R = err_w = 0.0
    for b in range(n):
        Rs, ws = evaluate(K[b], R0[b], ell[b], taus * tmax[b])
        wref = np.einsum("tij,tj->ti", Rref[b], mref[b] / K[b])
        err_R = max(err_R, np.abs(Rs - Rref[b]).max())
        err_w = max(err_w, (np.linalg.norm(ws - wref, axis=1) / np.linalg.norm(wref, axis=1)).max())
    print(f"max |R - R_dop853| = {err_R:.2e}, max rel omega error = {err_w:.2e}")
    assert err_R < 1e-9
    assert err_w < 1e-9


# --------------------------------------------------------------------------------------
# near the separatrix (k -> 1)
# --------------------------------------------------------------------------------------
def test_near_separatrix_matches_long_double_taylor():
    """States with 2T K_mid = L^2 (1 + delta), |delta| <= 1e-10, over 3 nutation periods.

    The problem's condition number is ~ 1/delta: a relative perturbation e of the data
    moves the orbit by ~ e / delta after one passage near the middle axis.  The long
    double reference (e ~ 1e-19) is thus good to ~1e-9; the closed form treats the
    rounded body momentum as exact and computes the separatrix distance in double-double,
    so it stays at ~1e-11.  Requirement: 1e-7.  (DOP853 at rtol 1e-13 is off by up to
    ~1e-5 here -- it is not a usable reference.)
    """
    rng = np.random.default_rng(7)
    deltas = [1e-10, -1e-10, 1e-11, -1e-11, 2e-16, -2e-16]
    n = len(deltas)
    K = np.array([rng.permutation([rng.uniform(0.1, 0.3), rng.uniform(0.4, 0.6),
                                   rng.uniform(0.7, 1.0)]) for _ in range(n)])
    R0 = np.array([random_rotation(rng) for _ in range(n)])
    lmag = 10.0 ** rng.uniform(-1, 3, n)
    ell = np.array([R0[b] @ near_separatrix_state(K[b], deltas[b], rng) * lmag[b]
                    for b in range(n)])
    mb = np.array([body_momentum(R0[b], ell[b]) for b in range(n)])
    tmax = np.array([3.0 * landau_period(K[b], mb[b]) for b in range(n)])
    taus = np.linspace(0.0, 1.0, 13)
    # the |delta| ~ 2e-16 states are beyond long double's reach: compare up to the first
    # passage near the middle axis only
    tmax[4:] /= 3.0
    Rref, mref = taylor_reference(K, R0, mb, tmax, taus)
    errs = []
    for b in range(n):
        Rs, ws = evaluate(K[b], R0[b], ell[b], taus * tmax[b])
        wref = np.einsum("tij,tj->ti", Rref[b], mref[b] / K[b])
        assert np.all(np.isfinite(Rs)) and np.all(np.isfinite(ws))
        errs.append(max(np.abs(Rs - Rref[b]).max(),
                        (np.linalg.norm(ws - wref, axis=1) / np.linalg.norm(wref, axis=1)).max()))
    print("near-separatrix errors vs long double Taylor:", ", ".join(f"{e:.1e}" for e in errs))
    assert max(errs) < 1e-7
