"""A user's grain from a mesh file or a config's points (docs/model.md §9): formats, the hull, hostile input."""

import tomllib

import numpy as np
import pytest
import trimesh
from scipy.spatial.transform import Rotation

from direct_model import registry, shapes
from direct_model.registry import MAX_HULL_VERTICES
from tablegen.tabulation.config import ConfigError, parse_config
from tablegen.tabulation.grain_files import GrainError, grain_from_mesh, grain_from_points
from tablegen.tabulation.shape_config import parse_shape_sections
from tests.helpers.grains import LOWERED_HULL_LIMIT

ROTATION = Rotation.random(random_state=3).as_matrix()


def _irregular_mesh(seed=0, n=40):
    """The hull of a random cloud: a closed convex mesh, its coordinates multiples of 1/16 so that every format
    stores them exactly (binary STL holds float32, trimesh writes OBJ with 8 digits)."""
    points = np.random.default_rng(seed).normal(size=(n, 3)) @ ROTATION.T * (1.0, 0.7, 0.5)
    return trimesh.convex.convex_hull(np.round(16.0 * points) / 16.0 + 3.0)


def _config(text, folder, log=None):
    return parse_shape_sections(tomllib.loads(text)["shapes"], folder, "grains.toml", log)


@pytest.mark.parametrize("suffix", [".stl", ".obj", ".off", ".ply"])
def test_every_mesh_format_gives_the_same_grain(tmp_path, suffix):
    mesh = _irregular_mesh()
    path = tmp_path / f"sand{suffix}"
    mesh.export(path)
    grain = grain_from_mesh("sand", path)
    reference = grain_from_points("sand", mesh.vertices, "points")
    np.testing.assert_allclose(grain.vertices, reference.vertices, rtol=0, atol=1e-12)
    np.testing.assert_allclose(grain.inertia, reference.inertia, rtol=1e-12)


def test_a_non_convex_mesh_warns_once_with_the_added_volume(tmp_path):
    """An L-shaped prism (volume 1.75): its hull fills half the missing corner, 0.125, so 7.14% of its volume."""
    path = tmp_path / "notched.off"
    trimesh.Trimesh(*_l_prism(), process=False).export(path)
    lines = []
    grain = grain_from_mesh("notched", path, log=lines.append)
    assert len(lines) == 1
    assert str(path) in lines[0] and "not convex" in lines[0] and "adds 7.14% to its volume" in lines[0], lines[0]
    assert grain.volume > 0
    lines.clear()
    convex = tmp_path / "convex.off"
    _irregular_mesh().export(convex)
    grain_from_mesh("convex", convex, log=lines.append)
    assert lines == []


def _l_prism():
    """Vertices and outward triangles of an L-shaped prism: a 2 × 1 rectangle less a 0.5 × 0.5 corner, z in [0, 1]."""
    outline = [(-1.0, -0.5), (1.0, -0.5), (1.0, 0.0), (0.5, 0.0), (0.5, 0.5), (-1.0, 0.5)]   # counter-clockwise
    n = len(outline)
    vertices = [(x, y, 0.0) for x, y in outline] + [(x, y, 1.0) for x, y in outline]
    caps = [(0, 5, 1), (1, 5, 2), (2, 5, 3), (3, 5, 4)]          # the L as four triangles, seen from below
    triangles = [t for t in caps] + [(n + a, n + c, n + b) for a, b, c in caps]
    for i in range(n):
        j = (i + 1) % n
        triangles += [(i, j, n + j), (i, n + j, n + i)]
    return np.array(vertices), np.array(triangles)


def test_config_reads_meshes_relative_to_it_and_vertex_lists(tmp_path):
    (tmp_path / "grains").mkdir()
    _irregular_mesh(1).export(tmp_path / "grains" / "sand_a.stl")
    box = shapes.shape_vertices("prism", 1.0, 0.8, 0.6).tolist()
    records = _config(f"""
[shapes.sand_a]
mesh = "grains/sand_a.stl"
[shapes.sand_b]
vertices = {box}
aspect_ratio = {{mean = 0.7, sd = 0.1}}
both_hands = true
""", tmp_path)
    assert list(records) == ["sand_a", "sand_b"]
    assert records["sand_a"].aspect is None and not records["sand_a"].both_hands
    assert records["sand_b"].aspect == shapes.AspectRatioLaw(mean=0.7, sd=0.1)
    assert records["sand_b"].both_hands
    # settled vertices are within SETTLE/2 = 7.3e-12 of the box's: each half-extent (0.8, 0.6 at least) within
    # 1.3e-11 relative, the volume within their sum, < 1e-10
    assert records["sand_b"].volume == pytest.approx(8 * 0.8 * 0.6, rel=1e-10)




def _hostile_files(folder):
    """(config text, words of its one-line error), with the files it names written into ``folder``."""
    (folder / "empty.stl").write_bytes(b"")
    (folder / "garbage.obj").write_text("this is no mesh\n")
    (folder / "truncated.ply").write_bytes(b"ply\nformat binary_little_endian 1.0\nelement vertex 100\n"
                                           b"property float x\nend_header\n\x01\x02")
    (folder / "nan.off").write_text("OFF\n4 1 0\n0 0 0\n1 0 0\n0 1 0\nnan 0 1\n3 0 1 2\n")
    (folder / "flat.off").write_text("OFF\n4 1 0\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n3 0 1 2\n")
    (folder / "grain.xyz").write_text("0 0 0\n")
    (folder / "a_folder.stl").mkdir()
    sphere = np.random.default_rng(0).normal(size=(LOWERED_HULL_LIMIT + 1, 3))
    trimesh.convex.convex_hull(sphere / np.linalg.norm(sphere, axis=1)[:, None]).export(folder / "big.ply")
    thin = shapes.shape_vertices("prism", 1.0, 0.5, 1e-4).tolist()
    return [
        ('mesh = "missing.stl"', ["missing.stl", "cannot read"]),
        ('mesh = "empty.stl"', ["empty.stl", "empty"]),
        ('mesh = "garbage.obj"', ["garbage.obj", "no vertices"]),
        ('mesh = "truncated.ply"', ["truncated.ply", "cannot read the mesh"]),
        ('mesh = "a_folder.stl"', ["a_folder.stl", "folder"]),
        ('mesh = "grain.xyz"', ["grain.xyz", "unknown mesh format", ".stl, .obj, .off, .ply"]),
        ('mesh = "nan.off"', ["nan.off", "finite"]),
        ('mesh = "flat.off"', ["flat.off", "one plane"]),
        ('mesh = "big.ply"', ["big.ply", f"{LOWERED_HULL_LIMIT + 1} vertices", f"at most {LOWERED_HULL_LIMIT}"]),
        ("vertices = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]", ["shapes.sand.vertices", "3 distinct points", "at least 4"]),
        ("vertices = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 0]]", ["shapes.sand.vertices", "3 distinct points"]),
        ("vertices = [[0, 0, 0], [1, 0, 0], [2, 0, 0], [3, 0, 0]]", ["shapes.sand.vertices", "one plane"]),
        ("vertices = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, inf]]", ["shapes.sand.vertices", "point 3", "finite"]),
        ("vertices = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, nan]]", ["shapes.sand.vertices", "finite"]),
        (f"vertices = {thin}", ["shapes.sand.vertices", "flat", "0.0001 of its largest", ">= 0.001"]),
        ("vertices = [[0, 0], [1, 0]]", ["shapes.sand.vertices", "[x, y, z]"]),
        ("vertices = [[0, 0, true], [1, 0, 0], [0, 1, 0], [0, 0, 1]]", ["shapes.sand.vertices", "[x, y, z]"]),
        ('vertices = "cube"', ["shapes.sand.vertices", "[x, y, z]"]),
        ('mesh = "flat.off"\nvertices = [[0, 0, 0]]', ["shapes.sand", "exactly one of mesh", "both"]),
        ("both_hands = true", ["shapes.sand", "exactly one of mesh", "neither"]),
        ("mesh = 3", ["shapes.sand.mesh", "file name"]),
        ('mesh = "x.stl"\ncolour = "red"', ["shapes.sand.colour", "allowed: mesh, vertices"]),
        ('mesh = "x.stl"\nboth_hands = 1', ["shapes.sand.both_hands", "true or false"]),
        ('mesh = "x.stl"\naspect_ratio = {mean = 0.8, width = 1}', ["shapes.sand.aspect_ratio", "mean, sd, low, high"]),
        ('mesh = "x.stl"\naspect_ratio = {low = 0.9, high = 0.5}', ["shapes.sand.aspect_ratio", "low < high"]),
        ('mesh = "x.stl"\naspect_ratio = {sd = nan}', ["shapes.sand.aspect_ratio", "finite"]),
        ('mesh = "x.stl"\nmax_vertices = 3', ["shapes.sand.max_vertices", f"[4, {MAX_HULL_VERTICES}]", "got 3"]),
        ('mesh = "x.stl"\nmax_vertices = 8.5', ["shapes.sand.max_vertices", "an integer"]),
        ("vertices = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]]\ntriangles = [[0, 1, 2]]\nmax_vertices = 8",
         ["shapes.sand.max_vertices", "not with a canonical hull"]),
    ]


def test_hostile_grains_give_one_line_naming_the_file_or_key(tmp_path, monkeypatch):
    monkeypatch.setattr(registry, "MAX_HULL_VERTICES", LOWERED_HULL_LIMIT)     # small hulls (the real limit: registry's)
    for body, words in _hostile_files(tmp_path):
        with pytest.raises(ConfigError) as error:
            _config(f"[shapes.sand]\n{body}\n", tmp_path)
        message = str(error.value)
        assert "\n" not in message and message.startswith("grains.toml: "), message
        for word in words:
            assert word in message, (body, message)


@pytest.mark.parametrize("name", ["prism", "ellipsoid", "mix", "9lives", "sand-a"])
def test_names_clashing_with_built_ins_or_malformed_are_refused(tmp_path, name):
    with pytest.raises(ConfigError, match=f"shapes.{name}"):
        _config(f'[shapes."{name}"]\nvertices = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]]\n', tmp_path)


def test_the_shapes_table_must_hold_sections(tmp_path):
    with pytest.raises(ConfigError, match="'shapes.sand' must be a table"):
        _config('[shapes]\nsand = "grains/sand.stl"\n', tmp_path)


def test_grain_error_names_the_points_source():
    with pytest.raises(GrainError, match="^my points: point 1 is"):
        grain_from_points("sand", [[0, 0, 0], [np.inf, 0, 0], [0, 1, 0], [0, 0, 1]], "my points")


def _bulging_octahedron(height=1e-3, per_face=30, seed=1):
    """The octahedron of corners (±1, 0, 0), (0, ±1, 0), (0, 0, ±1) with points on its faces pushed out by
    ``height`` along the faces' normals: a hull of many vertices whose simplification to 6 is the octahedron."""
    corners = np.vstack([np.eye(3), -np.eye(3)])
    rng = np.random.default_rng(seed)
    points = [corners]
    for signs in np.array(np.meshgrid([1, -1], [1, -1], [1, -1])).reshape(3, -1).T:
        face = rng.dirichlet([2.0, 2.0, 2.0], per_face) @ np.diag(signs.astype(float))
        points.append(face + height * signs / np.sqrt(3.0))
    return np.vstack(points)


def test_a_simplified_hull_is_reported_against_the_one_it_replaces():
    """max_vertices = 6 on an octahedron whose faces bulge by 10⁻³: the simplified hull is the octahedron (each
    vertex within 3·10⁻³ of a corner: quadric decimation places a kept vertex off the corner by up to twice the
    bulge), and the report says so: 66 to 6 vertices, the volume lost between 0 and
    the bulges' at most (area 4√3 times 10⁻³ over the volume 4/3: 0.52 %), the largest distance between the
    hulls between half and twice the bulge (a is 1 here, to 3 %)."""
    import re

    from tablegen.tabulation.grain_files import convex_hull, simplification_report, simplified_hull

    vertices, triangles, _ = convex_hull(_bulging_octahedron(), "octahedron")
    simple, simple_triangles = simplified_hull(vertices, triangles, 6, "octahedron")
    corners = np.vstack([np.eye(3), -np.eye(3)])
    assert len(simple) == 6
    assert np.abs(np.sort(simple, axis=0) - np.sort(corners, axis=0)).max() < 3e-3
    line = simplification_report(vertices, triangles, simple, simple_triangles)
    assert line.startswith(f"simplified from {len(vertices)} to 6 hull vertices: volume -")
    volume = float(re.search(r"volume ([-+.\d]+)%", line).group(1))
    distance = float(re.search(r"original hull ([\d.e-]+) a", line).group(1))
    assert -0.52 < volume < 0.0 and 0.5e-3 < distance < 2e-3, line


def test_a_config_s_max_vertices_simplifies_the_grain_and_says_so():
    """The build's configuration reader: a grain of more hull vertices than max_vertices gets at most that many
    and one line on what changed; its stored text is the simplified hull, which reads back as it is."""
    points = _bulging_octahedron(per_face=60).tolist()
    lines = []
    config = parse_config(f'[grid]\nshapes = ["oct"]\n[shapes.oct]\nvertices = {points}\nmax_vertices = 10\n',
                          "case.toml", log=lines.append)
    assert len(config.grains[0].vertices) <= 10
    assert len(lines) == 1 and lines[0].startswith("case.toml: 'shapes.oct.vertices': simplified from ")
    assert parse_config(config.to_toml()).grains[0].vertices.tolist() == config.grains[0].vertices.tolist()
