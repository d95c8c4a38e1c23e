"""The support point by hill climbing the hull's vertex graph equals a scan of every vertex (docs/model.md §9)."""

import numpy as np
import pytest

from direct_model.polyhedron import vertex_graph
from direct_model.support import support_vertex
from tablegen.tabulation.grain_files import convex_hull


def _scan(vertices, d):
    """Reference: the highest vertex by brute force."""
    return int(np.argmax(vertices[:, 0] * d[0] + vertices[:, 1] * d[1] + vertices[:, 2] * d[2]))


def _random_hull(n, seed):
    """A hull of exactly n vertices: n random points on an ellipsoid, every one a vertex."""
    rng = np.random.default_rng(seed)
    points = rng.normal(size=(n, 3))
    points /= np.linalg.norm(points, axis=1)[:, None]
    vertices, triangles, _ = convex_hull(points * (1.0, 0.7, 0.5), "test")
    assert len(vertices) == n
    return vertices, triangles


@pytest.mark.parametrize("n", [8, 24, 64, 256])
def test_hill_climb_equals_brute_force(n):
    vertices, triangles = _random_hull(n, seed=n)
    start, neighbours = vertex_graph(triangles, n)
    rng = np.random.default_rng(1000 + n)
    last = 0
    for d in rng.normal(size=(500, 3)):
        expected = _scan(vertices, d)
        from_last = support_vertex(vertices, start, neighbours, d[0], d[1], d[2], last)     # a turning body
        from_anywhere = support_vertex(vertices, start, neighbours, d[0], d[1], d[2], int(rng.integers(n)))
        assert from_last == expected and from_anywhere == expected
        last = from_last


def test_hill_climb_follows_a_slowly_turning_direction():
    """The use in the free flight: the direction turns a little per step, and each search starts at the last answer."""
    vertices, triangles = _random_hull(64, seed=5)
    start, neighbours = vertex_graph(triangles, 64)
    last = 0
    for t in np.linspace(0.0, 20.0, 4001):
        d = np.array([np.cos(t), np.sin(1.3 * t), np.cos(0.7 * t) * np.sin(t)])
        last = support_vertex(vertices, start, neighbours, d[0], d[1], d[2], last)
        assert last == _scan(vertices, d)


def test_ties_on_a_face_give_a_vertex_of_the_face():
    """On a box, the support in ±ξ is a whole face: the climb stops at one of its four corners."""
    box = np.array([[x, y, z] for x in (-1.0, 1.0) for y in (-0.6, 0.6) for z in (-0.3, 0.3)])
    vertices, triangles, _ = convex_hull(box, "test")
    start, neighbours = vertex_graph(triangles, len(vertices))
    for sign in (1.0, -1.0):
        for first in range(len(vertices)):
            best = support_vertex(vertices, start, neighbours, sign, 0.0, 0.0, first)
            assert vertices[best, 0] == sign
