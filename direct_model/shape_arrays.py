"""Shapes as the kernels take them: a few plain arrays over every shape (docs/model.md §3 and §9).

The registry's records (:mod:`direct_model.registry`) are Python objects; a kernel (numba or C) takes the same
shapes as the arrays of :class:`ShapeArrays`, and a table stores those arrays as they are. Shape ``i`` is row
``i`` of every per-shape array; ``n`` shapes in all.

=================  ==================  ===========================================================================
array              dtype, shape        content
=================  ==================  ===========================================================================
``kind``           int8 (n,)           :data:`KIND_ELLIPSOID` (0) a smooth ellipsoid, :data:`KIND_POLYHEDRON` (1) a
                                       convex polyhedron
``vertex_start``   int64 (n + 1,)      shape i's rows of ``vertices`` are vertex_start[i] to vertex_start[i + 1]
``vertices``       float64 (total, 3)  the unit body in the body frame Oξηζ (centre of mass at the origin,
                                       principal axes along ξ, η, ζ), units of a: a polyhedron's hull vertices (4 to
                                       :data:`MAX_HULL_VERTICES`, largest half-extent (max − min)/2 along an axis
                                       1), an ellipsoid's semi-axes (one row, the largest 1)
``triangle_start`` int64 (n + 1,)      shape i's rows of ``triangles`` (none for an ellipsoid)
``triangles``      int32 (total_t, 3)  the hull's surface, counter-clockwise from outside, as indices into the
                                       shape's own vertices (0 to its count − 1)
``second_moments`` float64 (n, 3)      ∫ξ² dm/m, ∫η² dm/m, ∫ζ² dm/m of the unit body, a²: its principal
                                       J/m is (η² + ζ², ξ² + ζ², ξ² + η²) of these
``aspect``         float64 (n, 4)      the law of b/a and c/b (mean, sd, low, high) that stretches the shape per
                                       particle (:class:`direct_model.shapes.AspectRatioLaw`); a row of NaN: fixed
                                       proportions, the unit body itself
``both_hands``     uint8 (n,)          1: half of the particles are the mirror image (ζ → −ζ)
``aspect_cdf``     float64 (n, 2)      derived, never stored: Φ((low − mean)/sd), Φ((high − mean)/sd) of the law
                                       (libm's erfc), NaN for fixed proportions
``half_extents``   float64 (n, 3)      derived: (max − min)/2 of the unit body's vertices along ξ, η, ζ (an
                                       ellipsoid's semi-axes)
``graph_start``    int64 (total + 1,)  derived: vertex row r's neighbours are graph[graph_start[r]:graph_start[r +
                                       1]] (:func:`direct_model.polyhedron.vertex_graph`; none for an ellipsoid)
``graph``          int32 (2 × edges,)  derived: the hulls' vertex graphs, as the shape's own vertex indices
``starts``         int32 (n, MAP_SIZE) derived: a hull's start map, the vertex where a descent along a direction
                                       starts (:func:`direct_model.hull_walk.start_map`; 0 for a scanned shape)
``far_start``      int64 (n + 1,)      derived: shape i's rows of ``far``
``far``            int32 (total_f,)    derived: the vertices that may be a particle's farthest
                                       (:func:`direct_model.hull_walk.farthest_candidates`), the shape's own
                                       indices
=================  ==================  ===========================================================================

The unit body of a family (docs/model.md §3) is its body at b/a = c/b = 1, its vertices in the order of
:func:`direct_model.shapes.body_vertices` (the order and the operations decide the bits of a rebound): the cut
prism's 24 (κ is in them; at κ = 0 each corner thrice), the prism's 8, the tetrahedron's 4; the ellipsoid's
semi-axes (1, 1, 1). Its three second moments are equal, the factor s of J/m = s(b² + c², a² + c², a² + b²) that
tables record (:func:`direct_model.shapes.second_moment_factors`). A user's grain is its canonical hull
(:func:`direct_model.registry.grain`).

One particle's body (:func:`particle_body`): the unit body stretched by (1, b/a, b/a · c/b) along (ξ, η, ζ),
rescaled so that its largest half-extent along a principal axis is 1 (a means the same for every shape), and
mirrored for hand −1. The stretch keeps the axes principal, so J/m follows in closed form; three equal second
moments (a family's) give J/m as s(b² + c², ...), the product the kernels always formed for the families.

:func:`shape_arrays` turns records into these arrays, :func:`shape_records` turns them back (what a loader
needs to show or re-check the shapes); :func:`family_shape_arrays` gives the four families. Plain numpy and
numba: the runtime builds and reads them.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numba
import numpy as np

from direct_model.options import KERNEL
from direct_model.registry import (FRAME_CHECK, MAX_HULL_VERTICES, ConvexPolyhedron, Ellipsoid, built_in_shape,
                                   built_in_shapes, polyhedron)
from direct_model.shapes import DEFAULT_KAPPA, SHAPES, AspectRatioLaw, normal_cdf, second_moment_factor, shape_vertices
from direct_model.hull_walk import MAP_SIZE, WALK_ABOVE, farthest_candidates, start_map, walk_farthest
from direct_model.polyhedron import vertex_graph

KIND_ELLIPSOID, KIND_POLYHEDRON = 0, 1
MIN_HULL_VERTICES = 4
STORED = ("kind", "vertex_start", "vertices", "triangle_start", "triangles", "second_moments", "aspect", "both_hands")


class ShapeArrays(NamedTuple):
    """Every shape as plain arrays (module doc): read-only, C-contiguous; what the kernels take."""

    kind: np.ndarray             # int8 (n,)
    vertex_start: np.ndarray     # int64 (n + 1,)
    vertices: np.ndarray         # float64 (total, 3), units of a
    triangle_start: np.ndarray   # int64 (n + 1,)
    triangles: np.ndarray        # int32 (total_t, 3)
    second_moments: np.ndarray   # float64 (n, 3), a²
    aspect: np.ndarray           # float64 (n, 4): mean, sd, low, high; NaN row: fixed proportions
    both_hands: np.ndarray       # uint8 (n,)
    aspect_cdf: np.ndarray       # float64 (n, 2): derived from aspect
    half_extents: np.ndarray     # float64 (n, 3): derived from vertices
    graph_start: np.ndarray      # int64 (total + 1,): derived, the hulls' vertex graphs
    graph: np.ndarray            # int32 (2 × edges,)
    starts: np.ndarray           # int32 (n, MAP_SIZE): derived, where a descent starts
    far_start: np.ndarray        # int64 (n + 1,): derived, the farthest vertex's candidates
    far: np.ndarray              # int32 (total_f,)

    @property
    def n_shapes(self) -> int:
        return self.kind.shape[0]

    def stored(self) -> dict:
        """The arrays a table stores, by name (:data:`STORED`)."""
        return {name: getattr(self, name) for name in STORED}


def _frozen(x, dtype):
    x = np.array(x, dtype=dtype, order="C")         # a copy: nobody else can write to it
    x.flags.writeable = False
    return x


def from_stored(kind, vertex_start, vertices, triangle_start, triangles, second_moments, aspect,
                both_hands) -> ShapeArrays:
    """The kernels' arrays from the stored ones (a table's, or :func:`shape_arrays`'): checked, the law's CDF
    bounds derived; ValueError naming the first array and shape that is not as the module doc says."""
    arrays = dict(kind=_frozen(kind, np.int8), vertex_start=_frozen(vertex_start, np.int64),
                  vertices=_frozen(np.reshape(vertices, (-1, 3)), np.float64),
                  triangle_start=_frozen(triangle_start, np.int64),
                  triangles=_frozen(np.reshape(triangles, (-1, 3)), np.int32),
                  second_moments=_frozen(np.reshape(second_moments, (-1, 3)), np.float64),
                  aspect=_frozen(np.reshape(aspect, (-1, 4)), np.float64), both_hands=_frozen(both_hands, np.uint8))
    _check(**arrays)
    n = len(arrays["kind"])
    cdf, half = np.full((n, 2), np.nan), np.zeros((n, 3))
    starts, degrees, graphs, fars = np.zeros((n, MAP_SIZE), np.int32), [np.zeros(1, np.int64)], [], []
    for i, (mean, sd, low, high) in enumerate(arrays["aspect"]):
        if not np.isnan(mean):
            cdf[i] = normal_cdf((low - mean) / sd), normal_cdf((high - mean) / sd)
        lo, hi = arrays["vertex_start"][i], arrays["vertex_start"][i + 1]
        if arrays["kind"][i] == KIND_ELLIPSOID:
            half[i] = arrays["vertices"][lo]
            degrees.append(np.zeros(1, np.int64))
            fars.append(np.zeros(0, np.int32))
        else:
            unit = arrays["vertices"][lo:hi]
            half[i] = _half_extents(arrays["vertices"], lo, hi - lo)
            start, neighbours = vertex_graph(arrays["triangles"][arrays["triangle_start"][i]:
                                                                 arrays["triangle_start"][i + 1]], hi - lo)
            degrees.append(np.diff(start).astype(np.int64))
            graphs.append(neighbours)
            if hi - lo > WALK_ABOVE:
                starts[i] = start_map(unit, start, neighbours)
            fars.append(farthest_candidates(unit))
    graph_start = np.cumsum(np.concatenate(degrees))
    return ShapeArrays(**arrays, aspect_cdf=_frozen(cdf, np.float64), half_extents=_frozen(half, np.float64),
                       graph_start=_frozen(graph_start, np.int64),
                       graph=_frozen(np.concatenate([np.zeros(0, np.int32), *graphs]), np.int32),
                       starts=_frozen(starts, np.int32),
                       far_start=_frozen(np.concatenate([[0], np.cumsum([len(f) for f in fars])]), np.int64),
                       far=_frozen(np.concatenate([np.zeros(0, np.int32), *fars]), np.int32))


def _check(kind, vertex_start, vertices, triangle_start, triangles, second_moments, aspect, both_hands):
    n = kind.shape[0]
    for name, x, rows in (("vertex_start", vertex_start, n + 1), ("triangle_start", triangle_start, n + 1),
                          ("second_moments", second_moments, n), ("aspect", aspect, n), ("both_hands", both_hands, n)):
        if x.shape[0] != rows:
            raise ValueError(f"shape arrays: '{name}' has {x.shape[0]} rows; {n} shapes need {rows}")
    for name, start, total in (("vertex_start", vertex_start, len(vertices)),
                               ("triangle_start", triangle_start, len(triangles))):
        if start[0] != 0 or start[-1] != total or np.any(np.diff(start) < 0):
            raise ValueError(f"shape arrays: '{name}' must rise from 0 to {total}; got {start.tolist()}")
    for i in range(n):
        count = vertex_start[i + 1] - vertex_start[i]
        corners = triangles[triangle_start[i]:triangle_start[i + 1]]
        body = vertices[vertex_start[i]:vertex_start[i + 1]]
        if kind[i] == KIND_ELLIPSOID:
            if count != 1 or len(corners) or not (np.all(body > 0.0) and abs(body.max() - 1.0) <= FRAME_CHECK):
                raise ValueError(f"shape arrays: shape {i}, an ellipsoid, needs one row of semi-axes > 0, the "
                                 f"largest 1, and no triangles; got {body.tolist()}, {len(corners)} triangles")
        elif kind[i] == KIND_POLYHEDRON:
            if not MIN_HULL_VERTICES <= count <= MAX_HULL_VERTICES:
                raise ValueError(f"shape arrays: shape {i} has {count} vertices; allowed: {MIN_HULL_VERTICES} to "
                                 f"{MAX_HULL_VERTICES}")
            half = (body.max(axis=0) - body.min(axis=0)) / 2.0
            if not (np.all(np.isfinite(body)) and abs(half.max() - 1.0) <= FRAME_CHECK):
                raise ValueError(f"shape arrays: the vertices of shape {i} must be finite, their largest half-extent "
                                 f"1 (units of a); got {half.max()!r}")
            if len(corners) < 4 or corners.min() < 0 or corners.max() >= count:
                raise ValueError(f"shape arrays: shape {i} needs at least 4 triangles of vertex indices 0 to "
                                 f"{count - 1}")
        else:
            raise ValueError(f"shape arrays: 'kind' of shape {i} must be {KIND_ELLIPSOID} (ellipsoid) or "
                             f"{KIND_POLYHEDRON} (convex polyhedron); got {kind[i]}")
        if not np.all(second_moments[i] > 0.0) or not np.all(np.isfinite(second_moments[i])):
            raise ValueError(f"shape arrays: the second moments of shape {i} must be finite and > 0; got "
                             f"{second_moments[i].tolist()}")
        law = aspect[i]
        if not np.all(np.isnan(law)):
            AspectRatioLaw(*law)          # ValueError naming the bound that is wrong
        if both_hands[i] > 1:
            raise ValueError(f"shape arrays: 'both_hands' of shape {i} must be 0 or 1; got {both_hands[i]}")


def _family_rows(record: ConvexPolyhedron):
    """A family's unit vertices in the kernels' order, and its triangles re-indexed to them."""
    kernel = shape_vertices(record.name, 1.0, 1.0, 1.0, kappa=record.parameters.get("kappa", 0.0))
    first = {tuple(v): i for i, v in reversed(list(enumerate(kernel.tolist())))}     # κ = 0 repeats corners
    index = np.array([first[tuple(v)] for v in record.vertices.tolist()])
    return kernel, index[record.triangles]


def shape_arrays(records, second_moment_factors=None) -> ShapeArrays:
    """The arrays of the registry's ``records`` (in that order; module doc).

    ``second_moment_factors``: the families' factors s by name, as a table records them (the runtime gives the
    table's); a family not in it gets :func:`direct_model.shapes.second_moment_factor` at its κ (scipy). A
    record is a family when its name is a built-in's (a user's grain cannot have one).
    """
    factors = dict(second_moment_factors or {})
    kind, counts, vertices, t_counts, triangles, moments, aspect, hands = [], [], [], [], [], [], [], []
    for record in records:
        if isinstance(record, Ellipsoid):
            kind.append(KIND_ELLIPSOID)
            rows, tri = np.array([record.semi_axes], dtype=float), np.zeros((0, 3), np.int32)
            semi2 = rows[0] ** 2
            s = factors.get(record.name, 0.2) if record.name in SHAPES else None
            moments.append(np.full(3, s) if s is not None else semi2 / 5.0)
        else:
            kind.append(KIND_POLYHEDRON)
            if record.name in SHAPES:
                rows, tri = _family_rows(record)
                kappa = record.parameters.get("kappa", 0.0)
                s = factors[record.name] if record.name in factors else second_moment_factor(record.name, kappa)
                moments.append(np.full(3, s))
            else:
                rows, tri = record.vertices, record.triangles
                moments.append(record.inertia.sum() / 2.0 - record.inertia)
        counts.append(len(rows))
        vertices.append(rows)
        t_counts.append(len(tri))
        triangles.append(tri)
        law = record.aspect
        aspect.append((law.mean, law.sd, law.low, law.high) if law is not None else (np.nan,) * 4)
        hands.append(int(record.both_hands))
    return from_stored(np.array(kind), np.concatenate([[0], np.cumsum(counts)]), np.concatenate(vertices),
                       np.concatenate([[0], np.cumsum(t_counts)]), np.concatenate(triangles),
                       np.array(moments).reshape(-1, 3), np.array(aspect).reshape(-1, 4), np.array(hands))


def family_shape_arrays(kappa: float, aspect: AspectRatioLaw, second_moment_factors, grains=()) -> ShapeArrays:
    """The four families in code order (:data:`direct_model.shapes.SHAPES`) with κ, the law and the factors s
    (one per code) a table records, then the user grains' records ``grains``: what a runtime builds from a
    table (``table.direct_parameters`` and its grains)."""
    return shape_arrays([*built_in_shapes(kappa, aspect).values(), *grains],
                        dict(zip(SHAPES, map(float, second_moment_factors))))


def _cut_kappa(vertices) -> float:
    """The cut prism's κ from its first kernel vertex (−(1 − κ), −1, −1): the shortest decimal that gives it."""
    kept = -float(vertices[0, 0])
    for digits in range(1, 18):
        kappa = float(f"{1.0 - kept:.{digits}g}")
        if 1.0 - kappa == kept:
            return kappa
    return 1.0 - kept


def shape_records(arrays: ShapeArrays, names) -> dict:
    """The registry's records of the shapes in ``arrays``, by name (``names`` in the arrays' order).

    A built-in name gives the family's record (:func:`direct_model.registry.built_in_shape`, κ from the cut
    prism's vertices); another name a user's grain, checked as :func:`direct_model.registry.polyhedron` checks
    it. The families' factors s stay in ``arrays.second_moments``: :func:`shape_arrays` of these records with
    them gives ``arrays`` back, bit for bit.
    """
    names = list(names)
    if len(names) != arrays.n_shapes:
        raise ValueError(f"shape arrays: {arrays.n_shapes} shapes need as many names; got {len(names)}")
    records = {}
    for i, name in enumerate(names):
        rows = arrays.vertices[arrays.vertex_start[i]:arrays.vertex_start[i + 1]]
        law = None if np.isnan(arrays.aspect[i, 0]) else AspectRatioLaw(*map(float, arrays.aspect[i]))
        if arrays.kind[i] == KIND_ELLIPSOID:
            records[name] = Ellipsoid(name, tuple(map(float, rows[0])), aspect=law)
        elif name in SHAPES:
            kappa = _cut_kappa(rows) if name == "cut_prism" else DEFAULT_KAPPA
            records[name] = built_in_shape(name, kappa, aspect=law)
        else:
            tri = arrays.triangles[arrays.triangle_start[i]:arrays.triangle_start[i + 1]]
            records[name] = polyhedron(name, rows, tri, aspect=law, both_hands=bool(arrays.both_hands[i]))
    return records


@numba.njit(**KERNEL)
def particle_body(shapes, shape, ratio_ba, ratio_cb, hand, verts, K, semi, scale):
    """One particle's body from shape ``shape`` of ``shapes`` (:class:`ShapeArrays`, module doc); returns nv.

    ``ratio_ba``, ``ratio_cb``: the particle's b/a and c/b (ignored for a shape of fixed proportions);
    ``hand`` ±1 (−1: the mirror image ζ → −ζ; an ellipsoid is its own). Writes the factors that take the unit
    body to the particle's into ``scale`` (its vertex i is unit[i] · scale), the body frame's vertices into
    ``verts[:nv]`` if it has room for them (nv = 0 for an ellipsoid; a walked hull needs none), the principal J/m
    into ``K`` (a²) and the half-extents along ξ, η, ζ into ``semi`` (an ellipsoid's semi-axes), all in units of
    the particle's a (the largest is 1).
    """
    lo, nv = shapes.vertex_start[shape], shapes.vertex_start[shape + 1] - shapes.vertex_start[shape]
    unit = shapes.vertices
    if math.isnan(shapes.aspect[shape, 0]):
        ratio_ba, ratio_cb = 1.0, 1.0
    d0, d1, d2 = 1.0, ratio_ba, ratio_ba * ratio_cb
    if shapes.kind[shape] == KIND_ELLIPSOID:
        nv = 0
    e0, e1, e2 = shapes.half_extents[shape, 0], shapes.half_extents[shape, 1], shapes.half_extents[shape, 2]
    e0, e1, e2 = d0 * e0, d1 * e1, d2 * e2
    a = max(e0, max(e1, e2))
    semi[0], semi[1], semi[2] = e0 / a, e1 / a, e2 / a
    f0, f1, f2 = d0 / a, d1 / a, d2 / a
    if hand < 0.0:
        f2 = -f2
    scale[0], scale[1], scale[2] = f0, f1, f2
    if nv <= verts.shape[0]:
        for i in range(nv):
            verts[i, 0], verts[i, 1], verts[i, 2] = unit[lo + i, 0] * f0, unit[lo + i, 1] * f1, unit[lo + i, 2] * f2
    s0, s1, s2 = shapes.second_moments[shape, 0], shapes.second_moments[shape, 1], shapes.second_moments[shape, 2]
    a2, b2, c2 = f0 * f0, f1 * f1, f2 * f2
    if s0 == s1 and s1 == s2:           # a family's: J/m = s (b² + c², a² + c², a² + b²)
        K[0], K[1], K[2] = s0 * (b2 + c2), s0 * (a2 + c2), s0 * (a2 + b2)
    else:
        m0, m1, m2 = s0 * a2, s1 * b2, s2 * c2
        K[0], K[1], K[2] = m1 + m2, m0 + m2, m0 + m1
    return nv


@numba.njit(**KERNEL)
def _half_extents(unit, lo, nv):
    """(max − min)/2 of rows lo to lo + nv of ``unit`` along each axis."""
    lo0, lo1, lo2 = unit[lo, 0], unit[lo, 1], unit[lo, 2]
    hi0, hi1, hi2 = lo0, lo1, lo2
    for i in range(lo + 1, lo + nv):
        lo0, hi0 = min(lo0, unit[i, 0]), max(hi0, unit[i, 0])
        lo1, hi1 = min(lo1, unit[i, 1]), max(hi1, unit[i, 1])
        lo2, hi2 = min(lo2, unit[i, 2]), max(hi2, unit[i, 2])
    return 0.5 * (hi0 - lo0), 0.5 * (hi1 - lo1), 0.5 * (hi2 - lo2)


@numba.njit(**KERNEL)
def bounding_radius(kind, semi, verts, nv, hull):
    """Radius of the smallest centroid-centred sphere holding the body (units of a): the largest semi-axis of
    an ellipsoid, the farthest vertex of a polyhedron (of ``verts[:nv]``, or of a walked ``hull``'s candidates,
    :func:`particle_hull`)."""
    if kind == KIND_ELLIPSOID:
        return max(semi[0], max(semi[1], semi[2]))
    if hull[2].shape[0] > 0:
        return np.sqrt(walk_farthest(hull[0], hull[1], hull[5]))
    r2 = 0.0
    for i in range(nv):
        r2 = max(r2, verts[i, 0] ** 2 + verts[i, 1] ** 2 + verts[i, 2] ** 2)
    return np.sqrt(r2)


def scanned_hull(verts) -> tuple:
    """The ``hull`` argument of the kernels for a body given by its vertices alone (``verts``, scanned)."""
    return (np.asarray(verts, dtype=np.float64), np.ones(3), np.zeros(0, dtype=np.int64), np.zeros(0, np.int32),
            np.zeros(MAP_SIZE, np.int32), np.zeros(0, np.int32))


@numba.njit(inline="always", **KERNEL)
def particle_hull(shapes, shape, scale):
    """(unit, scale, graph_start, graph, starts, far): shape ``shape``'s unit vertices, its vertex graph (no rows
    for a hull scanned from ``verts``, of at most :data:`direct_model.hull_walk.WALK_ABOVE` vertices), start map
    and farthest candidates with the particle's ``scale`` (:func:`particle_body`), what the contact search takes
    (:func:`direct_model.flight.find_contact`). From Python call ``particle_hull.py_func``: compiled without
    numba's reference counts, the kernel hands Python each slice's whole parent array."""
    lo, hi = shapes.vertex_start[shape], shapes.vertex_start[shape + 1]
    last = hi + 1 if hi - lo > WALK_ABOVE else lo
    return (shapes.vertices[lo:hi], scale, shapes.graph_start[lo:last], shapes.graph, shapes.starts[shape],
            shapes.far[shapes.far_start[shape]:shapes.far_start[shape + 1]])
