"""Free flight between collisions and the search for the next contact (docs/model.md §5).

Between collisions the particle moves by inertia alone: the centre of mass
uniformly, the orientation by exact torque-free rotation
(:mod:`direct_model.rotation`). Only the height y of the centre of mass matters for
contact; lengths are in units of a, velocities in m/s, times in a/(m/s).

Candidate points. A polyhedron's candidates are its vertices p (body frame);
an ellipsoid's is its support point in direction −n, p = −A² g / |A g|. With
g = Rᵀ e_y the lab's normal seen from the body, a point's height is
h = y + g·p. The body sees g turn as ġ = g × ω, g̈ = ġ × ω + g × ω̇ (ω the
body-frame angular velocity, K ω̇ = (K ω) × ω), so a vertex has h' = v + ġ·p
and h'' = g̈·p exactly; the ellipsoid's lowest point has h = y − σ, σ = |A g|,
h' = v + ġ·p (the support point's material velocity) and h'' = −σ'' from
φ = gᵀA²g, σ'' = φ''/(2σ) − φ'²/(4σ³).

Contact search: conservative advancement. Every candidate's height has
|h''| ≤ M and |h'''| ≤ M3, with M and M3 from the invariants of the flight
(|L| and energy), so from the current h, h' no point can reach the wall before
the first positive root τ of

    h + h' τ − ½ M τ² = 0,

taken over the candidates. The binding point b (smallest τ) gets a longer
step from its exact curvature: on [0, T], h_b ≥ h + h'τ + ½(h'' − M3 T/3) τ²,
whose first root (capped at T, T at most the other points' τ and 4 times b's)
is safe too. The step is never too long: no contact is missed, however fast
the spin.

Near an approaching contact the search takes second-order Newton steps τ_T,
the root nearest 0 of h + h'τ + ½h''τ² for point b, where they are provably
safe: τ_T shorter than every other point's safe step, and b approaching the
wall monotonically during the step (h_b' + Mτ_T < 0, or
h_b' + h_b''τ_T + ½M3τ_T² < 0). Landing above the wall then proves that b did
not cross it; landing below brackets the contact, which the same steps
(bisection fallback) refine. Convergence is cubic. The search stops when the
lowest point is within ``contact_tol`` (units of a) of the wall, and a
collision follows if the contact point is approaching.

Bounds used (K = J/m principal values, ℓ = L/m, T = energy/m, Δ = K_max − K_min):
|Ω| ≤ ω = min(|ℓ|/K_min, √(2T/K_min));
|ω̇| ≤ ω̇_b = ½Δ ω² / K_min   (Euler: K ω̇ = (K ω) × ω = ((K − cI) ω) × ω);
|ω̈| ≤ Δ ω ω̇_b / K_min       (K ω̈ = ((K − cI) ω̇) × ω + ((K − cI) ω) × ω̇);
|g̈| ≤ g₂ = ω̇_b + ω², |g⃛| ≤ g₃ = |ω̈| + 3 ω ω̇_b + ω³;
vertex at distance ≤ R_b: M = g₂ R_b, M3 = g₃ R_b;
ellipsoid (|A²g| ≤ a_max σ, σ ≥ a_min): M = a_max² ω² / a_min + a_max g₂,
M3 = 6 a_max² ω g₂ / a_min + a_max g₃ + 6 a_max³ ω³ / a_min².

Only the smallest and second smallest safe steps matter. A point whose
h + h'T' − ½MT'² exceeds its round-off (T' = T(1 + 10⁻¹²)) provably has a safe
step above T, so it is passed over without its square root and division
(:func:`may_reach`): the same steps, the same bits, as a scan of every point.
T is the second smallest safe step of the points before it in the scan, and on
a scanned hull of more than :data:`PASS_OVER_ABOVE` vertices at most the larger
of the two lowest points' safe steps (:func:`pass_over_bound`), which costs a
scan and two safe steps first. A hull of more than
:data:`direct_model.hull_walk.WALK_ABOVE` vertices is not scanned but walked over
its vertex graph (:mod:`direct_model.hull_walk`, :func:`walk_safe_steps`), with
the same answers.

The flight's rotation set-up (:func:`direct_model.rotation.rotation_init`) is
done at the first step that needs the orientation at a later time: a flight
decided at its start (a contact at t = 0, an escape) never pays for it.
"""

import math

import numba
import numpy as np

from direct_model.options import KERNEL
from direct_model.rotation import rotation_at, rotation_init
from direct_model.shape_arrays import KIND_ELLIPSOID
from direct_model.hull_walk import (BAND, START, band, descend, height, level, map_start, member, nearer, reach, vertex,
                                   walk_contact_sums, walk_lowest)

SEARCH_CONTACT = 0      # a point touches the wall (within contact_tol) and approaches it
SEARCH_ESCAPED = 1      # the body can never reach the wall again
SEARCH_STALLED = 2      # max_steps reached without a decision

HORIZON = 4.0           # the binding point's longer step looks at most this many safe steps ahead
PASS_OVER_ABOVE = 24    # vertices; above this many the pass over starts from pass_over_bound (C: 12; the same bits)


@numba.njit(**KERNEL)
def _rate_bounds(K, ell, W):
    """Bounds (ω, |ω̇|, |ω̈|) on the angular velocity and its rates during a flight (module doc)."""
    kmin = min(K[0], min(K[1], K[2]))
    kmax = max(K[0], max(K[1], K[2]))
    l2 = ell[0] ** 2 + ell[1] ** 2 + ell[2] ** 2
    two_t = max(ell[0] * W[0] + ell[1] * W[1] + ell[2] * W[2], 0.0)
    w = min(np.sqrt(l2) / kmin, np.sqrt(two_t / kmin))
    wdot = 0.5 * (kmax - kmin) * w * w / kmin
    return w, wdot, (kmax - kmin) * w * wdot / kmin


@numba.njit(**KERNEL)
def curvature_bound(kind, semi, Rb, K, ell, W):
    """Bound M on |h''| of any candidate point's height during a flight (module doc).

    ``K`` principal J/m (a²), ``ell`` = L/m and ``W`` = Ω at any instant of the
    flight (lab frame); 2T = ℓ·Ω is the flight's invariant.
    """
    w, wdot, _ = _rate_bounds(K, ell, W)
    if kind == KIND_ELLIPSOID:
        amax = max(semi[0], max(semi[1], semi[2]))
        amin = min(semi[0], min(semi[1], semi[2]))
        return amax * amax * w * w / amin + amax * (wdot + w * w)
    return (wdot + w * w) * Rb


@numba.njit(**KERNEL)
def jerk_bound(kind, semi, Rb, K, ell, W):
    """Bound M3 on |h'''| of any candidate point's height during a flight (module doc)."""
    w, wdot, wddot = _rate_bounds(K, ell, W)
    g3 = wddot + 3.0 * w * wdot + w * w * w
    if kind == KIND_ELLIPSOID:
        amax = max(semi[0], max(semi[1], semi[2]))
        amin = min(semi[0], min(semi[1], semi[2]))
        return (6.0 * amax * amax * w * (wdot + w * w) / amin + amax * g3
                + 6.0 * amax * amax * amax * w * w * w / (amin * amin))
    return g3 * Rb


@numba.njit(**KERNEL)
def safe_step(h, hdot, M):
    """First τ ≥ 0 where h + hdot·τ − ½Mτ² reaches 0 (h < 0 taken as 0; M of any sign); inf if never."""
    if h < 0.0:
        h = 0.0
    disc = hdot * hdot + 2.0 * M * h
    if hdot <= 0.0:
        if disc < 0.0:
            return np.inf
        den = np.sqrt(disc) - hdot
        return 2.0 * h / den if den > 0.0 else 0.0
    if M <= 0.0:
        return np.inf
    return (hdot + np.sqrt(disc)) / M


@numba.njit(**KERNEL)
def pass_over_bound(h, h1, n, low, M):
    """T at least the second smallest safe step of the n points: the larger of the safe steps of point ``low``
    and of the lowest other point; inf for a single point (module doc)."""
    second, h_next = -1, np.inf
    for i in range(n):
        if i != low and h[i] < h_next:
            second, h_next = i, h[i]
    if second < 0:
        return np.inf
    return max(safe_step(h[low], h1[low], M), safe_step(h[second], h1[second], M))


@numba.njit(**KERNEL)
def may_reach(h, hdot, M, T):
    """False only if :func:`safe_step` of (h, hdot, M) is surely above T (> 0, finite): then
    h + hdot·T' − ½MT'² > 0 at T' = T(1 + 10⁻¹²) + 10⁻³⁰⁰ beyond the round-off of its evaluation, so the first
    root exceeds T', and the computed step (no cancellation in its formula) exceeds T. NaN: True."""
    if h < 0.0:
        h = 0.0
    T = T * (1.0 + 1e-12) + 1e-300
    q = h + (hdot - 0.5 * M * T) * T
    return not q > 1e-14 * (h + abs(hdot) * T + 0.5 * M * T * T)


@numba.njit(**KERNEL)
def taylor_root(h, hdot, hddot):
    """Root nearest 0 of h + hdot·s + ½hddot·s² (Newton's −h/hdot where it has none)."""
    disc = hdot * hdot - 2.0 * h * hddot
    if disc < 0.0:
        return -h / hdot
    return -2.0 * h / (hdot + math.copysign(np.sqrt(disc), hdot))


@numba.njit(inline="always", **KERNEL)
def turning(R, W, K):
    """The lab's normal seen from the body and how it turns (module doc): g = Rᵀ e_y, ġ, g̈, as 9 floats, from
    the orientation ``R``, the lab Ω ``W`` and the principal J/m ``K``."""
    g0, g1, g2 = R[1, 0], R[1, 1], R[1, 2]
    w0 = R[0, 0] * W[0] + R[1, 0] * W[1] + R[2, 0] * W[2]      # ω = Rᵀ Ω
    w1 = R[0, 1] * W[0] + R[1, 1] * W[1] + R[2, 1] * W[2]
    w2 = R[0, 2] * W[0] + R[1, 2] * W[1] + R[2, 2] * W[2]
    m0, m1, m2 = K[0] * w0, K[1] * w1, K[2] * w2
    e0 = (m1 * w2 - m2 * w1) / K[0]                               # ω̇ = K⁻¹ (K ω) × ω
    e1 = (m2 * w0 - m0 * w2) / K[1]
    e2 = (m0 * w1 - m1 * w0) / K[2]
    d0, d1, d2 = g1 * w2 - g2 * w1, g2 * w0 - g0 * w2, g0 * w1 - g1 * w0      # ġ = g × ω
    a0 = d1 * w2 - d2 * w1 + (g1 * e2 - g2 * e1)                  # g̈ = ġ × ω + g × ω̇
    a1 = d2 * w0 - d0 * w2 + (g2 * e0 - g0 * e2)
    a2 = d0 * w1 - d1 * w0 + (g0 * e1 - g1 * e0)
    return g0, g1, g2, d0, d1, d2, a0, a1, a2


@numba.njit(**KERNEL)
def lowest_points(kind, verts, nv, semi, K, R, W, y, v, h, h1, curv):
    """Heights ``h[i]`` and rates ``h1[i]`` of the candidate lowest points, and ``curv`` (3,), from which
    :func:`curvature` gives any one's curvature h'' (only the binding point's is needed).

    ``R``, ``W``: orientation and lab Ω now; ``y``, ``v``: the centre's height and vertical
    velocity. Candidates (body frame): the vertices ``verts[:nv]``, or the ellipsoid's support
    point, written into ``verts[0]``. ``curv`` receives g̈ (a vertex p has h'' = g̈·p), or the
    ellipsoid's h'' in ``curv[0]``. Returns the number of candidates (module doc).
    """
    g0, g1, g2, d0, d1, d2, a0, a1, a2 = turning(R, W, K)
    if kind == KIND_ELLIPSOID:
        u0, u1, u2 = semi[0] * g0, semi[1] * g1, semi[2] * g2
        sigma = np.sqrt(u0 * u0 + u1 * u1 + u2 * u2)
        q0, q1, q2 = semi[0] * u0, semi[1] * u1, semi[2] * u2      # A² g
        verts[0, 0], verts[0, 1], verts[0, 2] = -q0 / sigma, -q1 / sigma, -q2 / sigma
        phi1 = 2.0 * (q0 * d0 + q1 * d1 + q2 * d2)
        phi2 = 2.0 * (semi[0] * semi[0] * d0 * d0 + semi[1] * semi[1] * d1 * d1 + semi[2] * semi[2] * d2 * d2
                      + (q0 * a0 + q1 * a1 + q2 * a2))
        h[0] = y - sigma
        h1[0] = v - 0.5 * phi1 / sigma
        curv[0] = (0.25 * phi1 * phi1 / (sigma * sigma) - 0.5 * phi2) / sigma
        return 1
    for i in range(nv):
        p0, p1, p2 = verts[i, 0], verts[i, 1], verts[i, 2]
        h[i] = y + (g0 * p0 + g1 * p1 + g2 * p2)
        h1[i] = v + (d0 * p0 + d1 * p1 + d2 * p2)
    curv[0], curv[1], curv[2] = a0, a1, a2
    return nv


@numba.njit(inline="always", **KERNEL)
def curvature(kind, verts, i, curv):
    """Curvature h'' of candidate point ``i`` from :func:`lowest_points`' ``curv``."""
    if kind == KIND_ELLIPSOID:
        return curv[0]
    return curv[0] * verts[i, 0] + curv[1] * verts[i, 1] + curv[2] * verts[i, 2]


@numba.njit(**KERNEL)
def choose_contact(n, verts, h, h1, R, set_tol, rc):
    """Contact point among touching candidates (docs/model.md §4); False if none approaches.

    The points within ``set_tol`` of the lowest form the contact set. One
    point: it is the contact if it approaches the wall. Several (an edge or a
    face): their centroid if it approaches (the mean of their rates is its rate),
    else the lowest approaching point of the set (otherwise the body could pass
    through the wall). ``rc`` receives the contact point from the centroid, lab frame.
    """
    hmin = np.inf
    for i in range(n):
        hmin = min(hmin, h[i])
    count = 0
    p0, p1, p2, rate = 0.0, 0.0, 0.0, 0.0
    best, best_h = -1, np.inf
    for i in range(n):
        if h[i] <= hmin + set_tol:
            count += 1
            p0, p1, p2, rate = p0 + verts[i, 0], p1 + verts[i, 1], p2 + verts[i, 2], rate + h1[i]
            if h1[i] < 0.0 and h[i] < best_h:
                best, best_h = i, h[i]
    k = max(best, 0)
    return contact_point(count, p0, p1, p2, rate, best, verts[k, 0], verts[k, 1], verts[k, 2], R, rc)


@numba.njit(inline="always", **KERNEL)
def contact_point(count, p0, p1, p2, rate, best, q0, q1, q2, R, rc):
    """:func:`choose_contact`'s choice from the contact set's sums (``count`` points, Σp, Σh') and its lowest
    approaching point ``best`` at q (−1: none): the centroid if it approaches, else q; False if neither."""
    if not (count > 1 and rate < 0.0):
        if best < 0:
            return False
        p0, p1, p2, count = q0, q1, q2, 1
    p0, p1, p2 = p0 / count, p1 / count, p2 / count
    for k in range(3):
        rc[k] = R[k, 0] * p0 + R[k, 1] * p1 + R[k, 2] * p2
    return True


@numba.njit(inline="always", **KERNEL)
def take_step(h, hdot, M, T, i, tau, tau_other, b):
    """The safe-step loop's work on point i (:func:`find_contact`): (tau, tau_other, b) after it. A point whose
    safe step surely exceeds the second smallest so far (or T, at least the final second smallest) changes
    neither."""
    bound = min(T, tau_other)
    if bound < np.inf and not may_reach(h, hdot, M, bound):
        return tau, tau_other, b
    tau_i = safe_step(h, hdot, M)
    if tau_i < tau:
        return tau_i, tau, i
    return tau, min(tau_other, tau_i), b


REFINE = 3              # descents that tighten a walk's step bound before the walk (walk_safe_steps)


@numba.njit(inline="always", **KERNEL)
def _vertex_step(unit, scale, g, d, y, v, M, i):
    """Vertex i's safe step, its height and rate computed as the scan computes them."""
    h, p0, p1, p2 = height(unit, scale, g, y, i)
    return safe_step(h, v + (d[0] * p0 + d[1] * p1 + d[2] * p2), M)


@numba.njit(inline="always", **KERNEL)
def _tighten(unit, scale, g, d, y, v, M, j, t1, i1, t2, i2):
    """(t1, i1, t2, i2), the two smallest safe steps met and their vertices, after vertex j (not i1 nor i2)."""
    h, p0, p1, p2 = height(unit, scale, g, y, j)
    h1 = v + (d[0] * p0 + d[1] * p1 + d[2] * p2)
    if t2 < np.inf and not may_reach(h, h1, M, t2):
        return t1, i1, t2, i2
    tj = safe_step(h, h1, M)
    if tj < t1:
        return tj, j, t1, i1
    if tj < t2:
        return t1, i1, tj, j
    return t1, i1, t2, i2


@numba.njit(**KERNEL)
def walk_safe_steps(unit, scale, graph_start, graph, starts, g, d, y, v, M, low, work):
    """(tau, tau_other, b) of a hull's vertices walked over its graph (:mod:`direct_model.hull_walk`), what
    :func:`find_contact`'s loop over every vertex finds (b = −1 if no step is finite); h = y + g·p,
    h' = v + d·p, M the curvature bound, ``low`` the lowest vertex.

    The bound T, at least the second smallest step: the second smallest of the steps of distinct vertices, the
    lowest's and its neighbours' first, then those of the vertex where the level h + T'h' is lowest and of its
    neighbours (a descent from there or from the start map's vertex, ``starts``), each such round tightening T.
    The walk of the level's bound at T' (T(1 + 10⁻¹²) + 10⁻³⁰⁰, as :func:`may_reach`) meets every vertex that
    may_reach lets through at T, taken in index order as the scan takes them; T infinite: every vertex."""
    t1, i1, t2, i2 = _vertex_step(unit, scale, g, d, y, v, M, low), low, np.inf, -1
    for k in range(graph_start[low], graph_start[low + 1]):
        t1, i1, t2, i2 = _tighten(unit, scale, g, d, y, v, M, graph[k], t1, i1, t2, i2)
    m = low
    for _ in range(REFINE):
        if not t2 < np.inf:
            break
        before = t2
        Tp = t2 * (1.0 + 1e-12) + 1e-300
        mapped = map_start(starts, (g[0] + Tp * d[0], g[1] + Tp * d[1], g[2] + Tp * d[2]), scale)
        start = mapped if level(unit, scale, g, d, y, v, Tp, mapped) < level(unit, scale, g, d, y, v, Tp, m) else m
        last, m = m, descend(unit, scale, graph_start, graph, g, d, y, v, Tp, start)[0]
        if m == last:
            break
        for k in range(graph_start[m] - 1, graph_start[m + 1]):
            j = m if k < graph_start[m] else graph[k]        # m, then its neighbours
            if j != i1 and j != i2:
                t1, i1, t2, i2 = _tighten(unit, scale, g, d, y, v, M, j, t1, i1, t2, i2)
        if not t2 < before:
            break
    T = t2
    count = -1
    if T < np.inf:
        Tp = T * (1.0 + 1e-12) + 1e-300
        size = abs(y) + reach(g, scale) + (abs(v) + reach(d, scale)) * Tp + 0.5 * abs(M) * Tp * Tp
        count = band(unit, scale, graph_start, graph, g, d, y, v, Tp, 0.5 * M * Tp * Tp + BAND * size, i1, work)
    tau, tau_other, b = np.inf, np.inf, -1
    for k in range(count if count >= 0 else unit.shape[0]):
        i = member(work, count, k)
        h, p0, p1, p2 = height(unit, scale, g, y, i)
        tau, tau_other, b = take_step(h, v + (d[0] * p0 + d[1] * p1 + d[2] * p2), M, T, i, tau, tau_other, b)
    return tau, tau_other, b


@numba.njit(inline="always", **KERNEL)
def point_state(walk, kind, verts, h, h1, curv, unit, scale, g, d, y, v, b):
    """(h, h', h'') of candidate ``b``: from the scan's arrays, or computed for vertex b of a walked hull (the
    same operations as :func:`lowest_points` and :func:`curvature`)."""
    if walk:
        p0, p1, p2 = vertex(unit, scale, b)
        return (y + (g[0] * p0 + g[1] * p1 + g[2] * p2), v + (d[0] * p0 + d[1] * p1 + d[2] * p2),
                curv[0] * p0 + curv[1] * p1 + curv[2] * p2)
    return h[b], h1[b], curvature(kind, verts, b, curv)


@numba.njit(**KERNEL)
def find_contact(kind, verts, nv, semi, Rb, K, ell, M, M3, params, y0, v, contact_tol, set_tol,
                 max_steps, R, W, h, h1, curv, rc, hull, walk_work):
    """Advance a flight from its start (t = 0) to the next collision or to escape.

    Parameters
    ----------
    kind, verts, nv, semi, Rb : the body (:func:`direct_model.shape_arrays.particle_body`): its kind, its nv
        vertices (body frame), its half-extents (an ellipsoid's semi-axes) and its bounding radius.
    K, ell : principal J/m (a²) and ℓ = L/m (lab) of the flight.
    M, M3 : bounds from :func:`curvature_bound` and :func:`jerk_bound` for this flight.
    params : the flight's rotation parameters, filled here by
        :func:`direct_model.rotation.rotation_init` when first needed.
    y0, v : centre-of-mass height at t = 0 (units of a) and its vertical velocity (m/s).
    contact_tol : a point this close to the wall touches it (units of a).
    set_tol : points this close to the lowest one share the contact (units of a).
    max_steps : step budget of this search.
    R, W : on entry the orientation and lab angular velocity at t = 0; on
        return, at the returned time.
    h, h1, curv, rc : work arrays (nv, nv, 3, 3 entries; :func:`lowest_points`); for a
        contact, rc receives the contact point relative to the centroid (lab frame).
    hull : (unit, scale, graph_start, graph, starts, far) of a hull walked over its vertex graph
        (:func:`direct_model.shape_arrays.particle_hull`, :mod:`direct_model.hull_walk`: its vertices are
        unit[i] · scale, and ``verts``, ``h``, ``h1`` are not read), or graph_start of no rows: the candidates
        are scanned. The same steps and bits either way.
    walk_work : (WALK_WORK,) a walk's work space (:func:`direct_model.hull_walk.clear` before a rebound's first
        search), its entry START the vertex a walk starts from, on return the last lowest vertex.

    Returns
    -------
    (code, t, n_steps) with code one of the ``SEARCH_*`` values.
    """
    unit, scale, graph_start, graph = hull[0], hull[1], hull[2], hull[3]
    walk = graph_start.shape[0] > 0
    g, d = (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)       # a walk's view of the normal and its turn (module doc)
    n = nv
    b = -1                # the binding point of the last step
    t = 0.0
    t_lo = 0.0            # latest time known to precede any contact
    t_hi = np.inf         # a time past the contact of point b, once a step overshoots
    for step in range(max_steps):
        if step > 0:
            if step == 1:
                rotation_init(K, R, ell, params)
            rotation_at(params, t, R, W)
        y = y0 + v * t
        if walk:
            g0, g1, g2, d0, d1, d2, a0, a1, a2 = turning(R, W, K)
            g, d = (g0, g1, g2), (d0, d1, d2)
            curv[0], curv[1], curv[2] = a0, a1, a2
            start = nearer(unit, scale, hull[4], g, y, walk_work)
            hmin, low = walk_lowest(unit, scale, graph_start, graph, g, y, start, walk_work)
            walk_work[START] = low
        else:
            n = lowest_points(kind, verts, nv, semi, K, R, W, y, v, h, h1, curv)
            hmin, low = np.inf, 0
            for i in range(n):
                if h[i] < hmin:
                    hmin, low = h[i], i
        if -contact_tol <= hmin <= contact_tol:
            if walk:
                count, p0, p1, p2, rate, best = walk_contact_sums(unit, scale, graph_start, graph, g, d, y, v,
                                                                  hmin + set_tol, low, walk_work)
                q0, q1, q2 = vertex(unit, scale, max(best, 0))
                touching = contact_point(count, p0, p1, p2, rate, best, q0, q1, q2, R, rc)
            else:
                touching = choose_contact(n, verts, h, h1, R, set_tol, rc)
            if touching:
                return SEARCH_CONTACT, t, step + 1
        if hmin < -contact_tol or t_hi < np.inf:
            # Bracket [t_lo, t_hi] in which only point b reaches the wall, monotonically:
            # safeguarded second-order Newton on its height.
            if b < 0:             # below the wall at the start: no bracket, the budget ends it
                b = low
            hb, h1b, h2b = point_state(walk, kind, verts, h, h1, curv, unit, scale, g, d, y, v, b)
            if hb < 0.0:
                t_hi = t
            else:
                t_lo = t
            t_new = t + taylor_root(hb, h1b, h2b)
            t = t_new if t_lo < t_new < t_hi else 0.5 * (t_lo + t_hi)
            continue
        if v > 0.0 and y > Rb:
            return SEARCH_ESCAPED, t, step + 1
        # the smallest and second smallest safe steps are at most T: points that surely take longer are passed
        if walk:
            tau, tau_other, found = walk_safe_steps(unit, scale, graph_start, graph, hull[4], g, d, y, v, M, low,
                                                    walk_work)
        else:
            T = pass_over_bound(h, h1, n, low, M) if n > PASS_OVER_ABOVE else np.inf
            tau, tau_other, found = np.inf, np.inf, -1
            for i in range(n):
                tau, tau_other, found = take_step(h[i], h1[i], M, T, i, tau, tau_other, found)
        if found >= 0:
            b = found
        if 0.0 < tau < np.inf:
            # b's longer step from its exact curvature, valid up to the horizon (module doc)
            hb, h1b, h2b = point_state(walk, kind, verts, h, h1, curv, unit, scale, g, d, y, v, b)
            horizon = min(tau_other, HORIZON * tau)
            tau = max(tau, min(horizon, safe_step(hb, h1b, min(M, M3 * horizon / 3.0 - h2b))))
        if v > 0.0 and tau >= (Rb - y) / v:
            return SEARCH_ESCAPED, t, step + 1
        if not (0.0 < tau < np.inf):
            return SEARCH_STALLED, t, step + 1
        # second-order Newton step of b where it is safe (module doc): no other point can
        # reach the wall first, and b approaches monotonically
        if h1b < 0.0:
            t_newton = taylor_root(hb, h1b, h2b)
            if tau < t_newton < tau_other and (h1b + M * t_newton < 0.0
                                               or h1b + (h2b + 0.5 * M3 * t_newton) * t_newton < 0.0):
                tau = t_newton
        t_lo = t
        t += tau
    return SEARCH_STALLED, t, max_steps
