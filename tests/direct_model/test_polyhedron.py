"""A hull's mass properties against closed forms, and its canonical frame (docs/model.md §3, §9)."""

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from direct_model.polyhedron import canonical_frame, mass_properties, symmetric_eigen, vertex_graph
from tablegen.tabulation.grain_files import convex_hull

CUBE = np.array([[x, y, z] for x in (-1.0, 1.0) for y in (-1.0, 1.0) for z in (-1.0, 1.0)])
REGULAR_TETRAHEDRON = np.array([[1.0, 1.0, 1.0], [1.0, -1.0, -1.0], [-1.0, 1.0, -1.0], [-1.0, -1.0, 1.0]])
ROTATIONS = Rotation.random(5, random_state=20261121).as_matrix()


def _hull(points):
    vertices, triangles, _ = convex_hull(points, "test")
    return vertices, triangles


def _moved(points, rotation, shift, scale):
    return scale * points @ rotation.T + shift


def _random_grain(seed, n=60, axes=(1.0, 0.7, 0.45)):
    """The hull of a Gaussian cloud stretched along three axes: an irregular grain, chiral, distinct moments."""
    return _hull(np.random.default_rng(seed).normal(size=(n, 3)) * axes)


@pytest.mark.parametrize("rotation", ROTATIONS)
def test_box_mass_properties_match_closed_form(rotation):
    a, b, c = 1.7, 0.9, 0.4
    shift = np.array([3.0, -2.0, 0.5])
    vertices, triangles = _hull(_moved(CUBE * (a, b, c), rotation, shift, 1.0))
    props = mass_properties(vertices, triangles)
    assert props.volume == pytest.approx(8 * a * b * c, rel=1e-13)
    np.testing.assert_allclose(props.centroid, shift, rtol=0, atol=1e-14 * 4)
    body = np.diag([b * b + c * c, a * a + c * c, a * a + b * b]) / 3.0
    np.testing.assert_allclose(props.inertia, rotation @ body @ rotation.T, rtol=0, atol=1e-14)


@pytest.mark.parametrize("side", [1.0, 2.5e-4])
def test_cube_mass_properties_match_closed_form(side):
    vertices, triangles = _hull(_moved(CUBE * side / 2, ROTATIONS[0], 10.0 * side, 1.0))
    props = mass_properties(vertices, triangles)
    assert props.volume == pytest.approx(side ** 3, rel=1e-13)
    np.testing.assert_allclose(props.centroid, 10.0 * side, rtol=1e-14)
    np.testing.assert_allclose(props.inertia, side ** 2 / 6.0 * np.eye(3), rtol=0, atol=1e-14 * side ** 2)


@pytest.mark.parametrize("rotation", ROTATIONS)
def test_regular_tetrahedron_mass_properties_match_closed_form(rotation):
    """Edge L: V = L³/(6√2), J/m = L²/20 about every axis through the centroid, centroid at the vertices' mean."""
    points = _moved(REGULAR_TETRAHEDRON, rotation, np.array([-1.0, 4.0, 2.0]), 0.3)
    edge = np.linalg.norm(points[0] - points[1])
    props = mass_properties(*_hull(points))
    assert props.volume == pytest.approx(edge ** 3 / (6 * math.sqrt(2)), rel=1e-13)
    np.testing.assert_allclose(props.centroid, points.mean(axis=0), rtol=0, atol=1e-14 * 4)
    np.testing.assert_allclose(props.inertia, edge ** 2 / 20.0 * np.eye(3), rtol=0, atol=1e-14)


def test_jacobi_eigenpairs_solve_the_matrix():
    rng = np.random.default_rng(4)
    for _ in range(20):
        m = rng.normal(size=(3, 3))
        m = m + m.T
        values, vectors = symmetric_eigen(m)
        assert values[0] >= values[1] >= values[2]
        np.testing.assert_allclose(m @ vectors, vectors * values, atol=1e-14 * np.abs(m).max())
        np.testing.assert_allclose(vectors.T @ vectors, np.eye(3), atol=1e-15)


@pytest.mark.parametrize("seed", range(6))
def test_moved_copies_give_the_same_canonical_grain(seed):
    """A rotated, translated and rescaled copy gives the same vertices, in the same order, to 1e-12 of a.

    The shift is a few sizes of the grain: a copy far from the origin has lost digits before we see it.
    """
    vertices, triangles = _random_grain(seed)
    reference = canonical_frame(vertices, triangles)
    for k, rotation in enumerate(ROTATIONS):
        scale = 10.0 ** (k - 2)
        copy = canonical_frame(_moved(vertices, rotation, scale * np.array([k, -2.0 * k, 5.0]), scale), triangles)
        np.testing.assert_allclose(copy.vertices, reference.vertices, rtol=0, atol=1e-12)
        assert copy.a == pytest.approx(reference.a * scale, rel=1e-12)


@pytest.mark.parametrize("seed", range(3))
def test_canonical_grain_is_centred_principal_right_handed_and_unit(seed):
    vertices, triangles = _random_grain(seed)
    frame = canonical_frame(vertices, triangles)
    props = mass_properties(frame.vertices, frame.triangles)
    np.testing.assert_allclose(props.centroid, 0.0, atol=1e-15)
    np.testing.assert_allclose(props.inertia - np.diag(np.diag(props.inertia)), 0.0, atol=1e-15)
    assert props.inertia[0, 0] < props.inertia[1, 1] < props.inertia[2, 2]                # ascending moments
    half = (frame.vertices.max(axis=0) - frame.vertices.min(axis=0)) / 2
    assert half.max() == pytest.approx(1.0, rel=1e-15)
    assert np.linalg.det(frame.rotation) == pytest.approx(1.0, rel=1e-14)
    # the map back to the file: x = a R x_canonical + centroid, vertex for vertex
    back = frame.a * frame.vertices @ frame.rotation.T + frame.centroid
    assert {tuple(np.round(p, 10)) for p in back} == {tuple(np.round(p, 10)) for p in vertices}


@pytest.mark.parametrize("seed", range(3))
def test_a_chiral_grain_keeps_its_hand(seed):
    """The mirror image's canonical grain is the canonical grain mirrored (ζ → −ζ), not the grain itself."""
    vertices, triangles = _random_grain(seed)
    mirrored = canonical_frame(vertices * (1.0, 1.0, -1.0), triangles[:, ::-1])
    reference = canonical_frame(vertices, triangles)
    as_set = lambda v: np.array(sorted(map(tuple, np.round(v, 11))))         # noqa: E731
    np.testing.assert_array_equal(as_set(mirrored.vertices), as_set(reference.vertices * (1.0, 1.0, -1.0)))
    assert as_set(mirrored.vertices).shape == as_set(reference.vertices).shape
    assert not np.array_equal(as_set(mirrored.vertices), as_set(reference.vertices))


@pytest.mark.parametrize("body, half_extents", [
    (CUBE, (1.0, 1.0, 1.0)),                                       # three equal moments
    (CUBE * (2.0, 1.0, 1.0), (1.0, 0.5, 0.5)),                     # a square rod: equal moments about η and ζ
    (CUBE * (1.5, 1.5, 1.0), (1.0, 1.0, 2.0 / 3.0)),               # a square plate: equal moments about ξ and η
    (REGULAR_TETRAHEDRON, None),                                   # three equal moments, no mirror-free axis
])
def test_equal_moments_give_one_canonical_grain(body, half_extents):
    """Where the inertia leaves the axes open, the hull fixes them: every rotated copy gives the same vertices."""
    frames = [canonical_frame(*_hull(_moved(body, rotation, 1.0, 3.0))) for rotation in ROTATIONS]
    for frame in frames[1:]:
        np.testing.assert_allclose(frame.vertices, frames[0].vertices, rtol=0, atol=1e-12)
    if half_extents is not None:       # boxes: the narrowest directions are the faces' normals, as for the prism
        v = frames[0].vertices
        np.testing.assert_allclose((v.max(axis=0) - v.min(axis=0)) / 2, half_extents, rtol=1e-14)


def test_vertex_graph_lists_each_edge_both_ways():
    vertices, triangles = _hull(CUBE)
    start, neighbours = vertex_graph(triangles, len(vertices))
    assert start[-1] == len(neighbours)
    edges = {frozenset(e) for t in triangles for e in ((t[0], t[1]), (t[1], t[2]), (t[2], t[0]))}
    listed = {frozenset((i, int(j))) for i in range(len(vertices)) for j in neighbours[start[i]:start[i + 1]]}
    assert listed == edges
    assert all(np.all(np.diff(neighbours[start[i]:start[i + 1]]) > 0) for i in range(len(vertices)))
