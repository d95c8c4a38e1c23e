"""Throughput benchmark of the direct rebound model (``direct_model.simulate.simulate``).

What is measured
----------------
For each shape and incidence angle α1 (default: the four shapes at 45° and
90°, |V⁻| = 200 m/s, Ω⁻ = 0) this script prints:

* rebounds/s per core: particles simulated per second of wall-clock time with
  numba limited to one thread (``numba.set_num_threads(1)``). Every particle
  counts, whatever its status; the time covers the whole ``simulate`` call
  (NumPy input draws + numba kernel + result assembly);
* rebounds/s on all cores: the same with numba's default thread count (the
  count used is printed);
* collisions/rebound and steps/rebound: the means of ``n_collisions`` and of
  ``extra["n_search_steps"]`` over the particles that rebounded. A search step is
  one instant examined by the contact search; every step but the first of each
  flight evaluates the exact free-flight orientation;
* the number of trapped and failed particles;
* cpu/wall: process CPU time over wall time of the one-thread timing. It is
  about 1 on an idle machine; well below 1 means other processes took the CPU
  and the rates are pessimistic (the load average is printed too);
* the target, 10⁵ rebounds/s per core at α1 = 45°, and whether each shape meets
  it. This is only printed: the exit code does not depend on it.

How
---
First a small run of each shape compiles the kernels (warm-up). Then, for each
configuration, pilot runs on one thread (grown until one takes ≥ 1/5 of
``--min-time``) estimate the rate, and n is chosen so that a timed run takes
about 1.2 × ``--min-time`` seconds on one thread (column ``t1 s``); the
all-cores timing uses n × threads particles. Each timing is the best of
``--repeats`` runs measured with ``time.perf_counter``. A fixed seed makes the
counts and means reproducible. The output starts with the machine details:
platform, CPU model, CPU count, Python, NumPy and numba versions, numba's
threading layer and the load average.

Run from the repository root::

    PYTHONPATH=. python benchmarks/bench_direct.py            # full run (about a minute)
    PYTHONPATH=. python benchmarks/bench_direct.py --quick    # smoke run
    PYTHONPATH=. python benchmarks/bench_direct.py --json bench.json

If the numbers look odd after kernel edits, delete numba's cache files
(``*.nbi``, ``*.nbc``) and rerun.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time

import numba
import numpy as np

from data_schema.samples import STATUS_FAILED, STATUS_TRAPPED
from machine import machine_info  # benchmarks/machine.py, next to this script
from direct_model.simulate import simulate

SHAPES = ("ellipsoid", "prism", "cut_prism", "tetrahedron")
TARGET_PER_CORE = 1e5     # rebounds/s per core
TARGET_ALPHA1 = 45.0      # degrees
SEED = 20240601
COLUMNS = (  # (header, width, format spec, key of the result row)
    ("shape", 12, "s", "shape"), ("alpha1", 6, "g", "alpha1_deg"), ("n", 8, "d", "n"),
    ("t1 s", 5, ".2f", "time_1thread_s"), ("cpu/wall", 8, ".2f", "cpu_over_wall_1thread"),
    ("per core/s", 11, ".3g", "rate_per_core"), ("all cores/s", 12, ".3g", "rate_all_cores"),
    ("thr", 3, "d", "threads"), ("coll/reb", 8, ".3f", "collisions_per_rebound"),
    ("steps/reb", 9, ".1f", "search_steps_per_rebound"), ("trapped", 7, "d", "trapped"),
    ("failed", 6, "d", "failed"), ("target", 6, "s", "meets_target"),
)


def best_time(shape, alpha1, speed, n, threads, repeats):
    """Time ``repeats`` simulate calls on ``threads`` threads.

    Returns (wall, cpu, samples): the best wall-clock time (s), the process CPU
    time of that same run (s), and the last result.
    """
    saved = numba.get_num_threads()
    numba.set_num_threads(threads)
    try:
        best = (math.inf, math.inf)
        for _ in range(repeats):
            w0, c0 = time.perf_counter(), time.process_time()
            samples = simulate(shape, alpha1, speed, n, seed=SEED, omega_in=(0.0, 0.0, 0.0))
            best = min(best, (time.perf_counter() - w0, time.process_time() - c0))
    finally:
        numba.set_num_threads(saved)
    return (*best, samples)


def bench_config(shape, alpha1, speed, threads, min_time, repeats, pilot_n=1000) -> dict:
    """Time one (shape, α1, speed) configuration, per core and on ``threads`` threads."""
    n = pilot_n                             # grow the pilot until it takes >= min_time / 5
    while (pilot_t := best_time(shape, alpha1, speed, n, 1, 1)[0]) < 0.2 * min_time:
        n = math.ceil(n * min(10.0, max(2.0, 0.3 * min_time / pilot_t)))
    n = math.ceil(1.2 * min_time * n / pilot_t)   # 1.2: margin, the pilot's rate is rough
    t1, cpu1, samples = best_time(shape, alpha1, speed, n, 1, repeats)
    tall, _, _ = best_time(shape, alpha1, speed, n * threads, threads, repeats)
    ok = samples.rebounded

    def mean(x):
        return float(np.mean(x[ok])) if ok.any() else float("nan")

    return {"shape": shape, "alpha1_deg": alpha1, "speed_m_s": speed, "n": n,
            "time_1thread_s": t1, "rate_per_core": n / t1,
            "cpu_time_1thread_s": cpu1, "cpu_over_wall_1thread": cpu1 / t1,
            "threads": threads, "n_all": n * threads, "time_all_s": tall,
            "rate_all_cores": n * threads / tall,
            "collisions_per_rebound": mean(samples.n_collisions),
            "search_steps_per_rebound": mean(samples.extra["n_search_steps"]),
            "rebounded": int(ok.sum()),
            "trapped": int(np.sum(samples.status == STATUS_TRAPPED)),
            "failed": int(np.sum(samples.status == STATUS_FAILED)),
            "meets_target": target_verdict(alpha1, n / t1)}


def target_verdict(alpha1, rate_per_core) -> str:
    """'yes'/'NO' at the target angle, '-' elsewhere."""
    if alpha1 != TARGET_ALPHA1:
        return "-"
    return "yes" if rate_per_core >= TARGET_PER_CORE else "NO"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help="small n, 1 repeat: a smoke run")
    parser.add_argument("--shapes", nargs="+", default=list(SHAPES),
                        choices=list(SHAPES) + ["mix"], metavar="SHAPE",
                        help="any of ellipsoid prism cut_prism tetrahedron mix (default: the first four)")
    parser.add_argument("--alpha1", nargs="+", type=float, default=[45.0, 90.0],
                        help="incidence angles α1 in degrees (default: 45 90)")
    parser.add_argument("--speed", type=float, default=200.0, help="|V⁻| in m/s (default: 200)")
    parser.add_argument("--repeats", type=int, default=None,
                        help="timed runs per figure, the best kept (default 3; --quick 1)")
    parser.add_argument("--min-time", type=float, default=None,
                        help="seconds per timed run, at least about (default 1; --quick 0.1)")
    parser.add_argument("--json", metavar="FILE", help="also write the figures as JSON to FILE")
    args = parser.parse_args(argv)
    repeats = args.repeats or (1 if args.quick else 3)
    min_time = args.min_time or (0.1 if args.quick else 1.0)

    info = machine_info()
    threads = info["numba_default_threads"]
    print("Direct rebound model throughput (direct_model.simulate)")
    for key, value in info.items():
        print(f"  {key:22s} {value}")
    print(f"  speed |V-| = {args.speed:g} m/s, omega_in = 0, seed = {SEED}, "
          f"best of {repeats}, >= {min_time:g} s per timing")
    print(f"  target: {TARGET_PER_CORE:.0e} rebounds/s per core at alpha1 = {TARGET_ALPHA1:g} deg")

    for shape in args.shapes:                       # warm-up: compile the kernels
        simulate(shape, args.alpha1[0], args.speed, 64, seed=SEED)
    print(f"  threading layer        {numba.threading_layer()}\n")

    header = " ".join(f"{h:{'<' if i == 0 else '>'}{w}}" for i, (h, w, _, _) in enumerate(COLUMNS))
    print(header)
    print("-" * len(header))
    rows = []
    for shape in args.shapes:
        for alpha1 in args.alpha1:
            rows.append(bench_config(shape, alpha1, args.speed, threads, min_time, repeats))
            print(" ".join(f"{rows[-1][k]:{'<' if i == 0 else '>'}{w}{spec}}"
                           for i, (_, w, spec, k) in enumerate(COLUMNS)), flush=True)
    print(f"\ntarget {TARGET_PER_CORE:.0e} rebounds/s per core at alpha1 = {TARGET_ALPHA1:g} deg: "
          f"'yes' met, 'NO' not met, '-' not a target angle.\n"
          "Means are over rebounded particles. cpu/wall = process CPU time / wall time of the\n"
          "one-thread timing: about 1 on an idle machine; well below 1, other work took the CPU\n"
          "and the rates are pessimistic.")

    if args.json:
        with open(args.json, "w") as f:
            json.dump({"machine": info, "threading_layer": numba.threading_layer(),
                       "settings": {"speed_m_s": args.speed, "seed": SEED, "repeats": repeats,
                                    "min_time_s": min_time, "quick": args.quick,
                                    "target_per_core": TARGET_PER_CORE,
                                    "target_alpha1_deg": TARGET_ALPHA1},
                       "results": rows}, f, indent=2)
        print(f"figures written to {args.json}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
