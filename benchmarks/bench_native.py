"""Cost per reflected state of the native runtime (native/, the C library) against the numba kernels.

One command, one run: the same N random incident states as ``bench_sampler.py`` (its generator, its seed
and its ``incident_states``; default N = 10⁶: α1 10–90°, |V⁻| over the table's range, random unit
normals, a = 0.1 mm, the four shapes with equal weights), timed five ways in ns per reflected state,
uniforms included:

* (C-1) C per particle: a C loop calling ``rbs_rng_fill`` (13 uniforms) and ``rbs_rebound`` (``RBS_METHOD_TABLE``,
  the uniforms given) per hit;
* (C-many) C many-particle call: ``rbs_draw_many`` on all the hits (uniforms from the rng's 32 lanes);
  breakdown: ``rbs_draw_many`` on pre-drawn uniforms, and the 13 uniforms alone;
* (N-1) numba per particle: ``table_rebound`` in an ``@njit`` loop with ``fill_uniforms``
  (bench_sampler's (b));
* (N-block) numba block kernel: ``table_rebound_many_rng`` (bench_sampler's (b-block));
* (C-GT) the Grant–Tabakoff sphere bounce of bench_sampler.py written in C, same loop (and numba's,
  bench_sampler's (d), for reference);
* (C-spin) every hit answered: (C-1)'s loop with ``rbs_rebound`` (method auto, uniforms from the rng) for
  non-spinning hits,
  where the table answers after the path decision (its overhead: (C-spin) − (C-1)), and in µs per hit for
  spinning ones (|Ω⁻| a/|V⁻| = 0.3 about random axes, the first 20 000 states), which the direct model
  answers.

The C loops run in a small C program (``native/bench/rbs_bench.c``) that CMake builds into a temporary
folder (or ``--build-dir``, a build of native/ with ``-DRBS_BUILD_BENCH=ON``); this script writes the
states to a file for it and reads its figures back. It also checks that the C many-particle call gives
numba's ``table_rebound_many_rng`` bits on these states. Targets reported: C per particle ≤ 150 ns, C many ≤
100 ns and ≤ 3 × the C Grant–Tabakoff bounce. The exit code does not depend on them.

Run from the repository root::

    PYTHONPATH=. python benchmarks/bench_native.py [--table T.h5] [--quick] [--json FILE]
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import bench_sampler  # noqa: E402  (benchmarks/, next to this script: its states, table and numba loops)
import surrogate  # noqa: E402
from machine import machine_info  # noqa: E402
from surrogate.kernels import table_rebound_many_rng  # noqa: E402

NATIVE = HERE.parent / "native"
TARGET_PER_PARTICLE_NS = 150.0
TARGET_MANY_NS = 100.0
TARGET_MANY_OVER_BOUNCE = 3.0


def build_native(folder: Path, target: str = "rbs_bench", shared: bool = False) -> Path:
    """Configure and build native/ (Release) with the bench program ``target`` into ``folder`` (and the shared
    library with ``shared``)."""
    for command in (["cmake", "-S", str(NATIVE), "-B", str(folder), "-DCMAKE_BUILD_TYPE=Release",
                     "-DRBS_BUILD_BENCH=ON", f"-DRBS_BUILD_SHARED={'ON' if shared else 'OFF'}"],
                    ["cmake", "--build", str(folder), "-j", "2", "--target", target]):
        done = subprocess.run(command, capture_output=True, text=True)
        if done.returncode != 0:
            raise SystemExit(f"{' '.join(command)} failed (native/install-deps.sh installs the tools):\n"
                             f"{done.stdout[-3000:]}\n{done.stderr[-3000:]}")
    return folder


def write_states(path: Path, V, n, a) -> None:
    with open(path, "wb") as f:
        f.write(np.int64(len(a)).tobytes())
        for x in (V, n, a):
            f.write(np.ascontiguousarray(x, dtype=np.float64).tobytes())


def best_ns(fn, count: int, repeats: int) -> float:
    fn()        # warm-up
    best = float("inf")
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - start)
    return best / count * 1e9


def verdict(ok: bool) -> str:
    return "met" if ok else "NOT met"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--table", metavar="PATH", help="use this table instead of building bench_sampler's")
    parser.add_argument("--quick", action="store_true", help="smoke run: N = 1e5, 1 repeat, 4096 particles per cell")
    parser.add_argument("-n", "--states", type=int, default=None, help="incident states N (default 1e6; --quick 1e5)")
    parser.add_argument("--repeats", type=int, default=None, help="timed runs per figure, the best kept (default 3)")
    parser.add_argument("--build-dir", metavar="DIR", help="a build of native/ holding rbs_bench (else built here)")
    parser.add_argument("--json", metavar="FILE", help="also write the figures as JSON to FILE")
    args = parser.parse_args(argv)
    count = args.states or (100_000 if args.quick else 1_000_000)
    repeats = args.repeats or (1 if args.quick else 3)

    print("Native runtime (C) cost per reflected state vs the numba kernels")
    for key, value in machine_info().items():
        print(f"  {key:22s} {value}")
    with tempfile.TemporaryDirectory(prefix="bench_native_") as tmp:
        tmp = Path(tmp)
        build = Path(args.build_dir) if args.build_dir else build_native(tmp / "build")
        program = build / "rbs_bench"
        if not program.is_file():
            raise SystemExit(f"{program} not found: build native/ with -DRBS_BUILD_BENCH=ON")
        if args.table:
            path = Path(args.table)
        else:
            print(f"  building bench_sampler's table ({4096 if args.quick else 20000} particles per cell) ...",
                  flush=True)
            path, _ = bench_sampler.build_bench_table(tmp, 4096 if args.quick else 20000)
        table = surrogate.load(path)
        data = table.kernel_data
        print(f"  table                  {path}: alpha1 [{', '.join(f'{x:g}' for x in table.alpha1_deg)}] deg; "
              f"speed [{', '.join(f'{x:g}' for x in table.speed_m_s)}] m/s; {data.nbytes / 1e6:.1f} MB of kernel "
              f"arrays")
        st = bench_sampler.incident_states(table, count, bench_sampler.SEED)
        V, nrm, a = st["V"], st["normal"], st["half_size"]
        print(f"  states                 N = {count} (bench_sampler.incident_states, seed {bench_sampler.SEED}); "
              f"best of {repeats}", flush=True)
        latency = bench_sampler.dependent_load_ns(data.nbytes)
        print(f"  memory latency         {latency:.1f} ns per dependent read at random over {data.nbytes / 1e6:.1f} MB "
              f"(the table's size)", flush=True)
        states = tmp / "states.bin"
        write_states(states, V, nrm, a)
        done = subprocess.run([str(program), str(path), str(states), str(repeats), str(bench_sampler.SEED)],
                              capture_output=True, text=True)
        if done.returncode != 0:
            raise SystemExit(f"rbs_bench failed:\n{done.stderr}")
        c = json.loads(done.stdout)

        # numba, the same states, mix and seed
        cdf = surrogate.mix_cdf(table, "mix")
        V_out, W_out = np.full((count, 3), np.nan), np.full((count, 3), np.nan)
        status = np.full(count, -1, dtype=np.int8)
        seed_state = surrogate.seed_state
        n1 = best_ns(lambda: bench_sampler.loop_kernel_rng(data, cdf, V, nrm, a, seed_state(bench_sampler.SEED), V_out,
                                                           W_out, status), count, repeats)
        nb = best_ns(lambda: bench_sampler.loop_block_rng(data, cdf, V, nrm, a, seed_state(bench_sampler.SEED), V_out,
                                                          W_out, status), count, repeats)
        gt = best_ns(lambda: bench_sampler.loop_bounce(V, nrm, V_out), count, repeats)

        # the C many-particle call gives numba's bits on these states
        m = min(count, 20000)
        V_py, W_py, s_py = np.empty((m, 3)), np.empty((m, 3)), np.empty(m, dtype=np.int8)
        table_rebound_many_rng(data, cdf, V[:m], nrm[:m], a[:m], seed_state(bench_sampler.SEED), V_py, W_py, s_py)
        results = tmp / "results.bin"
        check = subprocess.run([str(program), str(path), str(states), "0", str(bench_sampler.SEED), str(results)],
                               capture_output=True, text=True)
        if check.returncode != 0:
            raise SystemExit(f"rbs_bench failed:\n{check.stderr}")
        raw = results.read_bytes()
        V_c = np.frombuffer(raw, np.float64, 3 * count).reshape(count, 3)[:m]
        W_c = np.frombuffer(raw, np.float64, 3 * count, 24 * count).reshape(count, 3)[:m]
        s_c = np.frombuffer(raw, np.int8, count, 48 * count)[:m]
        same_bits = bool(np.array_equal(s_c, s_py) and np.array_equal(V_c.view(np.int64), V_py.view(np.int64))
                         and np.array_equal(W_c.view(np.int64), W_py.view(np.int64)))

    rows = [("(C-1)    C per particle: rbs_rng_fill + rbs_rebound (table)", c["c_per_particle"]),
            ("(C-many) C rbs_draw_many, all hits, uniforms from the rng", c["c_many"]),
            ("         breakdown: rbs_draw_many, uniforms given", c["c_many_given"]),
            ("         breakdown: 13 xoshiro256+ uniforms alone", c["c_rng"]),
            ("(N-1)    numba table_rebound in @njit loop", n1),
            ("(N-block) numba table_rebound_many_rng", nb),
            ("(C-GT)   C Grant-Tabakoff sphere bounce", c["c_grant_tabakoff"]),
            ("         numba Grant-Tabakoff bounce (bench_sampler (d))", gt),
            ("(C-spin) C rbs_rebound from the rng, auto, no spin (table)", c["c_spin_still"])]
    print(f"\n{'case':58s} {'ns/state':>10s}")
    print("-" * 69)
    for label, ns in rows:
        print(f"{label:58s} {ns:10.1f}")
    ratios = {"c_per_particle_over_numba": c["c_per_particle"] / n1, "c_many_over_numba_block": c["c_many"] / nb,
              "c_many_over_c_bounce": c["c_many"] / c["c_grant_tabakoff"],
              "c_per_particle_over_c_bounce": c["c_per_particle"] / c["c_grant_tabakoff"],
              "numba_block_over_numba_bounce": nb / gt}
    targets = {"c_per_particle_ns": c["c_per_particle"] <= TARGET_PER_PARTICLE_NS,
               "c_many_ns": c["c_many"] <= TARGET_MANY_NS,
               "c_many_over_c_bounce": ratios["c_many_over_c_bounce"] <= TARGET_MANY_OVER_BOUNCE}
    overhead = c["c_spin_still"] - c["c_per_particle"]
    print(f"\n(C-spin) every hit answered (rbs_rebound from the rng, method auto):")
    print(f"  no spin: {c['c_spin_still']:.1f} ns per hit against {c['c_per_particle']:.1f} under RBS_METHOD_TABLE: "
          f"the path decision costs {overhead:+.1f} ns ({c['still_direct']} of {count} states off the table's grid went to "
          f"the direct model)")
    print(f"  spinning, |Omega-| a/|V-| = 0.3: {c['c_spin_spinning_us']:.2f} us per hit over {c['spinning']} hits "
          f"({c['spinning_direct']} answered by the direct model, {c['spinning_failed']} failed)")
    print("\nratios and targets")
    print(f"  (C-1)/(N-1)        C / numba, per particle          {ratios['c_per_particle_over_numba']:8.3g}")
    print(f"  (C-many)/(N-block) C / numba, many particles        {ratios['c_many_over_numba_block']:8.3g}")
    print(f"  (C-1)/(C-GT)       per particle / bounce            {ratios['c_per_particle_over_c_bounce']:8.3g}")
    print(f"  (C-many)/(C-GT)    many / bounce                    {ratios['c_many_over_c_bounce']:8.3g}   "
          f"target <= {TARGET_MANY_OVER_BOUNCE:g}: {verdict(targets['c_many_over_c_bounce'])}")
    print(f"  (C-1)              C per particle, ns               {c['c_per_particle']:8.4g}   "
          f"target <= {TARGET_PER_PARTICLE_NS:g}: {verdict(targets['c_per_particle_ns'])}")
    print(f"  (C-many)           C many particles, ns             {c['c_many']:8.4g}   "
          f"target <= {TARGET_MANY_NS:g}: {verdict(targets['c_many_ns'])}")
    bits = "yes" if same_bits else "NO"
    print(f"\nC draws checked against numba's table_rebound_many_rng on the first {m} states: equal bits: {bits}")
    print("Targets are figures only: the exit code does not depend on them.")
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"machine": machine_info(), "states": count, "repeats": repeats, "table": str(path),
                       "memory_latency_ns": latency,
                       "ns_per_state": {"c_per_particle": c["c_per_particle"], "c_many": c["c_many"],
                                        "c_many_given": c["c_many_given"], "c_rng": c["c_rng"],
                                        "numba_per_particle": n1, "numba_block": nb,
                                        "c_grant_tabakoff": c["c_grant_tabakoff"], "numba_grant_tabakoff": gt,
                                        "c_spin_still": c["c_spin_still"]},
                       "spin": {"decision_overhead_ns": overhead, "still_direct": c["still_direct"],
                                "spinning_us_per_hit": c["c_spin_spinning_us"], "spinning": c["spinning"],
                                "spinning_direct": c["spinning_direct"], "spinning_failed": c["spinning_failed"]},
                       "ratios": ratios, "targets_met": targets, "same_bits": same_bits}, f, indent=2)
        print(f"figures written to {args.json}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
