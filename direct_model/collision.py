"""One impulsive collision of a rigid body with the wall y = 0 (docs/model.md §4).

Frame: lab, wall normal n = +Y, velocities in m/s, lengths in units of the
particle half-size a (so angular velocities are in (m/s)/a). Per unit mass:
K = J/m in the lab frame, impulse S/m = ΔV_p.

Equations (Panfilov & Tsirkunov 2022, eqs. 1–7)::

    V_c = V_p + Ω × r_c                       contact-point velocity
    ΔV_p = S/m,   K ΔΩ = r_c × ΔV_p            impulse at the contact point
    ΔV_c = ΔV_p + ΔΩ × r_c = G ΔV_p,           G = I − [r_c]× K⁻¹ [r_c]×  (SPD)
    Δv_c = −(1 + a_nc) v_c⁻                    normal restitution
    Δu_p = −C_f Δv_p (u_c⁻ + ½Δu_c) / |V_c⁻|     tangential impulse ∝ normal
    Δw_p = −C_f Δv_p (w_c⁻ + ½Δw_c) / |V_c⁻|     impulse × mean slip velocity

Solution. For a trial normal change λ = Δv_p the tangential equations are
linear in (Δu_p, Δw_p) with matrix I + ½μλ G_tt (μ = C_f/|V_c⁻|), positive
definite for λ ≥ 0. The normal equation f(λ) = [G ΔV_p(λ)]_y − Δv_c = 0 times
that matrix's determinant is a cubic P(λ) with P(0) = −Δv_c < 0 and leading
coefficient > 0 (the Schur complement of G), so a positive root always exists.
The cubic's critical points split (0, ∞) into monotone pieces; the smallest
positive root is bracketed in the first piece where P changes sign and polished
by Newton's method safeguarded with bisection, to machine precision, from the
root of P's second-order expansion at the bracket's lower end. Three
positive roots (a sign pattern decidable from P at the critical points) are
reported with :data:`COLLISION_MULTIPLE_ROOTS`; the smallest is taken.

Energy: per unit mass the kinetic energy changes by ΔV_p·(V_c⁻ + V_c⁺)/2. Its
normal part is ½λ(1 − a_nc)v_c⁻ ≤ 0 (λ > 0, v_c⁻ < 0) and its tangential part
−μλ|V_c,t⁻ + ½ΔV_c,t|² ≤ 0, so kinetic energy never increases; minus the two
parts are the work the collision does on the wall, W_n and W_t (:func:`wall_work`;
docs/model.md §4.7). Angular momentum about the contact point, KΩ − r_c × V_p,
is unchanged.
"""

import numba
import numpy as np

from direct_model.options import KERNEL
from direct_model.wall import friction_factor, restitution

COLLISION_OK = 0
COLLISION_MULTIPLE_ROOTS = 1      # resolved with the smallest positive root
COLLISION_NOT_APPROACHING = 2     # v_c⁻ ≥ 0: no collision, nothing changed
COLLISION_FAILED = 3              # root finder did not converge, nothing changed

_MAX_ROOT_ITERATIONS = 200


@numba.njit(**KERNEL)
def _cubic(c0, c1, c2, c3, x):
    return ((c3 * x + c2) * x + c1) * x + c0


@numba.njit(**KERNEL)
def _cubic_slope(c1, c2, c3, x):
    return (3.0 * c3 * x + 2.0 * c2) * x + c1


@numba.njit(**KERNEL)
def _first_guess(c0, c1, c2, c3, lo):
    """A first guess of the root above ``lo`` (P(lo) ≤ 0, P rising after lo): the root of P's second-order
    expansion at lo, P(lo) + P'(lo)d + ½P''(lo)d² (P(lo + d) = c3 d³ ≥ 0 there, so it is above the root), or a
    Newton step from lo where that has none; inf if neither exists."""
    p = _cubic(c0, c1, c2, c3, lo)
    slope = _cubic_slope(c1, c2, c3, lo)
    curvature = 6.0 * c3 * lo + 2.0 * c2
    disc = slope * slope - 2.0 * p * curvature
    if disc >= 0.0:
        denominator = slope + np.sqrt(disc)
        if denominator > 0.0:
            return lo - 2.0 * p / denominator
    return lo - p / slope if slope > 0.0 else np.inf


@numba.njit(**KERNEL)
def _bracketed_root(c0, c1, c2, c3, lo, hi):
    """Root of the cubic in [lo, hi] where it rises from ≤ 0 to ≥ 0 (monotone piece).

    Newton steps from :func:`_first_guess` (the bracket's midpoint if the guess is outside it), replaced by
    bisection whenever they leave the bracket, until P(x) is within the rounding of its evaluation (lo ≥ 0:
    |P(x)| ≤ 10⁻¹⁵ Σ|c_i| x^i, above the 6 rounding errors of Horner's scheme), the Newton step or the
    bracket below 4·10⁻¹⁶ relative. Returns (root, converged).
    """
    x = _first_guess(c0, c1, c2, c3, lo)
    if not lo < x < hi:
        x = 0.5 * (lo + hi)
    a0, a1, a2, a3 = 1e-15 * abs(c0), 1e-15 * abs(c1), 1e-15 * abs(c2), 1e-15 * abs(c3)
    for _ in range(_MAX_ROOT_ITERATIONS):
        fx = _cubic(c0, c1, c2, c3, x)
        if abs(fx) <= _cubic(a0, a1, a2, a3, x):
            return x, True
        if fx < 0.0:
            lo = x
        else:
            hi = x
        slope = _cubic_slope(c1, c2, c3, x)
        step_ok = False
        if slope > 0.0:
            xn = x - fx / slope
            step_ok = lo < xn < hi
        if not step_ok:
            xn = 0.5 * (lo + hi)
        if abs(xn - x) <= 4e-16 * abs(xn) or hi - lo <= 4e-16 * hi:
            return xn, True
        x = xn
    return x, False


@numba.njit(**KERNEL)
def smallest_positive_root(c0, c1, c2, c3):
    """Smallest positive root of c3 λ³ + c2 λ² + c1 λ + c0 with c0 < 0 < c3.

    Returns (root, n_positive_roots_is_three, converged).
    """
    # critical points of the cubic
    qa, qb, qc = 3.0 * c3, 2.0 * c2, c1
    disc = qb * qb - 4.0 * qa * qc
    # Cauchy bound on the roots' magnitude
    upper = 1.0 + max(abs(c0), max(abs(c1), abs(c2))) / c3
    if disc <= 0.0:
        root, ok = _bracketed_root(c0, c1, c2, c3, 0.0, upper)
        return root, False, ok
    sq = np.sqrt(disc)
    # numerically stable quadratic roots
    t = -0.5 * (qb + (sq if qb >= 0.0 else -sq))
    r1, r2 = t / qa, (qc / t if t != 0.0 else 0.0)
    x1, x2 = min(r1, r2), max(r1, r2)    # P rises on (−∞, x1], falls on [x1, x2], rises after
    if x2 <= 0.0 or x1 <= 0.0:
        # from P(0) < 0 the cubic falls, then rises once: a single positive root
        root, ok = _bracketed_root(c0, c1, c2, c3, max(x2, 0.0), upper)
        return root, False, ok
    p1 = _cubic(c0, c1, c2, c3, x1)
    if p1 >= 0.0:
        p2 = _cubic(c0, c1, c2, c3, x2)
        root, ok = _bracketed_root(c0, c1, c2, c3, 0.0, x1)
        return root, p2 <= 0.0, ok
    root, ok = _bracketed_root(c0, c1, c2, c3, x2, upper)
    return root, False, ok


@numba.njit(**KERNEL)
def _form(A, p, q):
    """pᵀ A q for a 3×3 array A and 3-tuples p, q."""
    acc = 0.0
    for i in range(3):
        for j in range(3):
            acc += p[i] * A[i, j] * q[j]
    return acc


@numba.njit(**KERNEL)
def collide(V, W, r, Kinv, wall, dV, dW):
    """Apply one collision at contact point ``r`` (relative to the centre of mass).

    Parameters
    ----------
    V : (3,) centre-of-mass velocity before, m/s, lab frame.
    W : (3,) angular velocity before, (m/s)/a, lab frame.
    r : (3,) contact point relative to the centre of mass, units of a, lab frame.
    Kinv : (3, 3) inverse of K = J/m in the lab frame, 1/a².
    wall : the wall law's kernel array, :meth:`direct_model.wall.Wall.as_array` (layout W_*).
    dV, dW : (3,) outputs, the changes of V and W.

    Returns
    -------
    One of the ``COLLISION_*`` codes; dV and dW are zero unless the code is OK
    or MULTIPLE_ROOTS.
    """
    dV[:] = 0.0
    dW[:] = 0.0
    rx, ry, rz = r[0], r[1], r[2]
    # contact-point velocity V_c = V + W × r
    uc = V[0] + W[1] * rz - W[2] * ry
    vc = V[1] + W[2] * rx - W[0] * rz
    wc = V[2] + W[0] * ry - W[1] * rx
    if not vc < 0.0:
        return COLLISION_NOT_APPROACHING
    speed_c = np.sqrt(uc * uc + vc * vc + wc * wc)
    a_nc = restitution(wall, speed_c, -vc / speed_c)
    dvc = -(1.0 + a_nc) * vc                      # > 0
    speed_p = np.sqrt(V[0] ** 2 + V[1] ** 2 + V[2] ** 2)
    rnorm = np.sqrt(rx * rx + ry * ry + rz * rz)
    cos_g = 0.0
    if speed_p > 0.0 and rnorm > 0.0:
        cos_g = (rx * V[0] + ry * V[1] + rz * V[2]) / (rnorm * speed_p)
    mu = friction_factor(wall, cos_g) / speed_c

    # G = I − [r]× K⁻¹ [r]×, G_ij = δ_ij + (r × e_i)·K⁻¹(r × e_j)
    e0 = (0.0, rz, -ry)
    e1 = (-rz, 0.0, rx)
    e2 = (ry, -rx, 0.0)
    g00 = 1.0 + _form(Kinv, e0, e0)
    g11 = 1.0 + _form(Kinv, e1, e1)
    g22 = 1.0 + _form(Kinv, e2, e2)
    g01 = _form(Kinv, e0, e1)
    g02 = _form(Kinv, e0, e2)
    g12 = _form(Kinv, e1, e2)

    # tangential system (1 + hλG_xx) x + hλG_xz z = rx(λ), hλG_zx x + (1 + hλG_zz) z = rz(λ)
    h = 0.5 * mu
    p, q, s = h * g00, h * g22, h * g02
    d1, d2 = p + q, p * q - s * s                      # det = 1 + d1 λ + d2 λ²
    rx1, rx2 = -mu * uc, -0.5 * mu * g01
    rz1, rz2 = -mu * wc, -0.5 * mu * g12
    x2, x3 = rx2 + q * rx1 - s * rz1, q * rx2 - s * rz2   # det·x = rx1 λ + x2 λ² + x3 λ³
    z2, z3 = rz2 + p * rz1 - s * rx1, p * rz2 - s * rx2   # det·z = rz1 λ + z2 λ² + z3 λ³
    c0 = -dvc
    c1 = g01 * rx1 + g12 * rz1 + g11 - dvc * d1
    c2 = g01 * x2 + g12 * z2 + g11 * d1 - dvc * d2
    c3 = g01 * x3 + g12 * z3 + g11 * d2
    if not c3 > 0.0:
        # frictionless limit (μ → 0): the cubic degenerates to a line
        if not c1 > 0.0:
            return COLLISION_FAILED
        lam, multiple, ok = dvc / c1, False, True
    else:
        lam, multiple, ok = smallest_positive_root(c0, c1, c2, c3)
    if not ok or not lam > 0.0:
        return COLLISION_FAILED

    det = 1.0 + d1 * lam + d2 * lam * lam
    bx = rx1 * lam + rx2 * lam * lam
    bz = rz1 * lam + rz2 * lam * lam
    dV[0] = (bx * (1.0 + q * lam) - s * lam * bz) / det
    dV[1] = lam
    dV[2] = (bz * (1.0 + p * lam) - s * lam * bx) / det
    # K ΔΩ = r × ΔV
    tx = ry * dV[2] - rz * dV[1]
    ty = rz * dV[0] - rx * dV[2]
    tz = rx * dV[1] - ry * dV[0]
    for i in range(3):
        dW[i] = Kinv[i, 0] * tx + Kinv[i, 1] * ty + Kinv[i, 2] * tz
    return COLLISION_MULTIPLE_ROOTS if multiple else COLLISION_OK


@numba.njit(**KERNEL)
def wall_work(V, W, r, dV, dW):
    """The work one collision does on the wall, per unit particle mass, m²/s² (docs/model.md §4.7): (W_n, W_t).

    V, W, r as :func:`collide`'s (before the collision; W × r in m/s, r in units of a), dV and dW its changes. The
    kinetic energy per unit mass changes by ΔV·(V_c⁻ + V_c⁺)/2 (the impulse acts at the contact point), with
    V_c⁻ = V + W × r and V_c⁺ = (V + ΔV) + (W + ΔW) × r; minus its normal part, −Δv (v_c⁻ + v_c⁺)/2 ≥ 0, is W_n
    (plastic indentation), minus its tangential part, −(Δu (u_c⁻ + u_c⁺) + Δw (w_c⁻ + w_c⁺))/2 ≥ 0, is W_t
    (the slip's cutting). Both ≥ 0 up to round-off; W_n + W_t is the kinetic energy the collision takes.
    Reads its inputs only, so the rebound's state keeps its bits.
    """
    rx, ry, rz = r[0], r[1], r[2]
    u0 = V[0] + W[1] * rz - W[2] * ry
    v0 = V[1] + W[2] * rx - W[0] * rz
    w0 = V[2] + W[0] * ry - W[1] * rx
    Vx, Vy, Vz = V[0] + dV[0], V[1] + dV[1], V[2] + dV[2]
    Wx, Wy, Wz = W[0] + dW[0], W[1] + dW[1], W[2] + dW[2]
    u1 = Vx + Wy * rz - Wz * ry
    v1 = Vy + Wz * rx - Wx * rz
    w1 = Vz + Wx * ry - Wy * rx
    normal = -(dV[1] * (v0 + v1)) * 0.5
    tangential = -(dV[0] * (u0 + u1) + dV[2] * (w0 + w1)) * 0.5
    return normal, tangential
