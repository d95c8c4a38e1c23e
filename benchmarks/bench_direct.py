"""Throughput benchmark of the direct rebound model: the batch API (``direct_model.simulate.simulate``) and
the run-time kernels (numba's ``surrogate.kernels.direct_rebound``, C's ``rbs_direct_rebound``).

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

What is measured: the run-time kernels
--------------------------------------
Microseconds per rebound of numba's ``direct_rebound`` and of the C library's ``rbs_direct_rebound``,
one particle per call in a loop on one thread (an ``@njit`` loop; a C loop in native/bench/rbs_bench_direct.c),
the 7 uniforms drawn per call from one xoshiro256+ stream of seed SEED (``fill_uniforms``, ``rbs_rng_fill``:
the same uniforms, so the C outputs are checked against numba's bits), as a solver would call them. Per
shape, on four sets of incident states:

* 'random, 0': ``--states`` random states, α1 uniform in [5°, 90°], |V⁻| uniform in 50–300 m/s, a random
  caller's frame, Ω⁻ = 0 (the tables' case: the body starts touching the wall);
* 'random, spin': the same with |Ω⁻|a/|V⁻| uniform in [0, 1.2] in a random direction (the flight in is
  simulated);
* 'spinning': strongly spinning states as a new user would try them: |Ω⁻|a/|V⁻| uniform in [0.02, 0.8],
  α1 in [20°, 70°], |V⁻| in 100–250 m/s;
* 'hopper': the wall hits of a hopperRebound run (benchmarks/data/hopper_hits.csv, written by
  integrations/openfoam/sample_hits.py: V⁻, n, a and Ω⁻ per hit, read by ``read_hits_sample``), each run
  with the shape.

The run-time targets, ≤ 2.5 µs per rebound on one core averaged over hopperRebound's hits for every shape,
and ≤ 4 µs averaged over the shapes at the 'spinning' states, are reported for C (a figure only: the exit code
does not depend on them). Where the time goes: numba's rebound alone
(``direct_model.runtime.rebound_model_frame``, the same uniforms; the rest of the call is the frame, the
checks and the uniforms), the same without the trapped particles (each runs n_max collisions), the mean
flights, collisions and contact-search steps per particle, and a split of the rebound's time: each piece
timed alone on the bodies of the first PIECE_ROWS rows (inputs that stay in cache), times its count per
rebound: a flight's setup (K in the lab frame, curvature_bound, jerk_bound and rotation_init; counted once per
flight, an upper count: a flight decided at its first step skips rotation_init), the free flight's orientation
at one instant (rotation_at; once per search step but a flight's first), the body's lowest points there with
their rates and g̈ for the curvatures (lowest_points; once per search step), a collision
(K⁻¹ in the lab frame and collide); the rest is the body's setup, the search's own logic and the frame.
The C program times the same pieces in C (rbs_rotation_init, rbs_rotation_at, rbs_lowest_points,
rbs_collide: the model's internal kernels) on the same inputs, and C's rebound alone
(rbs_rebound_model_frame), for C's split at the same counts.
Times are the best of ``--repeats`` runs in this thread's CPU time (C: CLOCK_THREAD_CPUTIME_ID), which
leaves out the time other jobs take on a shared machine. The C side builds native/ (or takes
``--build-dir``) and reads its parameters from a table (``--table``, else a small one built with the
defaults, the parameters numba's rows use too).

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
    PYTHONPATH=. python benchmarks/bench_direct.py --runtime  # the run-time kernels alone (about 2 min)
    PYTHONPATH=. python benchmarks/bench_direct.py --runtime --no-native    # numba's alone
"""

from __future__ import annotations

import argparse
import json
import math
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numba
import numpy as np

import surrogate
from data_schema.samples import STATUS_FAILED, STATUS_REBOUNDED, STATUS_TRAPPED
from direct_model.collision import collide
from direct_model.flight import curvature_bound, jerk_bound, lowest_points
from direct_model.body_rebound import lab_tensor, quaternion_to_matrix
from direct_model.rotation import ROT_PARAMS_SIZE, rotation_at, rotation_init
from direct_model.runtime import (P_WALL, SCRATCH_SIZE, U_AXIS, U_HAND, U_ORIENTATION, U_PER_REBOUND, U_RATIOS,
                                  aspect_ratio, family_shapes, model_parameters, rebound_model_frame,
                                  uniform_quaternion)
from direct_model.shape_arrays import bounding_radius, particle_body, scanned_hull
from direct_model.shapes import MAX_VERTICES, AspectRatioLaw, second_moment_factors
from direct_model.simulate import DEFAULT_CONTACT_TOL, DEFAULT_MAX_STEPS, DEFAULT_N_MAX, DEFAULT_SET_TOL, simulate
from direct_model.wall import CORUNDUM_ON_STEEL
from bench_native import build_native  # benchmarks/, next to this script
from machine import machine_info  # benchmarks/machine.py, next to this script
from surrogate.kernels import fill_uniforms, impact_frame, direct_rebound, seed_state
from surrogate.kernels.frame import dot
from tablegen import build_table, parse_config

SHAPES = ("ellipsoid", "prism", "cut_prism", "tetrahedron")
TARGET_PER_CORE = 1e5     # rebounds/s per core
TARGET_ALPHA1 = 45.0      # degrees
SEED = 20240601
HITS_SAMPLE = Path(__file__).resolve().parent / "data" / "hopper_hits.csv"
# a table only for its recorded model parameters (the defaults), for the C side: 2 × 2 cells of 256
BENCH_TABLE_CONFIG = ("[grid]\nalpha1_deg = [45.0, 90.0]\nspeed_m_s = [100.0, 200.0]\n"
                      "[simulation]\nparticles_per_cell = 256\nseed = 1\n")
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
    ("shape", 12, "s", "shape"), ("states", 12, "s", "states"), ("n", 6, "d", "n"),
    ("numba us", 8, ".2f", "us_per_rebound"), ("C us", 7, ".2f", "us_c"), ("C/numba", 7, ".2f", "c_over_numba"),
    ("frame us", 8, ".2f", "us_model_frame"), ("untrapped", 9, ".2f", "us_model_frame_untrapped"),
    ("flights", 7, ".2f", "flights_per_rebound"), ("coll", 6, ".2f", "collisions_per_rebound"),
    ("steps", 6, ".1f", "search_steps_per_rebound"), ("trapped", 7, "d", "trapped"), ("failed", 6, "d", "failed"),
)
SPLIT_COLUMNS = (
    ("shape", 12, "s", "shape"), ("states", 12, "s", "states"), ("setup us", 8, ".3f", "us_flight_setup"),
    ("orient us", 9, ".3f", "us_orientation"), ("lowest us", 9, ".3f", "us_lowest_points"),
    ("coll us", 7, ".3f", "us_collision"), ("setup %", 7, ".0f", "pct_flight_setup"),
    ("orient %", 8, ".0f", "pct_orientation"), ("lowest %", 8, ".0f", "pct_lowest_points"),
    ("coll %", 6, ".0f", "pct_collision"), ("rest %", 6, ".0f", "pct_rest"), ("trapped %", 9, ".0f", "pct_trapped"),
)
C_SPLIT_COLUMNS = tuple((h, w, spec, "c_" + k if k not in ("shape", "states") else k)
                        for h, w, spec, k in SPLIT_COLUMNS if k != "pct_trapped") + (
    ("frame us", 8, ".2f", "c_us_model_frame"),)
STATE_SETS = ("random, 0", "random, spin", "spinning", "hopper")
HOPPER_TARGET_US = 2.5      # C, µs per rebound averaged over hopperRebound's hits, every shape
SPINNING_TARGET_US = 4.0    # C, µs per rebound at the 'spinning' states, averaged over the shapes


@numba.njit
def _kernel_loop(params, shapes, shape, V, omega, n, a, state, status, V_out, W_out):
    """direct_rebound on every row, uniforms from ``state``: what a solver's loop does."""
    u = np.empty(U_PER_REBOUND)
    for i in range(V.shape[0]):
        fill_uniforms(state, u)
        hit = direct_rebound(params, shapes, shape, (V[i, 0], V[i, 1], V[i, 2]),
                             (omega[i, 0], omega[i, 1], omega[i, 2]), (n[i, 0], n[i, 1], n[i, 2]), a[i], u)
        st, Vo, Wo = hit.status, hit.V, hit.Omega
        status[i] = st
        for k in range(3):
            V_out[i, k], W_out[i, k] = Vo[k], Wo[k]


@numba.njit
def _model_frame_inputs(V, n, a, omega, state, u_all, model):
    """The uniforms the kernel loop draws and the model-frame inputs it builds, per row (untimed)."""
    for i in range(V.shape[0]):
        fill_uniforms(state, u_all[i])
        Vi, ni, Wi = (V[i, 0], V[i, 1], V[i, 2]), (n[i, 0], n[i, 1], n[i, 2]), (omega[i, 0], omega[i, 1], omega[i, 2])
        _, _, _, _, ex, ez = impact_frame(Vi, ni, u_all[i, U_AXIS])
        model[i, 0], model[i, 1] = dot(Vi, ex), dot(Vi, ni)
        model[i, 2], model[i, 3], model[i, 4] = a[i] * dot(Wi, ex), a[i] * dot(Wi, ni), a[i] * dot(Wi, ez)


@numba.njit
def _model_frame_loop(params, shapes, model, shape, u_all, counts, W_after):
    """rebound_model_frame alone on the rows' model-frame inputs; counts[i] = (status, collisions, steps),
    W_after[i] = Ω⁺ ((m/s)/a, model frame)."""
    scratch = np.empty(SCRATCH_SIZE)
    for i in range(model.shape[0]):
        done = rebound_model_frame(
            params, shapes, shape, model[i, 0], model[i, 1], model[i, 2], model[i, 3], model[i, 4], u_all[i], scratch)
        counts[i, 0], counts[i, 1], counts[i, 2] = done.status, done.n_collisions, done.n_search_steps
        W_after[i, 0], W_after[i, 1], W_after[i, 2] = done.Omega


# ----------------------------------------------------------------------------- the pieces of a rebound

@numba.njit
def _bodies(shapes, shape, u_all, semi, K, R, verts, nv, scale):
    """The bodies the rows' uniforms draw (as rebound_model_frame draws them): half-extents, J/m, orientation R,
    vertices (untimed)."""
    q = np.empty(4)
    law, cdf = shapes.aspect[shape], shapes.aspect_cdf[shape]
    for i in range(u_all.shape[0]):
        uniform_quaternion(u_all[i, U_ORIENTATION], u_all[i, U_ORIENTATION + 1], u_all[i, U_ORIENTATION + 2], q)
        quaternion_to_matrix(q, R[i])
        ratio_ba, ratio_cb = aspect_ratio(law, cdf, u_all[i, U_RATIOS]), aspect_ratio(law, cdf, u_all[i, U_RATIOS + 1])
        hand = 1.0 if shapes.both_hands[shape] == 0 or u_all[i, U_HAND] < 0.5 else -1.0
        nv[i] = particle_body(shapes, shape, ratio_ba, ratio_cb, hand, verts[i], K[i], semi[i], scale)


# without numba's reference counts, like the kernels they time: with them, each row's view (verts[i], R[i], ...)
# would cost an atomic increment and decrement that a rebound never pays
PIECE_LOOP = dict(_nrt=False)


@numba.njit(**PIECE_LOOP)
def _flight_setups(shapes, shape, semi, K, R, verts, nv, W, rot, K_lab, ell, hull):
    """What rebound does at the start of a flight: K in the lab frame, ℓ = KΩ, curvature_bound, jerk_bound and
    (at the flight's second search step, if it has one) rotation_init; rot[i] receives the rotation parameters;
    K_lab (3, 3) and ell (3,) are work arrays; ``hull`` a family's (scanned: no vertex graph)."""
    kind = shapes.kind[shape]
    for i in range(semi.shape[0]):
        lab_tensor(R[i], K[i], K_lab)
        for j in range(3):
            ell[j] = K_lab[j, 0] * W[i, 0] + K_lab[j, 1] * W[i, 1] + K_lab[j, 2] * W[i, 2]
        rotation_init(K[i], R[i], ell, rot[i])
        Rb = bounding_radius(kind, semi[i], verts[i], nv[i], hull)
        curvature_bound(kind, semi[i], Rb, K[i], ell, W[i])
        jerk_bound(kind, semi[i], Rb, K[i], ell, W[i])


@numba.njit(**PIECE_LOOP)
def _orientations(rot, t, R, W):
    """The free flight's orientation and spin at time t[i] (rotation_at) into R (3, 3) and W (3,): every search
    step but a flight's first computes it."""
    for i in range(rot.shape[0]):
        rotation_at(rot[i], t[i], R, W)


@numba.njit(**PIECE_LOOP)
def _lowest_points(shapes, shape, semi, K, R, verts, nv, W, h, h1, curv):
    """The candidate lowest points of the body, their heights and rates and what gives their curvatures
    (lowest_points) into h, h1 (MAX_VERTICES,) and curv (3,): what every search step computes."""
    kind = shapes.kind[shape]
    for i in range(semi.shape[0]):
        lowest_points(kind, verts[i], nv[i], semi[i], K[i], R[i], W[i], 1.0, 0.0, h, h1, curv)


@numba.njit(**PIECE_LOOP)
def _collisions(params, shapes, shape, semi, K, R, verts, nv, model, out, h, h1, vectors, Kinv_lab):
    """One collision per row, the body at rest touching the wall at its lowest point, hit at V⁻ (the first
    collision of a rebound with Ω⁻ = 0): K⁻¹ in the lab frame and collide. out[i] = collide's outcome; h, h1
    (MAX_VERTICES,), vectors (7, 3) and Kinv_lab (3, 3) are work arrays."""
    curv, r, Kinv, V, W, dV, dW = vectors[0], vectors[1], vectors[2], vectors[3], vectors[4], vectors[5], vectors[6]
    W[:] = 0.0
    wall = params[P_WALL:]
    kind = shapes.kind[shape]
    for i in range(semi.shape[0]):
        m = lowest_points(kind, verts[i], nv[i], semi[i], K[i], R[i], W, 0.0, 0.0, h, h1, curv)
        low = 0
        for j in range(m):
            low = j if h[j] < h[low] else low
        for j in range(3):
            r[j] = R[i, j, 0] * verts[i, low, 0] + R[i, j, 1] * verts[i, low, 1] + R[i, j, 2] * verts[i, low, 2]
            Kinv[j] = 1.0 / K[i, j]
        lab_tensor(R[i], Kinv, Kinv_lab)
        V[0], V[1], V[2] = model[i, 0], model[i, 1], 0.0
        out[i] = collide(V, W, r, Kinv_lab, wall, dV, dW)


def _best(fn, repeats) -> float:
    """The best of ``repeats`` runs of fn, in seconds of this thread's CPU time: the run-time loops run on one
    thread, and CPU time leaves out the time other jobs on a shared machine take (on an idle one it equals
    the wall-clock time)."""
    best = math.inf
    for _ in range(repeats):
        t0 = time.thread_time()
        fn()
        best = min(best, time.thread_time() - t0)
    return best


PIECES = ("flight_setup", "orientation", "lowest_points", "collision")
PIECE_ROWS = 2048     # the pieces run on the first rows only: their inputs stay in cache, as inside a rebound


def piece_inputs(shapes, shape_code, u_all, model, W_after) -> dict:
    """The inputs of the pieces (module doc), from the rows' bodies: a flight's setup with the spin after the
    rebound, the orientation 0.5 a/|V⁻| into that flight, the lowest points, a first collision; the first
    PIECE_ROWS rows."""
    u_all, model, W_after = u_all[:PIECE_ROWS], model[:PIECE_ROWS], W_after[:PIECE_ROWS]
    m = len(u_all)
    semi, K, R = np.empty((m, 3)), np.empty((m, 3)), np.empty((m, 3, 3))
    verts, nv = np.zeros((m, MAX_VERTICES, 3)), np.empty(m, dtype=np.int64)
    _bodies(shapes, shape_code, u_all, semi, K, R, verts, nv, np.empty(3))
    return {"semi": semi, "K": K, "R": R, "verts": verts, "nv": nv, "W": np.where(np.isfinite(W_after), W_after, 0.0),
            "t": 0.5 / np.hypot(model[:, 0], model[:, 1]), "model": model, "u": u_all}


def write_pieces(path: Path, pieces: dict) -> None:
    """The pieces' inputs as rbs_bench_direct reads them (native/bench/rbs_bench_direct.c)."""
    m = len(pieces["t"])
    rows = np.column_stack([pieces["semi"], pieces["R"].reshape(m, 9), pieces["verts"].reshape(m, -1),
                            pieces["nv"].astype(np.float64), pieces["W"], pieces["t"], pieces["model"], pieces["u"]])
    with open(path, "wb") as f:
        f.write(np.int64(m).tobytes())
        f.write(np.ascontiguousarray(rows, dtype=np.float64).tobytes())


def piece_costs(params, shapes, shape_code, pieces: dict, repeats) -> dict:
    """µs per call of numba's pieces of a rebound; each is cheap: the best of 5 × ``repeats`` runs."""
    semi, K, R, verts, nv, W, t, model = (pieces[k] for k in ("semi", "K", "R", "verts", "nv", "W", "t", "model"))
    m = len(t)
    rot = np.empty((m, ROT_PARAMS_SIZE))
    outcome = np.empty(m, dtype=np.int64)
    R1, vectors = np.empty((3, 3)), np.empty((7, 3))
    h, h1 = np.empty(MAX_VERTICES), np.empty(MAX_VERTICES)
    runs = 5 * repeats
    family = scanned_hull(verts[0])
    return {"us_flight_setup": 1e6 * _best(lambda: _flight_setups(shapes, shape_code, semi, K, R, verts, nv, W, rot,
                                                                    R1, vectors[0], family), runs) / m,
            "us_orientation": 1e6 * _best(lambda: _orientations(rot, t, R1, vectors[0]), runs) / m,
            "us_lowest_points": 1e6 * _best(lambda: _lowest_points(shapes, shape_code, semi, K, R, verts, nv, W, h,
                                                                   h1, vectors[0]), runs) / m,
            "us_collision": 1e6 * _best(lambda: _collisions(params, shapes, shape_code, semi, K, R, verts, nv, model,
                                                            outcome, h, h1, vectors, R1), runs) / m}


def split(row: dict, costs: dict, total_us: float) -> dict:
    """Each piece's share (%) of total_us at the row's counts per rebound; the rest."""
    counts = {"flight_setup": row["flights_per_rebound"],
              "orientation": row["search_steps_per_rebound"] - row["flights_per_rebound"],
              "lowest_points": row["search_steps_per_rebound"], "collision": row["collisions_per_rebound"]}
    shares = {f"pct_{k}": 100 * counts[k] * costs[f"us_{k}"] / total_us for k in PIECES}
    shares["pct_rest"] = 100 - sum(shares.values())
    return shares


# ----------------------------------------------------------------------------- incident states

def random_states(m: int, spin: tuple, seed: int, alpha1_deg: tuple = (5.0, 90.0),
                  speed_m_s: tuple = (50.0, 300.0)) -> dict:
    """m incident states (module doc), |Ω⁻|a/|V⁻|, α1 (degrees) and |V⁻| (m/s) uniform in the given ranges,
    Ω⁻ in a random direction: V (m, 3) m/s, n (m, 3) unit normals, a (m,) = 1 m, Ω (m, 3) rad/s."""
    rng = np.random.default_rng(seed)
    alpha1 = np.radians(rng.uniform(*alpha1_deg, m))
    speed = rng.uniform(*speed_m_s, m)
    frames = np.linalg.qr(rng.normal(size=(m, 3, 3)))[0]           # random orthonormal frames
    local_V = np.c_[np.cos(alpha1), -np.sin(alpha1), np.zeros(m)] * speed[:, None]
    local_W = rng.normal(size=(m, 3))
    local_W *= (rng.uniform(*spin, m) * speed / np.linalg.norm(local_W, axis=1))[:, None]
    return {"V": np.einsum("mij,mj->mi", frames, local_V), "n": np.ascontiguousarray(frames[:, :, 1]),
            "a": np.ones(m), "omega": np.einsum("mij,mj->mi", frames, local_W)}


def read_hits_sample(path: Path = HITS_SAMPLE) -> dict:
    """A sample of wall hits (integrations/openfoam/sample_hits.py writes it: '#' comment lines, then a header
    naming the columns) as arrays: V (m, 3) m/s, n (m, 3) unit normals into the gas, a (m,) m, omega (m, 3) Ω⁻
    rad/s, spin_ratio (m,) |Ω⁻|a/|V⁻|."""
    with open(path) as f:
        lines = [line for line in f if not line.startswith("#")]
    names = lines[0].strip().split(",")
    data = np.array([[float(x) for x in line.split(",")] for line in lines[1:]], dtype=np.float64)
    data = data.reshape(-1, len(names))

    def columns(*wanted):
        missing = [c for c in wanted if c not in names]
        if missing:
            raise ValueError(f"{path}: no column {','.join(missing)}; the columns are {lines[0].strip()!r}")
        return np.ascontiguousarray(data[:, [names.index(c) for c in wanted]])

    return {"V": columns("Vx", "Vy", "Vz"), "n": columns("nx", "ny", "nz"), "a": columns("a")[:, 0],
            "omega": columns("Wx", "Wy", "Wz"), "spin_ratio": columns("spin_ratio")[:, 0]}


def state_sets(m: int, hits_path: Path) -> dict:
    """The four sets of incident states of the run-time rows (module doc)."""
    hits = read_hits_sample(hits_path)
    return {"random, 0": random_states(m, (0.0, 0.0), SEED), "random, spin": random_states(m, (0.0, 1.2), SEED + 1),
            "spinning": random_states(m, (0.02, 0.8), SEED + 2, (20.0, 70.0), (100.0, 250.0)),
            "hopper": {k: hits[k] for k in ("V", "n", "a", "omega")}}


# ----------------------------------------------------------------------------- the C side

def c_runtime(program: Path, table: Path, states: dict, shape_code: int, repeats: int, folder: Path,
              pieces: dict) -> dict:
    """µs per rebound of rbs_direct_rebound in a C loop (native/bench/rbs_bench_direct.c) on the states, its
    outputs for the first timed pass (the uniforms of seed SEED, as the numba loop draws them), and µs per
    call of C's rebound alone and of its pieces on the same inputs as numba's."""
    count = len(states["a"])
    path, out, pieces_path = folder / "direct_states.bin", folder / "direct_out.bin", folder / "direct_pieces.bin"
    with open(path, "wb") as f:
        f.write(np.int64(count).tobytes())
        for key in ("V", "omega", "n", "a"):
            f.write(np.ascontiguousarray(states[key], dtype=np.float64).tobytes())
    write_pieces(pieces_path, pieces)
    done = subprocess.run([str(program), str(table), str(path), str(shape_code), str(repeats), str(SEED), str(out),
                           str(pieces_path)], capture_output=True, text=True)
    if done.returncode != 0:
        raise SystemExit(f"rbs_bench_direct failed:\n{done.stderr}")
    figures = json.loads(done.stdout)
    raw = out.read_bytes()
    figures["V_out"] = np.frombuffer(raw, np.float64, 3 * count).reshape(count, 3)
    figures["W_out"] = np.frombuffer(raw, np.float64, 3 * count, 24 * count).reshape(count, 3)
    figures["status"] = np.frombuffer(raw, np.int8, count, 48 * count)
    return figures


# ----------------------------------------------------------------------------- one row

def bench_runtime(params, shapes, states: dict, set_name: str, shape_code: int, repeats: int, native=None) -> dict:
    """µs per rebound of the run-time kernel on one set of states with one shape, the C kernel's if
    ``native`` = (program, table, folder), counts per rebound and the time split (module doc)."""
    V, n, a, W = states["V"], states["n"], states["a"], states["omega"]
    m = len(a)
    status, V_out, W_out = np.empty(m, dtype=np.int8), np.empty((m, 3)), np.empty((m, 3))
    best = _best(lambda: _kernel_loop(params, shapes, shape_code, V, W, n, a, seed_state(SEED), status, V_out, W_out),
                 repeats)
    u_all, model = np.empty((m, U_PER_REBOUND)), np.empty((m, 5))
    counts, W_after = np.empty((m, 3), dtype=np.int64), np.empty((m, 3))
    _model_frame_inputs(V, n, a, W, seed_state(SEED), u_all, model)
    best_model = _best(lambda: _model_frame_loop(params, shapes, model, shape_code, u_all, counts, W_after), repeats)
    rest = counts[:, 0] != STATUS_TRAPPED            # a trapped particle costs n_max collisions
    sub_model, sub_u, sub_counts, sub_W = model[rest], u_all[rest], counts[rest], W_after[rest]
    best_rest = _best(lambda: _model_frame_loop(params, shapes, sub_model, shape_code, sub_u, sub_counts, sub_W),
                      repeats)
    ok = counts[:, 0] == STATUS_REBOUNDED
    row = {"shape": SHAPES[shape_code], "states": set_name, "n": m,
           "us_per_rebound": 1e6 * best / m, "us_model_frame": 1e6 * best_model / m,
           "us_model_frame_untrapped": 1e6 * best_rest / max(1, int(rest.sum())),
           "flights_per_rebound": float(np.mean(counts[:, 1] + 1)),
           "collisions_per_rebound": float(np.mean(counts[:, 1])),
           "search_steps_per_rebound": float(np.mean(counts[:, 2])),
           "collisions_per_rebounded": float(counts[ok, 1].mean()),
           "search_steps_per_rebounded": float(counts[ok, 2].mean()),
           "trapped": int(np.sum(status == STATUS_TRAPPED)), "failed": int(np.sum(status == STATUS_FAILED)),
           "us_c": math.nan, "c_over_numba": math.nan, "c_same_bits": None}
    # the split: counts per rebound × µs per piece; the rest is the body's setup, the search's own logic
    # (the contact choice, Newton and safe steps) and the frame
    pieces = piece_inputs(shapes, shape_code, u_all, model, W_after)
    row.update(piece_costs(params, shapes, shape_code, pieces, repeats))
    row.update(split(row, row, row["us_model_frame"]))
    row["pct_trapped"] = 100 * (1 - best_rest / best_model) if not rest.all() else 0.0
    if native is not None:
        c = c_runtime(*native[:2], states, shape_code, repeats, native[2], pieces)
        row["us_c"], row["us_c_wall"] = c["us_per_rebound"], c["us_per_rebound_wall"]
        c_costs = {f"us_{k}": c[f"us_{k}"] for k in PIECES}
        row.update({f"c_{k}": v for k, v in c_costs.items()}, c_us_model_frame=c["us_model_frame"])
        row.update({f"c_{k}": v for k, v in split(row, c_costs, c["us_model_frame"]).items()})
        row["c_over_numba"] = row["us_c"] / row["us_per_rebound"]
        row["c_same_bits"] = bool(np.array_equal(c["status"], status)
                                  and np.array_equal(c["V_out"].view(np.int64), V_out.view(np.int64))
                                  and np.array_equal(c["W_out"].view(np.int64), W_out.view(np.int64)))
    return row


def _print_rows(rows, columns) -> None:
    header = " ".join(f"{h:{'<' if i < 2 else '>'}{w}}" for i, (h, w, _, _) in enumerate(columns))
    print(header)
    print("-" * len(header))
    for row in rows:
        print(" ".join(f"{row[k]:{'<' if i < 2 else '>'}{w}{spec}}" for i, (_, w, spec, k) in enumerate(columns)))


def main_runtime(states: int, repeats: int, hits_path: Path, table_path: Path | None, build_dir: Path | None,
                 native: bool) -> list:
    """Print and return the run-time kernels' figures (module doc)."""
    sets = state_sets(states, hits_path)
    with tempfile.TemporaryDirectory(prefix="bench_direct_") as tmp:
        tmp = Path(tmp)
        if table_path is None and native:
            table_path = tmp / "direct.h5"
            build_table(parse_config(BENCH_TABLE_CONFIG), table_path)
        params = (surrogate.load(table_path).direct_parameters if table_path is not None
                  else model_parameters(AspectRatioLaw(), 0.3, DEFAULT_N_MAX, CORUNDUM_ON_STEEL, DEFAULT_CONTACT_TOL,
                                        DEFAULT_SET_TOL, DEFAULT_MAX_STEPS, second_moment_factors(0.3)))
        shapes = family_shapes(params)
        c_side = None
        if native:
            folder = build_dir if build_dir is not None else build_native(tmp / "build", "rbs_bench_direct")
            program = folder / "rbs_bench_direct"
            if not program.is_file():
                raise SystemExit(f"{program} not found: build native/ with -DRBS_BUILD_BENCH=ON")
            c_side = (program, table_path, tmp)
        warm = random_states(16, (0.0, 1.2), SEED)
        for code in range(len(SHAPES)):                  # warm-up: compile the loops
            bench_runtime(params, shapes, warm, "warm-up", code, 1)
        print(f"\nRun-time kernels, one thread, best of {repeats}: numba (surrogate.kernels.direct_rebound)"
              + (" and C (rbs_direct_rebound)" if native else "") + f"; states: {states} random per row with Ω⁻ = 0 "
              f"('random, 0') or spinning ('random, spin'; 'spinning': |Ω⁻|a/|V⁻| 0.02–0.8, α1 20–70°, "
              f"100–250 m/s), "
              f"and {len(sets['hopper']['a'])} hopperRebound hits "
              f"({hits_path.name}, {np.mean(np.any(sets['hopper']['omega'] != 0, axis=1)):.0%} spinning) run with "
              "each shape ('hopper')")
        rows = [bench_runtime(params, shapes, sets[name], name, code, repeats, c_side)
                for code in range(len(SHAPES)) for name in STATE_SETS]
    _print_rows(rows, RUNTIME_COLUMNS)
    print("numba us, C us: µs per rebound of the whole call (uniforms, frame, checks, rebound), the mean over all\n"
          "the states, trapped ones included. frame us: numba's rebound alone (rebound_model_frame, the same\n"
          "uniforms); untrapped: the same over the particles not trapped (a trapped one runs n_max collisions).\n"
          "flights, coll, steps: means per particle (trapped included) of flights, collisions, contact-search steps.")
    if native:
        same = all(r["c_same_bits"] for r in rows)
        print(f"C outputs equal numba's bits on every row: {'yes' if same else 'NO'}")
    if native:
        hopper = {r["shape"]: r["us_c"] for r in rows if r["states"] == "hopper"}
        spinning = np.mean([r["us_c"] for r in rows if r["states"] == "spinning"])
        print(f"\nTargets, C: <= {HOPPER_TARGET_US} us per rebound on one core averaged over hopperRebound's hits, "
              "per shape: " + "; ".join(f"{k} {v:.2f} ({'met' if v <= HOPPER_TARGET_US else 'NOT met'})"
                                       for k, v in hopper.items())
              + f"\n  <= {SPINNING_TARGET_US} us averaged over the shapes at the 'spinning' states: {spinning:.2f} "
              f"({'met' if spinning <= SPINNING_TARGET_US else 'NOT met'})")
    else:
        print(f"\nTargets, C (<= {HOPPER_TARGET_US} us per hopperRebound hit, <= {SPINNING_TARGET_US} us at the "
              "'spinning' states): not measured (--no-native)")
    print("\nWhere numba's time goes (rebound alone): µs per call of each piece on the rows' bodies, times its\n"
          "count per rebound above, as a share of 'frame us'. setup: a flight's start (K in the lab frame, ℓ,\n"
          "the bounds, rotation_init), counted once per flight (an upper count: a flight decided at its first\n"
          "step skips rotation_init); orient: the free flight's orientation at one instant (rotation_at), once\n"
          "per search step but a flight's first; lowest: the body's lowest points with their rates and\n"
          "g̈ for the curvatures (lowest_points), once per search step; coll: one collision (K⁻¹ in the lab\n"
          "frame, collide), once per collision. rest: the body's setup,\n"
          "the search's own logic (the safe and Newton steps, the contact choice), the frame's rotations; the pieces\n"
          "timed alone run hotter in cache than inside a rebound, so rest is uncertain by about ±10 points.\n"
          "trapped %: the share of the time spent on trapped particles (1 − untrapped time / all).")
    _print_rows(rows, SPLIT_COLUMNS)
    if native:
        print("\nWhere C's time goes: the same pieces in C (rbs_rotation_init, rbs_rotation_at, rbs_lowest_points,\n"
              "rbs_collide, on the same inputs), times the same counts, as a share of C's rebound alone\n"
              "(rbs_rebound_model_frame, the same uniforms: frame us).")
        _print_rows(rows, C_SPLIT_COLUMNS)
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
    parser.add_argument("--hits", type=Path, default=HITS_SAMPLE,
                        help="the hopperRebound hits sample (default benchmarks/data/hopper_hits.csv)")
    parser.add_argument("--table", type=Path, help="take the model parameters from this table (default: the "
                        "defaults; with the C side, a small table built with them)")
    parser.add_argument("--build-dir", type=Path, help="a build of native/ holding rbs_bench_direct (else built here)")
    parser.add_argument("--no-native", action="store_true", help="the numba kernel only, not the C one")
    args = parser.parse_args(argv)
    repeats = args.repeats or (1 if args.quick else 3)
    min_time = args.min_time or (0.1 if args.quick else 1.0)
    states = args.states or (500 if args.quick else 20_000)

    info = machine_info()
    threads = info["numba_default_threads"]
    print("Direct rebound model throughput (direct_model.simulate; the run-time kernels direct_rebound, rbs_direct_rebound)")
    for key, value in info.items():
        print(f"  {key:22s} {value}")
    runtime_rows = main_runtime(states, repeats, args.hits, args.table, args.build_dir, not args.no_native)
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
