"""A tree of boxes over a hull's vertices: the contact search of a hull of many vertices in time that grows slowly
with their number, with the bits of a scan of every vertex (docs/design/grains.md, "Hulls of many vertices").

The tree. Leaves hold :data:`LEAF_SIZE` consecutive vertices (the last one fewer), an inner node :data:`BRANCH`
consecutive nodes of the level below, so that every node covers a contiguous range of vertex indices and a
depth-first walk that takes the children in order meets the vertices in index order. A node's box
(:func:`node_boxes`): centred on its vertices' bounding box, along the principal axes of their spread (a patch
of surface gives a thin box along its normal), each half-extent the vertices' largest distance from the centre
along the axis, widened by a relative 10⁻¹² and an absolute 10⁻¹⁴ (units of a). The nodes are stored in
depth-first preorder, so a walk needs no stack: from node k it goes on to k + 1 (its first child, or the next
node) or skips k's subtree. Arrays of one tree: ``nodes`` (k, :data:`NODE_SIZE`) float64, the centre, the three
axes and the three half-extents (unit body frame, units of a); ``links`` (k, 4) int64, the first vertex, the
vertex count, the node after the subtree and 1 for a leaf (0 for an inner node). Node 0 is the root. A hull
of :data:`TREE_ABOVE` vertices or fewer has no tree (k = 0) and is scanned. A grain's hull of more than 256
vertices is settled in Morton order (:func:`tablegen.tabulation.grain_files.settled`), so that a leaf is a small patch of the surface.

The queries (:func:`lowest_two`, :func:`contact_sums`, :func:`farthest` here, and
:func:`direct_model.flight.tree_safe_steps`). One particle's vertex i is p = unit[i] · scale (the unit body
stretched and mirrored per particle, as :func:`direct_model.shape_arrays.particle_body` copies it: the same
products), its height over the wall h = y + g·p and its rate h' = v + ġ·p (:mod:`direct_model.flight`). A
node's box bounds both from below for all its vertices (g·p = (g · scale)·unit, so the box needs no stretching),
less a margin for the round-off of every vertex's own value; a query walks into a node only if a vertex in it
may pass its test, and takes the vertices it meets in index order with the scan's own comparisons. So it finds
what a scan finds, to the bit: the lowest vertex and the first of equal ones, the contact set and its sums in
index order, the two smallest safe steps and the first vertex of the smallest (a vertex left out provably has a
larger one), the farthest vertex's squared distance.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from direct_model.options import JIT, KERNEL

TREE_ABOVE = 64         # vertices; a hull with more is searched through its tree (the same bits; docs/design/grains.md)
LEAF_SIZE = 16          # vertices per leaf
BRANCH = 8              # children per inner node
NODE_SIZE = 16          # a node's box: centre, three axes, three half-extents, one spare
ROUNDING = 1e-12        # relative widening of a box and of a bound (far above the round-off of one vertex's value)
FLOOR = 1e-14           # absolute widening of a box, units of a
JACOBI_SWEEPS = 50      # the principal axes of a box converge in a few


def build_tree(unit, leaf_size: int = LEAF_SIZE, above: int = TREE_ABOVE) -> tuple:
    """(nodes, links) of the tree over the vertex rows ``unit`` (n, 3) with leaves of ``leaf_size`` vertices
    (module doc); empty arrays for n ≤ ``above`` (a hull that is scanned)."""
    unit = np.ascontiguousarray(unit, dtype=np.float64)
    n = len(unit)
    if n <= above:
        return np.zeros((0, NODE_SIZE)), np.zeros((0, 4), dtype=np.int64)
    # each level: (first vertex, vertex count, its children in the level below as a range)
    levels = [[(first, min(leaf_size, n - first), 0, 0) for first in range(0, n, leaf_size)]]
    while len(levels[-1]) > 1:
        below = levels[-1]
        levels.append([(below[j][0], sum(node[1] for node in below[j:j + BRANCH]), j, min(BRANCH, len(below) - j))
                       for j in range(0, len(below), BRANCH)])
    order = []                          # (level, index) in depth-first preorder, children in index order

    def visit(level, j):
        order.append((level, j))
        _, _, child, n_children = levels[level][j]
        for c in range(child, child + n_children):
            visit(level - 1, c)
    visit(len(levels) - 1, 0)
    links = np.zeros((len(order), 4), dtype=np.int64)
    for k, (level, j) in enumerate(order):
        first, count, child, n_children = levels[level][j]
        # the node after this one's subtree: its next sibling, or its parent's (the end for the last)
        after = k + 1 + sum(_subtree_size(levels, level - 1, c) for c in range(child, child + n_children))
        links[k] = (first, count, after, 1 if n_children == 0 else 0)
    nodes = np.zeros((len(order), NODE_SIZE))
    node_boxes(unit, links, nodes)
    return nodes, links


@numba.njit(**JIT)
def node_boxes(unit, links, nodes):
    """Each node's box (module doc) into ``nodes``: centre c (the middle of its vertices' bounding box), axes the
    principal axes of their spread about c (the first of least spread: on a patch of surface, its normal;
    :func:`principal_axes`), and the half-extents along them: the vertices' largest |(p − c)·axis|, widened.
    Plain loops in a fixed order: the same bits on any CPU (a box decides speed, never a result)."""
    m, axes = np.empty((3, 3)), np.empty((3, 3))
    for k in range(links.shape[0]):
        first, last = links[k, 0], links[k, 0] + links[k, 1]
        for axis in range(3):
            low, high = unit[first, axis], unit[first, axis]
            for i in range(first + 1, last):
                low, high = min(low, unit[i, axis]), max(high, unit[i, axis])
            nodes[k, axis] = 0.5 * (low + high)
        for a in range(3):
            for b in range(3):
                total = 0.0
                for i in range(first, last):
                    total += (unit[i, a] - nodes[k, a]) * (unit[i, b] - nodes[k, b])
                m[a, b] = total
        principal_axes(m, axes)
        for a in range(3):
            reach = 0.0
            for i in range(first, last):
                reach = max(reach, abs((unit[i, 0] - nodes[k, 0]) * axes[a, 0] + (unit[i, 1] - nodes[k, 1]) * axes[a, 1]
                                       + (unit[i, 2] - nodes[k, 2]) * axes[a, 2]))
            nodes[k, 3 + 3 * a], nodes[k, 4 + 3 * a], nodes[k, 5 + 3 * a] = axes[a, 0], axes[a, 1], axes[a, 2]
            nodes[k, 12 + a] = reach * (1.0 + ROUNDING) + FLOOR


@numba.njit(**JIT)
def principal_axes(m, axes):
    """Orthonormal eigenvectors of the symmetric 3×3 ``m`` (overwritten) as the rows of ``axes``, the smallest
    eigenvalue's first, the largest's second, their cross product third: cyclic Jacobi rotations."""
    v = np.eye(3)
    for _ in range(JACOBI_SWEEPS):
        off = abs(m[0, 1]) + abs(m[0, 2]) + abs(m[1, 2])
        if off <= 1e-300 or off <= 1e-15 * (abs(m[0, 0]) + abs(m[1, 1]) + abs(m[2, 2])):
            break
        for p, q in ((0, 1), (0, 2), (1, 2)):
            if m[p, q] == 0.0:
                continue
            theta = (m[q, q] - m[p, p]) / (2.0 * m[p, q])
            t = math.copysign(1.0, theta) / (abs(theta) + math.sqrt(theta * theta + 1.0))
            c = 1.0 / math.sqrt(t * t + 1.0)
            s = t * c
            for k in range(3):            # m ← m J (columns p, q), then m ← Jᵀ m (rows p, q), v ← v J
                mkp, mkq = m[k, p], m[k, q]
                m[k, p], m[k, q] = c * mkp - s * mkq, s * mkp + c * mkq
            for k in range(3):
                mpk, mqk = m[p, k], m[q, k]
                m[p, k], m[q, k] = c * mpk - s * mqk, s * mpk + c * mqk
            for k in range(3):
                vkp, vkq = v[k, p], v[k, q]
                v[k, p], v[k, q] = c * vkp - s * vkq, s * vkp + c * vkq
    small, large = 0, 0
    for i in range(1, 3):
        if m[i, i] < m[small, small]:
            small = i
        if m[i, i] > m[large, large]:
            large = i
    if large == small:
        large = (small + 1) % 3
    for k in range(3):
        axes[0, k], axes[1, k] = v[k, small], v[k, large]
    axes[2, 0] = axes[0, 1] * axes[1, 2] - axes[0, 2] * axes[1, 1]
    axes[2, 1] = axes[0, 2] * axes[1, 0] - axes[0, 0] * axes[1, 2]
    axes[2, 2] = axes[0, 0] * axes[1, 1] - axes[0, 1] * axes[1, 0]


def _subtree_size(levels, level, j) -> int:
    """The number of nodes in the subtree of node j of ``level``."""
    _, _, child, n_children = levels[level][j]
    return 1 + sum(_subtree_size(levels, level - 1, c) for c in range(child, child + n_children))


@numba.njit(inline="always", **KERNEL)
def vertex(unit, scale, i):
    """Vertex i of the particle: unit[i] · scale, the products particle_body writes."""
    return unit[i, 0] * scale[0], unit[i, 1] * scale[1], unit[i, 2] * scale[2]


@numba.njit(inline="always", **KERNEL)
def height(unit, scale, g, y, i):
    """(h, p): vertex i's height y + g·p over the wall and the vertex p itself, as the scan computes them."""
    p0, p1, p2 = vertex(unit, scale, i)
    return y + (g[0] * p0 + g[1] * p1 + g[2] * p2), p0, p1, p2


@numba.njit(inline="always", **KERNEL)
def leaf_vertices(links, k):
    """The vertices of node k if it is a leaf, none for an inner node (a walk's step)."""
    return range(links[k, 0], links[k, 0] + links[k, 1] * links[k, 3])


@numba.njit(inline="always", **KERNEL)
def lower_bound(base, direction, scale, nodes, k):
    """A lower bound of base + direction·p over node k's box for the particle (p = unit · scale), below the
    computed value of every vertex in it: with w = direction · scale (elementwise), w·c − Σ |w·axis| half."""
    w0, w1, w2 = direction[0] * scale[0], direction[1] * scale[1], direction[2] * scale[2]
    dot = w0 * nodes[k, 0] + w1 * nodes[k, 1] + w2 * nodes[k, 2]
    reach = (abs(w0 * nodes[k, 3] + w1 * nodes[k, 4] + w2 * nodes[k, 5]) * nodes[k, 12]
             + abs(w0 * nodes[k, 6] + w1 * nodes[k, 7] + w2 * nodes[k, 8]) * nodes[k, 13]
             + abs(w0 * nodes[k, 9] + w1 * nodes[k, 10] + w2 * nodes[k, 11]) * nodes[k, 14]) * (1.0 + ROUNDING)
    return base + dot - reach - ROUNDING * (abs(base) + abs(dot) + reach + FLOOR)


@numba.njit(inline="always", **KERNEL)
def spread(direction, scale, nodes, k):
    """Σ |w·axis| half of node k's box (w = direction · scale): how far direction·p varies from its centre's."""
    w0, w1, w2 = direction[0] * scale[0], direction[1] * scale[1], direction[2] * scale[2]
    return (abs(w0 * nodes[k, 3] + w1 * nodes[k, 4] + w2 * nodes[k, 5]) * nodes[k, 12]
            + abs(w0 * nodes[k, 6] + w1 * nodes[k, 7] + w2 * nodes[k, 8]) * nodes[k, 13]
            + abs(w0 * nodes[k, 9] + w1 * nodes[k, 10] + w2 * nodes[k, 11]) * nodes[k, 14])


@numba.njit(**KERNEL)
def lowest_two(unit, scale, nodes, links, g, y):
    """(h_low, low, h_second, second): the lowest vertex (the first of equal ones) and the lowest other vertex (the
    first of equal ones: :func:`direct_model.flight.pass_over_bound`'s), heights h = y + g·p (units of a).

    A first descent into the child of the lowest sphere at every level finds a leaf whose second lowest vertex
    bounds the answer's second from above; the walk then passes over every node whose sphere lies above that."""
    k = 0
    while not links[k, 3]:
        best, best_low, child = k + 1, np.inf, k + 1
        while child < links[k, 2]:
            low = lower_bound(y, g, scale, nodes, child)
            if low < best_low:
                best, best_low = child, low
            child = links[child, 2]
        k = best
    h_low, limit = np.inf, np.inf
    for i in leaf_vertices(links, k):
        h = height(unit, scale, g, y, i)[0]
        if h < h_low:
            h_low, limit = h, h_low
        elif h < limit:
            limit = h
    h_low, low, h_second, second = np.inf, -1, np.inf, -1
    k = 0
    while k < nodes.shape[0]:
        if lower_bound(y, g, scale, nodes, k) > min(limit, h_second):
            k = links[k, 2]
            continue
        for i in leaf_vertices(links, k):
            h, p0, p1, p2 = height(unit, scale, g, y, i)
            if h < h_low:
                h_second, second, h_low, low = h_low, low, h, i
            elif h < h_second:
                h_second, second = h, i
        k += 1                  # into the first child, or past a leaf
    return h_low, low, h_second, second


@numba.njit(**KERNEL)
def contact_sums(unit, scale, nodes, links, g, d, y, v, limit):
    """Over the vertices with h ≤ ``limit`` in index order (:func:`direct_model.flight.choose_contact`'s set):
    (count, Σp (3), Σh', the lowest approaching one or −1); h = y + g·p, h' = v + d·p."""
    count = 0
    p0s, p1s, p2s, rate = 0.0, 0.0, 0.0, 0.0
    best, best_h = -1, np.inf
    k = 0
    while k < nodes.shape[0]:
        if lower_bound(y, g, scale, nodes, k) > limit:
            k = links[k, 2]
            continue
        for i in leaf_vertices(links, k):
            h, p0, p1, p2 = height(unit, scale, g, y, i)
            if h <= limit:
                h1 = v + (d[0] * p0 + d[1] * p1 + d[2] * p2)
                count += 1
                p0s, p1s, p2s, rate = p0s + p0, p1s + p1, p2s + p2, rate + h1
                if h1 < 0.0 and h < best_h:
                    best, best_h = i, h
        k += 1                  # into the first child, or past a leaf
    return count, p0s, p1s, p2s, rate, best


@numba.njit(**KERNEL)
def farthest(unit, scale, nodes, links):
    """max over the vertices of |p|² (p = unit[i] · scale), as :func:`direct_model.shape_arrays.bounding_radius`
    forms it. A first descent into the child of the farthest-reaching box at every level gives a lower bound;
    the walk then passes over every node whose box lies nearer."""
    k = 0
    while not links[k, 3]:
        best, best_reach, child = k + 1, -1.0, k + 1
        while child < links[k, 2]:
            reach = _reach(nodes, child, scale)
            if reach > best_reach:
                best, best_reach = child, reach
            child = links[child, 2]
        k = best
    r2 = 0.0
    for i in leaf_vertices(links, k):
        p0, p1, p2 = vertex(unit, scale, i)
        r2 = max(r2, p0 ** 2 + p1 ** 2 + p2 ** 2)
    k = 0
    while k < nodes.shape[0]:
        reach = _reach(nodes, k, scale)
        if reach * reach < r2:
            k = links[k, 2]
            continue
        for i in leaf_vertices(links, k):
            p0, p1, p2 = vertex(unit, scale, i)
            r2 = max(r2, p0 ** 2 + p1 ** 2 + p2 ** 2)
        k += 1                  # into the first child, or past a leaf
    return r2


@numba.njit(inline="always", **KERNEL)
def _reach(nodes, k, scale):
    """An upper bound of |p| over node k's box for the particle, above every vertex's computed value:
    |c · scale| + Σ half |axis · scale|."""
    total = math.sqrt((nodes[k, 0] * scale[0]) ** 2 + (nodes[k, 1] * scale[1]) ** 2 + (nodes[k, 2] * scale[2]) ** 2)
    for axis in range(3):
        u0, u1, u2 = (nodes[k, 3 + 3 * axis] * scale[0], nodes[k, 4 + 3 * axis] * scale[1],
                      nodes[k, 5 + 3 * axis] * scale[2])
        total += nodes[k, 12 + axis] * math.sqrt(u0 * u0 + u1 * u1 + u2 * u2)
    return total * (1.0 + ROUNDING) + FLOOR
