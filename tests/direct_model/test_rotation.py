"""Tests of direct_model.rotation: exact (elliptic-function) torque-free rigid-body rotation.

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

import numba
import numpy as np
import pytest
import scipy.special as sps
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scipy.integrate import solve_ivp

from direct_model import rotation as rot
from direct_model.options import JIT
from direct_model.rotation import ROT_PARAMS_SIZE, rotation_at, rotation_init


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


def landau_rates(K, mb):
    """(|nu|, k'^2) of Landau & Lifshitz eq. (37.10), plain double precision."""
    order = np.argsort(K, kind="stable")
    I = np.asarray(K, float)[order]
    n = np.asarray(mb, float)[order]
    l2 = n @ n
    two_e = np.sum(n * n / I)
    if l2 < two_e * I[1]:
        I = I[::-1]
    s_abs = abs(l2 - two_e * I[0])
    nu = math.sqrt(abs(I[2] - I[1]) * s_abs / (I[0] * I[1] * I[2]))
    kp2 = 1.0 - abs(I[1] - I[0]) * abs(two_e * I[2] - l2) / (abs(I[2] - I[1]) * s_abs)
    return nu, max(kp2, 0.0)


def landau_period(K, mb):
    """Nutation period 4 K(k) / |nu| (Landau & Lifshitz section 37)."""
    nu, kp2 = landau_rates(K, mb)
    return 4.0 * sps.ellipkm1(kp2) / nu


def dop853_reference(K, R0, mb, tmax, taus, batch=100):
    """DOP853 reference for many bodies at once: R (nb, nt, 3, 3), m (nb, nt, 3).

    Body b is integrated in the scaled time tau = t / tmax[b] in [0, 1], so that all
    bodies of a batch need similar steps; outputs at t = taus * tmax[b] (dense output).
    The step control sees the RMS error of the whole batch; in practice the per-body
    error (~3e-11 here, checked against the long double reference) does not depend on
    the batch size between 25 and 300.
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
    # scaled time: m_tau = tmax m gives dm_tau/dtau = m_tau x (m_tau / K), w = tmax omega
    m = np.asarray(mb, ld) * np.asarray(tmax, ld)[:, None]
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
            wc[0] = m / k
            for n in range(order):
                mc[n + 1] = np.cross(mc[: n + 1], wc[n::-1]).sum(axis=0) / (n + 1)
                wc[n + 1] = mc[n + 1] / k
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
        ref = sps.elliprj(0.0, y, 1.0, p)
        assert rot.carlson_rj(0.0, y, 1.0, p) == pytest.approx(ref, rel=1e-14)


@pytest.mark.parametrize("kp2", [1.0, 1.0 - 1e-14, 0.5, 1e-3, 1e-10, 1e-20, 1e-200, 5e-324])
def test_jacobi_functions_against_mpmath(kp2):
    """sn, cn, dn from the stored Landen chain on [-K, K] vs mpmath, and K(k).

    The argument u ~ K carries a rounding error ~ eps K, hence tolerances ~ eps (K + 10);
    dn >= k' must keep full *relative* accuracy (it is the small component of the body
    angular momentum near the separatrix).
    """
    mpmath = pytest.importorskip("mpmath")
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


@pytest.mark.parametrize("beta", [0.0, 1e-9, 0.3, 1.0, 1.5, 40.0, 1e9])
def test_third_kind_integral_forms_against_mpmath(beta):
    """Pi(phi; -beta | k): F + (Pi - F) for beta <= 1, reflected form for beta > 1."""
    mpmath = pytest.importorskip("mpmath")
    with mpmath.workdps(30):
        for k2 in (0.0, 0.3, 0.99, 1.0 - 1e-12):
            for phi in (-1.5, -0.4, 0.0, 0.2, 1.1, 0.5 * math.pi):
                s, c = math.sin(phi), math.cos(phi)
                d = math.sqrt(c * c + (1.0 - k2) * s * s)
                ref = float(mpmath.ellippi(-beta, phi, k2))
                if beta <= 1.0:
                    val = float(mpmath.ellipf(phi, k2)) + rot._pi_minus_f(s, c, d, beta)
                else:
                    gamma = k2 / beta
                    val = rot._pi_large_beta(s, c, d, gamma, math.sqrt((1 + beta) * (1 + gamma)))
                assert val == pytest.approx(ref, rel=4e-15, abs=1e-300)


@pytest.mark.parametrize("kp2", [1.0, 0.5, 1e-3, 1e-10, 1e-20, 1e-100, 1e-300])
def test_complete_integrals_from_the_landen_agm_against_mpmath(kp2):
    """K(k) from the Landen chain and (Pi(-eta|k) - K) / K from its AGM (DLMF 19.8.6),
    also for k -> 1 (k' down to 1e-150) and tiny eta; reference -eta/3 R_J / R_F."""
    mpmath = pytest.importorskip("mpmath")
    with mpmath.workdps(40):
        kp_mp = mpmath.sqrt(mpmath.mpf(kp2))
        k = float(mpmath.sqrt(1 - mpmath.mpf(kp2)))
        kref = mpmath.elliprf(0, kp2, 1)
        for eta in (0.0, 1e-12, 1e-4, 0.3, 1.0):
            params = np.zeros(ROT_PARAMS_SIZE)
            kk, pik = rot._landen_agm(k, float(kp_mp), eta, params)
            ref = -mpmath.mpf(eta) / 3 * mpmath.elliprj(0, kp2, 1, 1 + mpmath.mpf(eta)) / kref
            assert kk == pytest.approx(float(kref), rel=1.5e-15)
            assert pik == pytest.approx(float(ref), rel=2e-15, abs=1e-300)


def test_rj_with_known_square_roots_against_mpmath():
    """The R_J of the phase integral, R_J(cn^2, dn^2, 1, 1 + eta sn^2) with cn, dn as the
    square roots and (p - x)(p - y)(p - 1) in closed form, near phi = pi/2 and k = 1 too."""
    mpmath = pytest.importorskip("mpmath")
    rng = np.random.default_rng(17)
    with mpmath.workdps(40):
        for i in range(400):
            kp2 = 10.0 ** rng.uniform(-30, 0) if i % 2 else rng.uniform(0.0, 1.0)
            k2 = float(1 - mpmath.mpf(kp2))
            phi = 0.5 * math.pi - 10.0 ** rng.uniform(-16, 0)  # near pi/2 ...
            if i % 3:
                phi = rng.uniform(0.0, 0.5 * math.pi)  # ... or anywhere
            s, c = math.sin(phi), math.cos(phi)
            d = math.sqrt(c * c + kp2 * s * s)
            eta = 10.0 ** rng.uniform(-14, 0)
            delta = eta * (1.0 + eta) * (eta + k2) * (s * s) ** 3
            val = rot._rj_amp(c * c, c, d * d, d, 1.0 + eta * s * s, delta)
            ref = mpmath.elliprj(mpmath.mpf(c) ** 2, mpmath.mpf(d) ** 2, 1,
                                 1 + eta * mpmath.mpf(s) ** 2)
            assert val == pytest.approx(float(ref), rel=2e-15)


# --------------------------------------------------------------------------------------
# comparison with the numerical integration of Euler's equations
# --------------------------------------------------------------------------------------
def random_bodies(n, rng, hard=False):
    """K (unsorted, with ties and near-ties), R0, ell for n bodies, mixed cases.

    ``hard`` adds states that are ill conditioned for a double-precision integrator:
    K differing in the last bits, and nearly axisymmetric bodies whose momentum
    circulates around the axis that is nearly degenerate with the middle one (there
    ``nu`` is tiny, ``beta`` huge and ``L^2 - 2E I_mid`` ~ the asymmetry).
    """
    K = rng.uniform(0.1, 1.0, (n, 3))
    kind = rng.integers(0, 8 if hard else 6, n)
    mdir = rng.normal(size=(n, 3))
    for b in range(n):
        i, j, l = rng.permutation(3)
        if kind[b] == 1:  # axisymmetric, either pair
            K[b, j] = K[b, i]
        elif kind[b] == 2:  # nearly axisymmetric
            K[b, j] = K[b, i] * (1.0 + rng.choice([-1, 1]) * 10.0 ** rng.uniform(-12, -6))
        elif kind[b] == 3:  # sphere
            K[b, :] = K[b, i]
        elif kind[b] == 4:  # close to the axis of least or largest inertia
            # (near the middle axis the problem is ill conditioned, DOP853 fails there:
            # covered by the near-separatrix tests)
            a = rng.choice([np.argmin(K[b]), np.argmax(K[b])])
            mdir[b] *= 10.0 ** rng.uniform(-8, -3)
            mdir[b, a] = rng.choice([-1.0, 1.0])
        elif kind[b] == 6:  # last-bit differences
            K[b, j] = np.nextafter(K[b, i], 2.0)
            if rng.random() < 0.5:
                K[b, l] = np.nextafter(K[b, i], 0.0)
        elif kind[b] == 7:  # circulation around a nearly degenerate extreme axis
            lo, mid, hi = np.sort(K[b])
            e = 10.0 ** rng.uniform(-13, -3)
            r = rng.uniform(0.05, 0.95)
            if rng.random() < 0.5:  # hi ~ mid, x small
                I = np.array([lo, mid, mid * (1.0 + e)])
                n_s = [r * math.sqrt((I[2] - I[1]) * I[0] / ((I[1] - I[0]) * I[2])), 1.0, 1.0]
            else:  # lo ~ mid, z small
                I = np.array([mid * (1.0 - e), mid, hi])
                n_s = [1.0, 1.0, r * math.sqrt((I[1] - I[0]) * I[2] / ((I[2] - I[1]) * I[0]))]
            n_s = np.array(n_s) * rng.uniform(0.3, 3.0, 3) ** np.array([0, 1, 0])
            perm = rng.permutation(3)
            K[b, perm] = I
            mdir[b, perm] = n_s * rng.choice([-1.0, 1.0], 3)
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


def twenty_turn_error(K, R0, ell):
    """The largest error of R and of the relative omega against the long double Taylor reference, at six
    times over 20 turns of each body (rows of K, R0, ell)."""
    mb = np.array([body_momentum(R0[b], ell[b]) for b in range(len(K))])
    tmax = 40.0 * np.pi * np.median(K, axis=1) / np.linalg.norm(ell, axis=1)  # 20 turns
    taus = np.linspace(0.0, 1.0, 6)
    Rref, mref = taylor_reference(K, R0, mb, tmax, taus)
    err = 0.0
    for b in range(len(K)):
        Rs, ws = evaluate(K[b], R0[b], ell[b], taus * tmax[b])
        wref = np.einsum("tij,tj->ti", Rref[b], mref[b] / K[b])
        err = max(err, np.abs(Rs - Rref[b]).max(),
                  (np.linalg.norm(ws - wref, axis=1) / np.linalg.norm(wref, axis=1)).max())
    return err


def test_matches_long_double_taylor_for_random_bodies():
    """Same kind of bodies plus the hard cases against the long double Taylor reference
    (error ~1e-17 per unit phase): here the closed form itself is measured, ~1e-13 over
    20 turns (rounding ~ eps * phase)."""
    K, R0, ell = random_bodies(80, np.random.default_rng(4321), hard=True)
    err = twenty_turn_error(K, R0, ell)
    print(f"max error vs long double Taylor: {err:.1e}")
    assert err < 1e-12


def test_random_bodies_take_both_the_theta_and_the_landen_path():
    """The bodies of the two tests above run through both evaluations of the general motion: Jacobi's
    theta series and the Landen chain with R_J (nomes above 0.2, k^2 below 1e-4: close to a steady spin
    or to an axisymmetric body, and bodies that spin close to an axis of a nearly axisymmetric inertia)."""
    modes = []
    for seed, hard, n in ((20240611, False, 300), (4321, True, 80)):
        K, R0, ell = random_bodies(n, np.random.default_rng(seed), hard=hard)
        for b in range(n):
            params = np.zeros(ROT_PARAMS_SIZE)
            rotation_init(K[b], R0[b], ell[b], params)
            modes.append(params[rot._I_MODE])
    modes = np.array(modes)
    print(f"theta mode {np.mean(modes == rot._MODE_THETA):.2f}, Landen path {np.mean(modes == rot._MODE_GENERAL):.2f}")
    assert np.sum(modes == rot._MODE_THETA) >= 50
    assert np.sum(modes == rot._MODE_GENERAL) >= 50


def _alpha_and_nome(K, mb):
    """(alpha / K', q) of a general state by scipy's integrals: alpha with sc(alpha | k') = sqrt(beta) / k
    (module doc of direct_model.rotation, item 6), on the working axes of the circulation."""
    order = np.argsort(K, kind="stable")
    inertia, m = K[order], mb[order]
    l2, two_e = m @ m, np.sum(m * m / inertia)
    if l2 < two_e * inertia[1]:
        inertia = inertia[::-1]
    kp2 = 1.0 - abs(inertia[1] - inertia[0]) * abs(two_e * inertia[2] - l2) / (
        abs(inertia[2] - inertia[1]) * abs(l2 - two_e * inertia[0]))
    beta = inertia[2] * abs(inertia[1] - inertia[0]) / (inertia[0] * abs(inertia[2] - inertia[1]))
    kpk = sps.ellipk(kp2)
    alpha = sps.ellipkinc(math.atan(math.sqrt(beta / (1.0 - kp2))), kp2)
    return alpha / kpk, math.exp(-math.pi * kpk / sps.ellipk(1.0 - kp2))


def test_w_near_a_zero_of_theta_4_matches_long_double_taylor():
    """alpha -> K' puts theta_4(v + i alpha~) near a zero: its series cancels and Jacobi's zeta becomes as
    sensitive as K' - alpha to alpha's rounding. Taken through theta_1 beyond alpha = K'/2 (module doc, item
    6), states with rho = q e^{2 alpha~} above 0.6 stay within the random bodies' 1e-12 over 20 turns."""
    rng = np.random.default_rng(2611)
    K, R0, ell, rho = [], [], [], []
    for _ in range(2000):       # 343 draws give the 24 states
        if len(K) == 24:
            break
        k = rng.uniform(0.1, 1.0, 3)
        if rng.random() < 0.5:      # two close moments make beta large, alpha close to K'
            i, j = rng.permutation(3)[:2]
            k[j] = k[i] * (1.0 + rng.choice([-1.0, 1.0]) * 10.0 ** rng.uniform(-3.0, -0.5))
        r0 = random_rotation(rng)
        l = r0 @ (rng.normal(size=3) * 10.0 ** rng.uniform(-1.0, 1.0))
        params = np.zeros(ROT_PARAMS_SIZE)
        rotation_init(k, r0, l, params)
        if params[rot._I_MODE] != rot._MODE_THETA or params[rot._I_TH_REFLECT] != 1.0:
            continue
        alpha, q = _alpha_and_nome(k, body_momentum(r0, l))
        assert alpha > 0.5
        if q ** (1.0 - alpha) > 0.6:      # rho = q e^{2 alpha~}
            K.append(k), R0.append(r0), ell.append(l), rho.append(q ** (1.0 - alpha))
    assert len(K) == 24, "too few states through theta_1 above rho = 0.6"
    K, R0, ell, rho = map(np.array, (K, R0, ell, rho))
    print(f"rho from {rho.min():.2f} to {rho.max():.3f}")
    assert rho.max() > 0.9
    err = twenty_turn_error(K, R0, ell)
    print(f"max error vs long double Taylor: {err:.1e}")
    assert err < 1e-12


@pytest.mark.parametrize("axis", [0, 2])
def test_near_a_steady_spin_both_paths_match_long_double_taylor(axis):
    """L tilted by 1e-1 to 1e-7 from the smallest (axis 0) or largest (axis 2) principal axis. The theta
    series' two phases (of w and of m_0 + i m_1) then both turn fast and their difference loses digits
    as k -> 0 (measured: 1e-13 to 1e-12 at tilts 1e-3 to 1e-7, against 1e-14 for the Landen path), so
    states with k^2 < 1e-4 take the Landen path. Both stay at the accuracy of the random bodies above
    (1e-12 over 20 turns; measured at most 1.1e-13 here)."""
    K = np.array([0.3, 0.5, 0.8])
    tilts = 10.0 ** -np.arange(1.0, 8.0)
    n = len(tilts)
    mdir = np.zeros((n, 3))
    mdir[:, axis] = 1.0
    mdir[:, 1] = tilts
    mdir[:, 2 - axis] = 0.7 * tilts
    mdir /= np.linalg.norm(mdir, axis=1)[:, None]
    rng = np.random.default_rng(17 + axis)
    R0 = np.array([random_rotation(rng) for _ in range(n)])
    ell = np.einsum("bij,bj->bi", R0, mdir * 3.0)
    mb = np.array([body_momentum(R0[b], ell[b]) for b in range(n)])
    tmax = np.full(n, 40.0 * np.pi * 0.5 / 3.0)
    taus = np.linspace(0.0, 1.0, 6)
    Rref, mref = taylor_reference(np.tile(K, (n, 1)), R0, mb, tmax, taus)
    modes = []
    for b in range(n):
        params = np.zeros(ROT_PARAMS_SIZE)
        rotation_init(K, R0[b], ell[b], params)
        modes.append(params[rot._I_MODE])
        Rs, ws = evaluate(K, R0[b], ell[b], taus * tmax[b])
        wref = np.einsum("tij,tj->ti", Rref[b], mref[b] / K)
        err = max(np.abs(Rs - Rref[b]).max(), (np.linalg.norm(ws - wref, axis=1) / np.linalg.norm(wref, axis=1)).max())
        assert err < 1e-12, (tilts[b], err)
    assert modes[0] == rot._MODE_THETA and modes[-1] == rot._MODE_GENERAL, modes


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
    deltas = [1e-10, -1e-10, 3e-11, -3e-11]
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
    Rref, mref = taylor_reference(K, R0, mb, tmax, taus)
    errs = []
    for b in range(n):
        Rs, ws = evaluate(K[b], R0[b], ell[b], taus * tmax[b])
        wref = np.einsum("tij,tj->ti", Rref[b], mref[b] / K[b])
        errs.append(max(np.abs(Rs - Rref[b]).max(),
                        (np.linalg.norm(ws - wref, axis=1) / np.linalg.norm(wref, axis=1)).max()))
    print("near-separatrix errors vs long double Taylor:", ", ".join(f"{e:.1e}" for e in errs))
    assert max(errs) < 1e-7


def test_extremely_near_separatrix_follows_the_ode_window_by_window():
    """|delta| ~ 1e-16 (and tiny tilts off the middle axis): no reference of finite
    precision can follow these over a period, so tile [0, > 1 period] with short windows:
    start the long double Taylor integrator from the module's own state at the start
    of each window and compare at its end.  Within a window the ODE amplifies errors by
    < ~e^1.5, so a correct solution agrees to ~1e-13; 1e-10 is asserted.  Together with the
    exact invariants this shows that the closed form is the ODE's solution throughout.
    """
    rng = np.random.default_rng(11)
    cases = []
    for delta in (2e-16, -2e-16):
        K = rng.permutation([0.2, 0.5, 0.9])
        cases.append((K, near_separatrix_state(K, delta, rng)))
    for tilt in (1e-8, 1e-12):
        K = rng.permutation([0.15, 0.45, 0.8])
        m = rng.normal(size=3) * tilt
        m[np.argsort(K)[1]] = 1.0
        cases.append((K, m / np.linalg.norm(m)))
    nwin = 60  # windows of 1.5 / nu: more than a period (4K < 80 here)
    Ks, R0s, mbs, tms, ends = [], [], [], [], []
    for K, mdir in cases:
        R0 = random_rotation(rng)
        ell = R0 @ mdir * 7.0
        h = 1.5 / landau_rates(K, body_momentum(R0, ell))[0]
        Rs, ws = evaluate(K, R0, ell, h * np.arange(nwin + 1))
        assert np.all(np.isfinite(Rs)) and np.all(np.isfinite(ws))
        for i in range(nwin):
            Ks.append(K)
            R0s.append(Rs[i])
            mbs.append(K * (Rs[i].T @ ws[i]))
            tms.append(h)
            ends.append((Rs[i + 1], ws[i + 1]))
    Ks, R0s, mbs, tms = map(np.array, (Ks, R0s, mbs, tms))
    Rref, mref = taylor_reference(Ks, R0s, mbs, tms, np.array([0.0, 1.0]))
    err = 0.0
    for j, (R_end, w_end) in enumerate(ends):
        wref = Rref[j, 1] @ (mref[j, 1] / Ks[j])
        err = max(err, np.abs(R_end - Rref[j, 1]).max(),
                  np.linalg.norm(w_end - wref) / np.linalg.norm(wref))
    print(f"window-by-window error near the separatrix: {err:.1e}")
    assert err < 1e-10


def test_exact_separatrix():
    """k' = 0 exactly: I = (1, 3, 6), m = (1, y, 2) in sorted order gives L^2 = 2E I_mid
    in exact arithmetic.  Compared with long double Taylor while the orbit is still far
    from the saddle, and it must creep towards the middle axis without NaN for t -> inf.
    """
    for perm, y, scale in [((0, 1, 2), 0.75, 1.0), ((2, 0, 1), -1.5, 0.25), ((1, 2, 0), 0.0, 3.0)]:
        perm = np.array(perm)
        K = np.empty(3)
        K[perm] = np.array([1.0, 3.0, 6.0]) * scale
        m = np.empty(3)
        m[perm] = [1.0, y, 2.0]
        R0 = np.eye(3)[:, [1, 2, 0]]  # exact proper rotation: R0^T ell is exact
        ell = R0 @ m
        params = np.zeros(ROT_PARAMS_SIZE)
        rotation_init(K, R0, ell, params)
        assert params[rot._I_MODE] == rot._MODE_SEPARATRIX
        lam = math.sqrt(2.0 * 3.0 / (1.0 * 3.0 * 6.0)) * np.linalg.norm(m) / scale  # ~ rate
        taus = np.linspace(0.0, 1.0, 7)
        tmax = np.array([6.0 / lam])
        Rref, mref = taylor_reference(K[None], R0[None], m[None], tmax, taus)
        Rs, ws = evaluate(K, R0, ell, taus * tmax[0])
        assert np.abs(Rs - Rref[0]).max() < 1e-10
        Rs, ws = evaluate(K, R0, ell, [1e3 / lam, 1e6 / lam, 1e12])
        assert np.all(np.isfinite(Rs)) and np.all(np.isfinite(ws))
        mid = perm[1]
        mb_late = K * (Rs[0].T @ ws[0])
        assert abs(abs(mb_late[mid]) - np.linalg.norm(m)) < 1e-12 * np.linalg.norm(m)


# --------------------------------------------------------------------------------------
# degenerate cases and closed forms
# --------------------------------------------------------------------------------------
def test_zero_angular_momentum_does_not_rotate():
    rng = np.random.default_rng(0)
    R0 = random_rotation(rng)
    Rs, ws = evaluate([0.3, 0.5, 0.2], R0, np.zeros(3), [0.0, 1.0, 1e6])
    assert np.all(Rs == R0)
    assert np.all(ws == 0.0)


def test_sphere_rotates_uniformly():
    rng = np.random.default_rng(1)
    for _ in range(10):
        c = rng.uniform(0.1, 1.0)
        R0 = random_rotation(rng)
        ell = rng.normal(size=3) * 10.0 ** rng.uniform(-2, 3)
        omega = ell / c
        times = np.linspace(0.0, 50.0, 11) * 2 * np.pi / np.linalg.norm(omega)
        Rs, ws = evaluate([c, c, c], R0, ell, times)
        for t, R, w in zip(times, Rs, ws):
            phase = np.linalg.norm(omega) * t  # both sides carry rounding ~ eps * phase
            assert np.abs(R - axis_rotation(omega, phase) @ R0).max() < 1e-15 * (10.0 + phase)
            assert np.abs(w - omega).max() <= 1e-15 * np.linalg.norm(omega)


@pytest.mark.parametrize("which", ["min", "mid", "max"])
@pytest.mark.parametrize("exact_frame", [True, False])
def test_spin_about_principal_axis_stays_put(which, exact_frame):
    """Pure spin about a principal axis is a fixed point of Euler's equations -- also the
    unstable middle axis.  With a random R0 the body momentum R0^T ell is only known to
    rounding; it must still stay on the axis (to ~1e-15) for 1e4 turns."""
    rng = np.random.default_rng(2)
    K = rng.permutation([0.2, 0.45, 0.7])
    a = {"min": np.argmin(K), "mid": np.argsort(K)[1], "max": np.argmax(K)}[which]
    R0 = np.eye(3)[:, [2, 0, 1]] if exact_frame else random_rotation(rng)
    lmag = 123.0
    ell = R0[:, a] * lmag
    w = lmag / K[a]
    times = np.array([0.0, 1.0, 17.3, 1e4]) * 2 * np.pi / w
    Rs, ws = evaluate(K, R0, ell, times)
    for t, R, om in zip(times, Rs, ws):
        mb = K * (R.T @ om)
        off = np.delete(mb, a)
        assert np.abs(off).max() < 4e-15 * lmag
        assert np.linalg.norm(om - ell / K[a]) < 1e-14 * w
        assert np.abs(R - axis_rotation(ell, w * t) @ R0).max() < 1e-15 * max(1.0, w * t)


@pytest.mark.parametrize("pair", ["small", "large"])
def test_axisymmetric_body_precesses_regularly(pair):
    """Two equal moments I_p (either the small or the large pair), symmetry axis s with
    I_s: R(t) = Rot(ell, L t / I_p) R0 Rot(e_s, m_s (1/I_s - 1/I_p) t) (regular precession,
    Landau & Lifshitz section 33).  Error ~ eps * phase."""
    rng = np.random.default_rng(5 if pair == "small" else 6)
    for _ in range(12):
        ip = rng.uniform(0.2, 0.6)
        i_s = ip * (rng.uniform(1.2, 2.0) if pair == "small" else rng.uniform(0.3, 0.8))
        s_ax = rng.integers(3)
        K = np.full(3, ip)
        K[s_ax] = i_s
        R0 = random_rotation(rng)
        ell = rng.normal(size=3) * 10.0 ** rng.uniform(-2, 3)
        mb = R0.T @ ell
        lmag = np.linalg.norm(ell)
        e_s = np.eye(3)[s_ax]
        spin = mb[s_ax] * (1.0 / i_s - 1.0 / ip)
        times = np.linspace(0.0, 30.0, 13) * 2 * np.pi * ip / lmag
        Rs, ws = evaluate(K, R0, ell, times)
        for t, R, w in zip(times, Rs, ws):
            Rx = axis_rotation(ell, lmag * t / ip) @ R0 @ axis_rotation(e_s, spin * t)
            wx = ell / ip + spin * (Rx @ e_s)
            tol = 2e-15 * (10.0 + (lmag / ip + abs(spin)) * t)  # rounding ~ eps * phase
            assert np.abs(R - Rx).max() < tol
            assert np.linalg.norm(w - wx) < tol * np.linalg.norm(wx)


def test_axisymmetric_body_spinning_in_its_degenerate_plane_is_steady():
    rng = np.random.default_rng(8)
    K = np.array([0.4, 0.7, 0.4])
    R0 = random_rotation(rng)
    ell = R0 @ np.array([0.6, 0.0, -0.8]) * 5.0
    Rs, ws = evaluate(K, R0, ell, [0.0, 3.0, 300.0])
    for R, w in zip(Rs, ws):
        assert np.linalg.norm(w - ell / 0.4) < 1e-13 * np.linalg.norm(ell / 0.4)


def test_unsorted_axes_give_the_same_motion():
    """Relabelling the body axes (K permuted, the columns of R0 permuted with a sign flip
    for odd permutations to keep the frame right-handed) must not change the motion."""
    rng = np.random.default_rng(9)
    for _ in range(20):
        K = rng.uniform(0.1, 1.0, 3)
        R0 = random_rotation(rng)
        ell = rng.normal(size=3) * 3.0
        times = np.linspace(0.0, 20.0, 9)
        Rs, ws = evaluate(K, R0, ell, times)
        for perm, sign in (([1, 2, 0], [1, 1, 1]), ([2, 1, 0], [1, -1, 1]),
                           ([0, 2, 1], [-1, 1, 1]), ([1, 0, 2], [1, 1, -1])):
            Rp, wp = evaluate(K[perm], R0[:, perm] * sign, ell, times)
            assert np.abs(Rp - Rs[:, :, perm] * sign).max() < 1e-12
            assert np.abs(wp - ws).max() < 1e-12 * np.abs(ws).max()


def test_scaling_of_angular_momentum_rescales_time():
    """ell -> lambda ell is the same motion at lambda times the speed."""
    rng = np.random.default_rng(10)
    for lam in (1e-3, 1e3):
        K = rng.uniform(0.1, 1.0, 3)
        R0 = random_rotation(rng)
        ell = rng.normal(size=3)
        times = np.linspace(0.0, 30.0, 7)
        Rs, ws = evaluate(K, R0, ell, times)
        Rl, wl = evaluate(K, R0, lam * ell, times / lam)
        assert np.abs(Rl - Rs).max() < 1e-12
        assert np.abs(wl / lam - ws).max() < 1e-12 * np.abs(ws).max()


def test_asymmetric_body_really_precesses_and_nutates():
    """Guard against a 'constant omega' implementation: for an asymmetric body the lab
    angular velocity moves by O(1), the body angular momentum is periodic with the
    Landau-Lifshitz period 4K(k)/nu (and not constant), and R differs from the rigid
    rotation at the initial omega."""
    rng = np.random.default_rng(12)
    K = np.array([0.7, 0.25, 0.45])
    R0 = random_rotation(rng)
    ell = R0 @ np.array([0.5, 0.4, -0.75])
    mb0 = body_momentum(R0, ell)
    period = landau_period(K, mb0)
    times = np.linspace(0.0, 1.0, 25) * period
    Rs, ws = evaluate(K, R0, ell, times)
    w0 = ws[0]
    assert np.max(np.linalg.norm(ws - w0, axis=1)) > 0.3 * np.linalg.norm(w0)
    dev = [np.abs(R - axis_rotation(w0, np.linalg.norm(w0) * t) @ R0).max()
           for t, R in zip(times, Rs)]
    assert max(dev) > 0.5
    mb = np.einsum("tji,tj->ti", Rs, ws) * K
    assert np.ptp(mb, axis=0).max() > 0.3 * np.linalg.norm(ell)
    # periodicity of the body momentum (checks the rate nu and the modulus k)
    for t in (0.1, 0.37, 0.8):
        Ra, wa = evaluate(K, R0, ell, [t * period, (t + 1.0) * period, (t + 3.0) * period])
        ma = np.einsum("tji,tj->ti", Ra, wa) * K
        assert np.abs(ma[1] - ma[0]).max() < 1e-12 * np.linalg.norm(ell)
        assert np.abs(ma[2] - ma[0]).max() < 1e-12 * np.linalg.norm(ell)


def test_callable_from_jitted_code():
    """Kernels run in nopython mode from another kernel (how the simulator calls them)."""

    @numba.njit(**{**JIT, "cache": False})
    def trajectory(K, R0, ell, times, R_out, w_out):
        params = np.empty(ROT_PARAMS_SIZE)
        rotation_init(K, R0, ell, params)
        for i in range(times.size):
            rotation_at(params, times[i], R_out[i], w_out[i])

    rng = np.random.default_rng(13)
    K = np.array([0.3, 0.9, 0.5])
    R0 = random_rotation(rng)
    ell = np.array([1.0, -2.0, 0.5])
    times = np.linspace(0.0, 10.0, 5)
    Rj = np.zeros((5, 3, 3))
    wj = np.zeros((5, 3))
    trajectory(K, R0, ell, times, Rj, wj)
    Rs, ws = evaluate(K, R0, ell, times)
    assert np.array_equal(Rj, Rs) and np.array_equal(wj, ws)


# --------------------------------------------------------------------------------------
# properties: orthonormality, initial value, conservation laws
# --------------------------------------------------------------------------------------
@st.composite
def rigid_body_states(draw):
    moment = st.floats(0.1, 1.0)
    K = [draw(moment), draw(moment), draw(moment)]
    ties = draw(st.sampled_from(["none", "none", "01", "02", "12", "all"]))
    if ties == "all":
        K = [K[0]] * 3
    elif ties != "none":
        K[int(ties[1])] = K[int(ties[0])]
    q = [draw(st.floats(-1.0, 1.0)) for _ in range(4)]
    if np.linalg.norm(q) < 1e-3:
        q = [1.0, 0.0, 0.0, 0.0]
    R0 = quat_to_matrix(q)
    lmag = 10.0 ** draw(st.floats(-3.0, 3.0))
    kind = draw(st.sampled_from(["random", "random", "random", "axis", "zero"]))
    if kind == "zero":
        mdir = np.zeros(3)
    elif kind == "axis":
        mdir = np.eye(3)[draw(st.integers(0, 2))] * draw(st.sampled_from([-1.0, 1.0]))
    else:
        mdir = np.array([draw(st.floats(-1.0, 1.0)) for _ in range(3)])
        if np.linalg.norm(mdir) < 1e-3:
            mdir = np.array([0.0, 0.0, 1.0])
        mdir /= np.linalg.norm(mdir)
    ell = R0 @ mdir * lmag
    turns = draw(st.floats(0.0, 50.0))
    return np.array(K), R0, ell, turns


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(rigid_body_states())
def test_orthonormality_initial_value_and_invariants(state):
    """R orthonormal with det +1 (1e-13), R(0) = R0 (1e-14); lab angular momentum
    R K R^T omega = ell and kinetic energy omega.(K omega)/2 constant (1e-12 relative)."""
    K, R0, ell, turns = state
    lmag = np.linalg.norm(ell)
    w_scale = lmag / K.min()
    t_end = turns * 2 * np.pi / w_scale if lmag > 0 else turns
    times = np.array([0.0, 0.3 * t_end, t_end])
    Rs, ws = evaluate(K, R0, ell, times)
    assert np.abs(Rs[0] - R0).max() < 1e-14
    energy0 = None
    for R, w in zip(Rs, ws):
        assert np.abs(R.T @ R - np.eye(3)).max() < 1e-13
        assert abs(np.linalg.det(R) - 1.0) < 1e-13
        wb = R.T @ w
        assert np.linalg.norm(R @ (K * wb) - ell) <= 1e-12 * lmag
        energy = 0.5 * wb @ (K * wb)
        if energy0 is None:
            energy0 = energy
        assert abs(energy - energy0) <= 1e-12 * energy0
