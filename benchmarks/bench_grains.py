"""Cost per rebound of the direct model against the hull size of a convex grain (docs/model.md §9).

Random convex grains of 8, 24, 64, 256, 1000 and 10 000 hull vertices (random points on a sphere, every one a
vertex; a hull of more than 64 walked over its vertex graph, direct_model.hull_walk; in their
canonical frame, stretched per particle by the families' b/a, c/b law, both hands) and the prism for reference,
through the run-time kernel (``direct_model.runtime.rebound_model_frame``: the whole rebound from its 7
uniforms, what a direct hit costs, the caller's frame aside) on one thread. Printed per shape and set of states:
µs per rebound (this thread's CPU time, which leaves out other jobs on a shared machine; the best of --repeats
rounds, each round timing every shape in turn, so a busy spell of the machine weighs on all shapes alike), the
ratio to the prism's, collisions and contact-search steps per rebound, trapped and failed counts. States:
'random, 0' (α1 uniform in [5°, 90°], |V⁻| uniform in 50–300 m/s, Ω⁻ = 0, the tables' case) and 'random, spin'
(the same with |Ω⁻|a/|V⁻| uniform in [0, 1.2], random direction). The targets are reported (figures only: the
exit code does not depend on them): a 64-vertex grain within 2× the prism's cost per rebound, a 1000-vertex
grain within 1.5× and a 10 000-vertex grain within 2.5×.

    python benchmarks/bench_grains.py                        # 20000 states per row (about a minute)
    python benchmarks/bench_grains.py --states 2000 --repeats 1 --json grains.json
"""

import argparse
import json
import sys
import time

import numba
import numpy as np

from data_schema.samples import STATUS_FAILED, STATUS_TRAPPED
from direct_model.registry import built_in_shape, grain
from direct_model.runtime import SCRATCH_SIZE, U_PER_REBOUND, model_parameters, rebound_model_frame
from direct_model.shape_arrays import shape_arrays
from direct_model.shapes import DEFAULT_KAPPA, SHAPES, AspectRatioLaw, second_moment_factors
from direct_model.simulate import DEFAULT_CONTACT_TOL, DEFAULT_MAX_STEPS, DEFAULT_N_MAX, DEFAULT_SET_TOL
from direct_model.wall import CORUNDUM_ON_STEEL
from machine import machine_info  # benchmarks/machine.py, next to this script
from tablegen.tabulation.grain_files import convex_hull

SIZES = (8, 24, 64, 256, 1000, 10000)
SEED = 20261125
TARGETS = {64: 2.0, 1000: 1.5, 10000: 2.5}     # hull vertices: the most a rebound may cost, in prism rebounds


def shapes():
    """(names, vertex counts, shape arrays): the prism (the family, its factor s) and one random grain per size."""
    law = AspectRatioLaw()
    records = [built_in_shape("prism", aspect=law)]
    for n in SIZES:
        points = np.random.default_rng(n).normal(size=(n, 3))
        vertices, triangles, _ = convex_hull(points / np.linalg.norm(points, axis=1)[:, None], f"grain_{n}")
        assert len(vertices) == n
        records.append(grain(f"grain_{n}", vertices, triangles, aspect=law, both_hands=True))
    factor = {"prism": second_moment_factors(DEFAULT_KAPPA)[SHAPES.index("prism")]}
    return [r.name for r in records], [len(r.vertices) for r in records], shape_arrays(records, factor)


def states(m, spin, seed):
    """m incident states in the model frame, (m, 5): vt, vn (m/s), Ω⁻a (m/s, 3); and (m, 7) uniforms."""
    rng = np.random.default_rng(seed)
    alpha1, speed = np.radians(rng.uniform(5.0, 90.0, m)), rng.uniform(50.0, 300.0, m)
    omega = rng.normal(size=(m, 3))
    omega *= (spin * rng.uniform(0.0, 1.2, m) * speed / np.linalg.norm(omega, axis=1))[:, None]
    model = np.column_stack([speed * np.cos(alpha1), -speed * np.sin(alpha1), omega])
    return model, rng.random((m, U_PER_REBOUND))


@numba.njit
def _rebounds(params, arrays, shape, model, u, counts):
    """rebound_model_frame on every row; counts[i] = (status, collisions, search steps)."""
    scratch = np.empty(SCRATCH_SIZE)
    for i in range(model.shape[0]):
        done = rebound_model_frame(
            params, arrays, shape, model[i, 0], model[i, 1], model[i, 2], model[i, 3], model[i, 4], u[i], scratch)
        counts[i, 0], counts[i, 1], counts[i, 2] = done.status, done.n_collisions, done.n_search_steps


def best_us(params, arrays, model, u, counts, repeats) -> np.ndarray:
    """µs per rebound of every shape, the best of ``repeats`` rounds (one run of each shape per round) in this
    thread's CPU time; counts[shape] receives each shape's (status, collisions, steps) per row."""
    best = np.full(len(arrays.kind), np.inf)
    for _ in range(repeats):
        for shape in range(len(best)):
            t0 = time.thread_time()
            _rebounds(params, arrays, shape, model, u, counts[shape])
            best[shape] = min(best[shape], time.thread_time() - t0)
    return 1e6 * best / len(model)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--states", type=int, default=20_000, help="incident states per row (default 20000)")
    parser.add_argument("--repeats", type=int, default=3, help="timed runs per row, the best kept (default 3)")
    parser.add_argument("--json", metavar="FILE", help="also write the figures as JSON to FILE")
    args = parser.parse_args(argv)
    params = model_parameters(AspectRatioLaw(), DEFAULT_KAPPA, DEFAULT_N_MAX, CORUNDUM_ON_STEEL, DEFAULT_CONTACT_TOL,
                              DEFAULT_SET_TOL, DEFAULT_MAX_STEPS, second_moment_factors(DEFAULT_KAPPA))
    names, counts_v, arrays = shapes()
    info = machine_info()
    print("Direct model cost per rebound against hull size (direct_model.runtime.rebound_model_frame, one thread)")
    for key, value in info.items():
        print(f"  {key:22s} {value}")
    sets = {"random, 0": states(args.states, 0.0, SEED), "random, spin": states(args.states, 1.0, SEED + 1)}
    counts = np.empty((len(names), args.states, 3), dtype=np.int64)
    _rebounds(params, arrays, 0, *(x[:8] for x in sets["random, 0"]), counts[0, :8])      # warm-up: compile
    rows = []
    header = f"{'shape':<10} {'vertices':>8} {'states':<12} {'us/rebound':>10} {'/prism':>7} {'coll':>6} " \
             f"{'steps':>7} {'trapped':>7} {'failed':>6}"
    print(f"  {args.states} states per row, best of {args.repeats}\n\n{header}\n{'-' * len(header)}")
    for set_name, (model, u) in sets.items():
        times = best_us(params, arrays, model, u, counts, args.repeats)
        for shape, (name, nv) in enumerate(zip(names, counts_v)):
            us, c = float(times[shape]), counts[shape]
            row = {"shape": name, "vertices": nv, "states": set_name, "us_per_rebound": us,
                   "over_prism": us / float(times[0]), "collisions_per_rebound": float(c[:, 1].mean()),
                   "search_steps_per_rebound": float(c[:, 2].mean()),
                   "trapped": int(np.sum(c[:, 0] == STATUS_TRAPPED)), "failed": int(np.sum(c[:, 0] == STATUS_FAILED))}
            rows.append(row)
            print(f"{name:<10} {nv:>8d} {set_name:<12} {us:>10.2f} {row['over_prism']:>7.2f} "
                  f"{row['collisions_per_rebound']:>6.2f} {row['search_steps_per_rebound']:>7.1f} "
                  f"{row['trapped']:>7d} {row['failed']:>6d}", flush=True)
    print()
    for size, ratio in TARGETS.items():
        target = [r for r in rows if r["vertices"] == size and r["shape"].startswith("grain")]
        verdicts = [f"{r['states']} {r['over_prism']:.2f}x ({'met' if r['over_prism'] <= ratio else 'NOT met'})"
                    for r in target]
        print(f"Target: a {size}-vertex grain within {ratio:g}x the prism's cost per rebound: " + "; ".join(verdicts))
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"machine": info, "states": args.states, "repeats": args.repeats, "seed": SEED, "rows": rows},
                      f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
