"""The shapes a table holds, as data (group ``/shapes``; docs/format.md, "Shapes").

One row per shape of ``grid/shapes``, in its order; the records are those of :mod:`direct_model.registry`
(the built-in families, :data:`direct_model.registry.FAMILIES`, and the user's own grains,
:func:`direct_model.registry.grain`). Everything is in the body frame Oξηζ (centre of mass at the origin,
principal axes along ξ, η, ζ) and in units of a, the largest half-extent along a principal axis, at
b/a = c/b = 1 (the body before a particle's random stretch by the ``aspect`` law).

This module is the only place that writes or reads these arrays (the C twin: native/src/shape_records.c). Every
dataset carries the Fletcher-32 checksum, so a flipped bit fails to load naming the dataset; ``name`` is the
checksummed copy of ``grid/shapes``, and the record of one of the paper's four families (whose bodies the runtimes
also make from code, :data:`direct_model.shapes.SHAPES`) must be the family's at the table's κ and aspect-ratio law
(the fields of the table's ``model/parameters``). Any other shape, a later family's as a user grain's, is read
from its stored record alone. :func:`family_records` makes the families' records from κ and the law (a table in
memory that was given no records).
"""

from __future__ import annotations

import math

import h5py
import numpy as np

from direct_model.registry import (MAX_HULL_VERTICES, MIN_THICKNESS, NAME_PATTERN, FRAME_CHECK, ConvexPolyhedron,
                                   Ellipsoid, ShapeError, built_in_shape, polyhedron)
from direct_model.shapes import MIX, SHAPES, AspectRatioLaw

SHAPES_GROUP = "shapes"
KIND_SMOOTH, KIND_POLYHEDRON = 0, 1            # the ellipsoid; a convex polyhedron
NAME_SIZE = 64                                 # bytes of a stored name: NAME_PATTERN's longest
MIN_HULL_VERTICES = 4                          # a tetrahedron
# |coordinate| of a vertex, units of a: the centre of mass of a convex body lies at least 1/(d + 1) of its width
# from each supporting plane (Minkowski–Radon), so with half-extents <= 1 every coordinate is within 2 · 3/4
VERTEX_BOUND = 1.5 * (1.0 + FRAME_CHECK)
# principal J/m, units of a²: each second moment ∫ξ² dm/m is at most VERTEX_BOUND², J is a sum of two
INERTIA_BOUND = 2.0 * VERTEX_BOUND ** 2
# the most shapes a table may hold: far more than any build makes (each is a direct-model run per grid cell);
# it keeps every count of the C loader within an int
MAX_TABLE_SHAPES = 4096
# grid/shape_codes of a shape that is not a built-in family
USER_SHAPE_CODE = 255

# name: (dtype, units, meaning) of the datasets of group /shapes, in the order both loaders read and check them
SHAPE_DATASETS = {
    "name": (f"S{NAME_SIZE}", "1", "the shape's name, the checksummed copy of grid/shapes"),
    "kind": ("int8", "1", "0: a smooth body (the ellipsoid); 1: a convex polyhedron"),
    "vertex_start": ("int64", "1", "shape i's vertices are rows vertex_start[i] to vertex_start[i+1] - 1 of "
                                   "vertices (n_shape + 1 values)"),
    "vertices": ("float64", "a", "hull vertices in the body frame at b/a = c/b = 1, units of a"),
    "triangle_start": ("int64", "1", "shape i's triangles are rows triangle_start[i] to triangle_start[i+1] - 1 of "
                                     "triangles (n_shape + 1 values)"),
    "triangles": ("int32", "1", "the hull's triangles, indices into the shape's own vertices, counter-clockwise "
                                "from outside"),
    "inertia": ("float64", "a^2", "principal J/m along xi, eta, zeta at b/a = c/b = 1"),
    "aspect": ("float64", "1", "the law of b/a and c/b (mean, sd, low, high); a NaN row: fixed proportions"),
    "both_hands": ("uint8", "1", "1: half of the particles are the mirror image (zeta -> -zeta)"),
}


def _aspect_row(law: AspectRatioLaw | None) -> list:
    return [math.nan] * 4 if law is None else [law.mean, law.sd, law.low, law.high]


def shape_datasets(records) -> dict:
    """The datasets of :data:`SHAPE_DATASETS` (numpy arrays of their dtypes) for registry records, table order."""
    n = len(records)
    vertices, triangles = [np.zeros((0, 3))], [np.zeros((0, 3), dtype=np.int32)]
    vertex_start, triangle_start = np.zeros(n + 1, dtype=np.int64), np.zeros(n + 1, dtype=np.int64)
    for i, record in enumerate(records):
        if isinstance(record, ConvexPolyhedron):
            vertices.append(np.asarray(record.vertices, dtype=np.float64))
            triangles.append(np.asarray(record.triangles, dtype=np.int32))
        vertex_start[i + 1] = vertex_start[i] + len(vertices[-1]) * isinstance(record, ConvexPolyhedron)
        triangle_start[i + 1] = triangle_start[i] + len(triangles[-1]) * isinstance(record, ConvexPolyhedron)
    return {
        "name": np.array([r.name.encode() for r in records], dtype=SHAPE_DATASETS["name"][0]),
        "kind": np.array([KIND_POLYHEDRON if isinstance(r, ConvexPolyhedron) else KIND_SMOOTH for r in records],
                         dtype=np.int8),
        "vertex_start": vertex_start,
        "vertices": np.concatenate(vertices).astype(np.float64),
        "triangle_start": triangle_start,
        "triangles": np.concatenate(triangles).astype(np.int32),
        "inertia": np.array([np.asarray(r.inertia, dtype=np.float64) for r in records]).reshape(n, 3),
        "aspect": np.array([_aspect_row(r.aspect) for r in records], dtype=np.float64).reshape(n, 4),
        "both_hands": np.array([bool(r.both_hands) for r in records], dtype=np.uint8),
    }


def write_shape_records(f: h5py.File, records) -> None:
    """Group /shapes of an open table file: :func:`shape_datasets` as Fletcher-32 checksummed datasets."""
    group = f.create_group(SHAPES_GROUP)
    for name, values in shape_datasets(records).items():
        dtype, units, meaning = SHAPE_DATASETS[name]
        # chunked (a filter needs chunks) in one chunk; an empty dataset (no polyhedron) keeps a chunk of one row
        chunks = tuple(max(1, d) for d in values.shape)
        ds = group.create_dataset(name, data=values, dtype=dtype, fletcher32=True, chunks=chunks,
                                  maxshape=(None,) + values.shape[1:])
        ds.attrs["units"] = units
        ds.attrs["meaning"] = meaning


def family_records(names, kappa: float, aspect: tuple) -> tuple:
    """The records of the built-in families ``names`` at the table's κ and aspect-ratio law (mean, sd, low, high):
    what a table in memory without records holds. ValueError if a name is not a family's or the law or κ is not
    valid."""
    law = AspectRatioLaw(*aspect)
    return tuple(built_in_shape(name, kappa, law) for name in names)


def check_shape_datasets(arrays: dict, names, refuse) -> None:
    """``refuse`` (called with the message) unless the /shapes datasets obey the contract (docs/format.md,
    "Shapes"): their shapes, the names (the table's, each a built-in's or a user shape's allowed name), kinds,
    index ranges and vertex counts, bounded vertices (finite, |coordinate| <= VERTEX_BOUND, half-extents within
    FRAME_CHECK of the unit box's, the largest 1, the thinnest >= MIN_THICKNESS), inertia (finite, in
    (0, INERTIA_BOUND], J_i < J_j + J_k), the aspect-ratio law (a NaN row, or finite with sd > 0 and
    0 < low < high <= 1) and both_hands (0 or 1). The C loader checks the same, in the same order."""
    n = len(names)
    if n > MAX_TABLE_SHAPES:
        refuse(f"dataset 'grid/shapes' holds {n} shapes; a table may hold at most {MAX_TABLE_SHAPES}")
    n_vertex, n_triangle = len(arrays["vertices"]), len(arrays["triangles"])
    expected = {"name": (n,), "kind": (n,), "vertex_start": (n + 1,), "vertices": (n_vertex, 3),
                "triangle_start": (n + 1,), "triangles": (n_triangle, 3), "inertia": (n, 3), "aspect": (n, 4),
                "both_hands": (n,)}
    for name, shape in expected.items():
        if np.shape(arrays[name]) != shape:
            refuse(f"dataset 'shapes/{name}' has shape {np.shape(arrays[name])}, expected {shape}")
    stored = [s.decode("utf-8", "replace") if isinstance(s, bytes) else str(s) for s in arrays["name"]]
    for i, (name, copy) in enumerate(zip(names, stored)):
        if copy != name:
            refuse(f"dataset 'grid/shapes' ({name!r} at index {i}) differs from its checksummed copy 'shapes/name' "
                   f"({copy!r})")
        if not (name in SHAPES or (NAME_PATTERN.fullmatch(name) and name != MIX)) or name in names[:i]:
            refuse(f"dataset 'shapes/name' holds {name!r} at index {i}; each name must be a built-in's "
                   f"({', '.join(SHAPES)}) or 1-64 letters, digits or underscores starting with a letter (not "
                   f"'{MIX}'), each once")
    kind, hands = arrays["kind"], arrays["both_hands"]
    bad = np.flatnonzero((kind != KIND_SMOOTH) & (kind != KIND_POLYHEDRON))
    if bad.size:
        refuse(f"dataset 'shapes/kind' holds {int(kind[bad[0]])} at element {bad[0]}; its values must be 0 (smooth) "
               f"or 1 (convex polyhedron)")
    for what, start, total in (("vertex", arrays["vertex_start"], n_vertex),
                               ("triangle", arrays["triangle_start"], n_triangle)):
        counts = np.diff(start)
        if start[0] != 0 or start[-1] != total or np.any(counts < 0):
            refuse(f"dataset 'shapes/{what}_start' must rise from 0 to {total} (the rows of 'shapes/{what}s'); got "
                   f"{start.tolist()}")
    n_vertices, n_triangles = np.diff(arrays["vertex_start"]), np.diff(arrays["triangle_start"])
    for i in range(n):
        polyhedral = kind[i] == KIND_POLYHEDRON
        low, high = (MIN_HULL_VERTICES, MAX_HULL_VERTICES) if polyhedral else (0, 0)
        if not low <= n_vertices[i] <= high:
            refuse(f"dataset 'shapes/vertex_start' gives shape {names[i]!r} {int(n_vertices[i])} vertices; allowed: "
                   + (f"{low} to {high} for a convex polyhedron" if polyhedral else "0 for a smooth body"))
        if n_triangles[i] != (2 * n_vertices[i] - 4 if polyhedral else 0):
            refuse(f"dataset 'shapes/triangle_start' gives shape {names[i]!r} {int(n_triangles[i])} triangles; a hull "
                   f"of {int(n_vertices[i])} vertices has {max(0, 2 * int(n_vertices[i]) - 4)}")
        own = arrays["triangles"][arrays["triangle_start"][i]:arrays["triangle_start"][i + 1]]
        if np.any((own < 0) | (own >= n_vertices[i])):
            refuse(f"dataset 'shapes/triangles' of shape {names[i]!r} holds a vertex index outside 0..{n_vertices[i] - 1}")
        if polyhedral and np.bincount(own.ravel(), minlength=n_vertices[i]).min() == 0:
            # a vertex on no triangle is off the surface the contact search walks over
            first = int(np.argmin(np.bincount(own.ravel(), minlength=n_vertices[i])))
            refuse(f"dataset 'shapes/triangles' of shape {names[i]!r} leaves vertex {first} on no triangle; every "
                   f"vertex of a hull is on its surface")
    vertices = arrays["vertices"]
    bad = np.flatnonzero(~(np.abs(vertices) <= VERTEX_BOUND).ravel())
    if bad.size:
        refuse(f"dataset 'shapes/vertices' holds {vertices.ravel()[bad[0]].item()!r} at element {bad[0]}; its values "
               f"must be finite and in [-{VERTEX_BOUND:.17g}, {VERTEX_BOUND:.17g}] (units of a)")
    for i in np.flatnonzero(kind == KIND_POLYHEDRON):
        own = vertices[arrays["vertex_start"][i]:arrays["vertex_start"][i + 1]]
        half = (own.max(axis=0) - own.min(axis=0)) / 2.0
        if not (abs(half.max() - 1.0) <= FRAME_CHECK and half.min() >= MIN_THICKNESS):
            refuse(f"dataset 'shapes/vertices' gives shape {names[i]!r} half-extents {half.tolist()}; the largest must "
                   f"be 1 within {FRAME_CHECK:g} (units of a) and the thinnest >= {MIN_THICKNESS:g}")
    inertia = arrays["inertia"]
    bad = np.flatnonzero(~((inertia > 0.0) & (inertia <= INERTIA_BOUND)).ravel())
    if bad.size:
        refuse(f"dataset 'shapes/inertia' holds {inertia.ravel()[bad[0]].item()!r} at element {bad[0]}; its values "
               f"must be in (0, {INERTIA_BOUND:.17g}] (units of a^2)")
    bad = np.flatnonzero(np.any(2.0 * inertia >= inertia.sum(axis=1, keepdims=True), axis=1))
    if bad.size:
        refuse(f"dataset 'shapes/inertia' row {bad[0]} {inertia[bad[0]].tolist()} breaks the triangle inequality; "
               f"each principal J/m must be below the sum of the other two")
    aspect = arrays["aspect"]
    for i, (mean, sd, low, high) in enumerate(aspect):
        if np.all(np.isnan(aspect[i])):
            continue
        if not (math.isfinite(mean) and math.isfinite(sd) and sd > 0.0 and 0.0 < low < high <= 1.0):
            refuse(f"dataset 'shapes/aspect' row {i} is {aspect[i].tolist()}; a law (mean, sd, low, high) must be "
                   f"finite with sd > 0 and 0 < low < high <= 1, or all NaN (fixed proportions)")
    bad = np.flatnonzero(hands > 1)
    if bad.size:
        refuse(f"dataset 'shapes/both_hands' holds {int(hands[bad[0]])} at element {bad[0]}; its values must be 0 or 1")


def records_from_arrays(arrays: dict, names, kappa: float, aspect: tuple, refuse) -> tuple:
    """The registry records of checked /shapes datasets (:func:`check_shape_datasets`). A row of the paper's four
    families must be the family's record at κ and the aspect-ratio law ``aspect`` bit for bit; any other
    polyhedron's record (a user grain's, a later family's) is rebuilt from its vertices and triangles
    (:func:`direct_model.registry.polyhedron`), whose mass properties must give the stored inertia bit for bit.
    ``refuse`` names the first row that does not."""
    records = []
    for i, name in enumerate(names):
        if name in SHAPES:
            try:
                record = built_in_shape(name, kappa, AspectRatioLaw(*aspect))
            except ValueError as exc:
                refuse(f"the built-in shape {name!r} cannot be made at the table's kappa {kappa!r} and aspect-ratio "
                       f"law {list(aspect)}: {exc}")
            expected = shape_datasets([record])
            for key in ("kind", "vertices", "triangles", "inertia", "aspect", "both_hands"):
                if not np.array_equal(_row(arrays, key, i).view(np.uint8), expected[key].view(np.uint8)):
                    refuse(f"dataset 'shapes/{key}' of the built-in shape {name!r} differs from the family's record "
                           f"at the table's kappa and aspect-ratio law (dataset 'model/parameters')")
            records.append(record)
            continue
        row = arrays["aspect"][i]
        law = None if np.all(np.isnan(row)) else AspectRatioLaw(*(float(x) for x in row))
        if arrays["kind"][i] == KIND_SMOOTH:
            semi = np.sqrt(2.5 * (arrays["inertia"][i].sum() - 2.0 * arrays["inertia"][i]))
            records.append(Ellipsoid(name, tuple(float(s) for s in semi), law))
            continue
        try:
            record = polyhedron(name, _row(arrays, "vertices", i), _row(arrays, "triangles", i), law,
                                bool(arrays["both_hands"][i]))
        except (ShapeError, ValueError) as exc:
            refuse(f"datasets 'shapes/vertices' and 'shapes/triangles' of shape {name!r} are not a hull in its "
                   f"principal frame: {exc}")
        if not np.array_equal(record.inertia.view(np.uint64), arrays["inertia"][i].view(np.uint64)):
            refuse(f"dataset 'shapes/inertia' of shape {name!r} ({arrays['inertia'][i].tolist()}) differs from the "
                   f"mass properties of its hull, datasets 'shapes/vertices' and 'shapes/triangles' "
                   f"({record.inertia.tolist()})")
        records.append(record)
    return tuple(records)


def _row(arrays: dict, key: str, i: int) -> np.ndarray:
    """Shape i's part of dataset ``key`` (its vertex or triangle rows for those two)."""
    if key in ("vertices", "triangles"):
        start = arrays["vertex_start" if key == "vertices" else "triangle_start"]
        return np.ascontiguousarray(arrays[key][start[i]:start[i + 1]])
    return np.ascontiguousarray(arrays[key][i:i + 1])
