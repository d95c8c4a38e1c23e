"""Tables of the user's grains (issue 34, docs/model.md §9): a configuration's [shapes.NAME] sections build, the
table stores every grain's record and a configuration that rebuilds it from itself, a moved, turned and rescaled
copy of a mesh gives the same table, and the command lines take the grains (bad input: one line, exit 2, nothing
written)."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import surrogate
from data_schema.table import read_table, table_fingerprint
from direct_model import registry
from surrogate.cli import main as surrogate_main
from tablegen.cli import main as tablegen_main
from tablegen.tabulation.config import load_config, parse_config
from tablegen.tabulation.driver import build_table
from tests.helpers.cli import run_cli, user_error
from tests.helpers.grains import LOWERED_HULL_LIMIT
from tests.helpers.tables import GRAIN_MESH, GRAIN_TABLE_CONFIG, write_grain_config


def _same(a, b):
    return a.shape == b.shape and a.tobytes() == b.tobytes()


def test_two_grains_build_and_the_table_holds_what_rebuilds_it(grain_table_path):
    config = load_config(grain_table_path.parent / "grains.toml")
    table = read_table(grain_table_path)
    assert table.shapes == ("sand_a", "sand_b")
    assert np.all(table.cells["status_counts"].sum(axis=-1) == 3000)
    for record, grain in zip(table.shape_records(), config.grains):
        assert record.name == grain.name and record.both_hands == grain.both_hands and record.aspect == grain.aspect
        for key in ("vertices", "triangles", "inertia"):
            assert _same(getattr(record, key), getattr(grain, key)), (grain.name, key)
    assert len(config.grain("sand_a").vertices) == 17 and config.grain("sand_b").both_hands
    # the stored configuration holds the canonical hulls, not the mesh's path: parsed anywhere, it is the same
    # configuration, with the same records bit for bit
    stored = parse_config(table.config_text, "stored", base_dir="/nonexistent")
    assert stored == config and stored.sha256() == table.config_sha256 == config.sha256()
    assert "mesh" not in table.config_text
    for a, b in zip(stored.grains, config.grains):
        assert _same(a.vertices, b.vertices) and _same(a.triangles, b.triangles) and _same(a.inertia, b.inertia)
    loaded = surrogate.load(grain_table_path)
    assert loaded.shapes == table.shapes and loaded.model_shapes.tolist() == [4, 5]


def _obj(path, vertices, triangles):
    """An OBJ file of the mesh, coordinates as exact float reprs."""
    lines = [f"v {float(x)!r} {float(y)!r} {float(z)!r}" for x, y, z in vertices]
    lines += [f"f {i + 1} {j + 1} {k + 1}" for i, j, k in triangles]
    path.write_text("\n".join(lines) + "\n")


def test_a_moved_turned_rescaled_copy_of_the_mesh_gives_the_same_table(tmp_path):
    """The canonical frame undoes the motion to round-off and settling the vertices on a 2^-36 grid removes it
    (grain_files.settled), so the copy's table has the same fingerprint (config text, /shapes, cells)."""
    import trimesh
    mesh = trimesh.load(GRAIN_MESH, process=False)
    moved = (np.asarray(mesh.vertices) @ Rotation.random(random_state=34).as_matrix().T) * 3.7 + [12.5, -0.3, 4.0]
    text = ('[grid]\nalpha1_deg = [45.0]\nspeed_m_s = [150.0]\nshapes = ["sand"]\n[simulation]\n'
            'particles_per_cell = 1000\n[shapes.sand]\nmesh = "{}"\n')
    fingerprints = []
    for name, vertices in (("original.obj", mesh.vertices), ("copy.obj", moved)):
        _obj(tmp_path / name, vertices, mesh.faces)
        out = build_table(parse_config(text.format(name), base_dir=tmp_path), tmp_path / f"{name}.h5", workers=1)
        fingerprints.append(table_fingerprint(out))
    assert fingerprints[0] == fingerprints[1]


def test_the_cli_builds_a_grain_table_and_lists_its_shapes(grain_table_path, capsys):
    code, err, out = run_cli(tablegen_main, ["info", str(grain_table_path)], capsys)
    assert code == 0, err
    assert "  sand_a           user grain, convex polyhedron, 17 vertices; fixed proportions" in out
    assert "  sand_b           user grain, convex polyhedron" in out and "N(0.8, 0.1) in [0.5, 1]; both hands" in out


def test_report_of_a_grain_table(grain_table_path, tmp_path, capsys):
    code, err, out = run_cli(tablegen_main, ["report", "--table", str(grain_table_path), "-o", str(tmp_path / "r"),
                                             "-n", "300", "--seed", "1", "--no-progress"], capsys)
    assert code == 0, err
    index = (tmp_path / "r" / "index.md").read_text()
    assert "sand_a, sand_b, mix" in index and "### sand_b" in index
    user_error(tablegen_main, ["report", "--direct", "--shapes", "sand_a", "-o", str(tmp_path / "d")], capsys,
               "--shapes with --direct", "'sand_a'")
    assert not (tmp_path / "d").exists()


@pytest.mark.parametrize("method", ["table", "direct"])
def test_surrogate_samples_a_grain_by_name(grain_table_path, tmp_path, capsys, method):
    out = tmp_path / "s.h5"
    code, err, text = run_cli(surrogate_main, ["sample", "--table", str(grain_table_path), "--alpha1", "45",
                                               "--speed", "150", "--shape", "sand_b", "-n", "500", "--seed", "2",
                                               "--method", method, "--out", str(out)], capsys)
    assert code == 0 and out.exists(), err


def test_tablegen_simulate_takes_a_grain_of_a_config(tmp_path, capsys):
    config = write_grain_config(tmp_path)
    code, err, out = run_cli(tablegen_main, ["simulate", "--shape", "sand_b", "--config", str(config), "--alpha1",
                                             "45", "--speed", "150", "-n", "300", "--seed", "3", "--no-progress"],
                             capsys)
    assert code == 0 and "sand_b" in out, err
    argv = ["--alpha1", "45", "--speed", "150", "-n", "10", "--out", str(tmp_path / "x.h5")]
    user_error(tablegen_main, ["simulate", "--shape", "sand_b"] + argv, capsys, "--shape", "'sand_b'", "--config")
    user_error(tablegen_main, ["simulate", "--shape", "sand_c", "--config", str(config)] + argv, capsys,
               "'sand_c'", "its grains: sand_a, sand_b")
    assert not (tmp_path / "x.h5").exists()




def _hostile(folder):
    """(configuration text, words of its one-line error): a missing mesh, a degenerate (flat) hull, a name of a
    built-in, too many hull vertices, a grid name without a section, a section not in the grid."""
    (folder / "flat.off").write_text("OFF\n4 1 0\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n3 0 1 2\n")
    import trimesh
    sphere = np.random.default_rng(0).normal(size=(LOWERED_HULL_LIMIT + 1, 3))
    trimesh.convex.convex_hull(sphere / np.linalg.norm(sphere, axis=1)[:, None]).export(folder / "big.ply")
    grid = '[grid]\nshapes = ["prism", "sand"]\n'
    return [
        (grid + '[shapes.sand]\nmesh = "missing.stl"\n', ["shapes.sand", "missing.stl", "cannot read"]),
        (grid + '[shapes.sand]\nmesh = "flat.off"\n', ["flat.off", "one plane"]),
        ('[grid]\nshapes = ["prism"]\n[shapes.prism]\nmesh = "flat.off"\n', ["shapes.prism", "built-in"]),
        (grid + '[shapes.sand]\nmesh = "big.ply"\n', ["big.ply", f"at most {LOWERED_HULL_LIMIT}"]),
        (grid, ["grid.shapes", "'sand'", "no section"]),
        (grid + '[shapes.sand]\nmesh = "flat.off"\n[shapes.dust]\nmesh = "flat.off"\n',
         ["[shapes.dust]", "not named in 'grid.shapes'"]),
    ]


def test_bad_grains_are_one_line_exit_2_and_nothing_written(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(registry, "MAX_HULL_VERTICES", LOWERED_HULL_LIMIT)     # small hulls (the real limit: registry's)
    for k, (text, words) in enumerate(_hostile(tmp_path)):
        config = tmp_path / f"c{k}.toml"
        config.write_text(text)
        out = tmp_path / f"t{k}.h5"
        user_error(tablegen_main, ["build", "--config", str(config), "-o", str(out)], capsys, *words)
        assert not out.exists() and not (tmp_path / f"t{k}.h5.partial").exists()
        user_error(tablegen_main, ["simulate", "--shape", "sand", "--config", str(config), "--alpha1", "45",
                                   "--speed", "150", "-n", "10"], capsys, *words)
