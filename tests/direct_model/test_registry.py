"""Shape records (docs/model.md §3, §9): the four families as records give the bodies of direct_model.shapes."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from direct_model import registry, shapes
from direct_model.polyhedron import mass_properties
from direct_model.registry import (
    MAX_HULL_VERTICES, MIN_THICKNESS, ConvexPolyhedron, Ellipsoid, ShapeError, built_in_shape, built_in_shapes, grain,
    polyhedron,
)
from tablegen.tabulation.grain_files import convex_hull
from tests.helpers.grains import LOWERED_HULL_LIMIT

RATIOS = [(1.0, 1.0), (0.8, 0.9), (0.5, 0.5), (0.93, 0.61)]       # (b/a, c/b) inside the law's [0.5, 1]
POLYHEDRA = ["prism", "cut_prism", "tetrahedron"]


def _as_set(vertices):
    return np.array(sorted(map(tuple, np.round(vertices, 12))))


def test_the_registry_holds_the_four_families_in_order():
    records = built_in_shapes()
    assert list(records) == list(shapes.SHAPES)
    assert isinstance(records["ellipsoid"], Ellipsoid)
    assert all(isinstance(records[name], ConvexPolyhedron) for name in POLYHEDRA)
    assert [records[name].both_hands for name in shapes.SHAPES] == [False, False, False, True]
    assert records["cut_prism"].parameters == {"kappa": shapes.DEFAULT_KAPPA}
    assert all(r.aspect == shapes.AspectRatioLaw() for r in records.values())
    assert [len(records[name].vertices) for name in POLYHEDRA] == [8, 24, 4]


@pytest.mark.parametrize("hand", [1, -1])
@pytest.mark.parametrize("ratios", RATIOS)
@pytest.mark.parametrize("name", POLYHEDRA)
def test_stretched_family_is_the_body_of_direct_model_shapes(name, ratios, hand):
    """Vertices, volume and J/m of the stretched record = shapes.py's body and mass properties at those ratios."""
    ba, cb = ratios
    body = built_in_shape(name).stretched(ba, cb, hand)
    expected = shapes.shape_vertices(name, 1.0, ba, ba * cb, hand=hand)
    np.testing.assert_array_equal(_as_set(body.vertices), _as_set(expected))
    volume, centroid, inertia = shapes.polyhedron_mass_properties(expected)
    assert body.volume == pytest.approx(volume, rel=1e-13)
    np.testing.assert_allclose(body.inertia, np.diag(inertia), rtol=1e-13)
    s = shapes.second_moment_factor(name)
    a, b, c = 1.0, ba, ba * cb
    np.testing.assert_allclose(body.inertia, s * np.array([b * b + c * c, a * a + c * c, a * a + b * b]), rtol=1e-13)


@pytest.mark.parametrize("hand", [1, -1])
@pytest.mark.parametrize("name", POLYHEDRA)
def test_stretched_mass_properties_match_the_triangles(name, hand):
    """The closed-form stretch of the mass properties = the divergence theorem on the stretched triangles."""
    body = built_in_shape(name).stretched(0.7, 0.8, hand)
    props = mass_properties(body.vertices, body.triangles)      # also: the mirror's triangles still face outward
    assert props.volume == pytest.approx(body.volume, rel=1e-14)
    np.testing.assert_allclose(np.diag(props.inertia), body.inertia, rtol=1e-14)
    np.testing.assert_allclose(props.centroid, 0.0, atol=1e-15)


def test_ellipsoid_record_matches_the_closed_form():
    body = built_in_shape("ellipsoid").stretched(0.8, 0.9)
    a, b, c = 1.0, 0.8, 0.72
    assert body.semi_axes == pytest.approx((a, b, c), rel=1e-15)
    assert body.volume == pytest.approx(4 / 3 * np.pi * a * b * c, rel=1e-15)
    np.testing.assert_allclose(body.inertia, np.array([b * b + c * c, a * a + c * c, a * a + b * b]) / 5, rtol=1e-15)


@pytest.mark.parametrize("kappa", [0.0, 0.05, 0.5, 0.9])
def test_cut_prism_record_at_every_kappa(kappa):
    """κ = 0 is the box (the corners' faces shrink to points); the volume is the cube's less 8 corners of κ³/6."""
    record = built_in_shape("cut_prism", kappa=kappa)
    assert len(record.vertices) == (8 if kappa == 0.0 else 24)
    assert record.volume == pytest.approx(8.0 - 8.0 * kappa ** 3 / 6.0, rel=1e-14)
    assert record.inertia[0] / 2 == pytest.approx(shapes.second_moment_factor("cut_prism", kappa), rel=1e-13)


@pytest.mark.parametrize("ratios", RATIOS[1:])
def test_a_file_of_the_prism_gives_the_built_in_prism(ratios):
    """The prism's vertex set at fixed b/a, c/b, moved and rescaled as a file would be, round-trips to the
    built-in prism's body and mass properties at those ratios."""
    ba, cb = ratios
    points = shapes.shape_vertices("prism", 1.0, ba, ba * cb)
    rotation = Rotation.random(random_state=7).as_matrix()
    moved = 2.5e-4 * points @ rotation.T + [1e-3, 2e-3, -5e-4]          # metres, as from a micro-CT
    user = grain("my_prism", *convex_hull(moved, "test")[:2])
    family = built_in_shape("prism").stretched(ba, cb)
    np.testing.assert_allclose(_as_set(user.vertices), _as_set(family.vertices), rtol=0, atol=1e-12)
    assert user.volume == pytest.approx(family.volume, rel=1e-12)
    np.testing.assert_allclose(user.inertia, family.inertia, rtol=1e-12)


@pytest.mark.parametrize("name", ["prism", "ellipsoid", "cut_prism", "tetrahedron", "mix", "", "1sand", "sand a",
                                  "x" * 65, 3])
def test_names_of_built_ins_and_malformed_names_are_refused(name):
    vertices, triangles, _ = convex_hull(shapes.shape_vertices("prism", 1.0, 0.8, 0.6), "test")
    with pytest.raises(ShapeError, match="name"):
        grain(name, vertices, triangles)




def test_a_hull_over_the_runtime_limit_is_refused(monkeypatch):
    """The limit read where it is checked (the real one, 65536, in tests/native/test_native_shapes.py: both
    loaders refuse one vertex more alike); here lowered so that the hulls stay small."""
    monkeypatch.setattr(registry, "MAX_HULL_VERTICES", LOWERED_HULL_LIMIT)
    rng = np.random.default_rng(2)
    points = rng.normal(size=(LOWERED_HULL_LIMIT + 1, 3))
    points /= np.linalg.norm(points, axis=1)[:, None]           # on a sphere: every point is a hull vertex
    vertices, triangles, _ = convex_hull(points, "test")
    assert len(vertices) == LOWERED_HULL_LIMIT + 1 and MAX_HULL_VERTICES == 65536
    with pytest.raises(ShapeError, match=f"{LOWERED_HULL_LIMIT + 1} vertices; allowed: at most {LOWERED_HULL_LIMIT}"):
        grain("sphere", vertices, triangles)
    grain("sphere", *convex_hull(points[:LOWERED_HULL_LIMIT], "test")[:2])      # at the limit: taken


def test_a_flat_hull_is_refused():
    thin = shapes.shape_vertices("prism", 1.0, 0.5, MIN_THICKNESS / 2)
    with pytest.raises(ShapeError, match="flat"):
        grain("plate", *convex_hull(thin, "test")[:2])


def test_polyhedron_refuses_a_frame_that_is_not_principal():
    vertices, triangles, _ = convex_hull(shapes.shape_vertices("prism", 1.0, 0.8, 0.6), "test")
    polyhedron("centred", vertices, triangles)
    with pytest.raises(ShapeError, match="principal frame"):
        polyhedron("off_centre", vertices + 0.1, triangles)
    with pytest.raises(ShapeError, match="principal frame"):
        polyhedron("turned", vertices @ Rotation.from_euler("z", 0.1).as_matrix().T, triangles)
    with pytest.raises(ShapeError, match="unit size"):
        polyhedron("large", 2.0 * vertices, triangles)
