"""The support point of a convex grain: hill climbing the hull's vertex graph against a scan of every vertex.

The free flight asks for the lowest vertex many times while the body turns a little between two asks (§5); the
climb starts from the last answer. Hulls of 8, 24, 64 and 256 vertices (random points on an ellipsoid, every one
a vertex), a direction turning by --turn radians per query; prints ns per query for each and the ratio.

    python benchmarks/bench_support.py                  # the default: 200 000 queries per hull
    python benchmarks/bench_support.py --queries 20000 --turn 0.3
"""

import argparse
import json
import sys
import time

import numba
import numpy as np

from direct_model.polyhedron import vertex_graph
from direct_model.support import support_vertex
from machine import machine_info
from tablegen.tabulation.grain_files import convex_hull

SIZES = (8, 24, 64, 256)


@numba.njit(cache=True)
def _climb_along(vertices, start, neighbours, directions):
    """Sum of the answers' indices (keeps the work observable) for a sequence of directions, from the last answer."""
    last, total = 0, 0
    for i in range(directions.shape[0]):
        last = support_vertex(vertices, start, neighbours, directions[i, 0], directions[i, 1], directions[i, 2], last)
        total += last
    return total


@numba.njit(cache=True)
def _scan_along(vertices, directions):
    total = 0
    for i in range(directions.shape[0]):
        best, top = 0, -np.inf
        d0, d1, d2 = directions[i, 0], directions[i, 1], directions[i, 2]
        for j in range(vertices.shape[0]):
            h = d0 * vertices[j, 0] + d1 * vertices[j, 1] + d2 * vertices[j, 2]
            if h > top:
                best, top = j, h
        total += best
    return total


def _turning(n, turn, seed):
    """Unit directions along a random walk on the sphere, ``turn`` radians per step."""
    rng = np.random.default_rng(seed)
    d = np.empty((n, 3))
    d[0] = rng.normal(size=3)
    steps = rng.normal(size=(n, 3)) * turn / np.sqrt(3.0)
    for i in range(1, n):
        d[i] = d[i - 1] / np.linalg.norm(d[i - 1]) + steps[i]
    return d / np.linalg.norm(d, axis=1)[:, None]


def _ns_per_query(run, args, queries):
    run(*args)                                         # compile and warm up
    best = np.inf
    for _ in range(3):
        t0 = time.perf_counter()
        run(*args)
        best = min(best, time.perf_counter() - t0)
    return 1e9 * best / queries


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--queries", type=int, default=200_000, help="queries per hull (default: 200000)")
    parser.add_argument("--turn", type=float, default=0.05, help="radians the direction turns per query")
    parser.add_argument("--json", default=None, help="also write the figures to this JSON file")
    args = parser.parse_args(argv)
    directions = _turning(args.queries, args.turn, seed=1)
    results = {}
    print(json.dumps(machine_info()))
    for n in SIZES:
        rng = np.random.default_rng(n)
        points = rng.normal(size=(n, 3))
        vertices, triangles, _ = convex_hull(points / np.linalg.norm(points, axis=1)[:, None] * (1, 0.7, 0.5), "bench")
        start, neighbours = vertex_graph(triangles, len(vertices))
        climb = _ns_per_query(_climb_along, (vertices, start, neighbours, directions), args.queries)
        scan = _ns_per_query(_scan_along, (vertices, directions), args.queries)
        assert _climb_along(vertices, start, neighbours, directions) == _scan_along(vertices, directions)
        results[n] = {"climb_ns": climb, "scan_ns": scan, "scan_over_climb": scan / climb}
        print(f"{n:4d} vertices: climb {climb:7.1f} ns/query, scan {scan:7.1f} ns/query, "
              f"scan/climb {scan / climb:5.2f}")
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"turn": args.turn, "queries": args.queries, "results": results}, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
