"""A built-in family is an entry of direct_model.registry.FAMILIES and nothing else: the octahedron entered by the
tests (tests/helpers/families.py) is a family by name everywhere a family is (its record, simulate, a
configuration's grid, `tablegen info`), and its table holds its record, which is all the runtime reads of it."""

import numpy as np
import pytest

from data_schema.table import read_table
from direct_model.registry import FAMILIES, ConvexPolyhedron, ShapeError, built_in_shape, check_name
from direct_model.simulate import simulate
from tablegen.tabulation.info import describe_table
from tests.helpers.families import octahedron_entered


@pytest.fixture
def octahedron():
    with octahedron_entered():
        yield


def test_the_entry_gives_a_record_with_the_closed_form_mass_properties(octahedron):
    record = built_in_shape("octahedron")
    assert isinstance(record, ConvexPolyhedron) and len(record.vertices) == 6 and len(record.triangles) == 8
    # |ξ| + |η| + |ζ| ≤ 1: volume 4/3, ∫ξ² dV / V = 1/10, so J/m = 2/10 about each axis
    assert record.volume == pytest.approx(4.0 / 3.0, rel=1e-14)
    assert np.allclose(record.inertia, 0.2, rtol=1e-14, atol=0.0)
    with pytest.raises(ShapeError, match="'octahedron' is a built-in's"):
        check_name("octahedron")


def test_simulate_takes_the_entry_by_name_with_the_families_law(octahedron):
    by_name = simulate("octahedron", 45.0, 150.0, 200, seed=3)
    by_record = simulate(built_in_shape("octahedron"), 45.0, 150.0, 200, seed=3)
    assert by_name.shape == "octahedron" and np.mean(by_name.status == 0) > 0.9
    assert by_name.velocity.tobytes() == by_record.velocity.tobytes()
    assert len(np.unique(by_name.extra["b_over_a"])) > 100          # stretched per particle by the families' law


def test_without_the_entry_the_name_is_unknown():
    assert "octahedron" not in FAMILIES
    with pytest.raises(ValueError, match="must be one of ellipsoid, prism, cut_prism, tetrahedron, 'mix'"):
        simulate("octahedron", 45.0, 150.0, 10, seed=3)


def test_its_table_holds_the_record_the_runtime_reads(octahedron_table_path):
    import surrogate

    table = surrogate.load(octahedron_table_path)           # the entry is gone: the table alone
    assert table.shapes == ("prism", "octahedron") and list(table.model_shapes) == [1, 4]
    with octahedron_entered():
        expected = built_in_shape("octahedron")
    stored = table.records[1]
    assert stored.vertices.tobytes() == expected.vertices.tobytes()
    assert stored.inertia.tobytes() == expected.inertia.tobytes() and stored.aspect == expected.aspect
    draws = surrogate.sample_local(table, np.full(2000, 50.0), 150.0, shape="octahedron", random_state=5)
    assert np.mean(draws.status == 0) > 0.9
    with octahedron_entered():
        text = describe_table(read_table(octahedron_table_path))
    assert "octahedron       built-in, convex polyhedron, 6 vertices" in text
