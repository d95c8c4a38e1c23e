"""Throughput benchmark of the direct rebound model: the batch API (``direct_model.simulate.simulate``) and
the run-time kernel (``surrogate.kernels.rebound_direct_tuple``).

What is measured: the batch
---------------------------
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

What is measured: the run-time kernel
-------------------------------------
Microseconds per rebound of ``rebound_direct_tuple``, one particle per call in
an ``@njit`` loop on one thread, its 7 uniforms drawn per call from a xoshiro256+
state (``fill_uniforms``), as a solver would call it; per shape, at ``--states``
random incident states: α1 uniform in [5°, 90°], |V⁻| uniform in 50–300 m/s, a
random caller's frame, and Ω⁻ = 0 (the tables' case) or |Ω⁻|a/|V⁻| uniform in
[0, 1.2] in a random direction (the flight in is simulated), reported
separately. Where the time goes: the same states through the model-frame
rebound alone (``direct_model.runtime.rebound_model_frame``; the rest is the
frame, the checks and the uniforms), the same without the trapped particles
(each runs n_max collisions), and the mean collisions and contact-search steps
per rebound. Best of ``--repeats`` timings.

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
    PYTHONPATH=. python benchmarks/bench_direct.py --runtime  # the run-time kernel alone (about 20 s)

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

from data_schema.samples import STATUS_FAILED, STATUS_REBOUNDED, STATUS_TRAPPED
from direct_model.runtime import SCRATCH_SIZE, U_PER_REBOUND, model_parameters, rebound_model_frame
from direct_model.shapes import AspectRatioLaw, second_moment_factors
from direct_model.simulate import DEFAULT_CONTACT_TOL, DEFAULT_MAX_STEPS, DEFAULT_N_MAX, DEFAULT_SET_TOL, simulate
from direct_model.wall import CORUNDUM_ON_STEEL
from machine import machine_info  # benchmarks/machine.py, next to this script
from surrogate.kernels import fill_uniforms, impact_frame, rebound_direct_tuple, seed_state
from surrogate.kernels.frame import dot

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


RUNTIME_COLUMNS = (  # (header, width, format spec, key of the result row)
    ("shape", 12, "s", "shape"), ("spin", 5, "s", "spin"), ("n", 7, "d", "n"),
    ("us/rebound", 10, ".2f", "us_per_rebound"), ("model frame us", 14, ".2f", "us_model_frame"),
    ("untrapped us", 12, ".2f", "us_model_frame_untrapped"),
    ("coll/reb", 8, ".2f", "collisions_per_rebound"), ("steps/reb", 9, ".1f", "search_steps_per_rebound"),
    ("trapped", 7, "d", "trapped"), ("failed", 6, "d", "failed"),
)


@numba.njit
def _kernel_loop(params, V, n, a, omega, shape, state, status):
    """rebound_direct_tuple on every row, uniforms from ``state``: what a solver's loop does."""
    u = np.empty(U_PER_REBOUND)
    for i in range(V.shape[0]):
        fill_uniforms(state, u)
        status[i] = rebound_direct_tuple(params, (V[i, 0], V[i, 1], V[i, 2]), (n[i, 0], n[i, 1], n[i, 2]), a,
                                         (omega[i, 0], omega[i, 1], omega[i, 2]), shape, u)[0]


@numba.njit
def _model_frame_inputs(V, n, a, omega, state, u_all, model):
    """The uniforms the kernel loop draws and the model-frame inputs it builds, per row (untimed)."""
    for i in range(V.shape[0]):
        fill_uniforms(state, u_all[i])
        Vi, ni, Wi = (V[i, 0], V[i, 1], V[i, 2]), (n[i, 0], n[i, 1], n[i, 2]), (omega[i, 0], omega[i, 1], omega[i, 2])
        _, _, _, _, ex, ez = impact_frame(Vi, ni, u_all[i, 6])
        model[i, 0], model[i, 1] = dot(Vi, ex), dot(Vi, ni)
        model[i, 2], model[i, 3], model[i, 4] = a * dot(Wi, ex), a * dot(Wi, ni), a * dot(Wi, ez)


@numba.njit
def _model_frame_loop(params, model, shape, u_all, counts):
    """rebound_model_frame alone on the rows' model-frame inputs; counts[i] = (status, collisions, steps)."""
    scratch = np.empty(SCRATCH_SIZE)
    for i in range(model.shape[0]):
        st, n_coll, n_steps, _, _, _, _, _, _ = rebound_model_frame(
            params, shape, model[i, 0], model[i, 1], model[i, 2], model[i, 3], model[i, 4], u_all[i], scratch)
        counts[i, 0], counts[i, 1], counts[i, 2] = st, n_coll, n_steps


def random_states(m: int, spin: bool, seed: int):
    """m incident states (module doc): V (m, 3) m/s, n (m, 3) unit normals, Ω (m, 3) rad/s for a = 1 m."""
    rng = np.random.default_rng(seed)
    alpha1 = np.radians(rng.uniform(5.0, 90.0, m))
    speed = rng.uniform(50.0, 300.0, m)
    frames = np.linalg.qr(rng.normal(size=(m, 3, 3)))[0]           # random orthonormal frames
    local_V = np.c_[np.cos(alpha1), -np.sin(alpha1), np.zeros(m)] * speed[:, None]
    local_W = rng.normal(size=(m, 3))
    local_W *= (rng.uniform(0.0, 1.2, m) * speed / np.linalg.norm(local_W, axis=1))[:, None] * spin
    return (np.einsum("mij,mj->mi", frames, local_V), np.ascontiguousarray(frames[:, :, 1]),
            np.einsum("mij,mj->mi", frames, local_W))


def bench_runtime(shape_code, spin, m, repeats) -> dict:
    """µs per rebound of the run-time kernel at m random states of one shape (module doc)."""
    params = model_parameters(AspectRatioLaw(), 0.3, DEFAULT_N_MAX, CORUNDUM_ON_STEEL, DEFAULT_CONTACT_TOL,
                              DEFAULT_SET_TOL, DEFAULT_MAX_STEPS, second_moment_factors(0.3))
    V, n, W = random_states(m, spin, SEED + shape_code)
    status = np.empty(m, dtype=np.int8)
    best = math.inf
    for _ in range(repeats):
        state = seed_state(SEED)
        t0 = time.perf_counter()
        _kernel_loop(params, V, n, 1.0, W, shape_code, state, status)
        best = min(best, time.perf_counter() - t0)
    u_all, model, counts = np.empty((m, U_PER_REBOUND)), np.empty((m, 5)), np.empty((m, 3), dtype=np.int64)
    _model_frame_inputs(V, n, 1.0, W, seed_state(SEED), u_all, model)
    best_model = math.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        _model_frame_loop(params, model, shape_code, u_all, counts)
        best_model = min(best_model, time.perf_counter() - t0)
    ok = counts[:, 0] == STATUS_REBOUNDED
    rest = counts[:, 0] != STATUS_TRAPPED            # a trapped particle costs n_max collisions
    sub_model, sub_u, sub_counts = model[rest], u_all[rest], counts[rest]
    best_rest = math.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        _model_frame_loop(params, sub_model, shape_code, sub_u, sub_counts)
        best_rest = min(best_rest, time.perf_counter() - t0)
    return {"shape": SHAPES[shape_code], "spin": "yes" if spin else "0", "n": m,
            "us_per_rebound": 1e6 * best / m, "us_model_frame": 1e6 * best_model / m,
            "us_model_frame_untrapped": 1e6 * best_rest / max(1, int(rest.sum())),
            "collisions_per_rebound": float(counts[ok, 1].mean()),
            "search_steps_per_rebound": float(counts[ok, 2].mean()),
            "trapped": int(np.sum(status == STATUS_TRAPPED)), "failed": int(np.sum(status == STATUS_FAILED))}


def main_runtime(states: int, repeats: int) -> list:
    """Print and return the run-time kernel's figures (module doc)."""
    for code in range(len(SHAPES)):                  # warm-up: compile the loops
        bench_runtime(code, True, 16, 1)
    print(f"\nRun-time kernel (surrogate.kernels.rebound_direct_tuple), one thread, {states} random states per "
          f"row, best of {repeats}")
    header = " ".join(f"{h:{'<' if i == 0 else '>'}{w}}" for i, (h, w, _, _) in enumerate(RUNTIME_COLUMNS))
    print(header)
    print("-" * len(header))
    rows = []
    for code in range(len(SHAPES)):
        for spin in (False, True):
            rows.append(bench_runtime(code, spin, states, repeats))
            print(" ".join(f"{rows[-1][k]:{'<' if i == 0 else '>'}{w}{spec}}"
                           for i, (_, w, spec, k) in enumerate(RUNTIME_COLUMNS)), flush=True)
    print("spin: Ω⁻ = 0, or |Ω⁻|a/|V⁻| uniform in [0, 1.2] (flight in simulated). model frame us: the rebound\n"
          "alone (rebound_model_frame, the same uniforms); the rest of us/rebound is the frame, the checks and\n"
          "the uniforms. untrapped us: the same over the particles not trapped (a trapped one runs n_max\n"
          "collisions). Collisions and steps: means over rebounded particles.")
    return rows


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
    parser.add_argument("--runtime", action="store_true", help="the run-time kernel alone, not the batch")
    parser.add_argument("--states", type=int, default=None,
                        help="random incident states per run-time row (default 20000; --quick 500)")
    args = parser.parse_args(argv)
    repeats = args.repeats or (1 if args.quick else 3)
    min_time = args.min_time or (0.1 if args.quick else 1.0)
    states = args.states or (500 if args.quick else 20_000)

    info = machine_info()
    threads = info["numba_default_threads"]
    print("Direct rebound model throughput (direct_model.simulate, surrogate.kernels.rebound_direct_tuple)")
    for key, value in info.items():
        print(f"  {key:22s} {value}")
    runtime_rows = main_runtime(states, repeats)
    if args.runtime:
        _write_json(args.json, info, {"states": states, "repeats": repeats, "seed": SEED}, [], runtime_rows)
        return 0
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

    _write_json(args.json, info, {"speed_m_s": args.speed, "seed": SEED, "repeats": repeats, "min_time_s": min_time,
                                  "quick": args.quick, "target_per_core": TARGET_PER_CORE,
                                  "target_alpha1_deg": TARGET_ALPHA1, "states": states}, rows, runtime_rows)
    return 0


def _write_json(path, info, settings, rows, runtime_rows) -> None:
    """The figures as JSON (batch rows, run-time kernel rows), if a path was given."""
    if path:
        with open(path, "w") as f:
            json.dump({"machine": info, "threading_layer": numba.threading_layer(), "settings": settings,
                       "results": rows, "runtime": runtime_rows}, f, indent=2)
        print(f"figures written to {path}")


if __name__ == "__main__":
    sys.exit(main())
