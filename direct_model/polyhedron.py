"""Geometry of a convex polyhedron given by its hull (docs/model.md §3 and §9): mass properties, canonical frame.

A hull is ``vertices`` (n, 3) and ``triangles`` (m, 3) of vertex indices, each triangle counter-clockwise seen
from outside, together closing the body's surface. Plain numpy and exactly rounded sums (:func:`math.fsum`),
no BLAS and no LAPACK: the results are the same bits on any x86-64 CPU, so a table that stores them is
reproducible. The hull itself is taken elsewhere (the table build, with scipy); this module only needs it.

Mass properties (uniform density) come from the divergence theorem: the body is the union of the signed
tetrahedra joining an origin to each triangle, and a monomial integrates over a tetrahedron exactly
(:func:`monomial_integrals`).

The canonical frame (:func:`canonical_frame`) places a grain, whatever its position, orientation and size in
its file, with its centre of mass at the origin, its principal axes of inertia along ξ, η, ζ in ascending
order of moment (descending extent, as a ≥ b ≥ c for the families), right-handed (a proper rotation: a chiral
grain keeps its hand), and its size such that a, the largest half-extent (max − min)/2 along a principal axis,
is 1. What the inertia leaves open is fixed from the body itself:

* the sign of each axis, by the first odd moment that tells the two directions apart (third moments, then
  fourth-order mixed moments, which still tell them apart for a centrally symmetric body); a body none of them
  separates is taken with the signs the eigen-solver gave, and then at least one of the candidate frames maps
  the body onto itself for every shape we know of (boxes, ellipsoids, cubes);
* the axes within a plane of equal moments (a square cross-section, a regular prism): the narrowest direction
  in that plane (minimum width of the hull, found among the edges' normals) is the later axis;
* all three axes when the three moments are equal (a cube, a regular tetrahedron): the narrowest face normal is
  ζ, then the plane rule gives η and ξ.

Moments count as equal when they differ by less than :data:`EQUAL_MOMENTS` of the largest; a grain whose
moments differ by a little more than that has axes that round-off turns by about 1e-16 / (relative gap), so the
canonical vertices of two copies of it agree to that, not to 1e-16 (to 1e-12 for gaps above 1e-4).
"""

from __future__ import annotations

import functools
import itertools
import math
from typing import NamedTuple

import numpy as np

EQUAL_MOMENTS = 1e-9          # relative gap below which two principal moments are equal (symmetry, not round-off)
ZERO_ODD_MOMENT = 1e-9        # an odd moment below this × volume × radius^order does not pick an axis' sign
EQUAL_WIDTHS = 1e-12          # widths this close (relative) are one width: the narrowest direction is then any
SORT_DIRECTION = (1.0, 1.0 / math.pi, 1.0 / math.e)   # canonical vertex order: along a direction no symmetry holds


class MassProperties(NamedTuple):
    """Mass properties of a uniform body: volume (length³), centre of mass (length), J/m (length²)."""

    volume: float
    centroid: np.ndarray           # (3,)
    inertia: np.ndarray            # (3, 3): J/m about the centre of mass, in the vertices' frame


class CanonicalFrame(NamedTuple):
    """A hull in its canonical frame, and the map from the file: x_canonical = Rᵀ (x_file − centroid) / a."""

    vertices: np.ndarray           # (n, 3) in units of a, sorted along SORT_DIRECTION
    triangles: np.ndarray          # (m, 3) int32, counter-clockwise from outside
    rotation: np.ndarray           # (3, 3) R: columns are ξ, η, ζ in the file's frame; det R = +1
    centroid: np.ndarray           # (3,) centre of mass in the file's frame
    a: float                       # largest half-extent along a principal axis, in the file's length unit


def _dot3(p, axis):
    """p · axis for rows of p, by elementwise arithmetic (no BLAS: the same bits on any CPU)."""
    return p[..., 0] * axis[0] + p[..., 1] * axis[1] + p[..., 2] * axis[2]


def _fsum_mean(values):
    return np.array([math.fsum(column) / len(values) for column in np.asarray(values).T])


def monomial_integrals(vertices, triangles, exponents):
    """∫ x^p y^q z^r dV over the body bounded by the triangles, for each (p, q, r) in ``exponents``.

    Each triangle (p₀, p₁, p₂) and the origin span a tetrahedron of signed volume det[p₀ p₁ p₂]/6 (positive for
    a counter-clockwise triangle facing away from the origin), and these add up to the body whatever the origin.
    On a tetrahedron with a vertex at the origin, x = Σᵢ λᵢ pᵢ in barycentric coordinates λ, and
    ∫ λ^α dV = 6 V α! / (|α| + 3)!, so a product of k coordinates integrates to
    6 V Σ over maps f: {1..k} → {0, 1, 2} of (Π counts!) / (k + 3)! · Π_m p_{f(m), axis m}. Exact for every
    degree; the sum over triangles is exactly rounded.
    """
    tri = np.asarray(vertices, dtype=float)[np.asarray(triangles)]          # (m, 3 corners, 3 axes)
    p0, p1, p2 = tri[:, 0], tri[:, 1], tri[:, 2]
    cross = np.stack([p1[:, 1] * p2[:, 2] - p1[:, 2] * p2[:, 1],
                      p1[:, 2] * p2[:, 0] - p1[:, 0] * p2[:, 2],
                      p1[:, 0] * p2[:, 1] - p1[:, 1] * p2[:, 0]], axis=1)
    six_volume = _dot3(p0, cross.T)
    column = [[np.ascontiguousarray(tri[:, corner, axis]) for axis in range(3)] for corner in range(3)]
    out = []
    for p, q, r in exponents:
        axes = (0,) * p + (1,) * q + (2,) * r
        k = len(axes)
        total = np.zeros(len(tri))
        for corners, weight in _corner_weights(k):
            term = np.full(len(tri), weight)
            for corner, axis in zip(corners, axes):
                term *= column[corner][axis]
            total += term
        out.append(math.fsum(six_volume * total))
    return out


@functools.cache
def _corner_weights(k: int) -> tuple:
    """Each map of k coordinates to the three corners with its weight (Π counts!)/(k + 3)! (monomial_integrals)."""
    return tuple((corners, math.prod(math.factorial(corners.count(i)) for i in range(3)) / math.factorial(k + 3))
                 for corners in itertools.product(range(3), repeat=k))


SECOND = ((2, 0, 0), (0, 2, 0), (0, 0, 2), (1, 1, 0), (1, 0, 1), (0, 1, 1))


def mass_properties(vertices, triangles) -> MassProperties:
    """Volume, centre of mass and J/m about it of the uniform body bounded by the triangles (module doc)."""
    vertices = np.asarray(vertices, dtype=float)
    origin = _fsum_mean(vertices)                         # an interior point: small coordinates, small round-off
    volume, *first = monomial_integrals(vertices - origin, triangles, ((0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)))
    if not volume > 0.0:
        raise ValueError(f"the triangles enclose no volume (volume {volume!r}): not a closed outward surface")
    centroid = origin + np.array(first) / volume
    xx, yy, zz, xy, xz, yz = np.array(monomial_integrals(vertices - centroid, triangles, SECOND)) / volume
    cov = np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])
    inertia = (xx + yy + zz) * np.eye(3) - cov
    return MassProperties(volume, centroid, inertia)


def symmetric_eigen(matrix):
    """Eigenvalues (descending) and unit eigenvectors (columns) of a symmetric 3×3 matrix, by cyclic Jacobi.

    Plain floating-point arithmetic in a fixed order (LAPACK's result may depend on the CPU's kernel).
    """
    a = [[float(matrix[i][j]) for j in range(3)] for i in range(3)]
    v = [[1.0 if i == j else 0.0 for j in range(3)] for i in range(3)]
    for _ in range(50):
        rotated = False
        for p, q in ((0, 1), (0, 2), (1, 2)):
            if abs(a[p][q]) <= 1e-18 * (abs(a[p][p]) + abs(a[q][q])):
                a[p][q] = a[q][p] = 0.0
                continue
            rotated = True
            theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q])
            t = math.copysign(1.0, theta) / (abs(theta) + math.sqrt(theta * theta + 1.0))
            c = 1.0 / math.sqrt(t * t + 1.0)
            s = t * c
            for k in range(3):                           # A ← A G (columns p, q), then Gᵀ A (rows p, q)
                akp, akq = a[k][p], a[k][q]
                a[k][p], a[k][q] = c * akp - s * akq, s * akp + c * akq
            for k in range(3):
                apk, aqk = a[p][k], a[q][k]
                a[p][k], a[q][k] = c * apk - s * aqk, s * apk + c * aqk
            for k in range(3):
                vkp, vkq = v[k][p], v[k][q]
                v[k][p], v[k][q] = c * vkp - s * vkq, s * vkp + c * vkq
        if not rotated:
            break
    order = sorted(range(3), key=lambda i: -a[i][i])
    values = np.array([a[i][i] for i in order])
    vectors = np.array([[v[k][i] for i in order] for k in range(3)])
    return values, vectors


def _unit(v):
    return v / math.sqrt(math.fsum(v * v))


def _cross(u, w):
    return np.array([u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]])


def _narrowest(points, directions):
    """The direction (unit rows) along which the points spread least; the first of those within EQUAL_WIDTHS."""
    heights = np.stack([_dot3(points, d) for d in directions], axis=1)
    widths = heights.max(axis=0) - heights.min(axis=0)
    return directions[int(np.argmax(widths <= widths.min() * (1.0 + EQUAL_WIDTHS)))]


def _edges(triangles):
    """The hull's edges (e, 2), each (smaller, larger vertex index), in ascending order of both."""
    t = np.asarray(triangles)
    pairs = np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]]).astype(np.int64)
    low, high = pairs.min(axis=1), pairs.max(axis=1)
    width = int(high.max()) + 1 if len(high) else 1
    keys = np.unique(low * width + high)              # one integer per edge: a sort of numbers, not of rows
    return np.stack([keys // width, keys % width], axis=1).astype(t.dtype)


def _plane_axes(points, triangles, normal):
    """Two axes spanning the plane ⊥ ``normal``: (the other one, the narrowest in-plane direction)."""
    edges = _edges(triangles)
    along = points[edges[:, 1]] - points[edges[:, 0]]
    candidates = np.stack([_cross(normal, e) for e in along])
    size = np.sqrt(candidates[:, 0] ** 2 + candidates[:, 1] ** 2 + candidates[:, 2] ** 2)
    keep = size > 1e-9 * size.max()                      # an edge along the normal has no in-plane normal
    candidates = candidates[keep] / size[keep, None]
    narrow = _narrowest(points, candidates)
    return _unit(_cross(narrow, normal)), narrow


def _principal_axes(points, triangles, variances, vectors):
    """Columns ξ, η, ζ: eigenvectors, with each plane (or space) of equal moments resolved (module doc)."""
    scale = variances[0]
    equal = [variances[i] - variances[i + 1] <= EQUAL_MOMENTS * scale for i in range(2)]
    axes = [vectors[:, i] for i in range(3)]
    if equal[0] and equal[1]:
        tri = points[np.asarray(triangles)]
        normals = np.stack([_cross(t[1] - t[0], t[2] - t[0]) for t in tri])
        size = np.sqrt((normals ** 2).sum(axis=1))
        keep = size > 1e-12 * size.max()                  # a triangle of zero area has no normal
        zeta = _narrowest(points, normals[keep] / size[keep, None])
        xi, eta = _plane_axes(points, triangles, zeta)
        axes = [xi, eta, zeta]
    elif equal[0]:
        axes[0], axes[1] = _plane_axes(points, triangles, axes[2])
    elif equal[1]:
        axes[1], axes[2] = _plane_axes(points, triangles, axes[0])
    frame = np.stack(axes, axis=1)
    if _dot3(_cross(frame[:, 0], frame[:, 1]), frame[:, 2]) < 0.0:
        frame[:, 2] = -frame[:, 2]
    return frame


def _sign_indicators(points, triangles, radius, volume):
    """Per axis, the first odd moment (in the order below) large enough to tell its two directions apart; 0 if none.

    Each listed moment changes sign with axis i and with no other when the frame turns by 180° about an axis:
    x_i³, x_i x_j², x_i x_k² (third order), then x_i² x_j x_k, x_j³ x_k, x_j x_k³ (fourth order; these separate
    the directions of a centrally symmetric body, whose odd moments all vanish).
    """
    signs = []
    for i in range(3):
        j, k = [m for m in range(3) if m != i]
        listed = []
        for powers in ({i: 3}, {i: 1, j: 2}, {i: 1, k: 2}, {i: 2, j: 1, k: 1}, {j: 3, k: 1}, {j: 1, k: 3}):
            listed.append(tuple(powers.get(m, 0) for m in range(3)))
        values = monomial_integrals(points, triangles, listed)
        sign = 0.0
        for exponent, value in zip(listed, values):
            if abs(value) > ZERO_ODD_MOMENT * volume * radius ** sum(exponent):
                sign = math.copysign(1.0, value)
                break
        signs.append(sign)
    return signs


def _axis_signs(indicators):
    """Signs σ of the axes, σ₁σ₂σ₃ = +1 (a rotation): the first two axes with an indicator follow it."""
    decided = [i for i in range(3) if indicators[i] != 0.0][:2]
    sigma = [1.0, 1.0, 1.0]
    for i in decided:
        sigma[i] = indicators[i]
    free = [i for i in range(3) if i not in decided]
    sigma[free[-1]] = sigma[free[-1]] * math.prod(sigma)   # makes the product +1
    return sigma


def canonical_frame(vertices, triangles) -> CanonicalFrame:
    """The hull moved to its centre of mass and principal axes, scaled so that a = 1 (module doc).

    ``vertices`` (n, 3) are the hull's vertices (each used by a triangle), ``triangles`` (m, 3) its surface,
    counter-clockwise from outside; any length unit. ValueError if they enclose no volume.
    """
    vertices = np.asarray(vertices, dtype=float)
    triangles = np.asarray(triangles, dtype=np.int32)
    props = mass_properties(vertices, triangles)
    cov = np.trace(props.inertia) / 2.0 * np.eye(3) - props.inertia      # ∫ x xᵀ dm / m
    variances, vectors = symmetric_eigen(cov)
    centred = vertices - props.centroid
    frame = _principal_axes(centred, triangles, variances, vectors)
    body = np.stack([_dot3(centred, frame[:, i]) for i in range(3)], axis=1)
    radius = math.sqrt(float((body ** 2).sum(axis=1).max()))
    sigma = _axis_signs(_sign_indicators(body, triangles, radius, props.volume))
    frame = frame * np.array(sigma)
    body = body * np.array(sigma)
    a = float(((body.max(axis=0) - body.min(axis=0)) / 2.0).max())
    body = body / a
    order = np.argsort(_dot3(body, SORT_DIRECTION), kind="stable")
    rank = np.empty(len(order), dtype=np.int32)
    rank[order] = np.arange(len(order), dtype=np.int32)
    return CanonicalFrame(body[order], rank[triangles], frame, props.centroid, a)


def vertex_graph(triangles, n_vertices):
    """The hull's edges as a compressed adjacency list: neighbours of vertex i are neighbours[start[i]:start[i+1]].

    Returns ``start`` (n_vertices + 1,) and ``neighbours`` (2 × edges,), int32, each list ascending.
    """
    edges = _edges(triangles)
    both = np.concatenate([edges, edges[:, ::-1]])
    both = both[np.lexsort((both[:, 1], both[:, 0]))]
    start = np.zeros(n_vertices + 1, dtype=np.int32)
    np.add.at(start, both[:, 0] + 1, 1)
    return np.cumsum(start, dtype=np.int32), both[:, 1].astype(np.int32)
