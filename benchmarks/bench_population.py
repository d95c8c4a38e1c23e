"""A population of user grains in one table: build time (on local workers and on a Dask cluster, the same file),
load time in Python and in C, and a mix drawn over all of them (docs/model.md §9).

Grains: the convex hulls of ``--vertices`` points on ellipsoids of random proportions (b/a in 0.5-0.9, c/a in
0.3-0.6; every point a hull vertex), one per seed, named g0, g1, ...; the table's grid is one α1 (40°) and one
|V⁻| (150 m/s) at ``--particles`` per cell, so that the build's time is the grains' and not the grid's. Printed:
the build's wall time on ``--workers`` local processes and (with ``--dask``) on a local Dask cluster of as many
workers, whether the two files have the same fingerprint (``tablegen info``), the file's size, ``surrogate.load``
(Python) and ``rbs_table_open`` (C; the library built here with CMake, or ``--build-dir``) in seconds, the best
of three, and the share of 10⁵ draws of the mix over all grains that each grain received (its min and max
against 1/N).

    python benchmarks/bench_population.py                   # 500 grains of 500 vertices (several minutes)
    python benchmarks/bench_population.py --grains 50 --vertices 200 --dask --json population.json
"""

from __future__ import annotations

import argparse
import ctypes
import json
import sys
import tempfile
import time
import timeit
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from bench_native import build_native  # noqa: E402  (benchmarks/bench_native.py, next to this script)


def population_config(grains: int, vertices: int, particles: int) -> str:
    """The build configuration of the population (module doc)."""
    names, sections = [], []
    for k in range(grains):
        rng = np.random.default_rng(k)
        points = rng.normal(size=(vertices, 3))
        points *= [1.0, rng.uniform(0.5, 0.9), rng.uniform(0.3, 0.6)] / np.linalg.norm(points, axis=1)[:, None]
        names.append(f"g{k}")
        rows = ", ".join("[" + ", ".join(repr(float(x)) for x in row) + "]" for row in points)
        sections.append(f"[shapes.g{k}]\nvertices = [{rows}]\n")
    return (f"[grid]\nalpha1_deg = [40.0]\nspeed_m_s = [150.0]\nshapes = {json.dumps(names)}\n"
            f"[simulation]\nparticles_per_cell = {particles}\nseed = 20261206\n" + "".join(sections))


def best_seconds(fn, repeats: int = 3) -> float:
    """The best of ``repeats`` wall-clock times of fn() (a load reads files: its wall time is what a user waits)."""
    return min(timeit.repeat(fn, number=1, repeat=repeats))


def c_open_seconds(library: Path, table: Path) -> float:
    """Best of three rbs_table_open + rbs_table_close of ``table`` through the shared library."""
    lib = ctypes.CDLL(str(library))
    lib.rbs_table_open.argtypes = [ctypes.c_char_p, ctypes.POINTER(ctypes.c_void_p), ctypes.c_char_p, ctypes.c_size_t]
    lib.rbs_table_close.argtypes = [ctypes.c_void_p]
    message = ctypes.create_string_buffer(1024)

    def once():
        handle = ctypes.c_void_p()
        code = lib.rbs_table_open(str(table).encode(), ctypes.byref(handle), message, len(message))
        if code != 0:
            raise SystemExit(f"rbs_table_open: {message.value.decode()}")
        lib.rbs_table_close(handle)
    return best_seconds(once)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--grains", type=int, default=500)
    parser.add_argument("--vertices", type=int, default=500, help="points per grain, each a hull vertex")
    parser.add_argument("--particles", type=int, default=256, help="particles per cell (at least 256)")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--dask", action="store_true", help="also build on a local Dask cluster and compare")
    parser.add_argument("--build-dir", metavar="DIR", help="a build of native/ (else built here)")
    parser.add_argument("--json", metavar="FILE")
    args = parser.parse_args(argv)

    import surrogate
    from data_schema.table import table_fingerprint
    from tablegen.tabulation.config import parse_config
    from tablegen.tabulation.driver import build_table

    figures = {"grains": args.grains, "points_per_grain": args.vertices, "particles_per_cell": args.particles}
    with tempfile.TemporaryDirectory(prefix="bench_population_") as tmp:
        tmp = Path(tmp)
        t0 = time.perf_counter()
        config = parse_config(population_config(args.grains, args.vertices, args.particles), "population.toml")
        figures["config_s"] = time.perf_counter() - t0
        figures["hull_vertices_mean"] = float(np.mean([len(g.vertices) for g in config.grains]))
        t0 = time.perf_counter()
        local = build_table(config, tmp / "local.h5", workers=args.workers)
        figures["build_local_s"] = time.perf_counter() - t0
        figures["file_MB"] = local.stat().st_size / 1e6
        figures["fingerprint"] = table_fingerprint(local)
        if args.dask:
            import distributed
            with distributed.LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True,
                                          dashboard_address=None) as cluster:
                t0 = time.perf_counter()
                remote = build_table(config, tmp / "dask.h5", scheduler=cluster.scheduler_address)
                figures["build_dask_s"] = time.perf_counter() - t0
            figures["dask_same_fingerprint"] = table_fingerprint(remote) == figures["fingerprint"]
        figures["load_python_s"] = best_seconds(lambda: surrogate.load(local))
        build = Path(args.build_dir) if args.build_dir else build_native(tmp / "native", "rebound_scatter", shared=True)
        library = next(build.rglob("librebound_scatter.so*"))
        figures["load_c_s"] = c_open_seconds(library, local)
        table = surrogate.load(local)
        rng = np.random.default_rng(1)
        n = 100_000
        alpha = np.radians(rng.uniform(35.0, 45.0, n))
        velocity = np.column_stack([150.0 * np.cos(alpha), -150.0 * np.sin(alpha), np.zeros(n)])
        out = surrogate.sample_global(table, velocity, [0.0, 1.0, 0.0], 1e-4, shape="mix", random_state=2)
        counts = np.bincount(out.shape[out.status == 0], minlength=len(table.shapes))
        share = counts / counts.sum() * len(table.shapes)
        figures["mix_share_over_uniform"] = [float(share.min()), float(share.max())]
    for key, value in figures.items():
        print(f"{key:26} {value:.4g}" if isinstance(value, float) else f"{key:26} {value}")
    if args.json:
        Path(args.json).write_text(json.dumps(figures, indent=2) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
