"""Free flight between collisions and the search for the next contact (docs/model.md §5).

Between collisions the particle moves by inertia alone: the centre of mass
uniformly, the orientation by exact torque-free rotation
(:mod:`direct_model.rotation`). Only the height y of the centre of mass matters for
contact; lengths are in units of a, velocities in m/s, times in a/(m/s).

Contact search: conservative advancement with a second-order bound. Every
body point's height h(t) has |h''| ≤ M, with M from the invariants of the
flight (|L| and energy), so from the current height h and rate h' no point
can reach the wall before the smallest positive root τ of

    h + h' τ − ½ M τ² = 0,

taken over the vertices (polyhedron) or the support point (ellipsoid). The
step τ is never too long: no contact is missed, however fast the spin.

Near an approaching contact the search takes Newton steps τ_N = h/|h'| of the
binding point b instead, where they are provably safe: τ_N shorter than every
other point's safe step, and h_b' + Mτ_N < 0 so that b approaches the wall
monotonically during the step. Landing above the wall then proves that b did
not cross it; landing below brackets the contact, which safeguarded Newton
(bisection fallback) refines. Either way convergence is quadratic with the
true curvature of h_b rather than the bound M. The search stops when the
lowest point is within ``contact_tol`` (units of a) of the wall, and a
collision follows if the contact point is approaching.

Bounds used (K = J/m principal values, ℓ = L/m, T = energy/m):
|Ω| ≤ ω_max = min(|ℓ|/K_min, √(2T/K_min));
|dΩ/dt| ≤ ½(K_max − K_min) ω_max² / K_min   (Euler: K Ω̇ = (KΩ) × Ω);
vertex at distance ≤ R from the centroid: |h''| ≤ (|Ω̇| + |Ω|²) R;
ellipsoid support height σ = |A Rᵀ e_y|: |σ''| ≤ 2 a_max² ω²/a_min + a_max (|Ω̇| + ω²).
"""

import numba
import numpy as np

from direct_model.options import JIT
from direct_model.rotation import rotation_at
from direct_model.shapes import ELLIPSOID

SEARCH_CONTACT = 0      # a point touches the wall (within contact_tol) and approaches it
SEARCH_ESCAPED = 1      # the body can never reach the wall again
SEARCH_STALLED = 2      # max_steps reached without a decision


@numba.njit(**JIT)
def curvature_bound(shape, semi, Rb, K, ell, W):
    """Bound M on |h''| of any body point's height during a flight (module doc).

    ``K`` principal J/m (a²), ``ell`` = L/m and ``W`` = Ω at any instant of the
    flight (lab frame); 2T = ℓ·Ω is the flight's invariant.
    """
    kmin = min(K[0], min(K[1], K[2]))
    kmax = max(K[0], max(K[1], K[2]))
    l2 = ell[0] ** 2 + ell[1] ** 2 + ell[2] ** 2
    two_t = max(ell[0] * W[0] + ell[1] * W[1] + ell[2] * W[2], 0.0)
    w = min(np.sqrt(l2) / kmin, np.sqrt(two_t / kmin))
    if w == 0.0:
        return 0.0
    wdot = 0.5 * (kmax - kmin) * w * w / kmin
    if shape == ELLIPSOID:
        amax = max(semi[0], max(semi[1], semi[2]))
        amin = min(semi[0], min(semi[1], semi[2]))
        return 2.0 * amax * amax * w * w / amin + amax * (wdot + w * w)
    return (wdot + w * w) * Rb


@numba.njit(**JIT)
def safe_step(h, hdot, M):
    """Time until h + hdot·τ − ½Mτ² first reaches 0 (h ≥ 0); inf if never."""
    if h < 0.0:
        h = 0.0
    if hdot <= 0.0:
        den = np.sqrt(hdot * hdot + 2.0 * M * h) - hdot
        return 2.0 * h / den if den > 0.0 else 0.0
    if M == 0.0:
        return np.inf
    return (hdot + np.sqrt(hdot * hdot + 2.0 * M * h)) / M


@numba.njit(**JIT)
def point_height_rate(v, W, r):
    """Height rate dh/dt of the body point at r (lab, from the centroid): v + (Ω × r)_y."""
    return v + W[2] * r[0] - W[0] * r[2]


@numba.njit(**JIT)
def lowest_points(shape, verts, nv, semi, R, y, h, r_all):
    """Heights ``h[i]`` and lab offsets ``r_all[i]`` of the candidate lowest points.

    Polyhedron: every vertex. Ellipsoid: the single support point in direction
    −n, r = −R A² u / |A u| with u = Rᵀ e_y. Returns the number of points.
    """
    if shape == ELLIPSOID:
        u0, u1, u2 = R[1, 0] * semi[0], R[1, 1] * semi[1], R[1, 2] * semi[2]
        sigma = np.sqrt(u0 * u0 + u1 * u1 + u2 * u2)
        b0, b1, b2 = -semi[0] * u0 / sigma, -semi[1] * u1 / sigma, -semi[2] * u2 / sigma
        for k in range(3):
            r_all[0, k] = R[k, 0] * b0 + R[k, 1] * b1 + R[k, 2] * b2
        h[0] = y + r_all[0, 1]
        return 1
    for i in range(nv):
        for k in range(3):
            r_all[i, k] = R[k, 0] * verts[i, 0] + R[k, 1] * verts[i, 1] + R[k, 2] * verts[i, 2]
        h[i] = y + r_all[i, 1]
    return nv


@numba.njit(**JIT)
def choose_contact(n, h, r_all, v, W, set_tol, rc):
    """Contact point among touching candidates (docs/model.md §4); False if none approaches.

    The points within ``set_tol`` of the lowest form the contact set. One
    point: it is the contact if it approaches the wall. Several (an edge or a
    face): their centroid if it approaches, else the lowest approaching point
    of the set (otherwise the body could pass through the wall).
    """
    hmin = np.inf
    for i in range(n):
        hmin = min(hmin, h[i])
    count = 0
    rc[:] = 0.0
    best, best_h = -1, np.inf
    for i in range(n):
        if h[i] <= hmin + set_tol:
            count += 1
            for k in range(3):
                rc[k] += r_all[i, k]
            if point_height_rate(v, W, r_all[i]) < 0.0 and h[i] < best_h:
                best, best_h = i, h[i]
    rc /= count
    if count > 1 and point_height_rate(v, W, rc) < 0.0:
        return True
    if best < 0:
        return False
    rc[:] = r_all[best]
    return True


@numba.njit(**JIT)
def find_contact(shape, verts, nv, semi, Rb, M, params, y0, v, contact_tol, set_tol,
                 max_steps, t, R, W, h, r_all, rc):
    """Advance the flight from time ``t`` to the next collision or to escape.

    Parameters
    ----------
    shape, verts, nv, semi, Rb : the body (codes and arrays of :mod:`direct_model.shapes`).
    M : curvature bound from :func:`curvature_bound` for this flight.
    params : rotation parameters of this flight (:func:`direct_model.rotation.rotation_init`).
    y0, v : centre-of-mass height at the flight's t = 0 (units of a) and its
        vertical velocity (m/s).
    contact_tol : a point this close to the wall touches it (units of a).
    set_tol : points this close to the lowest one share the contact (units of a).
    max_steps : step budget of this search.
    t : start time of the search (a/(m/s)), ≥ 0.
    R, W : on entry the orientation and lab angular velocity at time ``t``; on
        return, at the returned time.
    h, r_all, rc : work arrays; for a contact, rc receives the contact point
        relative to the centroid (lab frame).

    Returns
    -------
    (code, t, n_steps) with code one of the ``SEARCH_*`` values.
    """
    b = -1                # the binding point of the last step
    t_lo = t              # latest time known to precede any contact
    t_hi = np.inf         # a time past the contact of point b, once a Newton step overshoots
    for step in range(max_steps):
        if step > 0:
            rotation_at(params, t, R, W)
        y = y0 + v * t
        n = lowest_points(shape, verts, nv, semi, R, y, h, r_all)
        hmin = np.inf
        for i in range(n):
            hmin = min(hmin, h[i])
        if -contact_tol <= hmin <= contact_tol and choose_contact(n, h, r_all, v, W, set_tol, rc):
            return SEARCH_CONTACT, t, step + 1
        if hmin < -contact_tol or t_hi < np.inf:
            # Bracket [t_lo, t_hi] in which only point b reaches the wall, monotonically:
            # safeguarded Newton on its height.
            if h[b] < 0.0:
                t_hi = t
            else:
                t_lo = t
            t_new = t - h[b] / point_height_rate(v, W, r_all[b])
            t = t_new if t_lo < t_new < t_hi else 0.5 * (t_lo + t_hi)
            continue
        if v > 0.0 and y > Rb:
            return SEARCH_ESCAPED, t, step + 1
        tau, tau_other = np.inf, np.inf
        for i in range(n):
            tau_i = safe_step(h[i], point_height_rate(v, W, r_all[i]), M)
            if tau_i < tau:
                tau, tau_other, b = tau_i, tau, i
            else:
                tau_other = min(tau_other, tau_i)
        if v > 0.0 and tau >= (Rb - y) / v:
            return SEARCH_ESCAPED, t, step + 1
        if not (0.0 < tau < np.inf):
            return SEARCH_STALLED, t, step + 1
        # Newton step of the binding point where it is safe (module doc): no other
        # point can reach the wall first, and b approaches monotonically.
        rate_b = point_height_rate(v, W, r_all[b])
        if rate_b < 0.0:
            t_newton = h[b] / -rate_b
            if t_newton < tau_other and t_newton * M < -rate_b:
                tau = max(tau, t_newton)
        t_lo = t
        t += tau
    return SEARCH_STALLED, t, max_steps
