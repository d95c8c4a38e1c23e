"""Shapes as arrays (direct_model.shape_arrays): the families in the kernels' vertex order and factors, a user's
grain as its canonical hull, the round trip records → arrays → records, and one particle's body."""

import numpy as np
import pytest

from direct_model import shapes
from direct_model.registry import MAX_HULL_VERTICES, AspectRatioLaw, built_in_shapes
from direct_model.shape_arrays import (
    KIND_ELLIPSOID, KIND_POLYHEDRON, STORED, bounding_radius, family_shape_arrays, from_stored, particle_body,
    scanned_hull, shape_arrays, shape_records,
)
from tests.helpers.grains import cloud_grain

LAW = AspectRatioLaw()


def _bits(x):
    x = np.asarray(x)
    return x.view(np.uint64) if x.dtype == np.float64 else x


def _equal(one, other):
    """Every stored array the same bits."""
    return all(np.array_equal(_bits(getattr(one, f)), _bits(getattr(other, f))) for f in STORED)


def test_the_families_are_the_kernels_bodies_and_factors():
    """Vertices of each family in body_vertices' order at b/a = c/b = 1, the ellipsoid's semi-axes, s thrice."""
    kappa = 0.3
    arrays = family_shape_arrays(kappa, LAW, shapes.second_moment_factors(kappa))
    assert arrays.kind.tolist() == [KIND_ELLIPSOID] + [KIND_POLYHEDRON] * 3
    assert np.diff(arrays.vertex_start).tolist() == [1, 8, 24, 4]
    assert arrays.vertices[0].tolist() == [1.0, 1.0, 1.0]
    for code, name in enumerate(shapes.SHAPES[1:], start=1):
        rows = arrays.vertices[arrays.vertex_start[code]:arrays.vertex_start[code + 1]]
        assert np.array_equal(_bits(rows), _bits(shapes.shape_vertices(name, kappa=kappa)))
    assert np.array_equal(_bits(arrays.second_moments), _bits(np.repeat(shapes.second_moment_factors(kappa), 3)
                                                              .reshape(4, 3)))
    assert arrays.both_hands.tolist() == [0, 0, 0, 1]
    assert np.array_equal(arrays.aspect, np.tile([LAW.mean, LAW.sd, LAW.low, LAW.high], (4, 1)))
    assert np.all(np.diff(arrays.triangle_start) == [0, 12, 44, 4])


@pytest.mark.parametrize("kappa", [0.0, 0.1, 0.3, 0.5, 0.77, 0.99])
def test_records_round_trip_bit_for_bit(kappa):
    """arrays → records → arrays gives the same bits, families (every κ, the factors kept) and user grains."""
    records = list(built_in_shapes(kappa, LAW).values()) + [cloud_grain("sand_a", 60, 1, LAW),
                                                            cloud_grain("sand_b", 200, 2, None, True)]
    arrays = shape_arrays(records)
    names = [r.name for r in records]
    back = shape_records(arrays, names)
    assert list(back) == names
    assert back["cut_prism"].parameters == {"kappa": kappa}
    assert back["sand_b"].aspect is None and back["sand_b"].both_hands
    factors = {name: arrays.second_moments[i, 0] for i, name in enumerate(names[:4])}
    assert _equal(shape_arrays(back.values(), factors), arrays)
    assert _equal(from_stored(**arrays.stored()), arrays)


def test_a_grain_s_arrays_are_its_canonical_hull():
    sand = cloud_grain("sand", 120, 3)
    arrays = shape_arrays([sand])
    assert np.array_equal(arrays.vertices, sand.vertices) and np.array_equal(arrays.triangles, sand.triangles)
    second = arrays.second_moments[0]
    np.testing.assert_allclose([second[1] + second[2], second[0] + second[2], second[0] + second[1]], sand.inertia,
                               rtol=1e-14)
    assert np.isnan(arrays.aspect).all() and np.isnan(arrays.aspect_cdf).all()


@pytest.mark.parametrize("change, message", [
    (dict(kind=[2]), "'kind' of shape 0 must be 0 (ellipsoid) or 1 (convex polyhedron); got 2"),
    (dict(vertex_start=[0, 3]), "'vertex_start' must rise from 0 to"),
    (dict(second_moments=[[0.1, -0.1, 0.1]]), "second moments of shape 0 must be finite and > 0"),
    (dict(aspect=[[0.8, 0.2, 0.5, 1.5]]), "0 < low < high <= 1"),
    (dict(both_hands=[2]), "'both_hands' of shape 0 must be 0 or 1; got 2"),
    (dict(triangles=np.full((12, 3), 99)), "vertex indices 0 to 7"),
])
def test_arrays_out_of_their_ranges_are_refused(change, message):
    stored = shape_arrays([built_in_shapes(0.3, LAW)["prism"]], {"prism": 1.0 / 3.0}).stored()
    with pytest.raises(ValueError, match=message.replace("(", r"\(").replace(")", r"\)")):
        from_stored(**dict(stored, **change))


def test_a_hull_over_the_limit_is_refused():
    stored = shape_arrays([cloud_grain("sand", 60, 4)]).stored()
    count = MAX_HULL_VERTICES + 1
    stored.update(vertex_start=[0, count], vertices=np.zeros((count, 3)))
    with pytest.raises(ValueError, match=f"has {count} vertices; allowed: 4 to {MAX_HULL_VERTICES}"):
        from_stored(**stored)


@pytest.mark.parametrize("hand", [1.0, -1.0])
def test_a_particle_s_body_is_the_record_stretched(hand):
    """particle_body = the registry's stretched(): vertices, J/m, half-extents (largest 1) and radius."""
    sand = cloud_grain("sand", 150, 5, LAW)
    arrays = shape_arrays([sand])
    verts, K, semi, scale = np.empty((256, 3)), np.empty(3), np.empty(3), np.empty(3)
    for ba, cb in [(1.0, 1.0), (0.7, 0.9), (0.5, 0.5)]:
        nv = particle_body(arrays, 0, ba, cb, hand, verts, K, semi, scale)
        body = sand.stretched(ba, cb, int(hand))
        np.testing.assert_allclose(verts[:nv], body.vertices, rtol=0, atol=1e-15)
        np.testing.assert_allclose(K, body.inertia, rtol=1e-14)
        half = (body.vertices.max(axis=0) - body.vertices.min(axis=0)) / 2.0
        np.testing.assert_allclose(semi, half, rtol=1e-15)
        assert semi.max() == 1.0
        np.testing.assert_array_equal(arrays.vertices * scale, verts[:nv])      # the tree's view of the body
        assert bounding_radius(KIND_POLYHEDRON, semi, verts, nv, scanned_hull(verts)) == pytest.approx(
            np.linalg.norm(body.vertices, axis=1).max(), rel=1e-15)


def test_fixed_proportions_ignore_the_ratios():
    sand = cloud_grain("sand", 80, 6)
    arrays = shape_arrays([sand])
    one, other = ((np.empty((256, 3)), np.empty(3), np.empty(3), np.empty(3)),
                  (np.empty((256, 3)), np.empty(3), np.empty(3), np.empty(3)))
    n1 = particle_body(arrays, 0, 1.0, 1.0, 1.0, *one)
    n2 = particle_body(arrays, 0, 0.6, 0.7, 1.0, *other)
    assert n1 == n2 == len(sand.vertices)
    assert all(np.array_equal(x[:n1] if x.ndim == 2 else x, y[:n1] if y.ndim == 2 else y) for x, y in zip(one, other))
