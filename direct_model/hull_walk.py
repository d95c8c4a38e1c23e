"""Walks over a hull's vertex graph: the contact search of a hull of many vertices in time that barely grows with
their number, with the bits of a scan of every vertex (docs/design/grains.md, "Hulls of many vertices").

Why a walk finds what a scan finds. One particle's vertex i is p = unit[i] · scale (the unit body stretched and
mirrored, the products :func:`direct_model.shape_arrays.particle_body` writes), its height over the wall
h = y + g·p and its rate h' = v + d·p (:mod:`direct_model.flight`). Every query of the contact search asks about
the vertices where a *level* h + T·h', linear in p, is at most a bound L: the lowest (T = 0), the contact set
(T = 0, L the lowest height plus the set's tolerance), the vertices that may reach the wall within a step T
(h + T'h' ≤ ½MT'² plus round-off, as :func:`direct_model.flight.may_reach` decides). On a convex polyhedron the
vertices below a plane are connected in its vertex graph, so a breadth-first walk from one of them over the
vertices at most L (:func:`band`) meets them all; widened by :data:`BAND` of the level's terms, far above the
round-off of a level and the 2⁻³⁷ a by which settling moves a vertex off the hull, it still does. The walk then
applies the scan's own comparisons to the vertices it met, in index order: the same answers, to the bit. What
keeps a walk short is a good bound: a steepest descent (:func:`descend`) from the last answer or from the hull's
start map (:func:`nearer`) finds the lowest vertex in a few moves, and the step's bound is tightened from the
vertices near the level's lowest before the walk (:func:`direct_model.flight.walk_safe_steps`).

Arrays of one hull: ``unit`` (n, 3) its vertices, ``graph_start`` (n + 1,) and ``graph`` its vertex graph (the
neighbours of vertex i are graph[graph_start[i]:graph_start[i + 1]], indices into ``unit``), ``starts``
(:data:`MAP_SIZE`,) its start map (:func:`start_map`: a vertex near the lowest along any direction, where a
descent starts; it decides speed, never an answer) and ``far`` the vertices that may be the farthest from the
centre for some stretch (:func:`farthest_candidates`). A hull of :data:`WALK_ABOVE` vertices or fewer is scanned.
Work space: ``work`` (:data:`WALK_WORK`,) float64, a hash set of the vertices met, two lists and the last
answer; a walk that would meet more than :data:`ROOM` vertices gives up, and its query scans every vertex (the
same answer, slower).
"""

from __future__ import annotations

import numba
import numpy as np

from direct_model.options import JIT, KERNEL

WALK_ABOVE = 64         # vertices; a hull with more is walked (the same bits as a scan; docs/design/grains.md)
ROOM = 128              # vertices one walk may meet (its band and the ring around it); more: the query scans
SLOTS = 256             # hash slots of the vertices met: twice ROOM, so probes stay short
START = SLOTS + 2 * ROOM                # after the hash set, the slots of the vertices met, the band's members:
WALK_WORK = START + 1                   # the vertex the next walk starts from
BAND = 1e-9             # relative widening of a walk's bound (module doc)
MAP_CELLS = 16          # cells along a face's edge of a hull's start map (a cube map of directions)
MAP_SIZE = 6 * MAP_CELLS * MAP_CELLS
FAR_MARGIN = 1e-12      # a vertex is dropped from ``far`` when another beats it by this much (a², module doc)
_HASH = 2654435761      # Knuth's multiplicative hash


@numba.njit(**JIT)
def start_map(unit, graph_start, graph):
    """(MAP_SIZE,) int32: for each cell of a cube map of directions w (:func:`map_cell`), a vertex of ``unit``
    (n, 3) lowest along its centre's direction (its vertex graph ``graph_start``, ``graph`` local): where a descent
    along w starts. Each cell's by a steepest descent from the cell's before it (a speed device only)."""
    starts = np.empty(MAP_SIZE, dtype=np.int32)
    ones, zero, w = np.ones(3), (0.0, 0.0, 0.0), np.empty(3)
    i = 0
    for face in range(6):
        axis, sign = face // 2, -1.0 if face % 2 else 1.0
        for a in range(MAP_CELLS):
            for b in range(MAP_CELLS):
                w[axis] = sign
                w[(axis + 1) % 3] = (a + 0.5) / MAP_CELLS * 2.0 - 1.0
                w[(axis + 2) % 3] = (b + 0.5) / MAP_CELLS * 2.0 - 1.0
                i = descend(unit, ones, graph_start, graph, (w[0], w[1], w[2]), zero, 0.0, 0.0, 0.0, i)[0]
                starts[(face * MAP_CELLS + a) * MAP_CELLS + b] = i
    return starts


@numba.njit(inline="always", **KERNEL)
def map_cell(w0, w1, w2):
    """The start map's cell of the direction w ≠ 0: the face of its largest |component| (2·axis, +1 if negative),
    then the other two components over that one, (axis + 1, axis + 2) mod 3, each in MAP_CELLS equal parts."""
    a0, a1, a2 = abs(w0), abs(w1), abs(w2)
    if a0 >= a1 and a0 >= a2:
        axis, top, x, y = 0, w0, w1, w2
    elif a1 >= a2:
        axis, top, x, y = 1, w1, w2, w0
    else:
        axis, top, x, y = 2, w2, w0, w1
    face = 2 * axis + (1 if top < 0.0 else 0)
    big = abs(top)
    if not big > 0.0:
        return 0
    scale = 0.5 * MAP_CELLS / big
    i, j = int((x + big) * scale), int((y + big) * scale)       # |x|, |y| ≤ big: 0 to MAP_CELLS
    return (face * MAP_CELLS + min(i, MAP_CELLS - 1)) * MAP_CELLS + min(j, MAP_CELLS - 1)


@numba.njit(inline="always", **KERNEL)
def map_start(starts, direction, scale):
    """The start map's vertex for the level of ``direction`` (a body-frame vector, as g or g + T·d): the unit
    body's direction direction · scale."""
    return starts[map_cell(direction[0] * scale[0], direction[1] * scale[1], direction[2] * scale[2])]


@numba.njit(inline="always", **KERNEL)
def nearer(unit, scale, starts, g, y, work):
    """Where the descent to the lowest vertex starts: the last answer (``work[START]``) or the start map's vertex
    for g, the lower of the two (the body may have turned far since the last answer)."""
    last, mapped = int(work[START]), map_start(starts, g, scale)
    return mapped if height(unit, scale, g, y, mapped)[0] < height(unit, scale, g, y, last)[0] else last


@numba.njit(**JIT)
def farthest_candidates(unit):
    """The vertices of ``unit`` (n, 3) that may give the particle's farthest |p|² (p = unit[i] · scale), in
    index order, as int32.

    A particle's scale has |s0| ≥ |s1| ≥ |s2| > 0 (b/a ≤ 1, c/b ≤ 1), so |p|² = w2·A + (w1 − w2)·B + (w0 − w1)·C
    with w = s² and A = |u|², B = u0² + u1², C = u0², weights ≥ 0: a vertex that another exceeds by at least
    :data:`FAR_MARGIN` in A, B and C has a smaller |p|² by at least FAR_MARGIN·w0, beyond the round-off of either,
    and is never the farthest. Sorted by A, a vertex's dominators come before it; keeping the undominated ones
    (a dominated dominator is itself dominated by a kept one, by more) gives the list in n times its length."""
    n = unit.shape[0]
    keys = np.empty((n, 3))
    for i in range(n):
        c = unit[i, 0] * unit[i, 0]
        b = c + unit[i, 1] * unit[i, 1]
        keys[i, 0], keys[i, 1], keys[i, 2] = b + unit[i, 2] * unit[i, 2], b, c
    order = np.argsort(-keys[:, 0], kind="mergesort")
    kept = np.empty(n, dtype=np.int64)
    count = 0
    for i in order:
        beaten = False
        for k in range(count):
            j = kept[k]
            if (keys[j, 0] >= keys[i, 0] + FAR_MARGIN and keys[j, 1] >= keys[i, 1] + FAR_MARGIN
                    and keys[j, 2] >= keys[i, 2] + FAR_MARGIN):
                beaten = True
                break
        if not beaten:
            kept[count] = i
            count += 1
    return np.sort(kept[:count]).astype(np.int32)


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
def level(unit, scale, g, d, y, v, T, i):
    """Vertex i's level h + T·h' (T = 0: its height, bit for bit)."""
    h, p0, p1, p2 = height(unit, scale, g, y, i)
    if T == 0.0:
        return h
    return h + T * (v + (d[0] * p0 + d[1] * p1 + d[2] * p2))


@numba.njit(inline="always", **KERNEL)
def reach(direction, scale):
    """Σ |direction_k · scale_k| · 2: a bound on |direction·p| over the unit body (|unit| < 2 a per axis)."""
    return 2.0 * (abs(direction[0] * scale[0]) + abs(direction[1] * scale[1]) + abs(direction[2] * scale[2]))


@numba.njit(**KERNEL)
def descend(unit, scale, graph_start, graph, g, d, y, v, T, i):
    """(vertex, its level, its lowest neighbour's level): steepest descent of the level from vertex ``i`` to a
    vertex with no lower neighbour."""
    best = level(unit, scale, g, d, y, v, T, i)
    while True:
        here, around = i, np.inf
        for k in range(graph_start[here], graph_start[here + 1]):
            j = graph[k]
            x = level(unit, scale, g, d, y, v, T, j)
            around = min(around, x)
            if x < best:
                i, best = j, x
        if i == here:
            return i, best, around


@numba.njit(**KERNEL)
def band(unit, scale, graph_start, graph, g, d, y, v, T, limit, start, work):
    """The vertices connected to ``start`` through vertices of level at most ``limit``, ascending, into
    ``work[SLOTS + ROOM:START]``; returns their number, or −1 if ``start`` is above the limit or the walk would meet
    more than ROOM vertices (module doc). ``work[:SLOTS]`` is zero on entry and on return (:func:`clear`)."""
    slots, where, members = work[:SLOTS], work[SLOTS:SLOTS + ROOM], work[SLOTS + ROOM:START]
    if not level(unit, scale, g, d, y, v, T, start) <= limit:
        return -1
    slot = (int(start) * _HASH) & (SLOTS - 1)
    slots[slot] = start + 1.0
    where[0], members[0] = slot, start
    n_met, count, head = 1, 1, 0
    while head < count and n_met >= 0:
        i = int(members[head])
        head += 1
        for k in range(graph_start[i], graph_start[i + 1]):
            j = graph[k]
            slot = (int(j) * _HASH) & (SLOTS - 1)
            while slots[slot] != 0.0 and slots[slot] != j + 1.0:
                slot = (slot + 1) & (SLOTS - 1)
            if slots[slot] != 0.0:
                continue
            if n_met == ROOM:
                n_met = -n_met              # full: give up
                break
            slots[slot] = j + 1.0
            where[n_met] = slot
            n_met += 1
            if level(unit, scale, g, d, y, v, T, j) <= limit:
                members[count] = j
                count += 1
    for k in range(abs(n_met)):
        slots[int(where[k])] = 0.0
    if n_met < 0:
        return -1
    for k in range(1, count):            # insertion sort: a band holds a few vertices
        x = members[k]
        m = k - 1
        while m >= 0 and members[m] > x:
            members[m + 1] = members[m]
            m -= 1
        members[m + 1] = x
    return count


@numba.njit(**KERNEL)
def clear(work):
    """Zero the hash set of ``work`` (:data:`WALK_WORK`,): once per rebound, before its first walk."""
    for k in range(SLOTS):
        work[k] = 0.0


@numba.njit(inline="always", **KERNEL)
def member(work, count, k):
    """The k-th vertex a query takes: of the band (``count`` ≥ 0 of them), or of the whole hull (count −1)."""
    return int(work[SLOTS + ROOM + k]) if count >= 0 else k


@numba.njit(**KERNEL)
def walk_lowest(unit, scale, graph_start, graph, g, y, start, work):
    """(h_low, low): the lowest vertex (the first of equal ones), h = y + g·p (units of a), descending from vertex
    ``start``. Every vertex as low as the descent's end is walked to from it (module doc); with no neighbour that
    low, the end is the answer without a walk."""
    zero = (0.0, 0.0, 0.0)
    m, h_m, around = descend(unit, scale, graph_start, graph, g, zero, y, 0.0, 0.0, start)
    limit = h_m + BAND * (abs(y) + reach(g, scale))
    if around > limit:
        return h_m, m
    count = band(unit, scale, graph_start, graph, g, zero, y, 0.0, 0.0, limit, m, work)
    h_low, low = np.inf, -1
    for k in range(count if count >= 0 else unit.shape[0]):
        i = member(work, count, k)
        h = height(unit, scale, g, y, i)[0]
        if h < h_low:
            h_low, low = h, i
    return h_low, low


@numba.njit(**KERNEL)
def walk_contact_sums(unit, scale, graph_start, graph, g, d, y, v, limit, low, work):
    """Over the vertices with h ≤ ``limit`` in index order (:func:`direct_model.flight.choose_contact`'s set):
    (count, Σp (3), Σh', the lowest approaching one or −1); h = y + g·p, h' = v + d·p; ``low`` the lowest
    vertex."""
    found = band(unit, scale, graph_start, graph, g, d, y, v, 0.0, limit + BAND * (abs(y) + reach(g, scale)), low,
                 work)
    count = 0
    p0s, p1s, p2s, rate = 0.0, 0.0, 0.0, 0.0
    best, best_h = -1, np.inf
    for k in range(found if found >= 0 else unit.shape[0]):
        i = member(work, found, k)
        h, p0, p1, p2 = height(unit, scale, g, y, i)
        if h <= limit:
            h1 = v + (d[0] * p0 + d[1] * p1 + d[2] * p2)
            count += 1
            p0s, p1s, p2s, rate = p0s + p0, p1s + p1, p2s + p2, rate + h1
            if h1 < 0.0 and h < best_h:
                best, best_h = i, h
    return count, p0s, p1s, p2s, rate, best


@numba.njit(**KERNEL)
def walk_farthest(unit, scale, far):
    """max over the vertices of |p|² (p = unit[i] · scale), as :func:`direct_model.shape_arrays.bounding_radius`
    forms it: over the candidates ``far`` (:func:`farthest_candidates`)."""
    r2 = 0.0
    for k in range(far.shape[0]):
        p0, p1, p2 = vertex(unit, scale, far[k])
        r2 = max(r2, p0 ** 2 + p1 ** 2 + p2 ** 2)
    return r2
