"""examples/grains: the script writes the shipped grains again, and every one is a valid grain of its config."""

import tomllib
from pathlib import Path

import numpy as np
import pytest

from tablegen.tabulation.shape_config import parse_shape_sections
from tests.helpers.examples import example_module

FOLDER = Path(__file__).resolve().parents[1] / "examples" / "grains"


@pytest.fixture(scope="module")
def make_grains():
    return example_module(FOLDER / "make_grains.py")


def _vertex_lines(path):
    return sorted(line for line in path.read_text().splitlines() if line.startswith("v "))


def test_the_script_writes_the_shipped_grains_again(make_grains, tmp_path):
    """Same seed, same points (the hull's triangle order is Qhull's, so the faces are compared as a count)."""
    written = make_grains.write_grains(tmp_path)
    assert [p.name for p in written] == sorted(p.name for p in FOLDER.glob("grain_*.obj"))
    for path in written:
        shipped = FOLDER / path.name
        assert _vertex_lines(path) == _vertex_lines(shipped)
        count = lambda p: sum(line.startswith("f ") for line in p.read_text().splitlines())   # noqa: E731
        assert count(path) == count(shipped) == 2 * len(_vertex_lines(path)) - 4               # a closed hull


def test_every_grain_of_the_config_is_irregular_and_convex(make_grains):
    config = tomllib.loads((FOLDER / "grains.toml").read_text())
    warnings = []
    records = parse_shape_sections(config["shapes"], FOLDER, "grains.toml", log=warnings.append)
    assert warnings == []                                          # hulls already: nothing added
    assert list(records) == [s for s in config["grid"]["shapes"] if s.startswith("grain_")]
    for record in records.values():
        assert len(record.vertices) == len(_vertex_lines(FOLDER / f"{record.name}.obj"))
        assert np.all(np.diff(record.inertia) > 1e-3 * record.inertia[0])     # no two moments alike: no symmetry
        half = (record.vertices.max(axis=0) - record.vertices.min(axis=0)) / 2
        assert half.max() == pytest.approx(1.0, rel=1e-15) and half.min() > 0.3


def test_the_law_figure_draws_every_shape(tmp_path, capsys):
    """plot_law.py with 300 particles a shape: a PNG, and a line for each family and each grain of the config."""
    pytest.importorskip("matplotlib")
    module = example_module(FOLDER / "plot_law.py")
    out = tmp_path / "law.png"
    assert module.main(["--n", "300", "--out", str(out)]) == 0
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    names = [line.split()[0] for line in capsys.readouterr().out.splitlines()[:-1]]
    shapes = tomllib.loads((FOLDER / "grains.toml").read_text())["grid"]["shapes"]
    assert names == ["ellipsoid", "prism", "cut_prism", "tetrahedron"] + [s for s in shapes if s.startswith("grain_")]
