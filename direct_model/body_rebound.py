"""A whole rebound: alternate free flights and collisions (docs/model.md §5).

Units inside the kernels: lengths in units of the particle's half-size a
(a = 1, b = b/a, c = (c/b)(b/a)), velocities in m/s, angular velocities in
(m/s)/a — so Ω a/|V⁻| = Ω / |V⁻| — and times in a/(m/s). Frames: lab (wall
y = 0, normal +Y) unless stated.

Sequence for one particle:

1. With Ω⁻ = 0 the body starts touching the wall (its lowest point at y = 0)
   and the first collision is at t = 0; otherwise its centre starts at the
   bounding radius and the flight in to the first contact is simulated.
2. Search the flight for the next contact (:func:`direct_model.flight.find_contact`).
   None: the particle has rebounded. A contact: apply one collision
   (:func:`direct_model.collision.collide`) and start a new flight there.
3. A particle that needs a collision beyond ``n_max`` is ``trapped``; a
   search that exhausts its step budget or a collision that fails is ``failed``.

All random inputs (orientation, aspect ratios, hand, shape) are drawn by the
caller and passed in, so each particle's result depends on its own inputs only:
the batch is bit-identical whatever the number of threads.
"""

from typing import NamedTuple

import numba
import numpy as np

from data_schema.samples import (
    FAILURE_COLLISION_SOLVER, FAILURE_NONE, FAILURE_NOT_APPROACHING, FAILURE_SEARCH_BUDGET,
    STATUS_FAILED, STATUS_REBOUNDED, STATUS_TRAPPED,
)
from direct_model.options import JIT, KERNEL
from direct_model.collision import COLLISION_FAILED, COLLISION_MULTIPLE_ROOTS, COLLISION_OK, collide, wall_work
from direct_model.flight import (SEARCH_ESCAPED, SEARCH_STALLED, curvature_bound, find_contact, jerk_bound,
                                  lowest_points)
from direct_model.rotation import ROT_PARAMS_SIZE
from direct_model.shape_arrays import bounding_radius, particle_body, particle_hull
from direct_model.hull_walk import START, WALK_ABOVE, WALK_WORK, clear, map_start, walk_lowest

HISTORY_COLUMNS = 17


class BodyRebound(NamedTuple):
    """What one particle's rebound did (:func:`body_rebound`), model frame (module doc's units)."""

    status: int                 # STATUS_REBOUNDED, STATUS_TRAPPED or STATUS_FAILED (data_schema.samples)
    failure: int                # why it failed: a FAILURE_* code of data_schema.samples; FAILURE_NONE otherwise
    n_collisions: int           # collisions applied (up to the trap or the failure)
    n_search_steps: int         # contact-search steps over every flight
    n_multiple_roots: int       # collisions whose impulse equation had several roots
    rotational_energy: float    # ½ Ω·KΩ per unit mass after the last collision, (m/s)²
    V: tuple                    # V after the last collision, m/s (3 floats): V⁺ if rebounded
    Omega: tuple                # Ω after the last collision, (m/s)/a (3 floats): Ω⁺ if rebounded
    # the work of the collisions on the wall per unit particle mass, m²/s², each ≥ 0 (collision.wall_work), summed
    # over the collisions applied (up to the trap or the failure); exactly, their sum is E⁻ − E⁺, E = ½|V|² + ½Ω·KΩ
    wall_work_normal: float     # W_n, the normal impulses' (plastic indentation)
    wall_work_tangential: float  # W_t, the tangential impulses' (the slip's cutting)

# layout of the scratch array of :func:`body_rebound`: the candidate points' heights and rates, then g̈ (curvatures)
_HEIGHTS = 0
_RATES = _HEIGHTS + WALK_ABOVE     # a scanned body's candidates: at most WALK_ABOVE (more: walked)
_CURVATURE = _RATES + WALK_ABOVE
_PARAMS = _CURVATURE + 3
_R = _PARAMS + ROT_PARAMS_SIZE
_K_LAB = _R + 9
_KINV_LAB = _K_LAB + 9
_K = _KINV_LAB + 9                 # then six 3-vectors: 1/K, ℓ, r_c, ΔV, ΔΩ, Ω(t)
_WALK = _K + 18
WORK_SIZE = _WALK + WALK_WORK
_BLOCKS = 1024                     # parallel work units of body_rebound_batch (scratch allocated per block)


@numba.njit(**KERNEL)
def quaternion_to_matrix(q, R):
    """Rotation matrix of the quaternion q = (w, x, y, z) (normalised here) into R."""
    n = np.sqrt(q[0] ** 2 + q[1] ** 2 + q[2] ** 2 + q[3] ** 2)
    w, x, y, z = q[0] / n, q[1] / n, q[2] / n, q[3] / n
    R[0, 0], R[0, 1], R[0, 2] = 1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)
    R[1, 0], R[1, 1], R[1, 2] = 2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)
    R[2, 0], R[2, 1], R[2, 2] = 2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)


@numba.njit(**KERNEL)
def lab_tensor(R, diag, out):
    """out = R diag(diag) Rᵀ: a body-frame principal tensor in the lab frame."""
    for i in range(3):
        for j in range(3):
            out[i, j] = R[i, 0] * diag[0] * R[j, 0] + R[i, 1] * diag[1] * R[j, 1] + R[i, 2] * diag[2] * R[j, 2]


@numba.njit(**KERNEL)
def body_rebound(kind, verts, nv, semi, K, Rb, R0, V0, W0, wall, n_max, contact_tol, set_tol, max_steps, V, W,
                 history, work, hull):
    """Simulate one particle's rebound.

    Parameters
    ----------
    kind, verts, nv, semi, K, Rb : the particle's body (:func:`direct_model.shape_arrays.particle_body`): its
        kind, its nv vertices in ``verts`` (body frame, units of a; the ellipsoid's support point is written into
        ``verts[0]``, so at least one row), its half-extents (an ellipsoid's semi-axes), its principal J/m (a²)
        and its bounding radius (:func:`direct_model.shape_arrays.bounding_radius`).
    R0 : (3, 3) body→lab orientation at the start.
    V0 : (3,) incident velocity, m/s; W0 : (3,) incident angular velocity, (m/s)/a.
    wall : the wall law's kernel array (:meth:`direct_model.wall.Wall.as_array`, layout W_*).
    n_max : collisions allowed before the particle is trapped.
    contact_tol, set_tol : contact and contact-set tolerances, units of a.
    max_steps : search-step budget per flight.
    V, W : (3,) work arrays: the velocity and angular velocity as the rebound goes, V⁺ and Ω⁺ at the end.
    history : (H, HISTORY_COLUMNS) output; row k receives the state at the start
        of flight k (k < H): time (a/(m/s)), centre height y (a), V (3), Ω (3),
        R (9, row-major). Pass an array with H = 0 to record nothing.
    work : (WORK_SIZE,) float64 scratch space (no allocation per particle).
    hull : (unit, scale, graph_start, graph, starts, far), a hull walked over its vertex graph
        (:func:`direct_model.flight.find_contact`): its vertices are unit[i] · scale and ``verts`` is not read;
        graph_start of no rows: ``verts[:nv]`` are scanned.

    Returns
    -------
    :class:`BodyRebound`.
    """
    h = work[_HEIGHTS:_HEIGHTS + WALK_ABOVE]
    h1 = work[_RATES:_RATES + WALK_ABOVE]
    curv = work[_CURVATURE:_CURVATURE + 3]
    params = work[_PARAMS:_PARAMS + ROT_PARAMS_SIZE]
    R = work[_R:_R + 9].reshape((3, 3))
    K_lab = work[_K_LAB:_K_LAB + 9].reshape((3, 3))
    Kinv_lab = work[_KINV_LAB:_KINV_LAB + 9].reshape((3, 3))
    Kinv = work[_K:_K + 3]
    ell = work[_K + 3:_K + 6]
    rc = work[_K + 6:_K + 9]
    dV = work[_K + 9:_K + 12]
    dW = work[_K + 12:_K + 15]
    Wt = work[_K + 15:_K + 18]          # angular velocity during the search
    walk_work = work[_WALK:_WALK + WALK_WORK]

    # element by element: an array assigned to a slice would compile numba's shape-mismatch message
    for i in range(3):
        Kinv[i] = 1.0 / K[i]
        V[i], W[i] = V0[i], W0[i]
        for j in range(3):
            R[i, j] = R0[i, j]

    if hull[2].shape[0] > 0:
        clear(walk_work)
        walk_work[START] = map_start(hull[4], (R[1, 0], R[1, 1], R[1, 2]), hull[1])
    if W0[0] == 0.0 and W0[1] == 0.0 and W0[2] == 0.0 and hull[2].shape[0] > 0:
        y = -walk_lowest(hull[0], hull[1], hull[2], hull[3], (R[1, 0], R[1, 1], R[1, 2]), 0.0,
                         int(walk_work[START]), walk_work)[0]
    elif W0[0] == 0.0 and W0[1] == 0.0 and W0[2] == 0.0:
        n = lowest_points(kind, verts, nv, semi, K, R, W, 0.0, 0.0, h, h1, curv)
        y = -np.inf
        for i in range(n):
            y = max(y, -h[i])         # −min h (h[:n].min() would need numba's runtime)
    else:
        y = Rb
    n_coll = 0
    n_steps = 0
    n_multi = 0
    status = STATUS_FAILED
    failure = FAILURE_NONE
    e_rot = 0.0
    work_n = 0.0
    work_t = 0.0
    t_abs = 0.0
    n_flights = 0
    while True:
        if n_flights < history.shape[0]:
            row = history[n_flights]
            row[0], row[1] = t_abs, y
            for i in range(3):
                row[2 + i], row[5 + i] = V[i], W[i]
                for j in range(3):
                    row[8 + 3 * i + j] = R[i, j]
        n_flights += 1
        lab_tensor(R, K, K_lab)
        for i in range(3):
            ell[i] = K_lab[i, 0] * W[0] + K_lab[i, 1] * W[1] + K_lab[i, 2] * W[2]
        e_rot = 0.5 * (W[0] * ell[0] + W[1] * ell[1] + W[2] * ell[2])
        M = curvature_bound(kind, semi, Rb, K, ell, W)
        M3 = jerk_bound(kind, semi, Rb, K, ell, W)
        for i in range(3):
            Wt[i] = W[i]
        code, t, steps = find_contact(kind, verts, nv, semi, Rb, K, ell, M, M3, params, y, V[1],
                                      contact_tol, set_tol, max_steps, R, Wt, h, h1, curv, rc, hull, walk_work)
        n_steps += steps
        if code == SEARCH_ESCAPED:
            status = STATUS_REBOUNDED
            break
        if code == SEARCH_STALLED:
            failure = FAILURE_SEARCH_BUDGET
            break
        if n_coll == n_max:
            status = STATUS_TRAPPED
            break
        y += V[1] * t
        t_abs += t
        for i in range(3):
            W[i] = Wt[i]
        lab_tensor(R, Kinv, Kinv_lab)
        outcome = collide(V, W, rc, Kinv_lab, wall, dV, dW)
        if outcome != COLLISION_OK and outcome != COLLISION_MULTIPLE_ROOTS:
            failure = FAILURE_COLLISION_SOLVER if outcome == COLLISION_FAILED else FAILURE_NOT_APPROACHING
            break
        n_multi += outcome == COLLISION_MULTIPLE_ROOTS
        hit_n, hit_t = wall_work(V, W, rc, dV, dW)
        work_n += hit_n
        work_t += hit_t
        V += dV
        W += dW
        n_coll += 1
    return BodyRebound(np.int64(status), np.int64(failure), np.int64(n_coll), np.int64(n_steps), np.int64(n_multi),
                       e_rot, (V[0], V[1], V[2]), (W[0], W[1], W[2]), work_n, work_t)


@numba.njit(parallel=True, **JIT)
def body_rebound_batch(shape_arrays, shapes, ratios, hands, quats, V0, W0, wall, n_max, contact_tol, set_tol,
                       max_steps, out_V, out_W, out_erot, out_ncoll, out_status, out_failure, out_steps, out_multi,
                       out_work_n, out_work_t):
    """Run :func:`body_rebound` for every particle i (parallel over blocks of particles).

    Inputs per particle: ``shapes[i]`` its shape's index in ``shape_arrays``
    (:class:`direct_model.shape_arrays.ShapeArrays`), ``ratios[i] = (b/a, c/b)``,
    ``hands[i]`` = ±1, ``quats[i]`` orientation quaternion (any norm > 0).
    Common: V0, W0 (lab; m/s and (m/s)/a), wall and the tolerances. Outputs (out_work_n and out_work_t: the
    wall work W_n and W_t, m²/s² per unit mass, :class:`BodyRebound`) are
    filled per particle; each particle's result depends on its inputs only, not
    on the blocking.
    """
    n = shapes.shape[0]
    n_blocks = min(n, _BLOCKS)
    for block in numba.prange(n_blocks):
        no_history = np.empty((0, HISTORY_COLUMNS))
        work = np.empty(WORK_SIZE)
        verts = np.empty((WALK_ABOVE, 3))
        K = np.empty(3)
        semi = np.empty(3)
        scale = np.empty(3)
        R0 = np.empty((3, 3))
        for i in range(block * n // n_blocks, (block + 1) * n // n_blocks):
            # int64 shape and kind, as the runtime passes them: one compilation of the model for both
            shape = np.int64(shapes[i])
            nv = particle_body(shape_arrays, shape, ratios[i, 0], ratios[i, 1], float(hands[i]), verts, K, semi,
                               scale)
            hull = particle_hull(shape_arrays, shape, scale)
            kind = np.int64(shape_arrays.kind[shape])
            quaternion_to_matrix(quats[i], R0)
            rebound = body_rebound(kind, verts, nv, semi, K, bounding_radius(kind, semi, verts, nv, hull), R0, V0, W0,
                                   wall, n_max, contact_tol, set_tol, max_steps, out_V[i], out_W[i], no_history, work,
                                   hull)
            out_status[i] = rebound.status
            out_failure[i] = rebound.failure
            out_ncoll[i] = rebound.n_collisions
            out_steps[i] = rebound.n_search_steps
            out_multi[i] = rebound.n_multiple_roots
            out_erot[i] = rebound.rotational_energy
            out_work_n[i] = rebound.wall_work_normal
            out_work_t[i] = rebound.wall_work_tangential
