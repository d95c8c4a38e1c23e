"""Benchmark of the offline table build (``tablegen build``).

Prints:

1. the wall time and file size of a build of the embedded ``default`` preset
   with all local cores (``--skip-default`` to leave it out);
2. a projection of the time to build a 19 α1 × 11 speed × 4 shape grid at 10⁶
   particles per cell on this machine. The projection is NOT a full build: it
   times a subset of cells (every shape at α1 ∈ {2, 30, 60, 90}°, |V⁻| ∈ {50, 175,
   300} m/s, ``--subset-particles`` each, one core), fits the cost per particle
   per cell, averages it over the grid (linear in α1 between the timed angles,
   mean over speeds) and divides by the core count.

Run from the repository root::

    python benchmarks/bench_build.py [--skip-default] [--subset-particles N] [--json FILE]
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import tempfile
import time
from pathlib import Path

import numba
import numpy as np

from tablegen import build_table, load_config, parse_config
from tablegen.tabulation.cells import compute_cell

SUBSET_ALPHA1 = (2.0, 30.0, 60.0, 90.0)
SUBSET_SPEED = (50.0, 175.0, 300.0)
PROJECTED_ALPHA1 = np.linspace(2.0, 90.0, 19)
PROJECTED_SPEEDS = 11
PROJECTED_PARTICLES = 1_000_000


def time_default_build() -> dict:
    config = load_config(preset="default")
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "default.h5"
        start = time.perf_counter()
        build_table(config, out, progress=False)
        seconds = time.perf_counter() - start
        size = out.stat().st_size
    return {"cells": config.n_cells, "particles_per_cell": config.particles_per_cell,
            "seconds": seconds, "megabytes": size / 1e6}


def cost_per_particle(shape: str, alpha1: float, speed: float, particles: int) -> float:
    """Seconds per particle of one cell (simulation + tabulation) on one core."""
    config = parse_config(f"[grid]\nalpha1_deg = [{alpha1}]\nspeed_m_s = [{speed}]\nshapes = [\"{shape}\"]\n"
                          f"[simulation]\nparticles_per_cell = {particles}\n")
    start = time.perf_counter()
    compute_cell(config, shape, 0, 0)
    return (time.perf_counter() - start) / particles


def projection(particles: int) -> dict:
    numba.set_num_threads(1)
    shapes = load_config(preset="default").shapes
    compute_cell(parse_config("[grid]\nalpha1_deg = [45.0]\nspeed_m_s = [200.0]\n"
                              "[simulation]\nparticles_per_cell = 5000\n"), "prism", 0, 0)   # compile
    per_shape = {}
    for shape in shapes:
        costs = np.array([[cost_per_particle(shape, a, v, particles) for v in SUBSET_SPEED]
                          for a in SUBSET_ALPHA1])
        per_alpha = np.interp(PROJECTED_ALPHA1, SUBSET_ALPHA1, costs.mean(axis=1))
        per_shape[shape] = {"us_per_particle": (costs * 1e6).round(3).tolist(),
                            "grid_core_seconds": float(per_alpha.sum() * PROJECTED_SPEEDS * PROJECTED_PARTICLES)}
    cores = os.cpu_count() or 1
    core_seconds = sum(v["grid_core_seconds"] for v in per_shape.values())
    numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
    return {"subset_particles": particles, "cores": cores, "per_shape": per_shape,
            "core_hours": core_seconds / 3600, "wall_hours_this_machine": core_seconds / cores / 3600}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--skip-default", action="store_true", help="do not time the default build")
    parser.add_argument("--subset-particles", type=int, default=50_000, help="particles per timed cell")
    parser.add_argument("--json", metavar="FILE", help="also write the figures as JSON")
    args = parser.parse_args()
    print(f"machine: {platform.platform()}, {os.cpu_count()} cores, numba {numba.__version__}")
    figures = {}
    if not args.skip_default:
        d = time_default_build()
        figures["default_build"] = d
        print(f"default preset: {d['cells']} cells x {d['particles_per_cell']} particles: "
              f"{d['seconds']:.1f} s wall on {os.cpu_count()} cores (numba compile included if the cache "
              f"was cold), file {d['megabytes']:.1f} MB")
    p = projection(args.subset_particles)
    figures["projection"] = p
    print(f"projection (timed subset: 4 shapes x alpha1 {SUBSET_ALPHA1} x speed {SUBSET_SPEED}, "
          f"{p['subset_particles']} particles per cell, one core):")
    for shape, v in p["per_shape"].items():
        print(f"  {shape:<12} us/particle by alpha1 (rows) and speed (columns): {v['us_per_particle']}")
    print(f"  19 alpha1 x 11 speeds x 4 shapes x 1e6 particles: {p['core_hours']:.2f} core-hours, "
          f"{p['wall_hours_this_machine']:.2f} h on this machine's {p['cores']} cores")
    if args.json:
        Path(args.json).write_text(json.dumps(figures, indent=2))
        print(f"figures written to {args.json}")


if __name__ == "__main__":
    main()
