"""Exact torque-free rotation of a rigid body (Euler-Poinsot motion).

Closed-form solution in Jacobi elliptic functions, evaluated by jitted plain functions
over float64 arrays:

* :func:`rotation_init` does the set-up once per flight (sorting of the axes, the
  elliptic modulus, the theta series or the Landen chain, complete integrals, the initial
  phase) and writes everything into a float64 array of length :data:`ROT_PARAMS_SIZE`.
* :func:`rotation_at` evaluates the orientation ``R(t)`` (body -> lab) and the lab-frame
  angular velocity ``omega(t)`` at any time ``t``, working on scalars only (no allocation).

Notation
--------
``K`` are the principal values of the inertia tensor per unit mass, ``ell`` the (constant)
lab angular momentum per unit mass, ``m = R^T ell`` the body-frame angular momentum,
``L = |ell|``, ``2E = sum m_i^2 / K_i`` twice the kinetic energy per unit mass.
Euler's equations in the body frame read ``dm/dt = m x omega_b`` with ``omega_b = m / K``.
No rescaling is done: ``|ell|`` and ``K`` should lie within ~1e+-100 of 1 (squares and
the exact products of the double-double step must neither overflow nor underflow).

Method
------
1. *Working frame.*  The axes are sorted, ``I_lo <= I_mid <= I_hi``.  The body-frame
   angular momentum circulates around the axis of largest inertia if
   ``L^2 > 2E I_mid`` and around the axis of smallest inertia if ``L^2 < 2E I_mid``
   (Landau & Lifshitz, *Mechanics*, section 37).  The working frame is a proper signed
   permutation ``Q`` of the body axes (body = ``Q`` working) whose third axis is the
   circulated one, whose second axis is the middle one, and in which ``m_0(0) >= 0``,
   ``m_2(0) >= 0``.  The working moments are ``J_0, J_1, J_2`` (``J_1`` the middle one;
   ``J_0 < J_1 < J_2`` or ``J_0 > J_1 > J_2``).  Euler's equations keep their form in any
   right-handed principal frame, so one set of formulas covers both cases.

2. *Body angular momentum* (Landau & Lifshitz section 37, eq. (37.10), written with
   absolute differences ``d_ij = |J_i - J_j|`` so that both cases read the same)::

       m(t) = (a_0 cn u, a_1 sn u, a_2 dn u),   u = nu t + u_0,
       a_0^2 = P J_0 / d_20,   a_1^2 = P J_1 / d_21,   a_2^2 = S J_2 / d_20,
       P = |2E J_2 - L^2| = m_0^2 d_20/J_0 + m_1^2 d_21/J_1,
       S = |L^2 - 2E J_0| = m_1^2 d_10/J_1 + m_2^2 d_20/J_2,
       nu = sign(J_2 - J_1) sqrt(d_21 S / (J_0 J_1 J_2)),
       k^2 = d_10 P / (d_21 S),
       k'^2 = 1 - k^2 = d_20 (d_21 m_2^2/J_2 - d_10 m_0^2/J_0) / (d_21 S).

   ``P`` and ``S`` are sums of terms of one sign (no cancellation).  The only
   cancellation is the distance to the separatrix in ``k'^2``; it is evaluated in
   double-double arithmetic (Dekker's exact products), so ``k'`` keeps full relative
   accuracy for states arbitrarily close to the separatrix (``k -> 1``), taking the
   rounded body-frame ``m(0) = R0^T ell`` as exact data.  The initial phase is
   ``u_0 = F(phi_0 | k)``, ``tan phi_0 = (m_1 / a_1) / (m_0 / a_0)``, computed with
   Carlson's ``R_F``.

3. *Jacobi functions.*  ``sn, cn, dn`` come from the descending Landen (Gauss)
   transformation (DLMF 22.7.1-22.7.3, Abramowitz & Stegun 16.12): with
   ``k_{n+1} = k_n^2 / (1 + k'_n)^2`` the modulus falls quadratically to zero, where
   ``sn = sin, cn = cos, dn = 1``; the chain of moduli is precomputed (it depends on the
   body and state only) and ``rotation_at`` climbs it back with a few rational
   operations (in homogeneous coordinates, one division in all, up to 7 levels).
   ``K(k) = pi/2 prod(1 + k_n)`` (DLMF 19.8.12); ``u`` is reduced to ``[-K, K]`` first.
   The moduli near 1 are formed as ``k_{n+1} = (1 - k'_n) / (1 + k'_n)`` from the
   accurate ``k'_n``, so that neither ``K`` nor the chain loses the accuracy of ``k'``.
   ``dn`` is formed as ``(cn^2 + (1 - k_n) sn^2) / (1 + k_n sn^2)`` which keeps full
   relative accuracy when ``dn ~ k'`` is small.  The exact separatrix (``k' = 0``) uses
   ``sn = tanh, cn = dn = sech``.

4. *Orientation* (the construction of Celledoni, Fasso, Safstrom & Zanna, "The exact
   computation of the free rigid body motion and its use in splitting methods",
   SIAM J. Sci. Comput. 30 (2008) 2084-2112, with our own choice of reference frames)::

       R(t) = C Rz(psi(t)) B(n(t))^T Q^T,     n = m / L,

   ``B(n)`` is the rotation about ``e_z x n`` taking ``e_z`` to ``n``; it is regular
   because ``n_2 = a_2 dn(u) / L > 0`` on the whole orbit (the circulated axis is the
   third working axis).  ``C`` is the constant lab matrix making ``R(0) = R0``.  Writing
   ``omega_b = psi' n + (angular velocity of the frame B)`` and projecting on ``n`` gives
   ``psi' = 2E/L - c m_2 / (L (L + m_2)) = L/J_2 + c / (L + m_2)``, ``c = 2E - L^2/J_2``.
   With ``L^2 - m_2^2 = a_0^2 (1 + beta sn^2)``, where ``beta = J_2 d_10 / (J_0 d_21)`` is
   a body constant, and ``c = kappa a_0^2``, ``kappa = 1/J_0 - 1/J_2``, this integrates
   to::

       psi(t) = L/J_2 t + kappa/nu (G(u) - G(u_0)),
       G(u) = int_0^u (L - a_2 dn) / (1 + beta sn^2) du
            = L Pi(am u; -beta | k) - a_2 atan(sqrt(1 + beta) tan am u) / sqrt(1 + beta),

   with ``u = nu t + u_0``.  ``G`` grows by the same amount every period ``2K``; its mean
   slope ``f_bar = G(K)/K`` goes into the secular rate and only the periodic remainder
   ``G_p(u) = G(u) - f_bar u`` is evaluated, on the reduced ``u_r`` in ``[-K, K]`` where
   ``F(am u_r | k) = u_r``::

       psi(t) = (L/J_2 + kappa f_bar) t + kappa/nu (G_p(u) - G_p(u_0)).

   The incomplete integral of the third kind is written through Carlson's ``R_J`` in one
   of two cancellation-free forms: ``Pi - F = -beta/3 sn^3 R_J(cn^2, dn^2, 1, 1 + beta
   sn^2)`` (DLMF 19.25.14) for ``beta <= 1``, and for ``beta > 1`` the reflection
   ``n -> k^2/n`` (DLMF 19.7.9), which leaves ``R_J`` with ``p = 1 + (k^2/beta) sn^2``
   plus an arctangent.  This keeps the error of psi at ~eps times its physical size
   also for nearly axisymmetric bodies, where ``nu`` is tiny and ``kappa/nu`` huge.
   Carlson's integrals use the duplication algorithms of B. C. Carlson, "Numerical
   computation of real or complex elliptic integrals", Numer. Algorithms 10 (1995)
   13-26, with the series DLMF 19.36.1 and 19.36.2 continued to degrees 9 and 11 (fewer
   duplication steps for the same truncation error); the ``R_J`` of ``G_p`` takes
   ``cn, dn`` as the square roots of its first arguments and
   ``(p - cn^2)(p - dn^2)(p - 1) = eta (1 + eta)(eta + k^2) sn^6`` in closed form.  The
   complete integrals in ``f_bar`` come from the AGM that accompanies the Landen chain
   (DLMF 19.8.6).  On the exact separatrix (``k = 1``, no period) ``G`` is elementary
   and used as it is.

5. *Steady rotations* -- ``m`` an eigenvector of the inertia tensor: a sphere, spin about
   any principal axis (including the unstable middle one, which therefore stays put
   exactly), or an axisymmetric body spinning in its degenerate plane -- are rotations
   at constant ``omega = R0 (m / K)``, done by Rodrigues' formula.  Body-frame components
   of ``m`` below ``16 eps L`` (rounding noise of ``R0^T ell``) are ignored for that test
   only.  ``ell = 0`` leaves ``R = R0``.  Axisymmetric bodies otherwise take the general
   path with ``k = 0, beta = 0`` (regular precession, all closed forms).

6. *Theta mode* -- Jacobi's own solution, used when the nome ``q = exp(-pi K'/K) <= 0.2``
   (``k^2`` below about 0.97) and ``k^2 >= 1e-4``; the other general states take items 3
   and 4.  With ``v = pi u / (2K)`` (DLMF 22.2.4-22.2.6, the
   common divisor ``theta_4(v)`` dropped, as ``n = m / |m|`` does not need it)::

       m ~ (a_0 theta_2(v) / sqrt(k), a_1 theta_1(v) / sqrt(k k'), a_2 theta_3(v)).

   The Euler angle of precession about ``L``, ``phi_E = psi + gamma`` with
   ``e^{i gamma} = (m_0 + i m_1) / |(m_0, m_1)|``, has ``phi_E' = L/J_0 + D sn^2 / (1 +
   beta sn^2)``, ``D = L (J_0 - J_1) d_20 / (J_0^2 d_21)``; Jacobi's form of the
   third-kind integral with the imaginary parameter ``i alpha``, ``sc(alpha | k') =
   sqrt(beta) / k``, that is ``alpha = sqrt(beta) R_F(k^2, k^2 (1 + beta), k^2 + beta)``,
   integrates it to::

       phi_E(t) = phi_E(0) + (L/J_0 + D z / P) t + arg w(u) - arg w(u_0),
       w = theta_4(v + i alpha~),  alpha~ = pi alpha / (2K),  P = sqrt(beta (k^2 + beta) (1 + beta)),

   with ``Z(i alpha) = i z`` (Jacobi's zeta, from the same series at ``v = i alpha~``).
   The coefficient of ``arg w`` is exactly -1 (``D = -nu P``), so ``e^{i psi} =
   e^{i lin t} (w/|w|) ((m_0 - i m_1) / |(m_0, m_1)|)`` times the constant that makes
   ``psi(0) = 0``: no arctangent, no ``R_J``, no Landen climb.  A step costs one
   sine-cosine pair of ``v`` (the multiple angles by complex recurrence), one of
   ``lin t``, 2 to 6 terms of five series and three square roots.  ``K`` and ``K'`` come
   from the AGM.  The series' terms are at most ``q^{n^2 - n} rho^n``, ``rho = q e^{2
   alpha~}``; they stop below 1e-17.

   ``alpha`` -> ``K'`` (``rho`` -> 1) puts ``w`` near a zero of ``theta_4``, where its
   series cancels, and makes ``z`` as sensitive as ``K' - alpha`` is to the rounding of
   ``alpha``.  So for ``alpha > K'/2``, that is ``beta > k``, ``w`` is taken through
   ``theta_1`` (the quasi-periodicity ``theta_4(x + pi tau/2) = i q^{-1/4} e^{-ix}
   theta_1(x)``, DLMF 20.2(iv))::

       theta_4(v + i alpha~) = i q^{-1/4} e^{-a} e^{-iv} theta_1(v - i a),
       a = pi (K' - alpha) / (2K),  K' - alpha = R_F(beta, k^2 + beta, 1 + beta),

   the last without a subtraction: ``K' - F(phi | k') = F(chi | k')`` for ``tan phi tan
   chi = 1/k``, here ``tan chi = 1/sqrt(beta)``, and DLMF 19.25.5.  The series of
   ``theta_1`` in the odd multiples of ``v`` have the coefficients ``q^{n^2 + n} cosh((2n +
   1) a)`` and ``q^{n^2 + n} sinh((2n + 1) a)`` (both by the addition theorems, without
   cancellation), ``e^{-iv}`` joins ``lin`` as ``-dv/dt``, and ``z = (pi/2K) (C / S - 1)``
   from ``theta_1'/theta_1`` at ``-i a``, ``C`` and ``S`` these two series at ``v = 0``
   with the factors ``2n + 1`` in ``C``.  Either way ``rho`` (reflected ``q e^{2a}``) is at
   most ``sqrt(q)``.  ``k`` -> 0 (close to a steady spin) makes the two phases turn fast
   and cancel in ``psi``; they lose digits, hence the bound on ``k^2``.

The lab angular momentum ``R K R^T omega = L C e_z = R0 Q n(0) L`` and the energy
``sum m_i^2 / J_i`` are constant by construction (to rounding).
"""

import math

import numba

from direct_model.elementary import sincos
from direct_model.options import KERNEL

# --------------------------------------------------------------------------------------
# Layout of the parameter array
# --------------------------------------------------------------------------------------
_MODE_STATIC = 0.0  # ell == 0: R = R0, omega = 0
_MODE_STEADY = 1.0  # constant omega about a principal direction
_MODE_GENERAL = 2.0  # elliptic solution, 0 < k' <= 1
_MODE_SEPARATRIX = 3.0  # elliptic solution on the separatrix, k' == 0
_MODE_THETA = 4.0  # Jacobi's theta series, nome q <= e^_THETA_LNQ_MAX, away from a steady spin

_NLEV_MAX = 24  # Landen levels; k' = 1e-9 needs 7, k' = 5e-324 needs 12
_LANDEN_KTOL = 1e-9  # stop once k_n < this: sn(w|k_n) = sin w + O(k_n^2)

_I_MODE = 0
_I_C = 1  # 9 entries, row-major: C (elliptic modes) or R0 (static / steady)
_I_OMEGA = 10  # 3 entries: constant lab omega (steady mode)
_I_LJ = 13  # 3 entries: L / J_i, J_i the working moments
_I_A = 16  # 3 entries: amplitudes a_0, a_1, a_2
_I_NU = 19  # du/dt
_I_U0 = 20  # u at t = 0
_I_TWOK = 21  # 2 K(k), period of the reduction of u
_I_INV2K = 22  # 1 / (2 K)
_I_L = 23  # |L|
_I_LIN = 24  # secular rate of psi
_I_KAPNU = 25  # kappa / nu
_I_BETA = 26  # beta = -alpha^2 of the third-kind integral
_I_G = 27  # g = sqrt(1 + beta)
_I_A2G = 28  # a_2 / g
_I_FORM2 = 29  # 1.0 if beta > 1 (reflected form 2), else 0.0
_I_ETA = 30  # characteristic of the R_J term: beta (form 1) or gamma = k^2/beta (form 2)
_I_DCOEF = 31  # eta (1 + eta) (eta + k^2): (p - x)(p - y)(p - z) = DCOEF sn^6 in R_J
_I_CPI = 32  # coefficient of sn^3 R_J in G_p: -L beta/3 (form 1), L gamma/3 (form 2)
_I_SQD = 33  # sqrt((1 + beta) (1 + gamma)) (form 2)
_I_LSQD = 34  # L / SQD (form 2)
_I_FOFF = 35  # mean integrand f_bar (form 2) or f_bar - L (form 1)
_I_G0 = 36  # G_p(u_0)
_I_PERM = 37  # 3 entries: body axis of working axis i
_I_SIGN = 40  # 3 entries: sign of working axis i
_I_NLEV = 43  # number of Landen levels
_I_WSCALE = 44  # 1 / prod(1 + k_n)
_I_KN = 45  # _NLEV_MAX entries: k_n, n = 1..N
_I_OMKN = _I_KN + _NLEV_MAX  # _NLEV_MAX entries: 1 - k_n

ROT_PARAMS_SIZE = _I_OMKN + _NLEV_MAX
"""Length of the float64 parameter array filled by :func:`rotation_init` (93)."""

# the theta mode keeps its series in the Landen chain's slots
_TH_TERMS = 8  # at most; q <= 0.2 needs 6
_I_TH_N = _I_KN  # number of terms
_I_TH_NUV = _I_KN + 1  # dv/dt, v = pi u / (2 K)
_I_TH_V0 = _I_KN + 2  # v at t = 0
_I_TH_CRE = _I_KN + 3  # e^{-i psi_raw(0)}: real and imaginary parts
_I_TH_CIM = _I_KN + 4
_I_TH_M0 = _I_KN + 5  # coefficients of cos((2n+1) v) in m_0
_I_TH_M1 = _I_TH_M0 + _TH_TERMS  # of sin((2n+1) v) in m_1
_I_TH_M2 = _I_TH_M1 + _TH_TERMS  # of cos(2n v) in m_2
_I_TH_WR = _I_TH_M2 + _TH_TERMS  # of cos(2n v) in Re w (sin((2n+1) v) reflected)
_I_TH_WI = _I_TH_WR + _TH_TERMS  # of sin(2n v) in Im w (cos((2n+1) v) reflected)
_I_TH_REFLECT = _I_TH_WI + _TH_TERMS  # 1.0 if w is taken through theta_1 (beta > k, module doc), else 0.0
_THETA_LNQ_MAX = -1.6094379124341003  # ln 0.2: larger nomes (k^2 > 0.97) take the Landen path
_THETA_TOL = 1e-17  # the first term left out of every series is below this (relative to its first term)
_THETA_K2_MIN = 1e-4  # closer to a steady spin (k -> 0) the theta phases lose digits: the Landen path

_PHASE_MAX = 2.0 ** 62  # sincos's domain: int() of the multiple of pi/2 stays within int64
_SNAP = 16.0 * 2.220446049250313e-16  # relative size of rounding noise in R0^T ell

# Duplication stops once the arguments agree to these relative spreads; the series
# below (R_J to degree 11, R_F to degree 9) then truncate at < 6e-18 (R_J) and < 2e-18
# (R_F) relative -- as small as the degree-5 series after the relative spreads 1.5e-3
# and 2e-3 of Carlson's usual criterion, with one to two fewer duplication steps.
_RJ_TOL_INV = 1.0 / 0.04
_RF_TOL_INV = 1.0 / 0.025


# --------------------------------------------------------------------------------------
# Carlson's symmetric elliptic integrals (Carlson, Numer. Algorithms 10 (1995) 13-26)
# --------------------------------------------------------------------------------------
@numba.njit(**KERNEL)
def _carlson_rc1(e):
    """Carlson's R_C(1, 1 + e) for e > -1 (DLMF 19.2.17-19.2.19).

    ``atan(sqrt(e))/sqrt(e)`` or ``atanh(sqrt(-e))/sqrt(-e)``; for |e| < 1e-3 the series
    ``sum_n (-e)^n / (2n + 1)`` (truncation < 1e-19).
    """
    if abs(e) < 1e-3:
        return 1.0 - e * (1.0 / 3.0 - e * (1.0 / 5.0 - e * (1.0 / 7.0
                                                         - e * (1.0 / 9.0 - e / 11.0))))
    if e > 0.0:
        s = math.sqrt(e)
        return math.atan(s) / s
    s = math.sqrt(-e)
    return math.atanh(s) / s


@numba.njit(**KERNEL)
def _rf_series(e2, e3):
    """Series of R_F (DLMF 19.36.1 continued to degree 9, A^(-1/2) factored out).

    Degree-N terms: the t^N coefficient of ``(1 + E_2 t^2 - E_3 t^3)^(-1/2)`` times
    ``(1/2)_N / (3/2)_N`` (the expansion of Carlson's R-function, DLMF 19.19.7), ``E_j``
    the elementary symmetric functions of ``(X, Y, Z)``, ``X + Y + Z = 0``.
    """
    return 1.0 + (e2 * (-1.0 / 10.0 + e2 * (1.0 / 24.0 + e2 * (-5.0 / 208.0
                                                            + e2 * (35.0 / 2176.0))))
            + e3 * (1.0 / 14.0 + e2 * (-3.0 / 44.0 + e2 * (1.0 / 16.0
                                                         - e2 * (35.0 / 608.0))))
            + e3 * e3 * (3.0 / 104.0 - e2 * (15.0 / 272.0) + e3 * (5.0 / 304.0)))


@numba.njit(**KERNEL)
def _rj_series(e2, e3, e4, e5):
    """Series of R_J (DLMF 19.36.2 continued to degree 11, A^(-3/2) factored out).

    Degree-N terms: the t^N coefficient of ``(1 + E_2 t^2 - E_3 t^3 + E_4 t^4 -
    E_5 t^5)^(-1/2)`` times ``(3/2)_N / (5/2)_N``, ``E_j`` the elementary symmetric
    functions of ``(X, Y, Z, P, P)`` (their sum is 0).
    """
    return 1.0 + (e2 * (-3.0 / 14.0 + e2 * (9.0 / 88.0 + e2 * (-1.0 / 16.0 + e2 * (
                    105.0 / 2432.0 - e2 * (189.0 / 5888.0)))))
                  + e3 * (1.0 / 6.0 + e2 * (-9.0 / 52.0 + e2 * (45.0 / 272.0 + e2 * (
                          -5.0 / 32.0 + e2 * (189.0 / 1280.0))))
                          + e3 * (3.0 / 40.0 + e2 * (-45.0 / 304.0 + e2 * (315.0 / 1472.0))
                                  + e3 * (5.0 / 112.0 - e2 * (21.0 / 160.0))))
                  + e4 * (-3.0 / 22.0 + e2 * (3.0 / 20.0 + e2 * (-45.0 / 304.0
                                                              + e2 * (105.0 / 736.0)))
                          + e3 * (-9.0 / 68.0 + e2 * (15.0 / 56.0 - e2 * (63.0 / 160.0))
                                  - e3 * (45.0 / 368.0))
                          + e4 * (9.0 / 152.0 - e2 * (45.0 / 368.0) + e3 * (9.0 / 80.0)))
                  + e5 * (3.0 / 26.0 + e2 * (-9.0 / 68.0 + e2 * (15.0 / 112.0
                                                              - e2 * (21.0 / 160.0)))
                          + e3 * (9.0 / 76.0 - e2 * (45.0 / 184.0) + e3 * (9.0 / 80.0))
                          + e4 * (-3.0 / 28.0 + e2 * (9.0 / 40.0)) + e5 * (9.0 / 184.0)))


@numba.njit(**KERNEL)
def _rf_step(x, y, z, a, fac):
    """One duplication step of R_F (Carlson 1995, section 2): the arguments, their mean
    ``a`` and the spread's factor ``fac`` each divided by 4."""
    sx = math.sqrt(x)
    sy = math.sqrt(y)
    sz = math.sqrt(z)
    lam = sx * (sy + sz) + sy * sz
    return 0.25 * (x + lam), 0.25 * (y + lam), 0.25 * (z + lam), 0.25 * (a + lam), fac * 0.25


@numba.njit(**KERNEL)
def _rf_end(a, fac, qx, qy):
    """R_F from the series once the duplication has stopped: ``qx = A_0 - x_0``,
    ``qy = A_0 - y_0`` and ``fac = 4^-m`` give Carlson's ``X = qx fac / A_m`` etc. free of
    the cancellation in ``A_m - x_m``."""
    f = fac / a
    dx = qx * f
    dy = qy * f
    dz = -(dx + dy)
    return _rf_series(dx * dy - dz * dz, dx * dy * dz) / math.sqrt(a)


@numba.njit(**KERNEL)
def _rf_start(x, y, z):
    """The state ``(x, y, z, a, fac, qx, qy, qmax)`` of R_F(x, y, z)'s duplication before
    its first step; ``qmax`` is the spread already divided by the tolerance: the steps
    go on while ``fac qmax > a``."""
    a = (x + y + z) / 3.0
    qx = a - x
    qy = a - y
    qmax = max(abs(qx), abs(qy), abs(a - z)) * _RF_TOL_INV
    return x, y, z, a, 1.0, qx, qy, qmax


@numba.njit(**KERNEL)
def _rf_amp_start(x, sx, y, sy):
    """:func:`_rf_start` for R_F(x, y, 1) after its first step, which takes no square root
    with ``sx = sqrt(x)``, ``sy = sqrt(y)`` known."""
    a = (x + y + 1.0) / 3.0
    qx = a - x
    qy = a - y
    qmax = max(abs(qx), abs(qy), abs(a - 1.0)) * _RF_TOL_INV
    lam = sx * (sy + 1.0) + sy
    return 0.25 * (x + lam), 0.25 * (y + lam), 0.25 * (1.0 + lam), 0.25 * (a + lam), 0.25, qx, qy, qmax


@numba.njit(**KERNEL)
def _rf_open(a, fac, qmax):
    """True while R_F's duplication needs another step: the spread ``fac qmax`` is above ``a``."""
    return fac * qmax > a


@numba.njit(**KERNEL)
def _rf_tail(x, y, z, a, fac, qx, qy, qmax):
    """R_F from a duplication state (:func:`_rf_start`): steps while :func:`_rf_open`, then the series."""
    while _rf_open(a, fac, qmax):
        x, y, z, a, fac = _rf_step(x, y, z, a, fac)
    return _rf_end(a, fac, qx, qy)


@numba.njit(**KERNEL)
def carlson_rf(x, y, z):
    """Carlson's R_F(x, y, z) = 1/2 int_0^inf dt / sqrt((t+x)(t+y)(t+z)).

    x, y, z >= 0 with at most one of them zero.  Duplication theorem (Carlson 1995,
    section 2) until the arguments agree to a relative 2.5e-2, then the series DLMF
    19.36.1 continued to degree 9 (truncation < 2e-18).
    """
    x, y, z, a, fac, qx, qy, qmax = _rf_start(x, y, z)
    return _rf_tail(x, y, z, a, fac, qx, qy, qmax)


@numba.njit(**KERNEL)
def _rf_amp(x, sx, y, sy):
    """R_F(x, y, 1) with ``sx = sqrt(x)``, ``sy = sqrt(y)`` known (:func:`_rf_amp_start`)."""
    x, y, z, a, fac, qx, qy, qmax = _rf_amp_start(x, sx, y, sy)
    return _rf_tail(x, y, z, a, fac, qx, qy, qmax)


@numba.njit(**KERNEL)
def _rj_tail(x, y, z, p, delta, a, fac, acc, qx, qy, qz, qmax):
    """Duplication steps of R_J (Carlson 1995, Algorithm 3, with the R_C corrections
    ``6 sum 4^-m R_C(1, 1 + e_m) / d_m``, ``e_m = 4^{-3m} delta / d_m^2``) until the spread
    ``fac qmax`` falls below ``a``, then the series; as in :func:`_rf_tail`."""
    while fac * qmax > a:
        sx = math.sqrt(x)
        sy = math.sqrt(y)
        sz = math.sqrt(z)
        sp = math.sqrt(p)
        lam = sx * (sy + sz) + sy * sz
        inv = 1.0 / ((sp + sx) * (sp + sy) * (sp + sz))
        acc += fac * _carlson_rc1(fac * fac * fac * delta * inv * inv) * inv
        x = 0.25 * (x + lam)
        y = 0.25 * (y + lam)
        z = 0.25 * (z + lam)
        p = 0.25 * (p + lam)
        a = 0.25 * (a + lam)
        fac *= 0.25
    f = fac / a
    dx = qx * f
    dy = qy * f
    dz = qz * f
    dp = -0.5 * (dx + dy + dz)
    xyz = dx * dy * dz
    dp2 = dp * dp
    e2 = dx * dy + dx * dz + dy * dz - 3.0 * dp2
    e3 = xyz + 2.0 * e2 * dp + 4.0 * dp2 * dp
    e4 = (2.0 * xyz + e2 * dp + 3.0 * dp2 * dp) * dp
    e5 = xyz * dp2
    return fac * _rj_series(e2, e3, e4, e5) / (a * math.sqrt(a)) + 6.0 * acc


@numba.njit(**KERNEL)
def carlson_rj(x, y, z, p):
    """Carlson's R_J(x, y, z, p) = 3/2 int_0^inf dt / ((t+p) sqrt((t+x)(t+y)(t+z))).

    x, y, z >= 0 with at most one of them zero, p > 0.  Duplication with the R_C
    corrections of Carlson (1995), Algorithm 3 (``e_m = 4^{-3m} delta / d_m^2``), until
    the arguments agree to a relative 4e-2, then the series DLMF 19.36.2 continued to
    degree 11 (truncation < 6e-18).
    """
    delta = (p - x) * (p - y) * (p - z)
    a = (x + y + z + 2.0 * p) / 5.0
    qx = a - x
    qy = a - y
    qz = a - z
    qmax = max(abs(qx), abs(qy), abs(qz), abs(a - p)) * _RJ_TOL_INV
    return _rj_tail(x, y, z, p, delta, a, 1.0, 0.0, qx, qy, qz, qmax)


@numba.njit(**KERNEL)
def _rj_amp(x, sx, y, sy, p, delta):
    """R_J(x, y, 1, p) with ``sx = sqrt(x)``, ``sy = sqrt(y)`` and
    ``delta = (p - x)(p - y)(p - 1) >= 0`` given (in closed form by the caller, free of
    cancellation): the first duplication step takes one square root."""
    a = (x + y + 1.0 + 2.0 * p) / 5.0
    qx = a - x
    qy = a - y
    qz = a - 1.0
    qmax = max(abs(qx), abs(qy), abs(qz), abs(a - p)) * _RJ_TOL_INV
    sp = math.sqrt(p)
    lam = sx * (sy + 1.0) + sy
    inv = 1.0 / ((sp + sx) * (sp + sy) * (sp + 1.0))
    acc = _carlson_rc1(delta * inv * inv) * inv
    return _rj_tail(0.25 * (x + lam), 0.25 * (y + lam), 0.25 * (1.0 + lam),
                    0.25 * (p + lam), delta, 0.25 * (a + lam), 0.25, acc, qx, qy, qz, qmax)


# --------------------------------------------------------------------------------------
# Double-double helpers (Dekker 1971) for the distance to the separatrix
# --------------------------------------------------------------------------------------
@numba.njit(**KERNEL)
def _two_sum(a, b):
    """s + e == a + b exactly, s = fl(a + b) (Knuth)."""
    s = a + b
    bb = s - a
    return s, (a - (s - bb)) + (b - bb)


@numba.njit(**KERNEL)
def _two_prod(a, b):
    """p + e == a * b exactly, p = fl(a * b) (Dekker, Veltkamp splitting, no FMA)."""
    p = a * b
    ca = 134217729.0 * a
    ah = ca - (ca - a)
    al = a - ah
    cb = 134217729.0 * b
    bh = cb - (cb - b)
    bl = b - bh
    return p, ((ah * bh - p) + ah * bl + al * bh) + al * bl


@numba.njit(**KERNEL)
def _dd_mul(ah, al, bh, bl):
    """Product of two double-double numbers (relative error ~ 1e-32)."""
    p, e = _two_prod(ah, bh)
    e += ah * bl + al * bh
    s = p + e
    return s, e - (s - p)


@numba.njit(**KERNEL)
def _separatrix_distance(i_lo, i_mid, i_hi, m_lo, m_hi):
    """H = (I_hi - I_mid) I_lo m_hi^2 - (I_mid - I_lo) I_hi m_lo^2 in double-double.

    ``H / (I_lo I_hi) = L^2 - 2E I_mid``: its sign tells around which axis ``m``
    circulates, and ``|H|`` gives ``k'^2`` with full relative accuracy near ``k = 1``.
    """
    dh, dl = _two_sum(i_hi, -i_mid)
    qh, ql = _two_prod(m_hi, m_hi)
    t1h, t1l = _dd_mul(dh, dl, qh, ql)
    t1h, t1l = _dd_mul(t1h, t1l, i_lo, 0.0)
    dh, dl = _two_sum(i_mid, -i_lo)
    qh, ql = _two_prod(m_lo, m_lo)
    t2h, t2l = _dd_mul(dh, dl, qh, ql)
    t2h, t2l = _dd_mul(t2h, t2l, i_hi, 0.0)
    s, e = _two_sum(t1h, -t2h)
    return s + (e + (t1l - t2l))


# --------------------------------------------------------------------------------------
# Jacobi elliptic functions and the phase integral
# --------------------------------------------------------------------------------------
@numba.njit(**KERNEL)
def _landen_sncndn(w, params):
    """sn, cn, dn of ``u = w prod(1 + k_n)`` by climbing the stored Landen chain.

    At the bottom ``k_N < 1e-9`` and ``sn = sin w, cn = cos w, dn = 1``; each level applies
    the Gauss transformation (DLMF 22.7.1-22.7.3) with ``s = sn(w_n | k_n)``::

        sn_{n-1} = (1 + k_n) s / (1 + k_n s^2),   cn_{n-1} = cn_n dn_n / (1 + k_n s^2),
        dn_{n-1} = (cn_n^2 + (1 - k_n) s^2) / (1 + k_n s^2)   [= (1 - k_n s^2)/(...)].

    Up to 7 levels (k' > ~1e-9) the climb runs in homogeneous coordinates
    ``sn = S/W, cn = C/W, dn = D/V`` (``W, V >= 1`` grow at most like ``2^706``), which
    replaces the division of each level by a few products: one division at the end.
    """
    s = math.sin(w)
    c = math.cos(w)
    d = 1.0
    nlev = int(params[_I_NLEV])
    if nlev > 7:
        for i in range(nlev - 1, -1, -1):
            kn = params[_I_KN + i]
            s2 = s * s
            r = 1.0 / (1.0 + kn * s2)
            d_new = (c * c + params[_I_OMKN + i] * s2) * r
            s = (1.0 + kn) * s * r
            c = c * d * r
            d = d_new
        return s, c, d
    # homogeneous coordinates: S' = (1 + k) S W V, C' = C D W, W' = V P, D' = C^2 +
    # (1 - k) S^2, V' = P with P = W^2 + k S^2 (the common denominator of the level)
    w = 1.0
    v = 1.0
    for i in range(nlev - 1, -1, -1):
        kn = params[_I_KN + i]
        s2 = s * s
        w2 = w * w
        pw = w2 + kn * s2
        dn = c * c + params[_I_OMKN + i] * s2
        s = (1.0 + kn) * s * (w * v)
        c = c * d * w
        w = v * pw
        v = pw
        d = dn
    rw = 1.0 / w
    return s * rw, c * rw, d / v


@numba.njit(**KERNEL)
def _pi_minus_f(s, c, d, beta):
    """Pi(phi; -beta | k) - F(phi | k) = -beta/3 sn^3 R_J(cn^2, dn^2, 1, 1 + beta sn^2).

    DLMF 19.25.14 with ``sin phi = s``, ``cos phi = c >= 0``, ``Delta = d``; free of
    cancellation for ``beta <= 1`` (form 1).  (The kernels use the same formula through
    :func:`_gp_amp`.)
    """
    if beta == 0.0 or s == 0.0:
        return 0.0
    return -beta / 3.0 * s * s * s * carlson_rj(c * c, d * d, 1.0, 1.0 + beta * s * s)


@numba.njit(**KERNEL)
def _pi_large_beta(s, c, d, gamma, sqd):
    """Pi(phi; -beta | k) for beta > 1 (form 2), a sum of two terms of one sign.

    The relation between ``Pi(phi; n)`` and ``Pi(phi; k^2/n)`` (DLMF 19.7.9, the R_C
    reduced to an arctangent) and DLMF 19.25.14 for ``n' = k^2/n = -gamma`` give::

        Pi(phi; -beta | k) = gamma/3 sn^3 R_J(cn^2, dn^2, 1, 1 + gamma sn^2)
                             + atan(sqrt(D) sn / (cn dn)) / sqrt(D),
        D = (1 + beta)(1 + gamma).
    """
    pi3 = math.atan2(sqd * s, c * d) / sqd
    if s != 0.0:
        pi3 += gamma / 3.0 * s * s * s * carlson_rj(c * c, d * d, 1.0, 1.0 + gamma * s * s)
    return pi3


@numba.njit(**KERNEL)
def _gp_amp(params, s, c, d, ur):
    """Periodic part ``G_p`` of the phase integral at ``sin phi = s``, ``cos phi = c >= 0``,
    ``Delta = d``, ``phi = am u_r``, ``u_r`` in ``[-K, K]`` (see :func:`_phase_state`)::

        form 1 (beta <= 1):  G_p = L (Pi - F) - a_2 T - (f_bar - L) u_r,
        form 2 (beta > 1):   G_p = L Pi - a_2 T - f_bar u_r,

    ``Pi - F`` (form 1) as in :func:`_pi_minus_f`, ``Pi`` (form 2) as in
    :func:`_pi_large_beta`, ``T = atan(g tan phi) / g``.  The ``R_J`` term
    ``CPI sn^3 R_J(cn^2, dn^2, 1, 1 + eta sn^2)`` gets its square roots ``cn, dn`` and
    ``(p - x)(p - y)(p - 1) = eta (1 + eta)(eta + k^2) sn^6`` in closed form.
    ``eta = 0`` only for an axisymmetric body with ``J_0 = J_1`` (``k = beta = 0``,
    ``am u = u``, ``f = L - a_2 = f_bar``): there ``G_p = 0`` identically.
    """
    eta = params[_I_ETA]
    if eta == 0.0:
        return 0.0
    gp = -params[_I_A2G] * math.atan2(params[_I_G] * s, c) - params[_I_FOFF] * ur
    if params[_I_FORM2] != 0.0:
        gp += params[_I_LSQD] * math.atan2(params[_I_SQD] * s, c * d)
    if s != 0.0:
        s2 = s * s
        rj = _rj_amp(c * c, c, d * d, d, 1.0 + eta * s2, params[_I_DCOEF] * (s2 * s2 * s2))
        gp += params[_I_CPI] * (s * s2) * rj
    return gp


@numba.njit(**KERNEL)
def _phase_state(params, u):
    """sn(u), cn(u), dn(u) and the periodic part ``G_p(u)`` of the phase integral.

    ``G(u) = int_0^u f du'``, ``f = (L - a_2 dn) / (1 + beta sn^2)``, is
    ``L Pi(am u; -beta | k) - a_2 T(am u)`` with ``T(phi) = atan(g tan phi) / g``,
    ``g = sqrt(1 + beta)`` (module docstring, item 4).  With ``u = u_r + 2jK``,
    ``u_r`` in ``[-K, K]`` (``am u_r`` in ``[-pi/2, pi/2]``, ``F(am u_r) = u_r``), and
    ``f_bar`` the mean of ``f``, ``G(u) = f_bar u + G_p(u_r)``: the secular part goes
    into the rate of psi and only the periodic part is evaluated (:func:`_gp_amp`), each
    form with the cancellation-free expression of ``Pi`` for its range of ``beta``.
    (The rounding of ``u`` then perturbs psi by ``eps |u| kappa (f - f_bar) / nu``, the
    size of the physical oscillation of psi times eps.)  On the separatrix (``k = 1``,
    not periodic) ``sn = tanh u, cn = dn = sech u`` and the whole ``G`` is returned, with
    ``Pi(am u; -beta | 1) = (u + sqrt(beta) atan(sqrt(beta) tanh u)) / (1 + beta)``.
    """
    if params[_I_MODE] == _MODE_SEPARATRIX:
        beta = params[_I_BETA]
        g = params[_I_G]
        s = math.tanh(u)
        c = 1.0 / math.cosh(u)
        sb = math.sqrt(beta)
        pi3 = (u + sb * math.atan(sb * s)) / (1.0 + beta)
        return s, c, c, params[_I_L] * pi3 - params[_I_A + 2] * math.atan2(g * s, c) / g
    twok = params[_I_TWOK]
    j = math.floor(u * params[_I_INV2K] + 0.5)
    ur = u - j * twok
    s, c, d = _landen_sncndn(ur * params[_I_WSCALE], params)
    gp = _gp_amp(params, s, abs(c), d, ur)
    if int(j) & 1:  # sn(u_r + 2jK) = (-1)^j sn(u_r), likewise cn; dn has period 2K
        s = -s
        c = -c
    return s, c, d, gp


@numba.njit(**KERNEL)
def _unit_momentum(params, s, c, d):
    """Unit body angular momentum n = m / |m| in the working frame from sn, cn, dn."""
    m0 = params[_I_A + 0] * c
    m1 = params[_I_A + 1] * s
    m2 = params[_I_A + 2] * d
    inv = 1.0 / math.sqrt(m0 * m0 + m1 * m1 + m2 * m2)
    return m0 * inv, m1 * inv, m2 * inv


# --------------------------------------------------------------------------------------
# Jacobi's theta series (the theta mode)
# --------------------------------------------------------------------------------------
@numba.njit(**KERNEL)
def _agm_open(a, g):
    """True while the arithmetic-geometric mean of ``(a, g)`` needs another step: once
    ``|a - g| <= 1e-9 a`` the next mean is exact to ~1e-19 (written so that a NaN ends the
    steps too)."""
    return abs(a - g) > 1e-9 * a


@numba.njit(**KERNEL)
def _theta_elliptic(k, kp, ax, ay, az, x, sx, y, sy):
    """The four elliptic quantities of the theta mode's set-up: ``K(k)``, ``K(k')``,
    ``R_F(ax, ay, az)`` for ``alpha`` or ``K' - alpha`` (:func:`_theta_init`) and
    ``R_F(x, y, 1)`` for ``u_0`` (:func:`_rf_amp`, ``sx = sqrt(x)``, ``sy = sqrt(y)``).

    ``K = pi / (2 AGM(1, k'))`` (DLMF 19.8.5).  The four chains of square roots (two AGMs,
    two duplications) are independent; their steps are interleaved so that the CPU runs
    them side by side.  Each chain stops at its own test and takes the same operations as
    alone.
    """
    a1 = 1.0  # AGM(1, k')
    g1 = kp
    a2 = 1.0  # AGM(1, k)
    g2 = k
    xa, ya, za, aa, fa, qxa, qya, qma = _rf_start(ax, ay, az)
    xu, yu, zu, au, fu, qxu, qyu, qmu = _rf_amp_start(x, sx, y, sy)
    while True:
        open1 = _agm_open(a1, g1)
        open2 = _agm_open(a2, g2)
        open3 = _rf_open(aa, fa, qma)
        open4 = _rf_open(au, fu, qmu)
        if not (open1 or open2 or open3 or open4):
            break
        if open1:
            a1, g1 = 0.5 * (a1 + g1), math.sqrt(a1 * g1)
        if open2:
            a2, g2 = 0.5 * (a2 + g2), math.sqrt(a2 * g2)
        if open3:
            xa, ya, za, aa, fa = _rf_step(xa, ya, za, aa, fa)
        if open4:
            xu, yu, zu, au, fu = _rf_step(xu, yu, zu, au, fu)
    return math.pi / (a1 + g1), math.pi / (a2 + g2), _rf_end(aa, fa, qxa, qya), _rf_end(au, fu, qxu, qyu)


@numba.njit(**KERNEL)
def _theta_init(params, kk, kkp, rf, k, kp, beta, reflect, lmag, j0, j1, d20, d21, nu, a0, a1, a2, u0):
    """Set up the theta mode (module docstring, item 6) from ``kk = K(k)``, ``kkp = K(k')``
    and ``rf`` (:func:`_theta_elliptic`): ``R_F(k^2, k^2 (1 + beta), k^2 + beta)``, so that
    ``alpha = sqrt(beta) rf``, or with ``reflect`` (``beta > k``, that is ``alpha > K'/2``)
    ``R_F(beta, k^2 + beta, 1 + beta) = K' - alpha``. False, and nothing to be read left
    behind, if the state needs the Landen path (``q > 0.2`` or more than ``_TH_TERMS`` terms).

    The terms of ``w``'s series are at most ``q^{n^2 - n} rho^n``, ``rho = q e^{2 alpha~} <=
    sqrt(q)``; reflected, those of ``theta_1`` relative to its first are at most ``(2n + 1)
    q^{n^2 + n} cosh((2n + 1) a)``, ``a = pi (K' - alpha) / (2K)``, ``q e^{2a} <= sqrt(q)``.
    """
    lq = -math.pi * kkp / kk
    if not lq <= _THETA_LNQ_MAX:
        return False
    k2 = k * k
    hw = 0.5 * math.pi / kk
    q = math.exp(lq)
    s4 = math.exp(0.25 * lq)
    f0 = 2.0 * a0 * s4 / math.sqrt(k)
    f1 = 2.0 * a1 * s4 / (math.sqrt(k) * math.sqrt(kp))
    params[_I_TH_M0] = f0
    params[_I_TH_M1] = f1
    params[_I_TH_M2] = a2
    e = 1.0
    sh = 0.0  # sinh, cosh of (2n + 1) a (reflected)
    ch = 1.0
    s2a = 0.0  # sinh, cosh of 2a
    c2a = 1.0
    if reflect:
        a = hw * rf
        sh = math.sinh(a)
        ch = math.cosh(a)
        s2a = 2.0 * sh * ch
        c2a = 1.0 + 2.0 * sh * sh
        params[_I_TH_WR] = ch
        params[_I_TH_WI] = -sh
    else:
        e = math.exp(2.0 * hw * math.sqrt(beta) * rf)
        params[_I_TH_WR] = 1.0
        params[_I_TH_WI] = 0.0
    qo = q  # q^(2n - 1)
    qn = 1.0  # q^(n^2)
    qd = 1.0  # q^(n (n + 1))
    cp = 1.0  # q^(n^2) e^(n at2), at2 = 2 alpha~ (reflected: the bound above)
    cm = 1.0  # q^(n^2) e^(-n at2)
    sgn = 1.0
    zn = 0.0  # sums for Jacobi's zeta (reflected: sum (2n + 1) WR_n and -sum WI_n)
    zd = 1.0
    if reflect:
        zn = ch
        zd = sh
    n = 1
    while True:
        qn *= qo
        qd *= qo * q
        if reflect:
            sh, ch = sh * c2a + ch * s2a, ch * c2a + sh * s2a  # no cancellation for small a
            cp = (2 * n + 1) * qd * ch
        else:
            cp *= qo * e
            cm *= qo / e
        if not (cp > _THETA_TOL or qn > _THETA_TOL):
            break
        if n == _TH_TERMS:
            return False
        sgn = -sgn
        if reflect:
            wr = sgn * qd * ch
            wi = -sgn * qd * sh
            zn += (2 * n + 1) * wr
            zd -= wi
        else:
            wr = sgn * (cp + cm)
            wi = -sgn * (cp - cm)
            zn += n * wi
            zd += wr
        params[_I_TH_M0 + n] = f0 * qd
        params[_I_TH_M1 + n] = sgn * f1 * qd
        params[_I_TH_M2 + n] = 2.0 * a2 * qn
        params[_I_TH_WR + n] = wr
        params[_I_TH_WI + n] = wi
        qo *= q * q
        n += 1
    # Z(i alpha) = i z; D/P_a of the rate of phi_E
    if reflect:
        z = hw * (zn / zd - 1.0)  # from theta_1'/theta_1 at -i a
    else:
        z = math.pi / kk * zn / zd  # (pi/K) sum n WI_n / sum WR_n
    pa = math.sqrt(beta * (k2 + beta) * (1.0 + beta))
    lin = lmag / j0 + lmag * (j0 - j1) * d20 / (j0 * j0 * d21) * z / pa
    params[_I_TH_NUV] = nu * hw
    if reflect:
        lin -= params[_I_TH_NUV]  # w's factor e^{-iv}
    params[_I_LIN] = lin
    params[_I_TH_N] = n
    params[_I_TH_V0] = u0 * hw
    params[_I_TH_CRE] = 1.0
    params[_I_TH_CIM] = 0.0
    params[_I_TH_REFLECT] = 1.0 if reflect else 0.0
    return True


@numba.njit(**KERNEL)
def _phase_sincos(x):
    """(sin x, cos x) of a phase: :func:`direct_model.elementary.sincos` on its domain ``|x| < 2^62``, libm's
    beyond (where ulp(x) > 1000 makes the phase meaningless, but numba and C still agree)."""
    if abs(x) < _PHASE_MAX:
        return sincos(x)
    return math.sin(x), math.cos(x)


@numba.njit(**KERNEL)
def _theta_state(params, t):
    """The working-frame unit momentum ``n = m / |m|`` and ``(cos psi, sin psi)`` at time
    ``t`` in the theta mode (module docstring, item 6).

    The multiple angles come from one sine-cosine pair by complex recurrence.
    ``e^{i psi} = e^{i lin t} (w / |w|) ((m_0 - i m_1) / |(m_0, m_1)|) e^{-i psi_raw(0)}``;
    reflected, ``w`` is ``theta_1(v - i a)``, its series in the odd multiples of ``v``.
    """
    v = params[_I_TH_NUV] * t + params[_I_TH_V0]
    s1, c1 = _phase_sincos(v)
    c2 = c1 * c1 - s1 * s1
    s2 = 2.0 * s1 * c1
    co = c1  # cos, sin of (2n + 1) v
    so = s1
    ce = 1.0  # cos, sin of 2n v
    se = 0.0
    m0 = 0.0
    m1 = 0.0
    m2 = 0.0
    wr = 0.0
    wi = 0.0
    odd = params[_I_TH_REFLECT] != 0.0
    for i in range(int(params[_I_TH_N])):
        m0 += params[_I_TH_M0 + i] * co
        m1 += params[_I_TH_M1 + i] * so
        m2 += params[_I_TH_M2 + i] * ce
        wr += params[_I_TH_WR + i] * (so if odd else ce)
        wi += params[_I_TH_WI + i] * (co if odd else se)
        co_next = co * c2 - so * s2
        so = so * c2 + co * s2
        co = co_next
        ce_next = ce * c2 - se * s2
        se = se * c2 + ce * s2
        ce = ce_next
    sa, ca = _phase_sincos(params[_I_LIN] * t)
    r = 1.0 / math.sqrt((wr * wr + wi * wi) * (m0 * m0 + m1 * m1))
    xr = wr * m0 + wi * m1  # w (m_0 - i m_1)
    xi = wi * m0 - wr * m1
    yr = (xr * ca - xi * sa) * r
    yi = (xr * sa + xi * ca) * r
    cre = params[_I_TH_CRE]
    cim = params[_I_TH_CIM]
    inv = 1.0 / math.sqrt(m0 * m0 + m1 * m1 + m2 * m2)
    return m0 * inv, m1 * inv, m2 * inv, yr * cre - yi * cim, yr * cim + yi * cre


@numba.njit(**KERNEL)
def _ez_to_n(n0, n1, n2):
    """Rotation B (row-major entries) about e_z x n taking e_z to the unit vector n.

    ``B = I + [v]x + [v]x^2 / (1 + n_2)``, ``v = e_z x n``; regular for ``n_2 > -1`` and
    well conditioned for ``n_2 >= 0``, which holds on the whole orbit.
    """
    f = 1.0 / (1.0 + n2)
    b01 = -f * n0 * n1
    return (1.0 - f * n0 * n0, b01, n0,
            b01, 1.0 - f * n1 * n1, n1,
            -n0, -n1, n2)


# --------------------------------------------------------------------------------------
# Set-up
# --------------------------------------------------------------------------------------
@numba.njit(**KERNEL)
def _is_steady(m0, m1, m2, k0, k1, k2):
    """True if (m0, m1, m2) is an eigenvector of diag(k0, k1, k2) (exact comparison)."""
    if m0 != 0.0 and m1 != 0.0 and k0 != k1:
        return False
    if m0 != 0.0 and m2 != 0.0 and k0 != k2:
        return False
    if m1 != 0.0 and m2 != 0.0 and k1 != k2:
        return False
    return True


@numba.njit(**KERNEL)
def _landen_agm(k, kp, eta, params):
    """Store the descending Landen moduli; return K(k) = pi/2 prod(1 + k_n) and
    ``(Pi(-eta | k) - K(k)) / K(k)`` (complete integrals, ``0 <= eta``).

    ``k_{n+1} = k_n^2 / (1 + k'_n)^2``, ``1 - k_{n+1} = 2 k'_n / (1 + k'_n)``,
    ``k'_{n+1} = 2 sqrt(k'_n) / (1 + k'_n)`` -- all free of cancellation for k -> 0 and
    k -> 1 (needs k' > 0).  The same sequence is the AGM ``a_n, g_n = a_n k'_n`` of
    ``(1, k')``, ``a_{n+1} = a_n (1 + k'_n) / 2``, which carries the complete integral of
    the third kind (DLMF 19.8.6 with ``alpha^2 = -eta``)::

        p_0^2 = 1 + eta,  Q_0 = 1,  eps_n = (p_n^2 - a_n g_n) / (p_n^2 + a_n g_n),
        p_{n+1} = (p_n^2 + a_n g_n) / (2 p_n),  Q_{n+1} = Q_n eps_n / 2,
        Pi(-eta | k) - K(k) = -K(k)/2 eta/(1 + eta) sum_n Q_n,

    a sum of terms of one sign up to the quadratically small ones, with
    ``p_0^2 - a_0 g_0 = eta + k^2 / (1 + k')`` written without cancellation.  It runs
    until ``Q_n`` is negligible (at least as long as the Landen chain).  The ratio
    ``(Pi - K) / K`` does not depend on the rounding of ``K``.

    ``k_{n+1}`` is taken as ``(1 - k'_n) / (1 + k'_n)`` while ``k'_n <= 1/2``: the moduli
    near 1 then keep full accuracy (the squared form doubles their relative error at each
    level, which near the separatrix cost ~1e-14 in ``prod(1 + k_n)`` and in the
    effective ``k'`` of the chain).
    """
    n = 0
    prod = 1.0
    a = 1.0
    pp2 = 1.0 + eta
    num = eta + k * k / (1.0 + kp)
    q = 1.0
    qsum = 1.0
    while True:
        den = pp2 + a * a * kp
        q *= 0.5 * num / den
        qsum += q
        landen = k >= _LANDEN_KTOL and n < _NLEV_MAX
        if not landen and not abs(q) > 1e-17 * qsum:    # written so that a NaN ends the loop too
            break
        opk = 1.0 + kp
        r = 1.0 / opk
        if landen:
            k = (1.0 - kp) * r if kp <= 0.5 else (k * r) ** 2
            params[_I_KN + n] = k
            params[_I_OMKN + n] = 2.0 * kp * r
            prod *= 1.0 + k
            n += 1
        a = 0.5 * a * opk
        kp = 2.0 * math.sqrt(kp) * r
        pp2 = den * den / (4.0 * pp2)
        num = pp2 - a * a * kp
    params[_I_NLEV] = n
    params[_I_WSCALE] = 1.0 / prod
    return 0.5 * math.pi * prod, -0.5 * eta / (1.0 + eta) * qsum


@numba.njit(**KERNEL)
def _landen_chain(k, kp, params):
    """Store the descending Landen moduli and return K(k) = pi/2 prod(1 + k_n)
    (:func:`_landen_agm`)."""
    return _landen_agm(k, kp, 0.0, params)[0]


@numba.njit(**KERNEL)
def _store_r0(R0, params):
    """C = R0 (static and steady modes)."""
    for r in range(3):
        for c in range(3):
            params[_I_C + 3 * r + c] = R0[r, c]


@numba.njit(**KERNEL)
def rotation_init(K, R0, ell, params):
    """Precompute torque-free motion.

    K      : float64[3]   principal values of the inertia tensor per unit mass (J/m) along
                          the body axes 0,1,2 (positive, any order, possibly equal)
    R0     : float64[3,3] rotation matrix body->lab at t = 0 (x_lab = R0 @ x_body)
    ell    : float64[3]   angular momentum per unit mass L/m in the LAB frame (constant);
                          may be exactly zero (then the body does not rotate)
    params : float64[ROT_PARAMS_SIZE] output, filled in place

    See the module docstring for the formulas (Landau & Lifshitz section 37; Celledoni
    et al. 2008; Carlson 1995).
    """
    for i in range(_I_KN):  # the Landen levels beyond _I_NLEV are never read
        params[i] = 0.0
    mb0 = R0[0, 0] * ell[0] + R0[1, 0] * ell[1] + R0[2, 0] * ell[2]
    mb1 = R0[0, 1] * ell[0] + R0[1, 1] * ell[1] + R0[2, 1] * ell[2]
    mb2 = R0[0, 2] * ell[0] + R0[1, 2] * ell[1] + R0[2, 2] * ell[2]
    lmag = math.sqrt(mb0 * mb0 + mb1 * mb1 + mb2 * mb2)
    if lmag == 0.0:
        params[_I_MODE] = _MODE_STATIC
        _store_r0(R0, params)
        return

    # ---- steady rotation about an eigenvector of the inertia tensor
    thr = _SNAP * lmag
    s0 = mb0 if abs(mb0) > thr else 0.0
    s1 = mb1 if abs(mb1) > thr else 0.0
    s2 = mb2 if abs(mb2) > thr else 0.0
    if _is_steady(s0, s1, s2, K[0], K[1], K[2]):
        params[_I_MODE] = _MODE_STEADY
        _store_r0(R0, params)
        w0 = s0 / K[0]
        w1 = s1 / K[1]
        w2 = s2 / K[2]
        for r in range(3):
            params[_I_OMEGA + r] = R0[r, 0] * w0 + R0[r, 1] * w1 + R0[r, 2] * w2
        return

    # ---- working frame: sort the axes, pick the circulated one, fix the signs
    mb = (mb0, mb1, mb2)
    i_lo, i_mid, i_hi = 0, 1, 2
    if K[i_mid] < K[i_lo]:
        i_lo, i_mid = i_mid, i_lo
    if K[i_hi] < K[i_mid]:
        i_mid, i_hi = i_hi, i_mid
    if K[i_mid] < K[i_lo]:
        i_lo, i_mid = i_mid, i_lo
    hsep = _separatrix_distance(K[i_lo], K[i_mid], K[i_hi], mb[i_lo], mb[i_hi])
    if hsep >= 0.0:  # L^2 >= 2E I_mid: circulation around the axis of largest inertia
        o0, o1, o2 = i_lo, i_mid, i_hi
    else:
        o0, o1, o2 = i_hi, i_mid, i_lo
    parity = 1.0 if (o1 - o0) * (o2 - o0) * (o2 - o1) > 0 else -1.0
    sg0 = 1.0 if mb[o0] >= 0.0 else -1.0
    sg2 = 1.0 if mb[o2] >= 0.0 else -1.0
    sg1 = parity * sg0 * sg2
    x = sg0 * mb[o0]
    y = sg1 * mb[o1]
    z = sg2 * mb[o2]
    j0 = K[o0]
    j1 = K[o1]
    j2 = K[o2]
    params[_I_PERM + 0] = o0
    params[_I_PERM + 1] = o1
    params[_I_PERM + 2] = o2
    params[_I_SIGN + 0] = sg0
    params[_I_SIGN + 1] = sg1
    params[_I_SIGN + 2] = sg2
    params[_I_LJ + 0] = lmag / j0
    params[_I_LJ + 1] = lmag / j1
    params[_I_LJ + 2] = lmag / j2

    # ---- Landau-Lifshitz amplitudes, rate and modulus
    d10 = abs(j1 - j0)
    d20 = abs(j2 - j0)
    d21 = abs(j2 - j1)
    pp = x * x * d20 / j0 + y * y * d21 / j1
    ss = y * y * d10 / j1 + z * z * d20 / j2
    kp2 = min(d20 * abs(hsep) / (j0 * j2 * d21 * ss), 1.0)
    k2 = min(d10 * pp / (d21 * ss), 1.0)
    a2 = math.sqrt(ss * j2 / d20)
    params[_I_A + 0] = math.sqrt(pp * j0 / d20)
    params[_I_A + 1] = math.sqrt(pp * j1 / d21)
    params[_I_A + 2] = a2
    nu = math.copysign(math.sqrt(d21 * ss / (j0 * j1 * j2)), j2 - j1)
    params[_I_NU] = nu
    beta = j2 * d10 / (j0 * d21)
    gamma = pp * j0 / (ss * j2)  # = k^2 / beta
    gfac = math.sqrt(1.0 + beta)
    sqd = math.sqrt((1.0 + beta) * (1.0 + gamma))
    kappa = (j2 - j0) / (j0 * j2)
    params[_I_BETA] = beta
    params[_I_G] = gfac
    params[_I_A2G] = a2 / gfac
    params[_I_L] = lmag
    params[_I_KAPNU] = kappa / nu

    # ---- initial amplitude phi_0 (cos phi_0 >= 0) and phase u_0 = F(phi_0 | k)
    cf = x * math.sqrt(j1 * d20)
    sf = y * math.sqrt(j0 * d21)
    hinv = 1.0 / math.sqrt(cf * cf + sf * sf)  # no hypot: |ell| and K within 1e+-100 of 1 (module doc)
    cf *= hinv
    sf *= hinv
    theta = kp2 != 0.0 and k2 >= _THETA_K2_MIN  # a candidate for the theta mode
    if kp2 == 0.0:
        params[_I_MODE] = _MODE_SEPARATRIX
        params[_I_LIN] = lmag / j2
        u0 = math.asinh(sf / cf)
    elif k2 == 0.0:  # axisymmetric (J_0 = J_1): F(phi | 0) = phi
        u0 = math.atan2(sf, cf)
    else:
        d = math.sqrt(cf * cf + kp2 * sf * sf)  # dn(u_0)
        if theta:
            k = math.sqrt(k2)
            kp = math.sqrt(kp2)
            reflect = beta > k  # alpha > K'/2: w passes near a zero of theta_4, so it is taken through theta_1
            kk, kkp, rf_shift, rf_u0 = _theta_elliptic(
                k, kp, beta if reflect else k2, k2 + beta if reflect else k2 * (1.0 + beta),
                1.0 + beta if reflect else k2 + beta, cf * cf, cf, d * d, d)
        else:
            rf_u0 = _rf_amp(cf * cf, cf, d * d, d)
        u0 = sf * rf_u0
    params[_I_U0] = u0
    if theta and _theta_init(
            params, kk, kkp, rf_shift, k, kp, beta, reflect, lmag, j0, j1, d20, d21, nu,
            params[_I_A + 0], params[_I_A + 1], a2, u0):
        params[_I_MODE] = _MODE_THETA
        n0, n1, n2, cr, ci = _theta_state(params, 0.0)
        params[_I_TH_CRE] = cr  # then psi(0) = 0 and R(0) = R0 up to rounding
        params[_I_TH_CIM] = -ci
    else:
        if kp2 != 0.0:
            params[_I_MODE] = _MODE_GENERAL
            # the R_J term: Pi - F with eta = beta (form 1) or Pi(-gamma) - F (form 2)
            form2 = beta > 1.0
            eta = gamma if form2 else beta
            params[_I_FORM2] = 1.0 if form2 else 0.0
            params[_I_ETA] = eta
            params[_I_DCOEF] = eta * (1.0 + eta) * (eta + k2)
            params[_I_CPI] = lmag * gamma / 3.0 if form2 else -lmag * beta / 3.0
            params[_I_SQD] = sqd
            params[_I_LSQD] = lmag / sqd
            kcomp, pik = _landen_agm(math.sqrt(k2), math.sqrt(kp2), eta, params)
            params[_I_TWOK] = 2.0 * kcomp
            params[_I_INV2K] = 0.5 / kcomp
            # mean f_bar = G(K) / K; psi' = L/J_2 + kappa f  =>  mean rate L/J_2 + kappa f_bar
            # G(K) = L Pi(-beta) - a_2 T(pi/2) with Pi(-beta) - K = pik K (form 1) or
            # Pi(-beta) = K - Pi(-gamma) + pi / (2 sqd) (form 2)
            g_quarter = -a2 * 0.5 * math.pi / gfac  # -a_2 T(pi/2)
            if form2:
                g_quarter += lmag * (0.5 * math.pi / sqd - pik * kcomp)
                foff = g_quarter / kcomp  # f_bar
                params[_I_LIN] = lmag / j2 + kappa * foff
            else:
                foff = lmag * pik - a2 * 0.5 * math.pi / (gfac * kcomp)  # f_bar - L
                params[_I_LIN] = lmag / j0 + kappa * foff
            params[_I_FOFF] = foff
        # G_p and n at u_0 as rotation_at evaluates them (not from sf, cf, d): then
        # psi(0) = 0 and R(0) = R0 exactly up to rounding
        s, c, d, gval = _phase_state(params, u0)
        params[_I_G0] = gval
        n0, n1, n2 = _unit_momentum(params, s, c, d)

    # ---- C = R0 Q B(n(0)): makes R(0) = R0 exactly up to rounding
    b00, b01, b02, b10, b11, b12, b20, b21, b22 = _ez_to_n(n0, n1, n2)
    for r in range(3):
        q0 = sg0 * R0[r, o0]
        q1 = sg1 * R0[r, o1]
        q2 = sg2 * R0[r, o2]
        params[_I_C + 3 * r + 0] = q0 * b00 + q1 * b10 + q2 * b20
        params[_I_C + 3 * r + 1] = q0 * b01 + q1 * b11 + q2 * b21
        params[_I_C + 3 * r + 2] = q0 * b02 + q1 * b12 + q2 * b22


# --------------------------------------------------------------------------------------
# Evaluation
# --------------------------------------------------------------------------------------
@numba.njit(**KERNEL)
def rotation_at(params, t, R_out, omega_out):
    """Fill R_out (3x3, body->lab) and omega_out (3, lab-frame angular velocity) at time t.

    ``params`` comes from :func:`rotation_init`.  Any real ``t`` (typically ``t >= 0``,
    possibly many periods); no allocation.
    """
    mode = params[_I_MODE]
    if mode == _MODE_STATIC:
        for r in range(3):
            omega_out[r] = 0.0
            for c in range(3):
                R_out[r, c] = params[_I_C + 3 * r + c]
        return
    if mode == _MODE_STEADY:
        w0 = params[_I_OMEGA + 0]
        w1 = params[_I_OMEGA + 1]
        w2 = params[_I_OMEGA + 2]
        wn = math.sqrt(w0 * w0 + w1 * w1 + w2 * w2)
        e0 = w0 / wn
        e1 = w1 / wn
        e2 = w2 / wn
        sn = math.sin(wn * t)
        vc = 2.0 * math.sin(0.5 * wn * t) ** 2  # 1 - cos
        # Rodrigues: Rot = I + sin [e]x + (1 - cos) [e]x^2
        r00 = 1.0 - vc * (e1 * e1 + e2 * e2)
        r11 = 1.0 - vc * (e0 * e0 + e2 * e2)
        r22 = 1.0 - vc * (e0 * e0 + e1 * e1)
        r01 = vc * e0 * e1 - sn * e2
        r10 = vc * e0 * e1 + sn * e2
        r02 = vc * e0 * e2 + sn * e1
        r20 = vc * e0 * e2 - sn * e1
        r12 = vc * e1 * e2 - sn * e0
        r21 = vc * e1 * e2 + sn * e0
        for c in range(3):
            p0 = params[_I_C + c]
            p1 = params[_I_C + 3 + c]
            p2 = params[_I_C + 6 + c]
            R_out[0, c] = r00 * p0 + r01 * p1 + r02 * p2
            R_out[1, c] = r10 * p0 + r11 * p1 + r12 * p2
            R_out[2, c] = r20 * p0 + r21 * p1 + r22 * p2
        omega_out[0] = w0
        omega_out[1] = w1
        omega_out[2] = w2
        return

    if mode == _MODE_THETA:
        n0, n1, n2, cp, sp = _theta_state(params, t)
    else:
        u = params[_I_NU] * t + params[_I_U0]
        s, c, d, gval = _phase_state(params, u)
        n0, n1, n2 = _unit_momentum(params, s, c, d)
        psi = params[_I_LIN] * t + params[_I_KAPNU] * (gval - params[_I_G0])
        cp = math.cos(psi)
        sp = math.sin(psi)
    b00, b01, b02, b10, b11, b12, b20, b21, b22 = _ez_to_n(n0, n1, n2)
    # M = Rz(psi) B^T (rows of B^T are the columns of B)
    m00 = cp * b00 - sp * b01
    m01 = cp * b10 - sp * b11
    m02 = cp * b20 - sp * b21
    m10 = sp * b00 + cp * b01
    m11 = sp * b10 + cp * b11
    m12 = sp * b20 + cp * b21
    # working-frame angular velocity L n / J
    w0 = params[_I_LJ + 0] * n0
    w1 = params[_I_LJ + 1] * n1
    w2 = params[_I_LJ + 2] * n2
    o0 = int(params[_I_PERM + 0])
    o1 = int(params[_I_PERM + 1])
    o2 = int(params[_I_PERM + 2])
    sg0 = params[_I_SIGN + 0]
    sg1 = params[_I_SIGN + 1]
    sg2 = params[_I_SIGN + 2]
    for r in range(3):
        c0 = params[_I_C + 3 * r + 0]
        c1 = params[_I_C + 3 * r + 1]
        c2 = params[_I_C + 3 * r + 2]
        rw0 = c0 * m00 + c1 * m10 + c2 * b02
        rw1 = c0 * m01 + c1 * m11 + c2 * b12
        rw2 = c0 * m02 + c1 * m12 + c2 * b22
        R_out[r, o0] = sg0 * rw0
        R_out[r, o1] = sg1 * rw1
        R_out[r, o2] = sg2 * rw2
        omega_out[r] = rw0 * w0 + rw1 * w1 + rw2 * w2
