"""The ``[shapes.NAME]`` sections of a build configuration: a user's grains (docs/model.md §9).

::

    [shapes.sand_a]
    mesh = "grains/sand_a.stl"        # relative to the configuration file; STL, OBJ, OFF or PLY
    [shapes.sand_b]
    vertices = [[0.0, 0.0, 0.0], [1.0, 0.1, 0.0], ...]     # points whose convex hull is the grain
    aspect_ratio = {mean = 0.8, sd = 0.2, low = 0.5, high = 1.0}   # optional: b/a, c/b drawn per particle
    both_hands = true                  # optional: half of the particles are the mirror image (default false)
    max_vertices = 256                 # optional: a hull of more vertices is simplified (tablegen build says how)
    [shapes.sand_c]
    vertices = [[...], ...]            # with triangles: the grain's canonical hull, taken as it is
    triangles = [[0, 1, 2], ...]

Exactly one of ``mesh`` and ``vertices``. ``triangles`` (indices into ``vertices``, counter-clockwise from
outside) says that the vertices are already the canonical hull (body frame, units of a): what a table's stored
configuration holds (:meth:`tablegen.tabulation.config.BuildConfig.to_toml`), so that it rebuilds the record
bit for bit; they must then be a convex hull in a principal frame of unit size, or ConfigError.

Without ``aspect_ratio`` the grain keeps the proportions of its file; with it, each particle's grain is stretched
along η and ζ by the drawn b/a and (b/a)(c/b) (:meth:`direct_model.registry.ConvexPolyhedron.stretched`), as
the families are.

:func:`parse_shape_sections` turns the parsed TOML table ``shapes`` into records;
:func:`tablegen.tabulation.config.parse_config` calls it for the sections of a build configuration.
"""

from __future__ import annotations

import math
from pathlib import Path

from data_schema.shape_records import MIN_HULL_VERTICES
from direct_model.registry import MAX_HULL_VERTICES, ShapeError, check_name
from direct_model.shapes import AspectRatioLaw
from tablegen.tabulation.config_error import ConfigError
from tablegen.tabulation.grain_files import GrainError, canonical_grain, grain_from_mesh, grain_from_points

SHAPE_KEYS = ("mesh", "vertices", "triangles", "aspect_ratio", "both_hands", "max_vertices")
ASPECT_KEYS = ("mean", "sd", "low", "high")


def parse_shape_sections(shapes, base_dir, source: str, log=None, used=None) -> dict:
    """Records of the user's grains, by name, from the TOML table ``shapes`` (module doc).

    ``base_dir``: the folder the configuration file is in (relative mesh paths start there); ``source``: the
    configuration's name in messages; ``log``: called with a warning line (a mesh that is not convex); ``used``:
    if given, the shape names of ``grid.shapes``, each section's name must be one of them (checked before any
    mesh is read). ConfigError naming the key for anything wrong.
    """
    if not isinstance(shapes, dict):
        raise ConfigError(f"{source}: 'shapes' must be a table of [shapes.NAME] sections; got {shapes!r}")
    records = {}
    for name, spec in shapes.items():
        key = f"shapes.{name}"
        try:
            check_name(name)
        except ShapeError as exc:
            raise ConfigError(f"{source}: '[{key}]': {exc}") from None
        if used is not None and name not in used:
            raise ConfigError(f"{source}: '[{key}]' is not named in 'grid.shapes' ({', '.join(used)}); add "
                              f"{name!r} there or remove the section")
    for name, spec in shapes.items():
        key = f"shapes.{name}"
        if not isinstance(spec, dict):
            raise ConfigError(f"{source}: '{key}' must be a table ([{key}]) with mesh or vertices; got {spec!r}")
        unknown = sorted(set(spec) - set(SHAPE_KEYS))
        if unknown:
            raise ConfigError(f"{source}: unknown key '{key}.{unknown[0]}'; allowed: {', '.join(SHAPE_KEYS)}")
        if ("mesh" in spec) == ("vertices" in spec):
            raise ConfigError(f"{source}: '[{key}]' needs exactly one of mesh (a file) and vertices (a list of "
                              f"points); got {'both' if 'mesh' in spec else 'neither'}")
        if "triangles" in spec and "vertices" not in spec:
            raise ConfigError(f"{source}: '{key}.triangles' goes with vertices (the canonical hull), not with mesh")
        aspect = _aspect(spec.get("aspect_ratio"), f"{key}.aspect_ratio", source)
        both_hands = spec.get("both_hands", False)
        if not isinstance(both_hands, bool):
            raise ConfigError(f"{source}: '{key}.both_hands' must be true or false; got {both_hands!r}")
        max_vertices = spec.get("max_vertices")
        if max_vertices is not None and (isinstance(max_vertices, bool) or not isinstance(max_vertices, int)
                                         or not MIN_HULL_VERTICES <= max_vertices <= MAX_HULL_VERTICES):
            raise ConfigError(f"{source}: '{key}.max_vertices' must be an integer in [{MIN_HULL_VERTICES}, "
                              f"{MAX_HULL_VERTICES}]; got {max_vertices!r}")
        if max_vertices is not None and "triangles" in spec:
            raise ConfigError(f"{source}: '{key}.max_vertices' goes with mesh or vertices (points), not with a "
                              f"canonical hull (triangles), which is taken as it is")
        try:
            if "mesh" in spec:
                mesh = spec["mesh"]
                if not isinstance(mesh, str) or not mesh.strip():
                    raise ConfigError(f"{source}: '{key}.mesh' must be a file name; got {mesh!r}")
                records[name] = grain_from_mesh(name, Path(base_dir) / mesh, aspect, both_hands, log, max_vertices)
            elif "triangles" in spec:
                points = _points(spec["vertices"], f"{key}.vertices", source)
                triangles = _triangles(spec["triangles"], len(points), f"{key}.triangles", source)
                records[name] = canonical_grain(name, points, triangles, f"{source}: '[{key}]'", aspect, both_hands)
            else:
                points = _points(spec["vertices"], f"{key}.vertices", source)
                records[name] = grain_from_points(name, points, f"{source}: '{key}.vertices'", aspect, both_hands,
                                                  log=log, max_vertices=max_vertices)
        except GrainError as exc:
            raise ConfigError(f"{source}: '{key}': {exc}" if "mesh" in spec else str(exc)) from None
    return records


def _points(value, key, source):
    """A list of [x, y, z] numbers (NaN and inf are left to the hull's check, which names the point)."""
    ok = isinstance(value, list) and all(
        isinstance(p, list) and len(p) == 3 and all(isinstance(x, (int, float)) and not isinstance(x, bool)
                                                    for x in p) for p in value)
    if not ok:
        raise ConfigError(f"{source}: '{key}' must be a list of [x, y, z] numbers; got {value!r:.200}")
    return [[float(x) for x in p] for p in value]


def _triangles(value, n_points, key, source):
    """A list of [i, j, k] indices into the n_points vertices."""
    ok = isinstance(value, list) and value and all(
        isinstance(t, list) and len(t) == 3 and all(isinstance(i, int) and not isinstance(i, bool) and 0 <= i < n_points
                                                    for i in t) for t in value)
    if not ok:
        raise ConfigError(f"{source}: '{key}' must be a list of [i, j, k] vertex indices in 0..{n_points - 1}; "
                          f"got {value!r:.200}")
    return value


def _aspect(value, key, source):
    """The optional b/a, c/b law: None, or a table of mean, sd, low, high (missing keys: the families' law)."""
    if value is None:
        return None
    if not isinstance(value, dict) or set(value) - set(ASPECT_KEYS):
        raise ConfigError(f"{source}: '{key}' must be a table with keys {', '.join(ASPECT_KEYS)}; got {value!r}")
    if any(isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) for v in value.values()):
        raise ConfigError(f"{source}: '{key}' values must be finite numbers; got {value!r}")
    try:
        return AspectRatioLaw(**{k: float(v) for k, v in value.items()})
    except ValueError as exc:
        raise ConfigError(f"{source}: '{key}': {exc}") from None
