"""The support point of a convex polyhedron: its vertex farthest along a direction (docs/model.md §4, §9).

The contact point is the lowest vertex, the support point in −n; the next contact of a spinning body is sought
from the same vertex a moment later. On a convex polyhedron a vertex with no higher neighbour in the hull's
vertex graph is the highest of all (the support function is convex along every edge path), so climbing from
the last answer reaches it in a few steps when the direction has turned little, instead of scanning all n
vertices. Plain arrays: ``vertices`` (n, 3), the graph as ``neighbour_start`` (n + 1,) and ``neighbours``
(:func:`direct_model.polyhedron.vertex_graph`).
"""

import numba

from direct_model.options import JIT


@numba.njit(**JIT)
def support_vertex(vertices, neighbour_start, neighbours, d0, d1, d2, start):
    """Index of a vertex maximising (d0, d1, d2)·v, climbing the vertex graph from vertex ``start``.

    Steepest ascent: each step moves to the highest neighbour while one is strictly higher, so it ends, at a
    vertex whose height is the maximum (to round-off). ``vertices`` (n, 3) in any frame the direction is in.
    """
    best = start
    top = d0 * vertices[best, 0] + d1 * vertices[best, 1] + d2 * vertices[best, 2]
    while True:
        here = best
        for k in range(neighbour_start[here], neighbour_start[here + 1]):
            j = neighbours[k]
            h = d0 * vertices[j, 0] + d1 * vertices[j, 1] + d2 * vertices[j, 2]
            if h > top:
                best, top = j, h
        if best == here:
            return best
