"""Cost per reflected state of the runtime sampler, against the direct model and a restitution bounce.

What is measured
----------------
One run times the same N random incident states (default N = 10⁶) five ways
and prints the cost in ns per reflected state:

(a) ``surrogate.sample_global(table, V, normals, a, shape, random_state)``, the
    vectorised NumPy API in the global frame (its default ``method="auto"``: these
    states do not spin and lie in the grid, so the table answers them all), with numba's default thread
    count and with one numba thread. The time covers the whole call: input
    checks, the seeding of one xoshiro256+ stream per 1024 states, the
    parallel kernel (which draws the U_PER_DRAW uniforms per state) and the
    outputs; variants pass ``out=`` arrays that the caller keeps (no
    allocation, no first touch of fresh pages). Two breakdown rows time that
    kernel, ``surrogate.kernels.table_rebound_parallel_rng``, alone;
(b) ``surrogate.kernels.table_rebound`` called from a user's ``@njit`` loop
    on one thread, as a flow solver would call it per wall hit: the particle's
    V and n passed as 3-tuples of its components and V⁺, Ω⁺ returned as
    tuples (no array views, so the loop does no reference counting); the loop
    draws the U_PER_DRAW uniforms of each state with
    ``surrogate.fill_uniforms`` (xoshiro256+, caller-owned state) and that
    cost is included. Variants: ``surrogate.kernels.rebound`` in the same loop with Ω⁻ = 0 (each hit's path
    decided; the table answers every state of its grid); ``surrogate.kernels.table_rebound`` on the rows
    ``V[i]``, ``n[i]``, its outputs stored into ``V_out[i]``, ``Omega_out[i]`` (array views); the uniforms
    from numba's ``np.random.random()``; (b') the loop reading pre-drawn
    uniforms; (b-block) a solver that collects its wall hits and calls
    ``surrogate.kernels.table_rebound_many_rng`` on them from ``@njit`` code (its
    uniforms, from 32 xoshiro256+ lanes stepped as SIMD, included), and the variant that first draws them
    into an (N, 13) array for ``table_rebound_many``; breakdown row: the xoshiro256+
    draws alone;
(c) the direct model, ``direct_model.simulate.simulate`` with the shape mix, one
    thread, per particle simulated (whatever its status; NumPy input draws,
    kernel and result assembly included). The states' α1 distribution
    (uniform 10–90°) is represented by the midpoints of four equal α1 bins
    (20, 40, 60, 80°) and their |V⁻| distribution by the midpoints of two
    equal speed bins, each configuration weighted equally: the figure is the
    mean of the eight costs per particle;
(d) a deterministic bounce of a sphere with the Grant & Tabakoff (1975)
    restitution polynomials (:func:`grant_tabakoff_bounce`), from a user's
    ``@njit`` loop on one thread, built like our kernel's impact frame: what a
    solver pays today for a rebound without scatter;
(e) every hit answered (``method``, ``omega``): ``sample_global`` on one numba thread with
    ``method="table"`` on the states of (a) (no spin), then the default ``"auto"`` on the same states
    (the table answers every one of them too): the difference is the cost of the path decision; then ``"auto"`` on spinning states (the direct model answers every one: its µs per hit)
    and on a realistic mix where half the hits spin (as in OpenFOAM's ``hopperRebound``). Spinning
    states: the states of (a) with Ω⁻ of random direction and |Ω⁻|a/|V⁻| uniform over 0.3–1.2 (about
    hopperRebound's spinning hits: median 0.75, 90 % below 1.16); their count is N_SPIN = min(N, 20000),
    since each costs microseconds. Last, ``"auto"`` on rough walls of Δγ = 5°, 10°, 20° (docs/model.md §12;
    the states of (a), no spin): hit by hit, each facet hit on its own path, the re-hits by the direct model.

Then it prints the ratios (c)/(b), (b)/(d), (c)/(b-block), (b-block)/(d), rebound over table_rebound,
(e)'s auto over table,
spinning and the 50 % mix over table, each rough wall over table,
and the runtime's targets, each with 'met' or 'NOT met': (b) ≤ 150 ns per
state per core, (b-block) ≤ 100 ns and ≤ 3 × (d), a deterministic
restitution law. The exit code does not depend on the targets.

Incident states: speed uniform over the table's speed range, α1 uniform over
10–90° (within the table's α1 range), random unit wall normals, the
tangential direction uniform in the wall plane, half-size a = 0.1 mm, the
four shapes with equal weights. Trapped draws count as reflected states (the
sampler returns their status, as the direct model does). These states read
the whole table at random, the worst case for its caches. Two more rows time
(b) and (b-block) on the states of the wall beam of
``examples/particle_beam.py`` (α1 uniform over 28.5–31.5°, |V⁻| over
150–200 m/s, within the table's ranges; normals and tangents random as
above): the hits of one jet on one wall, which read a few cells only.

The table is built by the script into a temporary folder (α1 ∈ {10, 30, 50,
70, 90}°, |V⁻| ∈ {100, 200, 300} m/s, the four shapes, 20000 particles per
cell: about a minute on two cores; --quick: 4096 particles per cell), or
given with ``--table PATH``. A draw reads a component row and then residual
shape rows that the row names, two dependent memory reads at random places
of the table, so the per-particle figures depend on the memory latency at
the table's size: the script prints it (a pointer chase over a buffer as
large as the table's arrays). On the reference VM that latency was 25–142 ns
at the bench table's 4.9 MB (it sits at the edge of the share of the
last-level cache the VM gets, which varies with other work on the host) and
133–166 ns at the default table's 51–60 MB (main memory), so the per-particle
figures vary between runs far more than the block kernel's.

How
---
Everything timed is compiled and run once first (warm-up; numba compilation
is excluded). Each figure is the best of ``--repeats`` runs timed with
``time.perf_counter``; process CPU time over wall time of that run is shown
as cpu/wall: about the thread count used on an idle machine, lower when other
processes took the CPU (then the wall figures are pessimistic; the load
average is printed, and the column cpu ns/st, process CPU time per state of
that run, is the steadier figure). Ratios and targets use wall times. For (c),
pilot runs size n so that each timed run takes about ``--min-time`` seconds.
The output starts with the machine details.

Run from the repository root::

    PYTHONPATH=. python benchmarks/bench_sampler.py                  # full run (a few minutes)
    PYTHONPATH=. python benchmarks/bench_sampler.py --quick          # smoke run
    PYTHONPATH=. python benchmarks/bench_sampler.py --table table.h5 --json sampler.json
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import tempfile
import time
from pathlib import Path

import numba
import numpy as np

import surrogate
from machine import machine_info  # benchmarks/machine.py, next to this script
from surrogate.kernels import (PATH_DIRECT, U_PER_DRAW, chunk_states, fill_uniforms, rebound, seed_state,
                               table_rebound, table_rebound_many, table_rebound_many_rng, table_rebound_parallel_rng)

SEED = 20240601
HALF_SIZE = 1e-4                    # m, particle half-size a
ALPHA1_RANGE = (10.0, 90.0)         # deg, incident states
BEAM_ALPHA1 = (28.5, 31.5)          # deg, the wall beam of examples/particle_beam.py
BEAM_SPEED = (150.0, 200.0)         # m/s, the same
SHAPES = ("ellipsoid", "prism", "cut_prism", "tetrahedron")
TABLE_TOML = """
[grid]
alpha1_deg = [10.0, 30.0, 50.0, 70.0, 90.0]
speed_m_s = [100.0, 200.0, 300.0]
shapes = ["ellipsoid", "prism", "cut_prism", "tetrahedron"]
[simulation]
particles_per_cell = {particles}
"""
DIRECT_ALPHA1 = (20.0, 40.0, 60.0, 80.0)   # midpoints of four equal bins of 10–90°
SPIN_RATIO = (0.3, 1.2)                    # |Ω⁻|a/|V⁻| of the spinning states of (e)
N_SPIN = 20000                             # spinning states of (e) at most
ROUGHNESS_DEG = (5.0, 10.0, 20.0)       # (e)'s rough walls, degrees
# the runtime's targets (the same as the C library's, benchmarks/bench_native.py)
TARGET_KERNEL_NS = 150.0                   # (b) per particle at most, ns per state per core
TARGET_BLOCK_NS = 100.0                    # (b-block) at most
TARGET_BLOCK_OVER_BOUNCE = 3.0             # (b-block)/(d) at most

# the bench's own kernels: the options of surrogate.kernels.options.JIT, without the on-disk cache
JIT = dict(nogil=True, fastmath=False, error_model="numpy")

# Grant & Tabakoff (1975), sand on 2024 aluminium: coefficients of 1, β1, β1², β1³ (β1 in rad)
GT_NORMAL = (1.0, -0.4159, 0.4994, -0.292)
GT_TANGENTIAL = (1.0, -2.12, 3.0775, -1.1)


# ----------------------------------------------------------------------------- kernels of the bench

@numba.njit(**JIT)
def grant_tabakoff_bounce(V, n, V_out):
    """Deterministic rebound of a sphere with the Grant & Tabakoff restitution ratios.

    Restitution ratios as polynomials in the impact angle β1 (rad, from the
    wall), sand on 2024 aluminium, from G. Grant and W. Tabakoff, "Erosion
    prediction in turbomachinery resulting from environmental solid
    particles", J. Aircraft 12(5), 471–478 (1975)::

        e_N = V⁺_n / V⁻_n = 1 − 0.4159 β1 + 0.4994 β1² − 0.292 β1³
        e_T = V⁺_t / V⁻_t = 1 − 2.12 β1 + 3.0775 β1² − 1.1 β1³

    (coefficients as specified for this benchmark; some secondary sources
    print e_N with −0.4994 β1² + 0.292 β1³. The signs do not change the cost
    measured.) The wall frame is built as in
    :func:`surrogate.kernels.impact_frame`: normal and tangential parts of V,
    ex along the tangential part, ez = ex × n, β1 = atan2(−V·n, |V_t|); then
    V⁺ = e_T |V_t| ex − e_N (V·n) n + 0·ez is rotated back into the global
    frame as :func:`surrogate.kernels.table_rebound` does. No spin, no scatter.
    V must move into the wall (V·n < 0). Scalars only, like the sampler kernel.
    """
    vn = V[0] * n[0] + V[1] * n[1] + V[2] * n[2]
    tx, ty, tz = V[0] - vn * n[0], V[1] - vn * n[1], V[2] - vn * n[2]
    vt = math.sqrt(tx * tx + ty * ty + tz * tz)
    speed = math.sqrt(vn * vn + vt * vt)
    if vt > 1e-12 * speed:
        ex = (tx / vt, ty / vt, tz / vt)
    else:                       # normal impact: no tangential part to scale
        ex = (0.0, 0.0, 0.0)
    ez = (ex[1] * n[2] - ex[2] * n[1], ex[2] * n[0] - ex[0] * n[2], ex[0] * n[1] - ex[1] * n[0])
    beta1 = math.atan2(-vn, vt)
    e_n = GT_NORMAL[0] + beta1 * (GT_NORMAL[1] + beta1 * (GT_NORMAL[2] + beta1 * GT_NORMAL[3]))
    e_t = GT_TANGENTIAL[0] + beta1 * (GT_TANGENTIAL[1] + beta1 * (GT_TANGENTIAL[2] + beta1 * GT_TANGENTIAL[3]))
    lx, ly, lz = e_t * vt, -e_n * vn, 0.0
    for k in range(3):
        V_out[k] = lx * ex[k] + ly * n[k] + lz * ez[k]


@numba.njit(**JIT)
def seed_numba_rng(seed):
    """Seed numba's own generator (the one np.random.random() uses in nopython code)."""
    np.random.seed(seed)


@numba.njit(**JIT)
def loop_kernel_rng(data, cdf, V, n, a, state, V_out, Omega_out, status):
    """(b) A solver's loop: uniforms from a xoshiro256+ state (surrogate.fill_uniforms), our kernel on
    the particle's components (table_rebound: no array views)."""
    u = np.empty(U_PER_DRAW)
    for i in range(V.shape[0]):
        fill_uniforms(state, u)
        hit = table_rebound(data, cdf, (V[i, 0], V[i, 1], V[i, 2]),
                            (n[i, 0], n[i, 1], n[i, 2]), a[i], u)
        status[i], V_new, W_new = hit.status, hit.V, hit.Omega
        V_out[i, 0], V_out[i, 1], V_out[i, 2] = V_new
        Omega_out[i, 0], Omega_out[i, 1], Omega_out[i, 2] = W_new


@numba.njit(**JIT)
def loop_rebound_rng(data, params, shape_arrays, model_shapes, cdf, V, n, a, state, V_out, Omega_out, status):
    """(b, rebound) The same loop calling rebound, which decides each hit's path (Ω⁻ = 0: the table answers
    every state of the grid)."""
    u = np.empty(U_PER_DRAW)
    for i in range(V.shape[0]):
        fill_uniforms(state, u)
        hit = rebound(data, params, shape_arrays, model_shapes, cdf, (V[i, 0], V[i, 1], V[i, 2]),
                      (0.0, 0.0, 0.0), (n[i, 0], n[i, 1], n[i, 2]), a[i], u)
        status[i], V_new, W_new = hit.status, hit.V, hit.Omega
        V_out[i, 0], V_out[i, 1], V_out[i, 2] = V_new
        Omega_out[i, 0], Omega_out[i, 1], Omega_out[i, 2] = W_new


@numba.njit(**JIT)
def loop_kernel_views(data, cdf, V, n, a, state, V_out, Omega_out, status):
    """(b, rows) The same loop calling table_rebound on the rows V[i], n[i] and storing into V_out[i],
    Omega_out[i] (array views)."""
    u = np.empty(U_PER_DRAW)
    for i in range(V.shape[0]):
        fill_uniforms(state, u)
        hit = table_rebound(data, cdf, V[i], n[i], a[i], u)
        status[i], V_new, W_new = hit.status, hit.V, hit.Omega
        V_row, W_row = V_out[i], Omega_out[i]
        for k in range(3):
            V_row[k], W_row[k] = V_new[k], W_new[k]


@numba.njit(**JIT)
def loop_block_rng(data, cdf, V, n, a, state, V_out, Omega_out, status):
    """(b, block) A solver that collects its wall hits and calls table_rebound_many_rng on them with its state."""
    table_rebound_many_rng(data, cdf, V, n, a, state, V_out, Omega_out, status)


@numba.njit(**JIT)
def loop_block_given(data, cdf, V, n, a, state, U, V_out, Omega_out, status):
    """(b-block, U given) The same hits: their uniforms (xoshiro256+) into U first, then table_rebound_many."""
    for i in range(V.shape[0]):
        fill_uniforms(state, U[i])
    table_rebound_many(data, cdf, V, n, a, U, V_out, Omega_out, status)


@numba.njit(**JIT)
def loop_kernel_nprandom(data, cdf, V, n, a, V_out, Omega_out, status):
    """(b, np.random) The same loop drawing its uniforms with numba's np.random.random()."""
    u = np.empty(U_PER_DRAW)
    for i in range(V.shape[0]):
        for k in range(U_PER_DRAW):
            u[k] = np.random.random()
        hit = table_rebound(data, cdf, (V[i, 0], V[i, 1], V[i, 2]),
                            (n[i, 0], n[i, 1], n[i, 2]), a[i], u)
        status[i], V_new, W_new = hit.status, hit.V, hit.Omega
        V_out[i, 0], V_out[i, 1], V_out[i, 2] = V_new
        Omega_out[i, 0], Omega_out[i, 1], Omega_out[i, 2] = W_new


@numba.njit(**JIT)
def loop_kernel_predrawn(data, cdf, V, n, a, U, V_out, Omega_out, status, scaled):
    """(b') The same loop on pre-drawn uniforms U (N, U_PER_DRAW); with scaled=False, plain stochastic
    interpolation (no moment scaling, breakdown row)."""
    for i in range(V.shape[0]):
        hit = table_rebound(data, cdf, (V[i, 0], V[i, 1], V[i, 2]),
                            (n[i, 0], n[i, 1], n[i, 2]), a[i], U[i], scaled)
        status[i], V_new, W_new = hit.status, hit.V, hit.Omega
        V_out[i, 0], V_out[i, 1], V_out[i, 2] = V_new
        Omega_out[i, 0], Omega_out[i, 1], Omega_out[i, 2] = W_new


@numba.njit(**JIT)
def loop_rng_only(count, state, out):
    """Breakdown of (b): the U_PER_DRAW xoshiro256+ uniforms per state alone (summed into out)."""
    s = 0.0
    u = np.empty(U_PER_DRAW)
    for i in range(count):
        fill_uniforms(state, u)
        for k in range(U_PER_DRAW):
            s += u[k]
    out[0] = s


@numba.njit(**JIT)
def _chase(following, steps):
    i = 0
    for _ in range(steps):
        i = following[i]
    return i


def dependent_load_ns(nbytes: float, steps: int = 1_000_000) -> float:
    """Memory latency at a working set of ``nbytes``: ns per read of a chain of reads, each at a random
    cache line of the buffer that the previous read names (one random cycle through all its lines)."""
    lines = max(2, int(nbytes // 64))
    order = np.random.default_rng(SEED).permutation(lines) * 8        # int64 index of each line's start
    following = np.zeros(lines * 8, dtype=np.int64)
    following[order] = np.roll(order, -1)
    _chase(following, 1000)
    start = time.perf_counter()
    _chase(following, steps)
    return (time.perf_counter() - start) / steps * 1e9


@numba.njit(**JIT)
def loop_bounce(V, n, V_out):
    """(d) A solver's loop over the deterministic Grant–Tabakoff bounce."""
    for i in range(V.shape[0]):
        grant_tabakoff_bounce(V[i], n[i], V_out[i])


# ----------------------------------------------------------------------------- inputs

def build_bench_table(folder: Path, particles: int) -> tuple:
    """Build the bench's table into ``folder``; returns (path, seconds)."""
    from tablegen import build_table, parse_config
    path = folder / "bench_sampler_table.h5"
    start = time.perf_counter()
    build_table(parse_config(TABLE_TOML.format(particles=particles), "bench_sampler table"), path)
    return path, time.perf_counter() - start


def incident_states(table, count: int, seed: int, alpha1_range=ALPHA1_RANGE, speed_range=(0.0, math.inf)) -> dict:
    """Random incident states within the table's grid and the given ranges (deg, m/s; see the module doc).

    α1 and |V⁻| are drawn from ranges shrunk by a relative 1e-9 so that the
    values recomputed from V (rounding) stay inside the grid.
    """
    rng = np.random.default_rng(seed)
    a_lo, a_hi = max(alpha1_range[0], table.alpha1_range[0]), min(alpha1_range[1], table.alpha1_range[1])
    v_lo, v_hi = max(speed_range[0], table.speed_range[0]), min(speed_range[1], table.speed_range[1])
    if a_lo > a_hi or v_lo > v_hi:
        raise SystemExit(f"the table's alpha1 range {table.alpha1_range} deg and speed range {table.speed_range} "
                         f"m/s do not meet {alpha1_range} deg and {speed_range} m/s")
    alpha1 = rng.uniform(a_lo * (1 + 1e-9), a_hi * (1 - 1e-9), count) if a_hi > a_lo else np.full(count, a_lo)
    speed = rng.uniform(v_lo * (1 + 1e-9), v_hi * (1 - 1e-9), count) if v_hi > v_lo else np.full(count, v_lo)
    normal = rng.standard_normal((count, 3))
    normal /= np.linalg.norm(normal, axis=1)[:, None]
    tangent = rng.standard_normal((count, 3))
    tangent -= np.einsum("ij,ij->i", tangent, normal)[:, None] * normal
    tangent /= np.linalg.norm(tangent, axis=1)[:, None]
    a_rad = np.radians(alpha1)
    V = speed[:, None] * (np.cos(a_rad)[:, None] * tangent - np.sin(a_rad)[:, None] * normal)
    return {"V": np.ascontiguousarray(V), "normal": np.ascontiguousarray(normal),
            "half_size": np.full(count, HALF_SIZE), "alpha1": alpha1, "speed": speed,
            "U": rng.random((count, U_PER_DRAW)),
            "speed_bins": (v_lo + 0.25 * (v_hi - v_lo), v_lo + 0.75 * (v_hi - v_lo))}


def spinning(states: dict, count: int, seed: int) -> np.ndarray:
    """Ω⁻ (rad/s) of the first ``count`` states: random directions, |Ω⁻|a/|V⁻| uniform over SPIN_RATIO."""
    rng = np.random.default_rng(seed)
    direction = rng.standard_normal((count, 3))
    direction /= np.linalg.norm(direction, axis=1)[:, None]
    ratio = rng.uniform(*SPIN_RATIO, count)
    return direction * (ratio * states["speed"][:count] / states["half_size"][:count])[:, None]


# ----------------------------------------------------------------------------- timing

def best_time(fn, repeats: int, threads: int, setup=None) -> tuple:
    """Best wall time of ``repeats`` calls of fn() on ``threads`` numba threads: (wall s, cpu s of that run).

    ``setup()`` runs before each call, outside the timing.
    """
    saved = numba.get_num_threads()
    numba.set_num_threads(threads)
    try:
        best = (math.inf, math.inf)
        for _ in range(repeats):
            if setup is not None:
                setup()
            w0, c0 = time.perf_counter(), time.process_time()
            fn()
            best = min(best, (time.perf_counter() - w0, time.process_time() - c0))
    finally:
        numba.set_num_threads(saved)
    return best


def row(key, label, count, threads, wall, cpu, note="") -> dict:
    return {"key": key, "label": label, "n": count, "threads": threads, "time_s": wall,
            "cpu_over_wall": cpu / wall, "ns_per_state": wall / count * 1e9,
            "cpu_ns_per_state": cpu / count * 1e9, "states_per_s": count / wall, "note": note}


def direct_cost(speed_bins, min_time: float, repeats: int) -> tuple:
    """(c): mean ns per particle of simulate('mix', ...) over the α1 × speed configurations, one thread."""
    from direct_model.simulate import simulate

    def run(alpha1, speed, n):
        return lambda: simulate("mix", alpha1, speed, n, seed=SEED)

    simulate("mix", DIRECT_ALPHA1[0], speed_bins[0], 64, seed=SEED)     # warm-up: compile or load
    rows = []
    for alpha1 in DIRECT_ALPHA1:
        for speed in speed_bins:
            n = 500                             # grow the pilot until it takes >= min_time / 5
            while (pilot := best_time(run(alpha1, speed, n), 1, 1)[0]) < 0.2 * min_time:
                n = math.ceil(n * min(10.0, max(2.0, 0.3 * min_time / pilot)))
            n = max(1, math.ceil(min_time * n / pilot))
            wall, cpu = best_time(run(alpha1, speed, n), repeats, 1)
            rows.append({"alpha1_deg": alpha1, "speed_m_s": speed, "n": n, "time_s": wall,
                         "cpu_over_wall": cpu / wall, "ns_per_particle": wall / n * 1e9,
                         "cpu_ns_per_particle": cpu / n * 1e9})
    return float(np.mean([r["ns_per_particle"] for r in rows])), rows


# ----------------------------------------------------------------------------- main

COLUMNS = (("case", 46, "s", "label"), ("thr", 3, "d", "threads"), ("n", 9, "d", "n"),
           ("best s", 8, ".4f", "time_s"), ("cpu/wall", 8, ".2f", "cpu_over_wall"),
           ("ns/state", 10, ".1f", "ns_per_state"), ("cpu ns/st", 10, ".1f", "cpu_ns_per_state"),
           ("states/s", 10, ".3g", "states_per_s"))


def print_row(r: dict) -> None:
    print(" ".join(f"{r[k]:{'<' if i == 0 else '>'}{w}{spec}}" for i, (_, w, spec, k) in enumerate(COLUMNS)),
          flush=True)


def verdict(ok: bool) -> str:
    return "met" if ok else "NOT met"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true",
                        help="smoke run: N = 1e5, 1 repeat, 0.1 s per direct timing, 4096 particles per cell")
    parser.add_argument("--table", metavar="PATH", help="use this table instead of building one")
    parser.add_argument("-n", "--states", type=int, default=None,
                        help="incident states N (default 1e6; --quick 1e5)")
    parser.add_argument("--repeats", type=int, default=None, help="timed runs per figure, the best kept "
                        "(default 3; --quick 1)")
    parser.add_argument("--min-time", type=float, default=None,
                        help="seconds per direct-model timing, about (default 1; --quick 0.1)")
    parser.add_argument("--json", metavar="FILE", help="also write the figures as JSON to FILE")
    args = parser.parse_args(argv)
    count = args.states or (100_000 if args.quick else 1_000_000)
    repeats = args.repeats or (1 if args.quick else 3)
    min_time = args.min_time or (0.1 if args.quick else 1.0)
    particles = 4096 if args.quick else 20000

    info = machine_info()
    threads = info["numba_default_threads"]
    print("Runtime sampler cost per reflected state (surrogate) vs direct model and a restitution bounce")
    for key, value in info.items():
        print(f"  {key:22s} {value}")

    with tempfile.TemporaryDirectory(prefix="bench_sampler_") as tmp:
        if args.table:
            path, build_s = Path(args.table), None
        else:
            print(f"  building the table ({particles} particles per cell) ...", flush=True)
            path, build_s = build_bench_table(Path(tmp), particles)
        table = surrogate.load(path)
    print(f"  table                  {'built in %.1f s' % build_s if build_s is not None else path}: "
          f"shapes {', '.join(table.shapes)}; alpha1 [{', '.join(f'{x:g}' for x in table.alpha1_deg)}] deg; "
          f"speed [{', '.join(f'{x:g}' for x in table.speed_m_s)}] m/s; {table.particles_per_cell} particles per cell; "
          f"{table.kernel_data.nbytes / 1e6:.1f} MB of kernel arrays")
    missing = [s for s in SHAPES if s not in table.shapes]
    if missing:
        raise SystemExit(f"the table lacks shapes {missing}; the bench draws the equal mix of all four")

    st = incident_states(table, count, SEED)
    beam = incident_states(table, count, SEED + 1, BEAM_ALPHA1, BEAM_SPEED)
    V, nrm, a, U = st["V"], st["normal"], st["half_size"], st["U"]
    mix = {s: 0.25 for s in SHAPES}
    cdf = surrogate.mix_cdf(table, mix)
    data = table.kernel_data
    # outputs and scratch written once here, so that no timed run pays the first touch of their pages
    V_out, Omega_out = np.full((count, 3), np.nan), np.full((count, 3), np.nan)
    status = np.full(count, -1, dtype=np.int8)
    print(f"  states                 N = {count}: speed U{table.speed_range} m/s, alpha1 "
          f"U({st['alpha1'].min():.2f}, {st['alpha1'].max():.2f}) deg, random unit normals, a = {HALF_SIZE:g} m, "
          f"shape mix {', '.join(f'{s} {w:g}' for s, w in mix.items())}")
    print(f"  wall-beam states       the same, with alpha1 U({beam['alpha1'].min():.2f}, {beam['alpha1'].max():.2f}) "
          f"deg and speed U({beam['speed'].min():.1f}, {beam['speed'].max():.1f}) m/s")
    print(f"  best of {repeats}; seed {SEED}; U_PER_DRAW = {U_PER_DRAW}")

    # warm-up: compile everything timed below (a small slice; numba caches per type signature)
    m = min(count, 1000)
    surrogate.sample_global(table, V[:m], nrm[:m], a[:m], shape=mix, random_state=SEED)
    table_rebound_parallel_rng(data, cdf, V[:m], nrm[:m], a[:m], chunk_states(np.random.default_rng(SEED), m),
                      V_out[:m], Omega_out[:m], status[:m])
    streams = chunk_states(np.random.default_rng(SEED), count)
    seed_numba_rng(SEED)
    loop_kernel_rng(data, cdf, V[:m], nrm[:m], a[:m], seed_state(SEED), V_out[:m], Omega_out[:m], status[:m])
    loop_kernel_nprandom(data, cdf, V[:m], nrm[:m], a[:m], V_out[:m], Omega_out[:m], status[:m])
    U_block = U.copy()
    loop_block_rng(data, cdf, V[:m], nrm[:m], a[:m], seed_state(SEED), V_out[:m], Omega_out[:m], status[:m])
    loop_block_given(data, cdf, V[:m], nrm[:m], a[:m], seed_state(SEED), U_block[:m], V_out[:m], Omega_out[:m],
                     status[:m])
    loop_kernel_views(data, cdf, V[:m], nrm[:m], a[:m], seed_state(SEED), V_out[:m], Omega_out[:m], status[:m])
    direct = (table.direct_parameters, table.shape_arrays, table.model_shapes)
    loop_rebound_rng(data, *direct, cdf, V[:m], nrm[:m], a[:m], seed_state(SEED), V_out[:m], Omega_out[:m], status[:m])
    for scaled in (True, False):
        loop_kernel_predrawn(data, cdf, V[:m], nrm[:m], a[:m], U[:m], V_out[:m], Omega_out[:m], status[:m], scaled)
    loop_rng_only(m, seed_state(SEED), np.empty(1))
    loop_bounce(V[:m], nrm[:m], V_out[:m])
    print(f"  threading layer        {numba.threading_layer()}")
    table_bytes = data.nbytes
    latency = {"table_bytes": table_bytes, "ns_at_table_size": dependent_load_ns(table_bytes),
               "ns_at_256kB": dependent_load_ns(256e3)}
    print(f"  memory latency         {latency['ns_at_table_size']:.1f} ns per dependent read at random over "
          f"{table_bytes / 1e6:.1f} MB (the table's size), {latency['ns_at_256kB']:.1f} ns over 0.26 MB\n")

    header = " ".join(f"{h:{'<' if i == 0 else '>'}{w}}" for i, (h, w, _, _) in enumerate(COLUMNS))
    print(header)
    print("-" * len(header))
    rows = {}

    def record(key, label, thr, fn, setup=None, note="", states=count):
        wall, cpu = best_time(fn, repeats, thr, setup)
        rows[key] = row(key, label, states, thr, wall, cpu, note)
        print_row(rows[key])

    def api():
        return surrogate.sample_global(table, V, nrm, a, shape=mix, random_state=SEED)

    kept = surrogate.empty_rebounds(count)

    def api_out():
        return surrogate.sample_global(table, V, nrm, a, shape=mix, random_state=SEED, out=kept)

    record("a_all", "(a) sample_global, all cores", threads, api)
    record("a_1", "(a) sample_global, 1 numba thread", 1, api)
    record("a_out_all", "    variant: with out= arrays kept, all cores", threads, api_out)
    record("a_out_1", "    variant: with out= arrays kept, 1 thread", 1, api_out)
    record("a_kernel_all", "    breakdown: table_rebound_parallel_rng, all cores", threads,
           lambda: table_rebound_parallel_rng(data, cdf, V, nrm, a, streams, V_out, Omega_out, status))
    record("a_kernel_1", "    breakdown: table_rebound_parallel_rng, 1 thread", 1,
           lambda: table_rebound_parallel_rng(data, cdf, V, nrm, a, streams, V_out, Omega_out, status))
    trapped_api = float(np.mean(api().status != 0))
    record("b", "(b) table_rebound in @njit loop, xoshiro256+", 1,
           lambda: loop_kernel_rng(data, cdf, V, nrm, a, seed_state(SEED), V_out, Omega_out, status))
    record("b_rebound", "    variant: rebound (its path decided; no spin)", 1,
           lambda: loop_rebound_rng(data, *direct, cdf, V, nrm, a, seed_state(SEED), V_out, Omega_out, status))
    record("b_views", "    variant: table_rebound on array rows (views)", 1,
           lambda: loop_kernel_views(data, cdf, V, nrm, a, seed_state(SEED), V_out, Omega_out, status))
    record("b_nprandom", "    variant: uniforms from np.random.random()", 1,
           lambda: loop_kernel_nprandom(data, cdf, V, nrm, a, V_out, Omega_out, status),
           setup=lambda: seed_numba_rng(SEED))
    trapped_b = float(np.mean(status != 0))
    record("b_predrawn", "(b') table_rebound in @njit loop, pre-drawn u", 1,
           lambda: loop_kernel_predrawn(data, cdf, V, nrm, a, U, V_out, Omega_out, status, True))
    record("b_unscaled", "    breakdown: (b') without moment scaling", 1,
           lambda: loop_kernel_predrawn(data, cdf, V, nrm, a, U, V_out, Omega_out, status, False))
    record("b_block", "(b-block) table_rebound_many_rng in @njit", 1,
           lambda: loop_block_rng(data, cdf, V, nrm, a, seed_state(SEED), V_out, Omega_out, status))
    record("b_block_given", "    variant: uniforms into U, table_rebound_many", 1,
           lambda: loop_block_given(data, cdf, V, nrm, a, seed_state(SEED), U_block, V_out, Omega_out, status))
    record("b_beam", "(b) on the wall-beam states", 1,
           lambda: loop_kernel_rng(data, cdf, beam["V"], beam["normal"], a, seed_state(SEED), V_out, Omega_out, status))
    record("b_block_beam", "(b-block) on the wall-beam states", 1,
           lambda: loop_block_rng(data, cdf, beam["V"], beam["normal"], a, seed_state(SEED), V_out, Omega_out, status))
    record("b_rng", f"    breakdown: {U_PER_DRAW} xoshiro256+ uniforms alone", 1,
           lambda: loop_rng_only(count, seed_state(SEED), np.empty(1)))
    record("d", "(d) Grant-Tabakoff sphere bounce, @njit loop", 1, lambda: loop_bounce(V, nrm, V_out))
    record("e_table", "(e) sample_global method='table', 1 thread", 1,
           lambda: surrogate.sample_global(table, V, nrm, a, shape=mix, random_state=SEED, method="table"))
    record("e_auto", "(e) the same, method='auto' (no spin)", 1, api)
    m_spin = min(count, N_SPIN)
    spin = spinning(st, m_spin, SEED + 2)
    half = spin.copy()
    half[::2] = 0.0
    for key, label, omega in (("e_spin", "(e) auto, spinning states, 1 thread", spin),
                              ("e_mix", "(e) auto, half of the states spinning, 1 thread", half)):
        paths = surrogate.sample_global(table, V[:m_spin], nrm[:m_spin], a[:m_spin], shape=mix, random_state=SEED,
                                        omega=omega).path
        record(key, label, 1, lambda: surrogate.sample_global(table, V[:m_spin], nrm[:m_spin], a[:m_spin], shape=mix,
                                                              random_state=SEED, omega=omega),
               note=f"{np.mean(paths == PATH_DIRECT):.3f} of the hits answered by the direct model", states=m_spin)

    for roughness in ROUGHNESS_DEG:
        hits = surrogate.sample_global(table, V, nrm, a, shape=mix, random_state=SEED, roughness_deg=roughness)
        record(f"e_rough{roughness:g}", f"(e) auto on a rough wall, {roughness:g} deg, 1 thread", 1,
               lambda: surrogate.sample_global(table, V, nrm, a, shape=mix, random_state=SEED,
                                               roughness_deg=roughness),
               note=f"{np.mean(hits.wall_hits > 1):.3f} of the hits hit again, "
                    f"{np.mean(hits.path == PATH_DIRECT):.3f} ended on the direct model")

    direct_ns, direct_rows = direct_cost(st["speed_bins"], min_time, repeats)
    cpu_direct = float(np.mean([r["cpu_over_wall"] for r in direct_rows]))
    rows["c"] = {"key": "c", "label": "(c) direct model simulate('mix'), mean", "n": sum(r["n"] for r in direct_rows),
                 "threads": 1, "time_s": sum(r["time_s"] for r in direct_rows), "cpu_over_wall": cpu_direct,
                 "ns_per_state": direct_ns, "states_per_s": 1e9 / direct_ns,
                 "cpu_ns_per_state": float(np.mean([r["cpu_ns_per_particle"] for r in direct_rows])),
                 "configurations": direct_rows}
    print_row(rows["c"])
    for r in direct_rows:
        print(f"    alpha1 {r['alpha1_deg']:4g} deg, |V-| {r['speed_m_s']:5g} m/s: n {r['n']:7d}, "
              f"{r['ns_per_particle']:10.1f} ns/particle, cpu/wall {r['cpu_over_wall']:.2f}, "
              f"{r['cpu_ns_per_particle']:10.1f} cpu ns/particle")

    b, d, c = rows["b"]["ns_per_state"], rows["d"]["ns_per_state"], rows["c"]["ns_per_state"]
    bb = rows["b_block"]["ns_per_state"]
    ratios = {"direct_over_kernel": c / b, "kernel_over_bounce": b / d, "kernel_ns": b,
              "direct_over_block": c / bb, "block_over_bounce": bb / d, "block_ns": bb,
              "kernel_predrawn_over_bounce": rows["b_predrawn"]["ns_per_state"] / d,
              "kernel_beam_ns": rows["b_beam"]["ns_per_state"], "block_beam_ns": rows["b_block_beam"]["ns_per_state"],
              "api_1thread_over_kernel": rows["a_1"]["ns_per_state"] / b,
              "rebound_over_kernel": rows["b_rebound"]["ns_per_state"] / b,
              "rng_share_of_kernel": rows["b_rng"]["ns_per_state"] / b,
              "auto_over_table": rows["e_auto"]["ns_per_state"] / rows["e_table"]["ns_per_state"],
              "spinning_over_table": rows["e_spin"]["ns_per_state"] / rows["e_table"]["ns_per_state"],
              "mix_over_table": rows["e_mix"]["ns_per_state"] / rows["e_table"]["ns_per_state"],
              "spinning_us": rows["e_spin"]["ns_per_state"] / 1e3, "mix_us": rows["e_mix"]["ns_per_state"] / 1e3,
              "auto_over_table_cpu": rows["e_auto"]["cpu_ns_per_state"] / rows["e_table"]["cpu_ns_per_state"],
              "spinning_cpu_us": rows["e_spin"]["cpu_ns_per_state"] / 1e3,
              "mix_cpu_us": rows["e_mix"]["cpu_ns_per_state"] / 1e3,
              **{f"rough{r:g}_over_table": rows[f"e_rough{r:g}"]["ns_per_state"] / rows["e_table"]["ns_per_state"]
                 for r in ROUGHNESS_DEG}}
    targets = {"kernel_ns": bool(b <= TARGET_KERNEL_NS), "block_ns": bool(bb <= TARGET_BLOCK_NS),
               "block_over_bounce": bool(bb / d <= TARGET_BLOCK_OVER_BOUNCE)}
    print(f"\ntrapped fraction drawn: (a) {trapped_api:.4f}, (b) {trapped_b:.4f}")
    print("\nratios (ns per state over ns per state)")
    print(f"  (c)/(b)  direct model / sampler kernel        {c / b:12.4g}")
    print(f"  (b)/(d)  sampler kernel / Grant-Tabakoff      {b / d:12.4g}")
    print(f"  (b)      sampler kernel, ns per state per core {b:11.4g}   target <= {TARGET_KERNEL_NS:g} ns: "
          f"{verdict(targets['kernel_ns'])}")
    print(f"  (c)/(b-block) direct model / block kernel     {c / bb:12.4g}")
    print(f"  (b-block)/(d) block kernel / Grant-Tabakoff   {bb / d:12.4g}   target <= "
          f"{TARGET_BLOCK_OVER_BOUNCE:g}: {verdict(targets['block_over_bounce'])}")
    print(f"  (b-block) block kernel, ns per state per core {bb:11.4g}   target <= {TARGET_BLOCK_NS:g} ns: "
          f"{verdict(targets['block_ns'])}")
    print(f"  (b), (b-block) on the wall-beam states, ns     {ratios['kernel_beam_ns']:11.4g} "
          f"{ratios['block_beam_ns']:11.4g}")
    print(f"  (b')/(d) kernel on pre-drawn uniforms / G-T   {ratios['kernel_predrawn_over_bounce']:12.4g}")
    print(f"  (a, 1 thread)/(b) NumPy API / @njit loop      {ratios['api_1thread_over_kernel']:12.4g}")
    print(f"  (b, rebound)/(b) rebound / table_rebound      {ratios['rebound_over_kernel']:12.4g}")
    print(f"  RNG share of (b)                              {ratios['rng_share_of_kernel']:12.4g}")
    print(f"  (e) auto / table, no spin (the path decision) {ratios['auto_over_table']:12.4g}   "
          f"in CPU time {ratios['auto_over_table_cpu']:.4g}")
    print(f"  (e) auto spinning / table, no spin            {ratios['spinning_over_table']:12.4g}   "
          f"{ratios['spinning_us']:.3g} us per spinning hit (CPU {ratios['spinning_cpu_us']:.3g} us)")
    print(f"  (e) auto half spinning / table, no spin       {ratios['mix_over_table']:12.4g}   "
          f"{ratios['mix_us']:.3g} us per hit (CPU {ratios['mix_cpu_us']:.3g} us)")
    for r in ROUGHNESS_DEG:
        print(f"  (e) auto, rough wall {r:2g} deg / table, smooth   {ratios[f'rough{r:g}_over_table']:12.4g}   "
              f"{rows[f'e_rough{r:g}']['ns_per_state']:.4g} ns per hit")
    print("\nTargets are figures only: the exit code does not depend on them. Ratios and targets use the wall\n"
          "times (ns/state). cpu/wall = process CPU time / wall time of the best run: about the thread count\n"
          "on an idle machine; lower, other work took the CPU and the wall figures are pessimistic (cpu ns/st,\n"
          "the process CPU time per state, is then the steadier figure; on several threads it sums them).\n"
          "(c) counts every particle simulated, whatever its status; (c) cpu ns/st is the mean over its rows.")

    if args.json:
        with open(args.json, "w") as f:
            json.dump({"machine": info, "threading_layer": numba.threading_layer(),
                       "memory_latency": latency,
                       "settings": {"states": count, "repeats": repeats, "min_time_s": min_time,
                                    "quick": args.quick, "seed": SEED, "half_size_m": HALF_SIZE,
                                    "table": str(path) if args.table else "built",
                                    "table_build_s": build_s, "particles_per_cell": table.particles_per_cell,
                                    "u_per_draw": U_PER_DRAW},
                       "targets": {"kernel_ns_max": TARGET_KERNEL_NS, "block_ns_max": TARGET_BLOCK_NS,
                                   "block_over_bounce_max": TARGET_BLOCK_OVER_BOUNCE, "met": targets},
                       "trapped_fraction": {"a": trapped_api, "b": trapped_b},
                       "results": rows, "ratios": ratios}, f, indent=2)
        print(f"figures written to {args.json}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
