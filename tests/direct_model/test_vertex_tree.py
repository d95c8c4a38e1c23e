"""The contact search of a hull of many vertices through its tree (direct_model.vertex_tree): each query finds
what a scan of every vertex finds, to the bit (the lowest vertex and the first of equal ones, the contact set's
sums in index order, the two smallest safe steps, the farthest vertex), and a whole rebound through the tree is
the rebound of a scan: a family forced through a tree against its scan, and a grain of 3000 vertices through its
tree against the same search with every vertex taken (a tree of one leaf)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from direct_model.body_rebound import body_rebound_batch, quaternion_to_matrix
from direct_model.flight import safe_step, take_step, tree_safe_steps
from direct_model.registry import grain
from direct_model.shape_arrays import family_shape_arrays, shape_arrays
from direct_model.shapes import SHAPES, AspectRatioLaw, second_moment_factors
from direct_model.simulate import incident_velocity
from direct_model.vertex_tree import TREE_ABOVE, build_tree, contact_sums, farthest, lowest_two
from direct_model.wall import CORUNDUM_ON_STEEL
from tablegen.tabulation.grain_files import convex_hull, settled


def _ellipsoid_grain(n, seed, name="scan"):
    """A grain of n hull vertices: points on the ellipsoid of semi-axes (1, 0.7, 0.5), settled as a build
    settles a grain (Morton order above 256 vertices)."""
    points = np.random.default_rng(seed).normal(size=(n, 3))
    points = points / np.linalg.norm(points, axis=1)[:, None] * [1.0, 0.7, 0.5]
    vertices, triangles, _ = convex_hull(points, name)
    return settled(grain(name, vertices, triangles, aspect=AspectRatioLaw(), both_hands=True))


def _ring_prism(sides=40):
    """A prism on a regular polygon: two rings of equal heights along its axis, so that a face parallel to the
    wall makes exact ties among 40 vertices."""
    angle = 2.0 * np.pi * np.arange(sides) / sides
    ring = np.column_stack([np.cos(angle), np.sin(angle)])
    points = np.vstack([np.column_stack([ring, np.full(sides, -0.4)]), np.column_stack([ring, np.full(sides, 0.4)])])
    vertices, triangles, _ = convex_hull(points, "rings")
    return settled(grain("rings", vertices, triangles))


@pytest.fixture(scope="module")
def big():
    return _ellipsoid_grain(1000, 3)


def _directions(rng, count):
    """Random unit normals g (as the rows of random rotations give them) and rates d."""
    out = []
    for q in rng.normal(size=(count, 4)):
        R = np.empty((3, 3))
        quaternion_to_matrix(q, R)
        out.append(((R[1, 0], R[1, 1], R[1, 2]), tuple(rng.normal(size=3) * rng.choice([0.0, 0.3, 3.0]))))
    return out


def _scan(unit, scale, g, d, y, v):
    """Every vertex's height and rate, as the scan computes them."""
    p = unit * scale
    return (y + (g[0] * p[:, 0] + g[1] * p[:, 1] + g[2] * p[:, 2]), v + (d[0] * p[:, 0] + d[1] * p[:, 1] + d[2] * p[:, 2]))


@pytest.mark.parametrize("leaf_size", [16, 4])
def test_each_query_finds_what_a_scan_finds(big, leaf_size):
    """On 200 random orientations and stretches (mirrored too) of a 1000-vertex grain: the lowest and second
    lowest vertex (first of equal ones), the contact set's count, sums and lowest approaching vertex, the
    farthest vertex's |p|², and the two smallest safe steps and the first vertex of the smallest for T at the
    pass-over bound: equal to the scan's, bit for bit."""
    unit = np.ascontiguousarray(big.vertices)
    nodes, links = build_tree(unit, leaf_size)
    rng = np.random.default_rng(8)
    for g, d in _directions(rng, 200):
        scale = np.array([1.0, rng.uniform(0.5, 1.0), rng.uniform(0.3, 1.0) * rng.choice([-1.0, 1.0])])
        y, v, M = rng.uniform(0.0, 1.5), rng.uniform(-300.0, 50.0), rng.choice([0.0, rng.uniform(0.0, 500.0)])
        h, h1 = _scan(unit, scale, g, d, y, v)
        low = int(np.argmin(h))
        others = np.where(np.arange(len(h)) == low, np.inf, h)
        second = int(np.argmin(others))
        assert lowest_two(unit, scale, nodes, links, g, y) == (h[low], low, h[second], second)
        limit = h[low] + 0.01
        members = np.flatnonzero(h <= limit)
        p = unit * scale
        approaching = members[(h1[members] < 0.0)]
        best = int(approaching[np.argmin(h[approaching])]) if len(approaching) else -1
        sums = [0.0, 0.0, 0.0, 0.0]
        for i in members:                       # in index order, one addition at a time, as the kernels add
            sums = [sums[0] + p[i, 0], sums[1] + p[i, 1], sums[2] + p[i, 2], sums[3] + h1[i]]
        assert contact_sums(unit, scale, nodes, links, g, d, y, v, limit) == (len(members), *sums, best)
        assert farthest(unit, scale, nodes, links) == np.max(p[:, 0] ** 2 + p[:, 1] ** 2 + p[:, 2] ** 2)
        T = max(safe_step(h[low], h1[low], M), safe_step(h[second], h1[second], M))
        tau, tau_other, b = np.inf, np.inf, -1
        for i in range(len(h)):
            tau, tau_other, b = take_step(h[i], h1[i], M, T, i, tau, tau_other, b)
        assert tree_safe_steps(unit, scale, nodes, links, g, d, y, v, M, T) == (tau, tau_other, b)


def test_exact_ties_are_resolved_as_a_scan_resolves_them():
    """A face of 40 vertices of equal height facing the wall: the lowest is the first of them, the second the
    next, the contact set all 40 summed in index order."""
    rings = _ring_prism()
    unit = np.ascontiguousarray(rings.vertices)
    nodes, links = build_tree(unit, 4, above=0)
    axis = int(np.argmax(np.ptp(unit, axis=0) < 1.0))       # the prism's axis: its smallest extent
    scale = np.ones(3)
    for sign in (-1.0, 1.0):
        g = tuple(sign if k == axis else 0.0 for k in range(3))
        h, _ = _scan(unit, scale, g, (0.0, 0.0, 0.0), 0.5, 0.0)
        tied = np.flatnonzero(h == h.min())
        assert len(tied) == 40
        assert lowest_two(unit, scale, nodes, links, g, 0.5) == (h.min(), tied[0], h.min(), tied[1])
        count, *_ = contact_sums(unit, scale, nodes, links, g, (0.0, 0.0, 0.0), 0.5, -1.0, h.min() + 1e-9)
        assert count == 40


def _run(arrays, shape, count=300, seed=5):
    """``count`` rebounds of shape ``shape`` through the batch kernel simulate uses (random orientations,
    proportions and hands; α1 = 35° at 150 m/s, then the same spinning): every output, one row per particle."""
    rng = np.random.default_rng(seed)
    codes, hands = np.full(count, shape, dtype=np.int8), rng.choice([-1, 1], count).astype(np.int8)
    ratios, quats = rng.uniform(0.5, 1.0, (count, 2)), rng.normal(size=(count, 4))
    rows = []
    for spin in (0.0, 60.0):
        out = (np.empty((count, 3)), np.empty((count, 3)), np.empty(count), np.empty(count, dtype=np.int32),
               np.empty(count, dtype=np.int8), np.empty(count, dtype=np.int8), np.empty(count, dtype=np.int32),
               np.empty(count, dtype=np.int32), np.empty(count), np.empty(count))
        body_rebound_batch(arrays, codes, ratios, hands, quats, incident_velocity(35.0, 150.0),
                           np.array([0.0, 0.0, spin]), CORUNDUM_ON_STEEL.as_array(), 1000, 1e-10, 1e-9, 100_000, *out)
        rows.append(np.column_stack([x.reshape(count, -1).astype(np.float64) for x in out]))
    return np.vstack(rows)


def _with_tree(arrays, shape, leaf_size, above=TREE_ABOVE):
    """``arrays`` with shape ``shape``'s tree built with leaves of ``leaf_size`` (every other shape without one)."""
    lo, hi = arrays.vertex_start[shape], arrays.vertex_start[shape + 1]
    nodes, links = build_tree(arrays.vertices[lo:hi], leaf_size, above)
    start = np.zeros(len(arrays.kind) + 1, dtype=np.int64)
    start[shape + 1:] = len(nodes)
    for x in (start, nodes, links):         # read-only, as the kernels were compiled for
        x.setflags(write=False)
    return arrays._replace(tree_start=start, tree_nodes=nodes, tree_links=links)


def test_a_family_through_a_tree_rebounds_as_its_scan():
    """The cut prism at κ = 0 (each corner thrice: exact ties) and the prism, forced through a tree of leaves of
    4 vertices: every rebound's outputs equal its scan's, bit for bit."""
    arrays = family_shape_arrays(0.0, AspectRatioLaw(), second_moment_factors(0.0))
    for name in ("cut_prism", "prism"):
        shape = SHAPES.index(name)
        scanned = _run(arrays, shape)
        assert np.array_equal(_run(_with_tree(arrays, shape, 4, above=0), shape), scanned, equal_nan=True)


def test_a_3000_vertex_grain_rebounds_as_with_every_vertex_taken():
    """A grain of 3000 hull vertices through its tree against the same search with every vertex taken (one leaf
    of all 3000: nothing passed over): every output equal, bit for bit, spinning and not."""
    record = _ellipsoid_grain(3000, 7)
    assert len(record.vertices) == 3000
    arrays = shape_arrays([record])
    assert arrays.tree_nodes.shape[0] > 1
    whole = _with_tree(arrays, 0, 3000)
    assert whole.tree_nodes.shape[0] == 1
    outputs = _run(arrays, 0, count=200)
    assert np.array_equal(outputs, _run(whole, 0, count=200), equal_nan=True)
    assert np.all(outputs[:, 8] == 0) and math.isfinite(outputs[:, :7].sum())       # status: every one rebounded
