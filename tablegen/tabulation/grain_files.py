"""A user's grain from a mesh file or a list of points (docs/model.md §9): read, hull, canonical record.

The body is the convex hull of the points (scipy's Qhull); a mesh that is not convex is replaced by its hull,
with one line through ``log`` saying how much volume the hull adds. The hull is then placed in its canonical
frame (:func:`direct_model.registry.grain`) and settled (:func:`settled`): its vertices rounded to multiples of
:data:`SETTLE`, vertices and triangles put in an order of their own, so that a moved, turned or rescaled copy of
a file, whose canonical vertices agree to round-off only, gives the same bits, hence the same table. Meshes are
read with trimesh (the ``build`` extra): STL, OBJ, OFF and PLY, and a file of points alone (OBJ or PLY vertices
without faces).

Every problem is one :class:`GrainError` whose message starts with the file (or the config key) and says what
is wrong: a folder, a missing, empty or unreadable file, NaN or inf, fewer than 4 points off a common plane, a
flat hull, a hull larger than the runtime takes.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from direct_model.polyhedron import SORT_DIRECTION
from direct_model.registry import ShapeError, grain, polyhedron

MESH_SUFFIXES = (".stl", ".obj", ".off", ".ply")
NOT_CONVEX = 1e-6           # the hull adds more than this fraction of the mesh's volume: the mesh is not convex
COPLANAR = 1e-9             # points whose spread off their best plane is below this of their size are coplanar
# the grid (units of a) canonical vertices are rounded to: a power of two (the rounding is exact arithmetic), far
# above the round-off by which two copies' canonical vertices differ (about 1e-15 for moments 1e-4 apart,
# direct_model.polyhedron) and far below the frame's tolerance (registry.FRAME_CHECK, 1e-9) and any mesh's
# precision. Two copies differ only if a coordinate lies within that round-off of a rounding boundary (a chance
# of about 1e-4 per coordinate); a settled record settles to itself exactly.
SETTLE = 2.0 ** -36
# a larger hull's vertices go in Morton order: neighbours in space near in index, so that a walk over its vertex
# graph (direct_model.hull_walk) reads nearby memory; a smaller hull keeps the order its tables were built in
SPATIAL_ORDER_ABOVE = 256
MORTON_BITS = 21            # per axis: 63 bits in all


class GrainError(ValueError):
    """A grain that cannot be read or used; the message starts with its source."""


def read_mesh(path):
    """The points (n, 3) of a mesh file and the volume it encloses (None if its faces close no surface)."""
    import trimesh                                  # here: the build extra, only when a mesh is read

    path = Path(path)
    if path.is_dir():
        raise GrainError(f"{path}: is a folder; expected a mesh file ({', '.join(MESH_SUFFIXES)})")
    if path.suffix.lower() not in MESH_SUFFIXES:
        raise GrainError(f"{path}: unknown mesh format {path.suffix!r}; allowed: {', '.join(MESH_SUFFIXES)}")
    try:
        size = path.stat().st_size
    except OSError as exc:
        raise GrainError(f"{path}: cannot read the mesh: {exc.strerror}") from None
    if size == 0:
        raise GrainError(f"{path}: the file is empty")
    try:
        loaded = trimesh.load(path, process=False)     # as written: processing would drop NaN vertices silently
        if isinstance(loaded, trimesh.Scene):           # an OBJ or PLY of several objects: one grain of all
            loaded = trimesh.load(path, force="mesh", process=False)
    except Exception as exc:                       # a parser of many formats: any failure means unreadable
        raise GrainError(f"{path}: cannot read the mesh: {(str(exc) or type(exc).__name__).splitlines()[0]}") from None
    points = np.asarray(getattr(loaded, "vertices", np.empty((0, 3))), dtype=float).reshape(-1, 3)
    if len(points) == 0:
        raise GrainError(f"{path}: no vertices in the file (not a {path.suffix[1:].upper()} mesh, or an empty one)")
    if not (isinstance(loaded, trimesh.Trimesh) and len(loaded.faces) > 0 and np.isfinite(points).all()):
        return points, None
    surface = trimesh.Trimesh(points, loaded.faces)     # merges the corners that STL repeats per triangle
    return points, abs(float(surface.volume)) if surface.is_watertight else None


def convex_hull(points, source):
    """Vertices (k, 3) and triangles (m, 3), counter-clockwise from outside, of the points' convex hull."""
    from scipy.spatial import ConvexHull, QhullError     # here: the build extra

    points = np.asarray(points, dtype=float)
    if points.ndim != 2 or points.shape[1] != 3:
        raise GrainError(f"{source}: points must be a list of [x, y, z]; got an array of shape {points.shape}")
    bad = np.flatnonzero(~np.isfinite(points).all(axis=1))
    if len(bad):
        raise GrainError(f"{source}: point {bad[0]} is {points[bad[0]].tolist()}; coordinates must be finite "
                         f"(no NaN or inf)")
    points = np.unique(points, axis=0)
    if len(points) < 4:
        raise GrainError(f"{source}: {len(points)} distinct points; a grain needs at least 4 not in one plane")
    spread = np.linalg.svd(points - points.mean(axis=0), compute_uv=False)
    if spread[2] <= COPLANAR * spread[0]:
        raise GrainError(f"{source}: all {len(points)} points lie in one plane (or on one line); a grain needs "
                         f"at least 4 not in one plane")
    try:
        hull = ConvexHull(points)
    except QhullError as exc:
        raise GrainError(f"{source}: degenerate hull: {str(exc).splitlines()[0]}") from None
    triangles = hull.simplices.copy()
    p = points[triangles]
    normal = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    inward = (normal * hull.equations[:, :3]).sum(axis=1) < 0.0        # Qhull's own outward normals
    triangles[inward] = triangles[inward][:, ::-1]
    used = np.unique(triangles)
    index = np.full(len(points), -1)
    index[used] = np.arange(len(used))
    return points[used], index[triangles], float(hull.volume)


def grain_from_points(name, points, source, aspect=None, both_hands=False, mesh_volume=None, log=None,
                      max_vertices=None):
    """The record of the grain whose body is the hull of ``points`` (any frame and length unit).

    ``mesh_volume``: the volume the mesh encloses, if it closes one; when the hull adds more than
    :data:`NOT_CONVEX` of it, ``log`` (if given) gets one line saying how much. ``max_vertices``: a hull of more
    vertices is simplified to at most that many (:func:`simplified_hull`) and ``log`` gets what that changed
    (:func:`simplification_report`).
    """
    vertices, triangles, volume = convex_hull(points, source)
    if mesh_volume is not None and log is not None and volume > mesh_volume * (1.0 + NOT_CONVEX):
        log(f"{source}: warning: the mesh is not convex; its convex hull, the body used, adds "
            f"{100.0 * (volume / mesh_volume - 1.0):.3g}% to its volume")
    if max_vertices is not None and len(vertices) > max_vertices:
        simple = simplified_hull(vertices, triangles, max_vertices, source)
        if log is not None:
            log(f"{source}: " + simplification_report(vertices, triangles, *simple))
        vertices, triangles = simple
    try:
        return settled(grain(name, vertices, triangles, aspect=aspect, both_hands=both_hands))
    except ShapeError as exc:
        raise GrainError(f"{source}: {exc}") from None


def simplified_hull(vertices, triangles, max_vertices: int, source) -> tuple:
    """(vertices, triangles): the convex hull of the hull's surface decimated by quadric error (the
    fast-simplification library, what trimesh and PyVista use) to at most ``max_vertices`` vertices; the target
    triangle count is lowered until the hull of what is left has no more vertices than that."""
    from fast_simplification import simplify     # here: the build extra

    target = 2 * max_vertices - 4                 # the triangles of a closed hull of max_vertices vertices
    while True:
        points, _ = simplify(np.asarray(vertices, dtype=np.float64), np.asarray(triangles, dtype=np.int32),
                             target_count=target)
        hull, hull_triangles, _ = convex_hull(points, source)
        if len(hull) <= max_vertices or target <= 4:
            return hull, hull_triangles
        target = max(4, int(target * max_vertices / len(hull)) - 2)


def simplification_report(vertices, triangles, simple_vertices, simple_triangles) -> str:
    """One line on what a simplification changed: the vertex count, the volume, the principal moments of inertia
    and a (in the original's units), and the largest distance between the two hulls' surfaces relative to the
    original's a (each hull's vertices against the other's face planes)."""
    from scipy.spatial import ConvexHull     # here: the build extra
    from direct_model.polyhedron import canonical_frame, mass_properties, symmetric_eigen

    def described(points, tris):
        props = mass_properties(points, tris)
        return props.volume, np.sort(symmetric_eigen(props.inertia)[0]), canonical_frame(points, tris).a

    (volume, moments, a), (volume_s, moments_s, a_s) = described(vertices, triangles), described(
        simple_vertices, simple_triangles)

    def farthest_from(points, hull_points):
        planes = ConvexHull(hull_points).equations          # unit outward normals and offsets
        signed = points @ planes[:, :3].T + planes[:, 3]    # > 0 outside a face's plane
        return float(np.abs(signed.max(axis=1)).max())

    distance = max(farthest_from(simple_vertices, vertices), farthest_from(vertices, simple_vertices))
    change = ", ".join(f"{100.0 * (x / y - 1.0):+.2f}%" for x, y in zip(moments_s, moments))
    return (f"simplified from {len(vertices)} to {len(simple_vertices)} hull vertices: volume "
            f"{100.0 * (volume_s / volume - 1.0):+.2f}%, principal moments {change}, "
            f"a {100.0 * (a_s / a - 1.0):+.2f}%, largest distance from the original hull {distance / a:.3g} a")


def canonical_grain(name, vertices, triangles, source, aspect=None, both_hands=False):
    """The record of a hull given in its canonical frame (a table's stored configuration, :func:`settled` vertices
    and triangles), taken as it is: GrainError unless it is in a principal frame of unit size
    (:func:`direct_model.registry.polyhedron`) and convex (every vertex on the hull of the vertices, the
    triangles enclosing the hull's volume)."""
    vertices = np.asarray(vertices, dtype=float)
    hull, _, volume = convex_hull(vertices, source)
    try:
        record = polyhedron(name, vertices, triangles, aspect, both_hands)
    except (ShapeError, ValueError) as exc:
        raise GrainError(f"{source}: {exc}") from None
    if len(hull) != len(vertices) or abs(record.volume - volume) > COPLANAR * volume:
        raise GrainError(f"{source}: the triangles are not the convex hull of the vertices (volume "
                         f"{record.volume:.17g} against the hull's {volume:.17g}, {len(vertices) - len(hull)} vertices "
                         f"inside it); give the hull, or the points alone (vertices without triangles)")
    return record


def settled(record):
    """The canonical record with its vertices rounded to multiples of :data:`SETTLE` and put in ascending order of
    (their height along SORT_DIRECTION, as canonical_frame orders them, then ξ, η, ζ), a hull of more than
    :data:`SPATIAL_ORDER_ABOVE` vertices first by their :func:`morton_codes`; its triangles each turned
    to start at its smallest index (a cyclic turn keeps it counter-clockwise) and in ascending order; mass
    properties recomputed from these (module doc)."""
    vertices = np.round(record.vertices / SETTLE) * SETTLE
    along = sum(vertices[:, i] * SORT_DIRECTION[i] for i in range(3))         # elementwise: no BLAS
    keys = (vertices[:, 2], vertices[:, 1], vertices[:, 0], along)
    if len(vertices) > SPATIAL_ORDER_ABOVE:
        keys += (morton_codes(vertices),)
    order = np.lexsort(keys)
    rank = np.empty(len(order), dtype=np.int32)
    rank[order] = np.arange(len(order), dtype=np.int32)
    triangles = rank[record.triangles]
    first = np.argmin(triangles, axis=1)
    triangles = np.take_along_axis(triangles, (first[:, None] + np.arange(3)) % 3, axis=1)
    triangles = triangles[np.lexsort(triangles.T[::-1])]
    return polyhedron(record.name, vertices[order], triangles, record.aspect, record.both_hands)


def morton_codes(vertices) -> np.ndarray:
    """Each vertex's Morton code (uint64): its coordinates scaled to integers in [0, 2^21) over the hull's box,
    their bits interleaved (ξ lowest). Elementwise float operations and integer ones: the same on any CPU."""
    low, high = vertices.min(axis=0), vertices.max(axis=0)
    top = float(2 ** MORTON_BITS - 1)
    cells = np.floor((vertices - low) / np.where(high > low, high - low, 1.0) * top).astype(np.uint64)
    codes = np.zeros(len(vertices), dtype=np.uint64)
    for bit in range(MORTON_BITS):
        for axis in range(3):
            codes |= ((cells[:, axis] >> np.uint64(bit)) & np.uint64(1)) << np.uint64(3 * bit + axis)
    return codes


def grain_from_mesh(name, path, aspect=None, both_hands=False, log=None, max_vertices=None):
    """The record of the grain in a mesh file (STL, OBJ, OFF, PLY): the hull of its vertices (module doc),
    simplified to at most ``max_vertices`` (:func:`grain_from_points`)."""
    points, mesh_volume = read_mesh(path)
    return grain_from_points(name, points, str(path), aspect, both_hands, mesh_volume, log, max_vertices)
