"""A table holding user grains (format 3.4) in the Python runtime: the table path draws them by name, so does the
direct model (sample_direct, method "direct", and "auto" for spinning hits), and `tablegen info` lists every
shape with its kind and vertex count."""

from __future__ import annotations

import numpy as np
import pytest

import surrogate
from tests.helpers.python_side import many_shape_table

V = [[100.0, -120.0, 5.0]] * 200
NORMAL = [0.0, 1.0, 0.0]
A = 1e-4


@pytest.fixture(scope="module")
def grains_path(small_table_path, tmp_path_factory):
    path = tmp_path_factory.mktemp("grains") / "grains.h5"
    many_shape_table(small_table_path, path, 6)
    return path


def test_the_table_path_draws_a_user_grain_by_name(grains_path):
    table = surrogate.load(grains_path)
    assert table.shapes[4:] == ("grain_00", "grain_01") and table.model_shapes.tolist() == [0, 1, 2, 3, 4, 5]
    for shape in ("grain_01", {"grain_00": 0.5, "prism": 0.5}):
        hits = surrogate.sample_global(table, V, NORMAL, A, shape=shape, random_state=1, method="table")
        V_out, status = hits.V, hits.status
        rebounded = status == surrogate.STATUS_REBOUNDED
        assert np.all(rebounded | (status == surrogate.STATUS_TRAPPED)) and rebounded.sum() > 150
        assert np.all(V_out[rebounded, 1] > 0.0)


def test_the_direct_model_answers_a_user_grain(grains_path):
    """200 hits of grain_00 at α1 = 50°, 156 m/s: at Ω⁻ = 0 each rebound leaves the wall no faster than it came
    (the wall law dissipates; docs/model.md §4.4); spinning, under "auto", every hit goes to the direct model and
    none is invalid."""
    table = surrogate.load(grains_path)
    hits = surrogate.sample_direct(table, V, NORMAL, A, shape="grain_00", random_state=1)
    V_out, status = hits.V, hits.status
    rebounded = status == surrogate.STATUS_REBOUNDED
    assert rebounded.sum() > 150 and np.all(V_out[rebounded, 1] > 0.0)
    assert np.all(np.linalg.norm(V_out[rebounded], axis=1) <= np.linalg.norm(V[0]) * (1 + 1e-12))
    spin = [0.0, 0.0, 0.3 * np.linalg.norm(V[0]) / A]
    hits = surrogate.sample_global(table, V, NORMAL, A, shape="grain_00", random_state=1, omega=spin)
    status, path = hits.status, hits.path
    assert np.all(status != surrogate.STATUS_INVALID) and np.all(path == 1)


def test_info_lists_every_shape(grains_path, capsys):
    from tablegen.cli import main
    table = surrogate.load(grains_path)
    assert main(["info", str(grains_path)]) == 0
    out = capsys.readouterr().out
    assert "shapes: 6 (cut_prism kappa = 0.3)" in out
    assert "  prism            built-in, convex polyhedron, 8 vertices; b/a, c/b ~ N(0.8, 0.2) in [0.5, 1]" in out
    count = len(table.records[4].vertices)
    assert (f"  grain_00         user grain, convex polyhedron, {count} vertices; b/a, c/b ~ N(0.85, 0.1) in "
            f"[0.6, 1]; both hands") in out
    assert "  grain_01         user grain, convex polyhedron" in out and "fixed proportions" in out
