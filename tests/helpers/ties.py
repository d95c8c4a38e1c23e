"""Rebounds whose first contact is a tie (docs/model.md §4.5): a face or an edge of a polyhedron exactly down, Ω⁻ = 0.

Lab frame: wall y = 0, normal +Y, V⁻ in the XY plane; lengths in units of a, velocities in m/s, Ω in (m/s)/a.
A :class:`TieState` is a body, an orientation R (body → lab) that puts the vertices ``contact`` (body rows) lowest
together, and V⁻; :func:`tie_states` are those of the tests, written once for the numba and the C tests.
:func:`reference` solves one collision (docs/model.md §4) at a given contact point independently of the kernels,
in 40-digit arithmetic; :func:`below_centre` is its closed form when the contact point is directly below the centre.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import mpmath
import numpy as np

from direct_model.body_rebound import HISTORY_COLUMNS, WORK_SIZE, body_rebound
from direct_model.registry import grain
from direct_model.shape_arrays import scanned_hull
from direct_model.hull_walk import WALK_ABOVE
from direct_model.wall import CORUNDUM_ON_STEEL
from tablegen.tabulation.grain_files import convex_hull
from tests.helpers.one_particle import Body, body

WALL = CORUNDUM_ON_STEEL
CONTACT_TOL, SET_TOL = 1e-10, 1e-9        # the model's defaults, units of a
N_MAX, MAX_STEPS = 1000, 100_000
MIRROR = np.diag([1.0, 1.0, -1.0])        # z → −z (lab), ζ → −ζ (body)
BOX_RATIOS = (0.6, 0.6)                   # b/a, c/b of the box: a = 1, b = 0.6, c = 0.36
NORMAL = ((90.0, 100.0), (90.0, 200.0))   # (α1 deg, |V⁻| m/s)


class TieState(NamedTuple):
    """One particle at its first contact, a tie of the vertices ``contact`` of ``body`` (module doc)."""

    name: str
    source: tuple            # (shape, (b/a, c/b), κ) of tests.helpers.one_particle.body
    body: Body               # its body of hand +1
    R: np.ndarray            # (3, 3) body → lab
    V: np.ndarray            # (3,) V⁻, m/s
    contact: tuple           # the vertices of the face or edge, rows of body.vertices
    mirrors: str             # the lab axes x, z whose reflection maps the state to itself

    @property
    def r_c(self) -> np.ndarray:
        """The contact point of the tie rule, lab frame: the centroid of the tied vertices (units of a)."""
        return self.R @ self.body.vertices[list(self.contact)].mean(axis=0)

    @property
    def K_lab(self) -> np.ndarray:
        """J/m in the lab frame, a²."""
        return self.R @ np.diag(self.body.K) @ self.R.T

    def mirrored(self) -> TieState:
        """The mirror image in the impact plane: the body of hand −1 (the vertices ζ → −ζ, the same rows) in
        orientation M R M."""
        shape, ratios, kappa = self.source
        return self._replace(name=self.name + "-mirror", body=body(shape, ratios, -1, kappa),
                             R=MIRROR @ self.R @ MIRROR)


def incident(alpha1, speed):
    """V⁻ = |V⁻|(cos α1, −sin α1, 0), m/s, α1 in degrees; exactly (0, −|V⁻|, 0) at 90°."""
    if alpha1 == 90.0:
        return np.array([0.0, -float(speed), 0.0])
    a = math.radians(alpha1)
    return np.array([speed * math.cos(a), -speed * math.sin(a), 0.0])


# -- orientations ------------------------------------------------------------------------------------------------

def azimuth(psi):
    """Rotation by ψ degrees about the lab's Y axis (heights unchanged); exact entries at multiples of 90°."""
    if psi % 90 == 0:
        c, s = [(1, 0), (0, 1), (-1, 0), (0, -1)][int(psi // 90) % 4]
    else:
        c, s = math.cos(math.radians(psi)), math.sin(math.radians(psi))
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]], dtype=float)


def facing_down(down, psi=0.0):
    """An orientation that turns the body direction ``down`` to −Y (its second row is −down/|down|), then ψ degrees
    about Y."""
    n = np.asarray(down, dtype=float) / np.linalg.norm(down)
    e0 = np.cross(np.eye(3)[np.argmin(np.abs(n))], n)
    e0 /= np.linalg.norm(e0)
    return azimuth(psi) @ np.array([e0, -n, np.cross(e0, -n)])


def box_face(down, along_x):
    """A signed permutation (exact) that puts the box's face +semi[down] down and body axis ``along_x`` along X."""
    columns = [None] * 3
    columns[down], columns[along_x] = np.array([0.0, -1.0, 0.0]), np.array([1.0, 0.0, 0.0])
    third = 3 - down - along_x
    columns[third] = np.cross(columns[(third + 1) % 3], columns[(third + 2) % 3])
    return np.column_stack(columns)


def box_edge(semi, axis, tilt, psi):
    """The box's edge along body axis ``axis`` at −semi of the other two (i, j) down and horizontal: the body
    direction −(sin θ, cos θ) in (i, j) turned to −Y, θ = atan(semi_i/semi_j) + tilt degrees (tilt 0: the centre
    directly above the edge), the edge along X turned ψ degrees about Y (ψ = 90: along −Z, exactly)."""
    i, j = [k for k in range(3) if k != axis]
    theta = math.atan2(semi[i], semi[j]) + math.radians(tilt)
    row0, row1 = np.zeros(3), np.zeros(3)
    row0[axis] = 1.0
    row1[i], row1[j] = math.sin(theta), math.cos(theta)
    return azimuth(psi) @ np.array([row0, row1, np.cross(row0, row1)])


# -- the contact set -----------------------------------------------------------------------------------------------

def heights(vertices, R):
    """Lab heights of the vertices above the centre as the kernels form them: g·p, g = R's second row."""
    g = R[1]
    return g[0] * vertices[:, 0] + g[1] * vertices[:, 1] + g[2] * vertices[:, 2]


def lowest(vertices, R, tol=SET_TOL):
    """The rows whose lab heights are within ``tol`` of the lowest, and the gap (units of a) from the lowest to the
    next vertex."""
    h = heights(vertices, R)
    tied = np.flatnonzero(h <= h.min() + tol)
    return tuple(int(i) for i in tied), float(np.delete(h, tied).min() - h.min())


def support(vertices, direction):
    """The rows of ``vertices`` farthest along the body direction ``direction`` (within 1e-12 a): a face or edge."""
    h = vertices @ (np.asarray(direction, dtype=float) / np.linalg.norm(direction))
    return tuple(int(i) for i in np.flatnonzero(h >= h.max() - 1e-12))


def coplanar_faces(record, vertices):
    """The faces of a hull record made of two or more triangles: {number of vertices: outward unit normal fitted to
    ``vertices``} (the particle's body, rows as the record's)."""
    v, t = record.vertices, record.triangles
    normals = np.cross(v[t[:, 1]] - v[t[:, 0]], v[t[:, 2]] - v[t[:, 0]])
    normals /= np.linalg.norm(normals, axis=1)[:, None]
    groups = {}
    for k, n in enumerate(normals):
        groups.setdefault(tuple(np.round(n, 6)), []).append(k)
    out = {}
    for key, members in groups.items():
        if len(members) > 1:
            rows = np.unique(t[members])
            normal = np.linalg.svd(vertices[rows] - vertices[rows].mean(axis=0))[2][2]
            out[len(rows)] = normal if normal @ key > 0 else -normal
    return out


# -- the states ----------------------------------------------------------------------------------------------------

def states(name, source, R, down, cases, mirrors=""):
    """One :class:`TieState` per (α1 deg, |V⁻| m/s) of ``cases``: the body of ``source`` = (shape, (b/a, c/b), κ) in
    orientation R, the tie being its support set in the body direction ``down``; reflection in x is a symmetry
    only at α1 = 90°."""
    bod = body(source[0], source[1], 1, source[2])
    contact = support(bod.vertices, down)
    return [TieState(f"{name}-{alpha1:g}deg-{speed:g}ms", source, bod, np.ascontiguousarray(R, dtype=float),
                     incident(alpha1, speed), contact, mirrors if alpha1 == 90.0 else mirrors.replace("x", ""))
            for alpha1, speed in cases]


def user_grain():
    """A user's grain, the hull of 11 points: an irregular, centrally symmetric hexagon (its base: 6 coplanar
    vertices, 4 triangles of the hull) under an irregular pentagon (its top: 5 coplanar vertices, 3 triangles)
    1.6 above it; no symmetry."""
    base = np.array([[1.0, 0.0], [0.55, 0.8], [-0.45, 0.7]])
    top = np.array([[0.5, 0.1], [0.2, 0.5], [-0.3, 0.35], [-0.4, -0.2], [0.25, -0.35]])
    points = np.vstack([np.column_stack([np.vstack([base, -base]), np.zeros(6)]),
                        np.column_stack([top, np.full(5, 1.6)])])
    vertices, triangles, _ = convex_hull(points, "tie_grain")
    return grain("tie_grain", vertices, triangles)


def tie_states():
    """Every tie state of the tests. The oblique α1 and the speeds are ones with a single collision and a margin
    (±2°, ±10 % in speed): on a face below the centre friction tips the body forward, and at low α1 or high speed
    (small a_nc) its leading edge comes down again, the sooner the longer the face along X against its height; an
    edge, or a face whose centre lies ahead of the centre of mass, tips less."""
    out = []
    source = ("prism", BOX_RATIOS, 0.3)
    A, B, C = body("prism", BOX_RATIOS).semi
    out += states("box_face_xi", source, box_face(0, 2), (1, 0, 0),
                  NORMAL + ((60.0, 100.0), (50.0, 100.0), (85.0, 200.0)), "xz")
    out += states("box_face_eta", source, box_face(1, 2), (0, 1, 0),
                  NORMAL + ((85.0, 100.0), (80.0, 100.0), (70.0, 50.0)), "xz")
    out += states("box_face_zeta", source, box_face(2, 0), (0, 0, 1),
                  NORMAL + ((85.0, 100.0), (80.0, 50.0), (75.0, 50.0)), "xz")
    edge_cases = NORMAL + ((60.0, 100.0), (60.0, 200.0), (30.0, 100.0), (30.0, 200.0))
    for name, tilt in (("box_edge_z", 0.0), ("box_edge_z_ahead", 10.0), ("box_edge_z_behind", -10.0)):
        out += states(name, source, box_edge((A, B, C), 2, tilt, 90), (-A, -B, 0), edge_cases, "z")
    out += states("box_edge_x", source, box_edge((A, B, C), 1, 0.0, 0), (-A, 0, -C),
                  NORMAL + ((85.0, 100.0), (80.0, 100.0), (70.0, 50.0)))
    out += states("box_edge_oblique", source, box_edge((A, B, C), 2, 5.0, 135), (-A, -B, 0), edge_cases)
    source = ("tetrahedron", (0.97, 0.97), 0.3)
    down = -1.0 / body(*source[:2]).semi       # the face opposite (a, b, c): ξ/a + η/b + ζ/c = −1
    out += states("tetrahedron", source, facing_down(down, 270), down,
                  ((90.0, 100.0), (90.0, 150.0), (85.0, 100.0), (80.0, 50.0)))
    source = ("tetrahedron", (0.8, 0.75), 0.3)
    down = -1.0 / body(*source[:2]).semi
    out += states("tetrahedron_ahead", source, facing_down(down, 250), down,
                  ((60.0, 100.0), (65.0, 100.0), (60.0, 200.0), (65.0, 200.0)))
    source = ("cut_prism", (0.9, 0.9), 0.3)
    down = 1.0 / body(*source[:2]).semi        # the cut face of corner (a, b, c)
    out += states("cut_prism", source, facing_down(down, 45), down, edge_cases)
    record = user_grain()
    source = (record, (1.0, 1.0), 0.3)
    faces = coplanar_faces(record, body(record).vertices)
    out += states("grain_pentagon", source, facing_down(faces[5], 20), faces[5],
                  NORMAL + ((75.0, 100.0), (60.0, 100.0), (80.0, 200.0)))
    out += states("grain_hexagon", source, facing_down(faces[6], 280), faces[6],
                  NORMAL + ((85.0, 100.0), (80.0, 50.0)))
    return out


# -- the rebound ---------------------------------------------------------------------------------------------------

def kernel_body(s: TieState):
    """The state's vertices as the kernels take them: WALK_ABOVE rows (a scanned body's most), the body's first."""
    verts = np.zeros((WALK_ABOVE, 3))
    verts[:len(s.body.vertices)] = s.body.vertices
    return verts


def rebound(s: TieState):
    """The state's rebound by the numba kernel: (V⁺ m/s, Ω⁺ (m/s)/a, status, n_collisions)."""
    V, W = np.empty(3), np.empty(3)
    done = body_rebound(
        s.body.kind, kernel_body(s), len(s.body.vertices), s.body.semi, s.body.K, s.body.radius, s.R, s.V,
        np.zeros(3), WALL.as_array(), N_MAX, CONTACT_TOL, SET_TOL, MAX_STEPS, V, W, np.empty((0, HISTORY_COLUMNS)),
        np.empty(WORK_SIZE), scanned_hull(kernel_body(s)))
    return V, W, done.status, done.n_collisions


# -- one collision, solved independently ------------------------------------------------------------------------

def reference(V, r, K_lab, digits=40):
    """One collision at the contact point ``r`` (lab, units of a) with Ω⁻ = 0 (docs/model.md §4): (V⁺, Ω⁺).

    V_c = V: a_nc = 1 − [1 − exp(−k|V|^p)] |v|/|V|, C_f = exp(q r·V/(|r||V|)), μ = C_f/|V|. For a trial
    λ = Δv_p the tangential laws Δu_p = −μλ(u + ½Δu_c), Δw_p = −μλ(w + ½Δw_c), with ΔV_c = G ΔV_p and
    G = I − [r]× K⁻¹ [r]×, are a 2 × 2 linear system in (Δu_p, Δw_p); λ is the smallest positive root of the
    normal law [G ΔV_p(λ)]_y = −(1 + a_nc) v, bracketed on a grid from λ = 0 (where the residual is −Δv_c < 0)
    and bisected to ``digits`` digits. ΔΩ = K⁻¹(r × ΔV_p).
    """
    mpf = mpmath.mpf
    with mpmath.workdps(digits):
        V = [mpf(float(x)) for x in V]
        r = [mpf(float(x)) for x in r]
        Kinv = mpmath.inverse(mpmath.matrix([[mpf(float(x)) for x in row] for row in K_lab]))
        cross = mpmath.matrix([[0, -r[2], r[1]], [r[2], 0, -r[0]], [-r[1], r[0], 0]])
        G = mpmath.eye(3) - cross * Kinv * cross
        speed = mpmath.sqrt(sum(x * x for x in V))
        a_nc = 1 - (1 - mpmath.exp(-mpf(WALL.k) * speed ** mpf(WALL.p))) * abs(V[1]) / speed
        cos_g = sum(ri * vi for ri, vi in zip(r, V)) / (mpmath.sqrt(sum(x * x for x in r)) * speed)
        mu = mpmath.exp(mpf(WALL.q) * cos_g) / speed
        dvc = -(1 + a_nc) * V[1]

        def impulse(lam):
            h = mu * lam / 2
            A = mpmath.matrix([[1 + h * G[0, 0], h * G[0, 2]], [h * G[2, 0], 1 + h * G[2, 2]]])
            b = mpmath.matrix([-mu * lam * (V[0] + G[0, 1] * lam / 2), -mu * lam * (V[2] + G[2, 1] * lam / 2)])
            x, z = mpmath.lu_solve(A, b)
            return mpmath.matrix([x, lam, z])

        def residual(lam):
            return (G * impulse(lam))[1] - dvc

        step = dvc / G[1, 1] / 64
        lo, hi = mpf(0), step
        while residual(hi) < 0:
            lo, hi = hi, hi + step
            assert hi < 1000 * dvc / G[1, 1], "no root of the normal law"
        for _ in range(4 * digits):
            mid = (lo + hi) / 2
            lo, hi = (mid, hi) if residual(mid) < 0 else (lo, mid)
        dV = impulse((lo + hi) / 2)
        dW = Kinv * mpmath.matrix([r[1] * dV[2] - r[2] * dV[1], r[2] * dV[0] - r[0] * dV[2],
                                   r[0] * dV[1] - r[1] * dV[0]])
        return np.array([float(V[i] + dV[i]) for i in range(3)]), np.array([float(dW[i]) for i in range(3)])


def below_centre(V, h, K_lab):
    """The closed form of one collision with Ω⁻ = 0 at r_c = (0, −h, 0), directly below the centre: (V⁺, Ω⁺)
    (tests/direct_model/test_contact_ties.py derives it)."""
    V = np.asarray(V, dtype=float)
    Kinv = np.linalg.inv(K_lab)
    speed = np.linalg.norm(V)
    sin_i = abs(V[1]) / speed
    lam = -(2.0 - (1.0 - math.exp(-WALL.k * speed ** WALL.p)) * sin_i) * V[1]
    mu = math.exp(WALL.q * sin_i) / speed
    G_tt = np.eye(2) + h * h * np.array([[Kinv[2, 2], -Kinv[2, 0]], [-Kinv[0, 2], Kinv[0, 0]]])
    du, dw = np.linalg.solve(np.eye(2) + 0.5 * mu * lam * G_tt, -mu * lam * V[[0, 2]])
    return V + [du, lam, dw], Kinv @ np.array([-h * dw, 0.0, h * du])


_REFERENCES = {}


def expected(s: TieState):
    """(V⁺, Ω⁺) of :func:`reference` at the state's face or edge centre (computed once per state)."""
    if s.name not in _REFERENCES:
        _REFERENCES[s.name] = reference(s.V, s.r_c, s.K_lab)
    return _REFERENCES[s.name]
