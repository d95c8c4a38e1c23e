"""The contact search of a hull of many vertices by walks over its vertex graph (direct_model.hull_walk): each
query finds what a scan of every vertex finds, to the bit (the lowest vertex, the first of equal ones; the contact
set's sums in index order, the two smallest safe steps and the first vertex of the smallest, the farthest vertex),
from any start, through exact ties and through a walk that gives up; and a whole rebound of a 3000-vertex grain
walked is its rebound with every vertex scanned at every query."""

from __future__ import annotations

import math

import numpy as np
import pytest

from direct_model.body_rebound import body_rebound_batch, quaternion_to_matrix
from direct_model.flight import take_step, walk_safe_steps
from direct_model.hull_walk import (MAP_CELLS, ROOM, SLOTS, WALK_ABOVE, WALK_WORK, farthest_candidates, map_cell,
                                    map_start, start_map, walk_contact_sums, walk_farthest, walk_lowest)
from direct_model.registry import grain
from direct_model.shape_arrays import particle_hull, shape_arrays
from direct_model.shapes import AspectRatioLaw
from direct_model.simulate import incident_velocity
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
    wall makes exact ties among ``sides`` vertices."""
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
    return (y + (g[0] * p[:, 0] + g[1] * p[:, 1] + g[2] * p[:, 2]),
            v + (d[0] * p[:, 0] + d[1] * p[:, 1] + d[2] * p[:, 2]))


def _queries_against_scan(record, rng, states, starts_at_random):
    """Every query of the walk on ``states`` random orientations, stretches (mirrored too), heights, rates and
    curvature bounds of ``record``'s particle, against the scan's answers computed here (module doc)."""
    arrays = shape_arrays([record])
    work = np.zeros(WALK_WORK)
    for g, d in _directions(rng, states):
        scale = np.array([1.0, rng.uniform(0.5, 1.0), rng.uniform(0.3, 1.0) * rng.choice([-1.0, 1.0])])
        unit, _, graph_start, graph, starts, far = particle_hull.py_func(arrays, 0, scale)
        y, v, M = rng.uniform(0.0, 1.5), rng.uniform(-300.0, 50.0), rng.choice([0.0, rng.uniform(0.0, 500.0)])
        h, h1 = _scan(unit, scale, g, d, y, v)
        low = int(np.argmin(h))
        start = int(rng.integers(len(unit))) if starts_at_random else int(map_start(starts, g, scale))
        assert walk_lowest(unit, scale, graph_start, graph, g, y, start, work) == (h[low], low)
        limit = h[low] + rng.choice([1e-9, 0.01, 0.1])
        members = np.flatnonzero(h <= limit)
        p = unit * scale
        approaching = members[(h1[members] < 0.0)]
        best = int(approaching[np.argmin(h[approaching])]) if len(approaching) else -1
        sums = [0.0, 0.0, 0.0, 0.0]
        for i in members:                       # in index order, one addition at a time, as the kernels add
            sums = [sums[0] + p[i, 0], sums[1] + p[i, 1], sums[2] + p[i, 2], sums[3] + h1[i]]
        assert walk_contact_sums(unit, scale, graph_start, graph, g, d, y, v, limit, low, work) == (len(members), *sums,
                                                                                                   best)
        assert walk_farthest(unit, scale, far) == np.max(p[:, 0] ** 2 + p[:, 1] ** 2 + p[:, 2] ** 2)
        tau, tau_other, b = np.inf, np.inf, -1
        for i in range(len(h)):                 # the scan, nothing passed over
            tau, tau_other, b = take_step(h[i], h1[i], M, np.inf, i, tau, tau_other, b)
        assert walk_safe_steps(unit, scale, graph_start, graph, starts, g, d, y, v, M, low, work) == (tau, tau_other, b)
        assert not work[:SLOTS].any()           # the hash set left empty for the next walk


@pytest.mark.parametrize("starts_at_random", [False, True])
def test_each_query_finds_what_a_scan_finds(big, starts_at_random):
    """On 200 random orientations and stretches (mirrored too) of a 1000-vertex grain, the walks started from the
    start map or from a random vertex: the lowest vertex (the first of equal ones), the contact
    set's count, sums and lowest approaching vertex for three widths of the set, the farthest vertex's |p|², and
    the two smallest safe steps and the first vertex of the smallest: equal to the scan's, bit for bit."""
    _queries_against_scan(big, np.random.default_rng(8 + starts_at_random), 200, starts_at_random)


def test_a_near_sphere_s_queries_find_what_a_scan_finds():
    """A hull of 3000 vertices on a sphere (every height nearly tied with its neighbours', the farthest vertex
    nearly any): 100 random states, the same answers as the scan."""
    points = np.random.default_rng(11).normal(size=(3000, 3))
    vertices, triangles, _ = convex_hull(points / np.linalg.norm(points, axis=1)[:, None], "sphere")
    _queries_against_scan(settled(grain("sphere", vertices, triangles, aspect=AspectRatioLaw(), both_hands=True)),
                          np.random.default_rng(12), 100, True)


@pytest.mark.parametrize("sides", [40, ROOM + 20])
def test_exact_ties_are_resolved_as_a_scan_resolves_them(sides):
    """A face of ``sides`` vertices of equal height facing the wall: the lowest is the first of them, the contact
    set all of them summed in index order; with more than ROOM of them the walk gives up
    and the query scans every vertex, with the same answers."""
    rings = _ring_prism(sides)
    assert len(rings.vertices) == 2 * sides > WALK_ABOVE
    arrays = shape_arrays([rings])
    scale = np.ones(3)
    unit, _, graph_start, graph, starts, _ = particle_hull.py_func(arrays, 0, scale)
    axis = int(np.argmax(np.ptp(unit, axis=0) < 1.0))       # the prism's axis: its smallest extent
    work = np.zeros(WALK_WORK)
    for sign in (-1.0, 1.0):
        g = tuple(sign if k == axis else 0.0 for k in range(3))
        h, _ = _scan(unit, scale, g, (0.0, 0.0, 0.0), 0.5, 0.0)
        tied = np.flatnonzero(h == h.min())
        assert len(tied) == sides
        for start in (int(map_start(starts, g, scale)), int(tied[-1]), int(np.argmax(h))):
            assert walk_lowest(unit, scale, graph_start, graph, g, 0.5, start, work) == (h.min(), tied[0])
            count, *_ = walk_contact_sums(unit, scale, graph_start, graph, g, (0.0, 0.0, 0.0), 0.5, -1.0,
                                          h.min() + 1e-9, tied[0], work)
            assert count == sides


def test_the_start_map_holds_each_cell_s_lowest_vertex(big):
    """The start map's cell of a direction holds a vertex lowest along the cell's centre (on a convex hull the
    descent that fills it ends there): checked at every cell's centre, where map_cell must give that cell back."""
    unit = np.ascontiguousarray(big.vertices)
    starts = start_map(unit, big.neighbour_start, big.neighbours)
    edge = (np.arange(MAP_CELLS) + 0.5) / MAP_CELLS * 2.0 - 1.0
    for face in range(6):
        axis, sign = face // 2, -1.0 if face % 2 else 1.0
        for i, x in enumerate(edge):
            for j, y in enumerate(edge):
                w = np.empty(3)
                w[axis], w[(axis + 1) % 3], w[(axis + 2) % 3] = sign, x, y
                cell = map_cell(*w)
                assert cell == (face * MAP_CELLS + i) * MAP_CELLS + j
                levels = unit[:, 0] * w[0] + unit[:, 1] * w[1] + unit[:, 2] * w[2]
                assert levels[starts[cell]] == levels.min()


def test_the_farthest_candidates_hold_the_farthest_vertex_of_every_stretch():
    """farthest_candidates keeps the vertex of largest |p|² for every stretch |s0| ≥ |s1| ≥ |s2| (10 000 random
    stretches of a 1000-vertex grain, the axes' equal stretch among them) and drops a vertex that another
    exceeds in all three of |u|², u0² + u1², u0² (an inner point of a box's corner region)."""
    unit = np.random.default_rng(5).uniform(-1.0, 1.0, size=(1000, 3))
    unit[17] = (0.1, 0.1, 0.1)
    kept = farthest_candidates(unit)
    assert 17 not in kept and np.all(np.diff(kept) > 0)
    rng = np.random.default_rng(6)
    for _ in range(10_000):
        s0 = rng.uniform(0.3, 2.0)
        s1 = s0 * rng.choice([1.0, rng.uniform(0.5, 1.0)])
        scale = np.array([s0, s1, s1 * rng.choice([1.0, rng.uniform(0.5, 1.0)]) * rng.choice([-1.0, 1.0])])
        p = unit * scale
        r2 = p[:, 0] ** 2 + p[:, 1] ** 2 + p[:, 2] ** 2
        assert walk_farthest(unit, scale, kept) == r2.max()


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


def _with_complete_graph(arrays):
    """``arrays`` (one shape) with every vertex the neighbour of every other: each walk meets more than ROOM
    vertices and gives up, so every query scans every vertex in index order."""
    n = len(arrays.vertices)
    graph = np.array([j for i in range(n) for j in range(n) if j != i], dtype=np.int32)
    start = np.arange(n + 1, dtype=np.int64) * (n - 1)
    for x in (start, graph):                # read-only, as the kernels were compiled for
        x.setflags(write=False)
    return arrays._replace(graph_start=start, graph=graph)


def test_a_3000_vertex_grain_rebounds_as_with_every_vertex_scanned():
    """A grain of 3000 hull vertices walked against the same grain whose every query scans every vertex (a
    complete vertex graph, on which every walk gives up): every output equal, bit for bit, spinning and not."""
    record = _ellipsoid_grain(3000, 7)
    assert len(record.vertices) == 3000
    arrays = shape_arrays([record])
    outputs = _run(arrays, 0, count=200)
    assert np.array_equal(outputs, _run(_with_complete_graph(arrays), 0, count=200), equal_nan=True)
    assert np.all(outputs[:, 8] == 0) and math.isfinite(outputs[:, :7].sum())       # status: every one rebounded
