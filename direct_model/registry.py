"""Shapes as data (docs/model.md §3 and §9): the record of a shape, and the registry of the built-in families.

A shape is a named record, one of two kinds:

* :class:`Ellipsoid` — a smooth body, its semi-axes;
* :class:`ConvexPolyhedron` — the hull's vertices in the body's principal frame, its triangles and vertex graph,
  and its mass properties.

Both are in the body frame Oξηζ (centre of mass at the origin, principal axes of inertia along ξ, η, ζ) and in
units of a, the largest half-extent along a principal axis: the a that a solver passes at run time means the same
for every shape. A record may carry a law that scales it at random per particle (``aspect``, the b/a, c/b law of
§3): a particle's body is :meth:`stretched` by the law's draws. ``both_hands`` draws the mirror image (ζ → −ζ)
for half of the particles (the family tetrahedron; a user's grain only when asked).

The built-in families are the entries of :data:`FAMILIES`, made into records by :func:`built_in_shape`; the
stretched bodies of the paper's four are those of :mod:`direct_model.shapes` (the tests check their mass properties
against it). Plain numpy: the runtime may build and read records.
"""

from __future__ import annotations

import dataclasses
import math
import re
from typing import Callable

import numpy as np

from direct_model.polyhedron import canonical_frame, mass_properties, vertex_graph
from direct_model.shapes import DEFAULT_KAPPA, MIX, SHAPES, AspectRatioLaw, check_kappa, shape_vertices

# A hull of more than direct_model.hull_walk.WALK_ABOVE vertices is walked over its vertex graph, with no work space
# per vertex; 2^16 vertices hold a micro-CT scan's hull several times over (docs/design/grains.md).
MAX_HULL_VERTICES = 65536
MIN_THICKNESS = 1e-3        # thinnest half-extent, in units of a: the flight bound grows as (a / thickness)²
NAME_PATTERN = re.compile(r"[A-Za-z][A-Za-z0-9_]{0,63}")   # also an HDF5 dataset name and a C identifier's tail
FRAME_CHECK = 1e-9       # a given frame must be principal and centred to this (units of a and a²)


class ShapeError(ValueError):
    """A shape definition the model cannot take; the message says what is wrong."""


def check_name(name) -> str:
    """A user shape's name: 1–64 letters, digits or underscores, a letter first, not a built-in's nor 'mix'."""
    if not isinstance(name, str) or not NAME_PATTERN.fullmatch(name):
        raise ShapeError(f"a shape name must be 1-64 letters, digits or underscores, starting with a letter; "
                         f"got {name!r}")
    if name in FAMILIES or name == MIX:
        raise ShapeError(f"the shape name {name!r} is a built-in's; built-in names: {', '.join(FAMILIES)}, {MIX}")
    return name


def _check_hull_size(n_vertices):
    if n_vertices > MAX_HULL_VERTICES:
        raise ShapeError(f"the hull has {n_vertices} vertices; allowed: at most {MAX_HULL_VERTICES}; simplify the "
                         f"mesh ([shapes.NAME] max_vertices)")


def _stretch_factors(ratio_ba, ratio_cb):
    return np.array([1.0, ratio_ba, ratio_ba * ratio_cb])


@dataclasses.dataclass(frozen=True, eq=False)
class Ellipsoid:
    """A smooth body: the ellipsoid of semi-axes ``semi_axes`` (units of a, the largest is 1)."""

    name: str
    semi_axes: tuple = (1.0, 1.0, 1.0)
    aspect: AspectRatioLaw | None = None
    both_hands = False                       # achiral

    @property
    def volume(self) -> float:
        """Volume, a³."""
        return 4.0 / 3.0 * math.pi * math.prod(self.semi_axes)

    @property
    def inertia(self) -> np.ndarray:
        """Principal J/m along ξ, η, ζ, a²: ((b² + c²), (a² + c²), (a² + b²)) / 5."""
        s2 = np.square(self.semi_axes)
        return np.array([s2[1] + s2[2], s2[0] + s2[2], s2[0] + s2[1]]) / 5.0

    def stretched(self, ratio_ba: float, ratio_cb: float, hand: int = 1) -> Ellipsoid:
        """One particle's body: semi-axes × (1, b/a, b/a · c/b), rescaled so that the largest is 1; no law."""
        semi = np.array(self.semi_axes) * _stretch_factors(ratio_ba, ratio_cb)
        return Ellipsoid(self.name, tuple(float(s) for s in semi / semi.max()))


@dataclasses.dataclass(frozen=True, eq=False)
class ConvexPolyhedron:
    """A convex polyhedron in its principal frame, units of a (build with :func:`polyhedron` or :func:`grain`).

    ``vertices`` (n, 3) the hull's vertices; ``triangles`` (m, 3) int32, counter-clockwise from outside;
    ``volume`` a³; ``inertia`` (3,) principal J/m along ξ, η, ζ, a²; ``neighbour_start`` (n + 1,) and
    ``neighbours`` the vertex graph (:func:`direct_model.polyhedron.vertex_graph`), the support query's input;
    ``parameters`` what defines a family's body besides b/a and c/b (the cut prism's κ).
    """

    name: str
    vertices: np.ndarray
    triangles: np.ndarray
    volume: float
    inertia: np.ndarray
    neighbour_start: np.ndarray
    neighbours: np.ndarray
    aspect: AspectRatioLaw | None = None
    both_hands: bool = False
    parameters: dict = dataclasses.field(default_factory=dict)

    def stretched(self, ratio_ba: float, ratio_cb: float, hand: int = 1) -> ConvexPolyhedron:
        """One particle's body: ξ, η, ζ × (1, b/a, b/a · c/b), rescaled to a = 1, mirrored (ζ → −ζ) if hand = −1.

        A stretch along the principal axes keeps them principal (∫ξη dm scales, so stays 0), so the mass
        properties follow in closed form: ∫ξᵢ² dm/m × dᵢ², volume × d₁d₂d₃ (dᵢ the factors over the new a).
        """
        d = _stretch_factors(ratio_ba, ratio_cb)
        body = self.vertices * d
        a = float(((body.max(axis=0) - body.min(axis=0)) / 2.0).max())
        d = d / a
        triangles = self.triangles
        if hand == -1:
            d[2] = -d[2]
            triangles = triangles[:, ::-1].copy()         # a mirror turns counter-clockwise into clockwise
        second = (self.inertia.sum() / 2.0 - self.inertia) * d * d      # ∫ξᵢ² dm / m of the new body
        return ConvexPolyhedron(self.name, self.vertices * d, triangles, self.volume * abs(float(np.prod(d))),
                                second.sum() - second, self.neighbour_start, self.neighbours,
                                parameters=self.parameters)


def polyhedron(name, vertices, triangles, aspect=None, both_hands=False, parameters=None) -> ConvexPolyhedron:
    """A record from a hull already in its principal frame and units of a (ShapeError if it is not).

    ``vertices`` (n, 3) and ``triangles`` (m, 3) counter-clockwise from outside; the mass properties are
    computed from them (divergence theorem).
    """
    vertices = np.array(vertices, dtype=float)
    triangles = np.array(triangles, dtype=np.int32)
    _check_hull_size(len(vertices))
    props = mass_properties(vertices, triangles)
    half = (vertices.max(axis=0) - vertices.min(axis=0)) / 2.0
    off = props.inertia - np.diag(np.diag(props.inertia))
    if (abs(half.max() - 1.0) > FRAME_CHECK or np.abs(props.centroid).max() > FRAME_CHECK
            or np.abs(off).max() > FRAME_CHECK):
        raise ShapeError("the vertices are not in a principal frame of unit size (centre of mass "
                         f"{props.centroid.tolist()}, products of inertia up to {np.abs(off).max():.3g}, largest "
                         f"half-extent {half.max():.17g}); build the record with grain()")
    if half.min() < MIN_THICKNESS:
        raise ShapeError(f"the hull is flat: its thinnest half-extent is {half.min():.3g} of its largest; allowed: "
                         f">= {MIN_THICKNESS:g}")
    start, neighbours = vertex_graph(triangles, len(vertices))
    return ConvexPolyhedron(name, vertices, triangles, props.volume, np.diag(props.inertia).copy(), start, neighbours,
                            aspect=aspect, both_hands=bool(both_hands), parameters=dict(parameters or {}))


def grain(name, vertices, triangles, aspect=None, both_hands=False) -> ConvexPolyhedron:
    """A user's grain from its convex hull in any position, orientation and size (the canonical frame, §9).

    ``vertices`` (n, 3): the hull's vertices, each used by a triangle; ``triangles`` (m, 3): its surface,
    counter-clockwise from outside. ShapeError for a name that is not allowed, a hull with no volume, too many
    vertices or too flat.
    """
    check_name(name)
    _check_hull_size(len(vertices))              # before the O(n²) work of the canonical frame
    try:
        frame = canonical_frame(vertices, triangles)
    except ValueError as exc:
        raise ShapeError(f"degenerate hull: {exc}") from None
    return polyhedron(name, frame.vertices, frame.triangles, aspect, both_hands)


def _faces_to_triangles(vertices, normals):
    """Triangles of the convex polyhedron whose faces have these outward normals (a fan per face, outward)."""
    triangles = []
    for normal in normals:
        height = vertices @ normal
        face = np.flatnonzero(height >= height.max() - 1e-12)
        if len(face) < 3:                         # a face that has shrunk to a point or an edge (κ = 0)
            continue
        centre = vertices[face].mean(axis=0)
        u = vertices[face[0]] - centre
        w = np.cross(normal, u)
        face = face[np.argsort(np.arctan2((vertices[face] - centre) @ w, (vertices[face] - centre) @ u))]
        triangles.extend((face[0], face[k], face[k + 1]) for k in range(1, len(face) - 1))
    return np.array(triangles, dtype=np.int32)


_AXES = np.vstack([np.eye(3), -np.eye(3)])
_CORNERS = np.array([[x, y, z] for x in (-1.0, 1.0) for y in (-1.0, 1.0) for z in (-1.0, 1.0)])


def _prism_body(kappa):
    return shape_vertices("prism"), _AXES


def _cut_prism_body(kappa):
    return shape_vertices("cut_prism", kappa=kappa), np.vstack([_AXES, _CORNERS])


def _tetrahedron_body(kappa):
    vertices = shape_vertices("tetrahedron")
    return vertices, -np.unique(vertices, axis=0)      # each face faces away from the opposite vertex


@dataclasses.dataclass(frozen=True)
class Family:
    """A built-in family (docs/model.md §3): how :func:`built_in_shape` makes its record.

    ``body(kappa)`` gives the body at b/a = c/b = 1 in units of a, in its principal frame: its vertices (n, 3;
    repeats allowed) and the outward normals of its faces (f, 3, any length); None for the ellipsoid, the one
    smooth family (a table stores no semi-axes for another). docs/design/grains.md, "A new built-in family".
    ``both_hands``: half of the particles are the mirror image; ``uses_kappa``: κ shapes the body (the record
    keeps it in ``parameters``).
    """

    body: Callable | None
    both_hands: bool = False
    uses_kappa: bool = False


# The built-in families by name: a new family is an entry here (its record is then stored in every table that
# holds it, which is where the runtimes read it). The first four are the paper's, with the codes 0-3 of
# direct_model.shapes.SHAPES that old tables, "mix" and the C and Fortran enums know them by.
FAMILIES = {
    "ellipsoid": Family(None),
    "prism": Family(_prism_body),
    "cut_prism": Family(_cut_prism_body, uses_kappa=True),
    "tetrahedron": Family(_tetrahedron_body, both_hands=True),
}


def built_in_shape(name: str, kappa: float = DEFAULT_KAPPA, aspect: AspectRatioLaw | None = AspectRatioLaw()):
    """The record of the family ``name`` of :data:`FAMILIES` at b/a = c/b = 1, with its aspect-ratio law.

    Stretching it by (b/a, c/b) (:meth:`ConvexPolyhedron.stretched`) gives the particle's body; for the paper's
    four, the body of :func:`direct_model.shapes.shape_vertices` at a = 1 and those ratios. ValueError for an
    unknown name or κ.
    """
    family = FAMILIES.get(name)
    if family is None:
        raise ValueError(f"The 'shape' parameter must be one of {', '.join(FAMILIES)}; got {name!r}.")
    if family.body is None:
        return Ellipsoid(name, aspect=aspect)
    kappa = check_kappa(kappa)
    vertices, normals = family.body(kappa)
    vertices = np.unique(np.asarray(vertices, dtype=float), axis=0)      # κ = 0 repeats the cut prism's corners
    return polyhedron(name, vertices, _faces_to_triangles(vertices, np.asarray(normals, dtype=float)), aspect=aspect,
                      both_hands=family.both_hands, parameters={"kappa": kappa} if family.uses_kappa else {})


def built_in_shapes(kappa: float = DEFAULT_KAPPA, aspect: AspectRatioLaw | None = AspectRatioLaw()) -> dict:
    """The paper's four families as records, by name, in the order of :data:`direct_model.shapes.SHAPES`."""
    return {name: built_in_shape(name, kappa, aspect) for name in SHAPES}
