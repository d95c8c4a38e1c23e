"""Cost per rebound of the direct model against the hull size of a convex grain (docs/model.md §9).

Random convex grains of 8, 24, 64, 256, 1000 and 10 000 hull vertices (random points on a sphere, every one a
vertex; a hull of more than 64 walked over its vertex graph, direct_model.hull_walk), two scanned-like grains (the
hulls of 2500 and 26 000 points of examples/grains/simplification.py's bumpy, noisy ellipsoid: about 1200 and
2500 vertices), all in their canonical frame, stretched per particle by the families' b/a, c/b law, both hands,
and the prism for reference,
through the run-time kernel (``direct_model.runtime.rebound_model_frame``: the whole rebound from its 7
uniforms, what a direct hit costs, the caller's frame aside) on one thread, in numba and in C (the same kernel,
``rbs_rebound_model_frame``, in a C loop: native/bench/rbs_bench_grains.c, built by CMake into a temporary folder
or taken from ``--build-dir``; ``--no-native`` leaves it out). Its outputs are checked against numba's, bit for
bit. Printed per shape and set of states:
µs per rebound (this thread's CPU time, which leaves out other jobs on a shared machine; the best of --repeats
rounds, each round timing every shape in turn, so a busy spell of the machine weighs on all shapes alike), the
ratio to the prism's, collisions and contact-search steps per rebound, trapped and failed counts. States:
'random, 0' (α1 uniform in [5°, 90°], |V⁻| uniform in 50–300 m/s, Ω⁻ = 0, the tables' case) and 'random, spin'
(the same with |Ω⁻|a/|V⁻| uniform in [0, 1.2], random direction). The targets are reported (figures only: the
exit code does not depend on them): a 64-vertex grain within 2× the prism's cost per rebound, a 1000-vertex
grain within 1.5× and a 10 000-vertex grain within 2.5×, in numba and in C.

    python benchmarks/bench_grains.py                        # 20000 states per row (about a minute)
    python benchmarks/bench_grains.py --states 2000 --repeats 1 --json grains.json
    python benchmarks/bench_grains.py --no-native            # numba alone
"""

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numba
import numpy as np

from data_schema.samples import STATUS_FAILED, STATUS_TRAPPED
from direct_model.registry import built_in_shape, grain
from direct_model.runtime import SCRATCH_SIZE, U_PER_REBOUND, model_parameters, rebound_model_frame
from direct_model.shape_arrays import shape_arrays
from direct_model.shapes import DEFAULT_KAPPA, SHAPES, AspectRatioLaw, second_moment_factors
from direct_model.simulate import DEFAULT_CONTACT_TOL, DEFAULT_MAX_STEPS, DEFAULT_N_MAX, DEFAULT_SET_TOL
from direct_model.wall import CORUNDUM_ON_STEEL
from bench_native import build_native  # benchmarks/, next to this script
from machine import machine_info

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "examples" / "grains"))
from simplification import scanned_points  # noqa: E402  (the scanned-like grain of the simplification figure)
from tablegen.tabulation.grain_files import convex_hull

SIZES = (8, 24, 64, 256, 1000, 10000)
SCANNED = (2500, 26000)     # points of a scanned-like grain (examples/grains/simplification.py)
SEED = 20261125
TARGETS = {64: 2.0, 1000: 1.5, 10000: 2.5}     # hull vertices: the most a rebound may cost, in prism rebounds


def shapes():
    """(names, vertex counts, shape arrays): the prism (the family, its factor s), one random grain per size, then
    the scanned-like grains (named by their vertex counts)."""
    law = AspectRatioLaw()
    records = [built_in_shape("prism", aspect=law)]
    for n in SIZES:
        points = np.random.default_rng(n).normal(size=(n, 3))
        vertices, triangles, _ = convex_hull(points / np.linalg.norm(points, axis=1)[:, None], f"grain_{n}")
        assert len(vertices) == n
        records.append(grain(f"grain_{n}", vertices, triangles, aspect=law, both_hands=True))
    for n in SCANNED:
        vertices, triangles, _ = convex_hull(scanned_points(points=n), "scanned")
        records.append(grain(f"scanned_{len(vertices)}", vertices, triangles, aspect=law, both_hands=True))
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
def _rebounds(params, arrays, shape, model, u, counts, out):
    """rebound_model_frame on every row; counts[i] = (status, collisions, search steps), out[i] = (V⁺, Ω⁺)."""
    scratch = np.empty(SCRATCH_SIZE)
    for i in range(model.shape[0]):
        done = rebound_model_frame(
            params, arrays, shape, model[i, 0], model[i, 1], model[i, 2], model[i, 3], model[i, 4], u[i], scratch)
        counts[i, 0], counts[i, 1], counts[i, 2] = done.status, done.n_collisions, done.n_search_steps
        for k in range(3):
            out[i, k], out[i, 3 + k] = done.V[k], done.Omega[k]


# rbs_shape_arrays' arrays in its order (native/src/shapes.h), as rbs_bench_grains reads them
C_ARRAYS = ("kind", "vertex_start", "vertices", "second_moments", "aspect", "aspect_cdf", "both_hands",
            "half_extents", "graph_start", "graph", "starts", "far_start", "far")


def c_us(program: Path, params, arrays, model, u, repeats: int, folder: Path) -> tuple:
    """(µs per rebound of each shape, each shape's (m, 6) V⁺ and Ω⁺) of rbs_rebound_model_frame in the C loop
    of native/bench/rbs_bench_grains.c on the same states and uniforms."""
    shapes_path, states_path, out_path = folder / "shapes.bin", folder / "states.bin", folder / "out.bin"
    with open(shapes_path, "wb") as f:
        f.write(np.int64(len(arrays.kind)).tobytes())
        for name in C_ARRAYS:
            raw = np.ascontiguousarray(getattr(arrays, name)).tobytes()
            f.write(np.int64(len(raw)).tobytes() + raw)
    with open(states_path, "wb") as f:
        f.write(np.int64(len(model)).tobytes())
        for x in (model, u, params):
            f.write(np.ascontiguousarray(x, dtype=np.float64).tobytes())
    done = subprocess.run([str(program), str(shapes_path), str(states_path), str(repeats), str(out_path)],
                          capture_output=True, text=True)
    if done.returncode != 0:
        raise SystemExit(f"rbs_bench_grains failed:\n{done.stderr}")
    m, raw = len(model), out_path.read_bytes()
    size = 48 * m + m
    outputs = [np.column_stack([np.frombuffer(raw, np.float64, 3 * m, k * size).reshape(m, 3),
                                np.frombuffer(raw, np.float64, 3 * m, k * size + 24 * m).reshape(m, 3)])
               for k in range(len(arrays.kind))]
    return np.array(json.loads(done.stdout)), outputs


def best_us(params, arrays, model, u, counts, out, repeats) -> np.ndarray:
    """µs per rebound of every shape, the best of ``repeats`` rounds (one run of each shape per round) in this
    thread's CPU time; counts[shape] receives each shape's (status, collisions, steps) per row, out[shape] its
    (V⁺, Ω⁺)."""
    best = np.full(len(arrays.kind), np.inf)
    for _ in range(repeats):
        for shape in range(len(best)):
            t0 = time.thread_time()
            _rebounds(params, arrays, shape, model, u, counts[shape], out[shape])
            best[shape] = min(best[shape], time.thread_time() - t0)
    return 1e6 * best / len(model)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--states", type=int, default=20_000, help="incident states per row (default 20000)")
    parser.add_argument("--repeats", type=int, default=3, help="timed runs per row, the best kept (default 3)")
    parser.add_argument("--json", metavar="FILE", help="also write the figures as JSON to FILE")
    parser.add_argument("--no-native", action="store_true", help="numba alone (no C loop, no CMake build)")
    parser.add_argument("--build-dir", type=Path, help="a build of native/ holding rbs_bench_grains (else built here)")
    args = parser.parse_args(argv)
    params = model_parameters(AspectRatioLaw(), DEFAULT_KAPPA, DEFAULT_N_MAX, CORUNDUM_ON_STEEL, DEFAULT_CONTACT_TOL,
                              DEFAULT_SET_TOL, DEFAULT_MAX_STEPS, second_moment_factors(DEFAULT_KAPPA))
    names, counts_v, arrays = shapes()
    info = machine_info()
    print("Direct model cost per rebound against hull size (rebound_model_frame, one thread, numba and C)")
    for key, value in info.items():
        print(f"  {key:22s} {value}")
    sets = {"random, 0": states(args.states, 0.0, SEED), "random, spin": states(args.states, 1.0, SEED + 1)}
    counts = np.empty((len(names), args.states, 3), dtype=np.int64)
    out = np.empty((len(names), args.states, 6))
    _rebounds(params, arrays, 0, *(x[:8] for x in sets["random, 0"]), counts[0, :8], out[0, :8])   # warm-up: compile
    rows = []
    header = f"{'shape':<12} {'vertices':>8} {'states':<12} {'numba us':>8} {'/prism':>6} {'C us':>6} {'/prism':>6} " \
             f"{'coll':>5} {'steps':>6} {'trapped':>7} {'failed':>6}"
    print(f"  {args.states} states per row, best of {args.repeats}\n\n{header}\n{'-' * len(header)}")
    with tempfile.TemporaryDirectory() as tmp:
        program = None
        if not args.no_native:
            folder = args.build_dir if args.build_dir is not None else build_native(Path(tmp) / "build",
                                                                                  "rbs_bench_grains")
            program = folder / "rbs_bench_grains"
        for set_name, (model, u) in sets.items():
            times = best_us(params, arrays, model, u, counts, out, args.repeats)
            c_times, same = np.full(len(names), np.nan), None
            if program is not None:
                c_times, c_out = c_us(program, params, arrays, model, u, args.repeats, Path(tmp))
                same = all(np.array_equal(mine, theirs, equal_nan=True) for mine, theirs in zip(out, c_out))
            for shape, (name, nv) in enumerate(zip(names, counts_v)):
                us, c_time, c = float(times[shape]), float(c_times[shape]), counts[shape]
                row = {"shape": name, "vertices": nv, "states": set_name, "us_per_rebound": us,
                       "over_prism": us / float(times[0]), "c_us_per_rebound": c_time,
                       "c_over_prism": c_time / float(c_times[0]), "collisions_per_rebound": float(c[:, 1].mean()),
                       "search_steps_per_rebound": float(c[:, 2].mean()),
                       "trapped": int(np.sum(c[:, 0] == STATUS_TRAPPED)),
                       "failed": int(np.sum(c[:, 0] == STATUS_FAILED)), "c_equals_numba": same}
                rows.append(row)
                print(f"{name:<12} {nv:>8d} {set_name:<12} {us:>8.2f} {row['over_prism']:>6.2f} {c_time:>6.2f} "
                      f"{row['c_over_prism']:>6.2f} {row['collisions_per_rebound']:>5.2f} "
                      f"{row['search_steps_per_rebound']:>6.1f} {row['trapped']:>7d} {row['failed']:>6d}", flush=True)
            if same is not None:
                print(f"  C's V+ and Omega+ equal numba's, bit for bit, for every shape: {'yes' if same else 'NO'}")
    print()
    for size, ratio in TARGETS.items():
        target = [r for r in rows if r["vertices"] == size and r["shape"].startswith("grain")]
        for key, runtime in (("over_prism", "numba"), ("c_over_prism", "C")):
            verdicts = [f"{r['states']} {r[key]:.2f}x ({'met' if r[key] <= ratio else 'NOT met'})" for r in target
                        if r[key] == r[key]]
            if verdicts:
                print(f"Target: a {size}-vertex grain within {ratio:g}x the prism's cost per rebound, {runtime}: "
                      + "; ".join(verdicts))
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"machine": info, "states": args.states, "repeats": args.repeats, "seed": SEED, "rows": rows},
                      f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
