#!/usr/bin/env python3
"""A particle beam hitting a flat wall and a cylinder: the surrogate's rebounds vs a specular sphere.

A tiny Lagrangian tracker (numba, straight-line motion, no gas) moves a beam of
non-spherical grains and calls the runtime sampler :func:`surrogate.kernels.rebound`
at each wall hit, with the grain's incident spin Ω⁻ (``--spin``; zero by default): the table
answers where it is valid, the direct model elsewhere (a spinning grain, a hit off the table's
grid). The same beam is tracked again with the rebound of a sphere
(v_n -> -e v_n with a constant restitution e, tangential velocity unchanged).

Frames and units (SI throughout): global frame XYZ, lengths in m, velocities in
m/s, times in s. The beam moves in the XY plane (z = 0 at the start).

1. Flat wall: the plane y = 0, gas at y > 0 (normal +Y); the beam comes in at
   ``--angle`` degrees from the wall, moving towards +X.
2. Cylinder: radius R, axis along Z through the origin (its cross-section is
   the XY plane); the beam moves along +X and covers |y| < R, so it strikes
   the front at every incidence angle, from normal (y = 0) to grazing
   (|y| -> R). The wall normal is the unit vector from the axis to the hit point.

Particles are points for the geometry (half-size a = 50 um << R); a is used by
the kernel to scale the spin (Ω in rad/s, Ω a/|V| dimensionless). Each particle hits at most once (the
rebound leaves a flat or convex wall). A trapped particle (status 1) stays at
its hit point.

    python examples/particle_beam.py                       # builds a small table first (~1-2 min)
    python examples/particle_beam.py --table TABLE.h5 --n 20000 --seed 1 --out beam_output
    python examples/particle_beam.py --spin 0.6         # grains spinning about Z, Omega- a/|V-| = 0.6
"""

from __future__ import annotations

import argparse
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
from numba import njit

REPO = Path(__file__).resolve().parent.parent
try:
    import surrogate
except ImportError:            # running from a source checkout without `pip install -e .`
    sys.path.insert(0, str(REPO))
    import surrogate
from surrogate import STATUS_REBOUNDED, STATUS_TRAPPED, U_PER_DRAW, fill_uniforms, seed_state
from surrogate.kernels import METHOD_AUTO, rebound

# A small table for this beam: alpha1 down to 2 deg (grazing hits on the
# cylinder; below 2 deg the direct model answers), speeds 100-200 m/s.
SMALL_TABLE_TOML = """\
# Small table for examples/particle_beam.py (builds in about 1-2 minutes on 2 cores).
[grid]
alpha1_deg = [2.0, 5.0, 10.0, 15.0, 20.0, 30.0, 40.0, 50.0, 60.0, 70.0, 80.0, 90.0]
speed_m_s = [100.0, 150.0, 200.0]
shapes = ["ellipsoid", "prism", "cut_prism", "tetrahedron"]

[simulation]
particles_per_cell = 20000
"""

WALL, CYLINDER = 0, 1          # geometry codes for the tracker
TABLE, SPECULAR = 0, 1         # rebound models
MISSED, REBOUNDED, TRAPPED = -2, STATUS_REBOUNDED, STATUS_TRAPPED   # per-particle outcome

SPEED_RANGE = (150.0, 200.0)   # beam speed, uniform, m/s
SPREAD_DEG = 1.5               # wall beam: direction spread (s.d., in the XY plane), degrees
HALF_SIZE = 50e-6              # particle half-size a, m
RADIUS = 0.01                  # cylinder radius R, m


# --------------------------------------------------------------------------- tracker

@njit
def hit_time(p, v, geometry, radius):
    """Time until the point p + v t reaches the wall (inf if it never does)."""
    if geometry == WALL:                       # plane y = 0, gas above
        return -p[1] / v[1] if v[1] < 0.0 else np.inf
    # cylinder |(x, y)| = R: smaller root of |p_xy + v_xy t|^2 = R^2, if approaching
    a = v[0] * v[0] + v[1] * v[1]
    b = p[0] * v[0] + p[1] * v[1]
    c = p[0] * p[0] + p[1] * p[1] - radius * radius
    disc = b * b - a * c
    if a == 0.0 or b >= 0.0 or disc < 0.0:
        return np.inf
    return max((-b - math.sqrt(disc)) / a, 0.0)


@njit   # not cache=True: a cached copy would not notice later edits to surrogate.kernels
def track(pos, vel, omega, t_end, dt, geometry, radius, model, data, params, shape_arrays, model_shapes, mix_cdf,
          half_size, e, rng_state):
    """Move every particle to time t_end (in place); rebound it at its wall hit.

    pos, vel, omega : (N, 3) start positions (m), velocities (m/s) and spins (rad/s, kept in free flight),
        global frame.
    model : TABLE (surrogate kernel: table.kernel_data, table.direct_parameters, table.shape_arrays,
        table.model_shapes) or SPECULAR (sphere with restitution e).
    rng_state : (4,) uint64 xoshiro256+ state (surrogate.seed_state), advanced in place.
    Returns (V+ at the hit (N, 3) m/s, NaN if missed or trapped; outcome (N,) int8).
    """
    n = pos.shape[0]
    v_out = np.full((n, 3), np.nan)
    outcome = np.full(n, MISSED, dtype=np.int8)
    u = np.empty(U_PER_DRAW)                   # uniforms for one kernel call
    normal = np.empty(3)
    vo = np.empty(3)
    n_steps = int(math.ceil(t_end / dt))
    dt = t_end / n_steps
    for i in range(n):
        p = pos[i].copy()
        v = vel[i].copy()
        for _ in range(n_steps):
            t_hit = hit_time(p, v, geometry, radius) if outcome[i] == MISSED else np.inf
            if t_hit > dt:                     # free flight over the whole step
                p += v * dt
                continue
            p += v * t_hit                     # to the wall; unit normal into the gas
            if geometry == WALL:
                normal[0], normal[1], normal[2] = 0.0, 1.0, 0.0
            else:
                r = math.sqrt(p[0] * p[0] + p[1] * p[1])
                normal[0], normal[1], normal[2] = p[0] / r, p[1] / r, 0.0
            if model == TABLE:
                fill_uniforms(rng_state, u)
                hit = rebound(data, params, shape_arrays, model_shapes, mix_cdf, (v[0], v[1], v[2]),
                              (omega[i, 0], omega[i, 1], omega[i, 2]),
                              (normal[0], normal[1], normal[2]), half_size, u, METHOD_AUTO)
                status, V_new = hit.status, hit.V
                vo[0], vo[1], vo[2] = V_new
            else:
                vn = v[0] * normal[0] + v[1] * normal[1] + v[2] * normal[2]
                for k in range(3):
                    vo[k] = v[k] - (1.0 + e) * vn * normal[k]
                status = REBOUNDED
            outcome[i] = status
            if status != REBOUNDED:            # trapped (or a rare failed direct rebound): stays where it hit
                break
            v_out[i] = vo
            v[:] = vo
            p += v * (dt - t_hit)              # rest of the step after the bounce
        pos[i] = p
    return v_out, outcome


# --------------------------------------------------------------------------- beams

def wall_beam(n, angle_deg, rng):
    """Beam towards the plane y = 0 at angle_deg from the wall, starting 5 mm above it."""
    speed = rng.uniform(*SPEED_RANGE, n)
    ang = np.radians(angle_deg + SPREAD_DEG * rng.standard_normal(n))
    vel = speed[:, None] * np.column_stack([np.cos(ang), -np.sin(ang), np.zeros(n)])
    pos = np.column_stack([rng.uniform(-0.005, 0.005, n), np.full(n, 0.005), np.zeros(n)])
    return pos, vel


def cylinder_beam(n, rng):
    """Parallel beam along +X from x = -2R, covering |y| < R (every incidence angle on the front)."""
    speed = rng.uniform(*SPEED_RANGE, n)
    vel = speed[:, None] * np.array([1.0, 0.0, 0.0])
    pos = np.column_stack([np.full(n, -2 * RADIUS), RADIUS * rng.uniform(-1, 1, n), np.zeros(n)])
    return pos, vel


def beam_spin(vel, spin):
    """Ω⁻ (rad/s) of grains spinning about +Z with Ω⁻a/|V⁻| = spin."""
    omega = np.zeros_like(vel)
    omega[:, 2] = spin * np.linalg.norm(vel, axis=1) / HALF_SIZE
    return omega


def run(pos, vel, t_end, geometry, model, table, cdf, e, seed, spin=0.0):
    """Track a copy of the beam, its grains spinning about +Z with Ω⁻a/|V⁻| = spin; returns (final positions,
    V+, outcome)."""
    pos = pos.copy()
    dt = 0.02 * RADIUS / SPEED_RANGE[1]        # 0.2 mm per step at the top speed
    params = table.direct_parameters if table.direct_parameters is not None else np.zeros(0)
    v_out, outcome = track(pos, vel, beam_spin(vel, spin), t_end, dt, geometry, RADIUS, model, table.kernel_data,
                           params, table.shape_arrays, table.model_shapes, cdf, HALF_SIZE, e, seed_state(seed))
    return pos, v_out, outcome


# --------------------------------------------------------------------------- table

def get_table(path, out):
    """Load --table, or build (once) a small table into the output folder."""
    if path is None:
        path = out / "beam_table.h5"
        if path.exists():
            print(f"no --table given: reusing the small table built earlier, {path}")
        else:
            config = out / "beam_table.toml"
            config.write_text(SMALL_TABLE_TOML)
            print(f"no --table given: building a small table into {path} (about 1-2 minutes; "
                  f"configuration {config}) ...", flush=True)
            env = dict(os.environ, PYTHONPATH=os.pathsep.join(filter(None, [str(REPO), os.environ.get("PYTHONPATH")])))
            cmd = [sys.executable, "-m", "tablegen.cli", "build", "--config", str(config), "-o", str(path),
                   "--no-progress"]
            if subprocess.run(cmd, env=env).returncode != 0:
                sys.exit(f"table build failed: {' '.join(cmd)}")
    table = surrogate.load(path)
    lo, hi = table.speed_range
    if SPEED_RANGE[0] < lo or SPEED_RANGE[1] > hi:
        print(f"note: beam speeds {SPEED_RANGE} m/s exceed the table's range [{lo:g}, {hi:g}] m/s; "
              f"the direct model answers those hits")
    return table


# --------------------------------------------------------------------------- plots and numbers

def angles(v):
    """In-plane angle from the wall (deg, 0 = +X along the wall, 90 = normal) and out-of-plane angle (deg)."""
    return (np.degrees(np.arctan2(v[:, 1], v[:, 0])),
            np.degrees(np.arcsin(v[:, 2] / np.linalg.norm(v, axis=1))))


def plot_wall(plt, res, angle_deg, e, path):
    fig = plt.figure(figsize=(12, 5))
    ax = fig.add_subplot(1, 2, 1, projection="polar")
    bins = np.radians(np.arange(0, 181, 2.0))
    for label, color in [("surrogate", "tab:blue"), ("specular sphere", "tab:orange")]:
        h, _ = np.histogram(np.radians(res[label]["alpha2"]), bins)
        r = np.repeat(h / h.max(), 2)                      # histogram as a closed step outline
        theta = np.column_stack([bins[:-1], bins[1:]]).ravel()
        ax.fill(np.r_[0.0, theta, 0.0], np.r_[0.0, r, 0.0], color=color, alpha=0.35)
        ax.plot(theta, r, color=color, lw=1, label=label)
    nominal = np.degrees(np.arctan(e * np.tan(np.radians(angle_deg))))
    ax.plot([0, np.radians(nominal)], [0, 1.1], "k--", lw=1, label=f"specular, e = {e:g} ({nominal:.1f} deg)")
    ax.annotate("", xy=(0, 0), xytext=(np.radians(180 - angle_deg), 1.1),
                arrowprops=dict(arrowstyle="->", color="gray", lw=1.5))
    ax.text(np.radians(180 - angle_deg + 8), 0.75, "incident", color="gray", ha="center")
    ax.set_thetamin(0)
    ax.set_thetamax(180)
    ax.set_rticks([])
    ax.set_title("in-plane rebound angle from the wall (deg)\nhistogram, peak = 1", fontsize=10)
    ax.legend(loc="upper left", bbox_to_anchor=(-0.1, -0.05), fontsize=8, ncol=2)

    ax = fig.add_subplot(1, 2, 2)
    t = res["surrogate"]
    ax.scatter(t["alpha2"], t["beta2"], s=1, alpha=0.15, color="tab:blue", label="surrogate", rasterized=True)
    s = res["specular sphere"]
    ax.scatter(s["alpha2"], s["beta2"], s=4, color="tab:orange", label="specular sphere")
    ax.set_xlim(0, 180)
    ax.set_ylim(-90, 90)
    ax.set_xlabel("in-plane rebound angle from the wall, alpha2 (deg)")
    ax.set_ylabel("out-of-plane angle, beta2 (deg)")
    ax.set_title(f"rebound directions; beam at {angle_deg:g} deg to the wall, {SPEED_RANGE[0]:g}-{SPEED_RANGE[1]:g} m/s",
                 fontsize=10)
    ax.legend(markerscale=5, fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def plot_cylinder(plt, res, y0, t_end, path):
    fig, axes = plt.subplots(1, 2, figsize=(12, 6), sharex=True, sharey=True, layout="constrained")
    r_mm = RADIUS * 1e3
    for ax, (label, r) in zip(axes, res.items()):
        x, y = r["pos"][:, 0] * 1e3, r["pos"][:, 1] * 1e3
        ok = r["outcome"] != TRAPPED
        sc = ax.scatter(x[ok], y[ok], c=y0[ok] / RADIUS, cmap="coolwarm", vmin=-1, vmax=1, s=1, alpha=0.5,
                        rasterized=True)
        ax.scatter(x[~ok], y[~ok], s=4, color="k", label=f"trapped ({np.sum(~ok)})")
        ax.add_patch(plt.Circle((0, 0), r_mm, color="0.6"))
        ax.set_aspect("equal")
        ax.set_xlim(-4 * r_mm, 4 * r_mm)
        ax.set_ylim(-4 * r_mm, 4 * r_mm)
        ax.set_xlabel("x (mm)")
        ax.set_title(f"{label}: positions at t = {t_end * 1e6:.0f} us", fontsize=10)
        ax.annotate("beam", xy=(-1.2 * r_mm, 0), xytext=(-3.8 * r_mm, 0), va="center",
                    arrowprops=dict(arrowstyle="->", color="gray"), color="gray")
        if np.any(~ok):
            ax.legend(loc="lower left", fontsize=8)
    axes[0].set_ylabel("y (mm)")
    fig.colorbar(sc, ax=axes, shrink=0.8, label="impact parameter y0 / R (start height)")
    fig.suptitle("beam along +X onto a cylinder (grey, R = %g mm), projected on XY" % r_mm)
    fig.savefig(path, dpi=120)
    plt.close(fig)


def counts(v_out, outcome):
    """Counts by outcome, as text."""
    return (f"rebounded {np.sum(outcome == REBOUNDED):6d}, trapped {np.sum(outcome == TRAPPED):4d}, "
            f"missed {np.sum(outcome == MISSED):4d}")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--table", type=Path, help="rebound table (default: build a small one into --out)")
    parser.add_argument("--n", type=int, default=20000, help="particles per beam (default %(default)s)")
    parser.add_argument("--seed", type=int, default=1, help="random seed (default %(default)s)")
    parser.add_argument("--out", type=Path, default=Path("beam_output"), help="output folder (default %(default)s)")
    parser.add_argument("--angle", type=float, default=30.0, help="wall beam angle from the wall, deg (default 30)")
    parser.add_argument("--restitution", type=float, default=0.5,
                        help="normal restitution e of the specular sphere (default %(default)s)")
    parser.add_argument("--shape", default="mix", choices=["mix", "ellipsoid", "prism", "cut_prism", "tetrahedron"],
                        help="particle shape; mix = equal weights of the table's shapes (default)")
    parser.add_argument("--spin", type=float, default=0.0,
                        help="the grains' incident spin about +Z, Omega- a/|V-| (default 0: no spin)")
    args = parser.parse_args(argv)
    if args.n < 1 or args.seed < 0 or not 0.0 < args.angle < 90.0 or not math.isfinite(args.spin):
        parser.error("need --n >= 1, --seed >= 0, 0 < --angle < 90 and a finite --spin")
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("This example plots with matplotlib, which is not installed. Install the optional extra:\n"
              "    pip install 'rebound-scatter[plots]'", file=sys.stderr)
        return 1

    args.out.mkdir(parents=True, exist_ok=True)
    table = get_table(args.table, args.out)
    shape = {s: 1.0 / len(table.shapes) for s in table.shapes} if args.shape == "mix" else args.shape
    cdf = surrogate.mix_cdf(table, shape)
    rng = np.random.default_rng(args.seed)
    models = {"surrogate": TABLE, "specular sphere": SPECULAR}
    print(f"table {table.path}: shapes {', '.join(table.shapes)}, alpha1 {table.alpha1_range} deg, "
          f"speed {table.speed_range} m/s; particles: {args.shape}, Omega- a/|V-| = {args.spin:g} about +Z")

    # 1. flat wall: rebound directions
    pos, vel = wall_beam(args.n, args.angle, rng)
    t_end = 2 * 0.005 / (SPEED_RANGE[0] * math.sin(math.radians(args.angle)))   # all have hit by then
    print(f"\n1. flat wall y = 0, beam at {args.angle:g} +- {SPREAD_DEG:g} deg from the wall, {args.n} particles")
    wall = {}
    for label, model in models.items():
        _, v_out, outcome = run(pos, vel, t_end, WALL, model, table, cdf, args.restitution, args.seed, args.spin)
        ok = outcome == REBOUNDED
        a2, b2 = angles(v_out[ok])
        ratio = np.linalg.norm(v_out[ok], axis=1) / np.linalg.norm(vel[ok], axis=1)
        print(f"  {label:16s} {counts(v_out, outcome)} | in-plane angle {a2.mean():5.1f} +- {a2.std():4.1f} deg, "
              f"out-of-plane s.d. {b2.std():4.1f} deg, |V+|/|V-| {ratio.mean():.3f}")
        wall[label] = dict(alpha2=a2, beta2=b2)
    plot_wall(plt, wall, args.angle, args.restitution, args.out / "wall_rebound_directions.png")

    # 2. cylinder: where the rebounds go
    pos, vel = cylinder_beam(args.n, rng)
    t_end = 5 * RADIUS / np.mean(SPEED_RANGE)   # about 3 radii of flight after the hit
    print(f"\n2. cylinder R = {RADIUS * 1e3:g} mm, beam along +X over |y| < R, {args.n} particles")
    cyl = {}
    for label, model in models.items():
        p_end, v_out, outcome = run(pos, vel, t_end, CYLINDER, model, table, cdf, args.restitution, args.seed,
                                    args.spin)
        v = v_out[outcome == REBOUNDED]
        deflection = np.degrees(np.arccos(v[:, 0] / np.linalg.norm(v, axis=1)))   # from +X: 0 = undeflected
        print(f"  {label:16s} {counts(v_out, outcome)} | deflection {deflection.mean():5.1f} +- "
              f"{deflection.std():4.1f} deg, {100 * np.mean(v[:, 0] < 0):4.1f}% thrown back upstream (V+_x < 0)")
        cyl[label] = dict(pos=p_end, outcome=outcome)
    plot_cylinder(plt, cyl, pos[:, 1], t_end, args.out / "cylinder_positions.png")
    print(f"\nplots written to {args.out}/wall_rebound_directions.png and {args.out}/cylinder_positions.png")
    return 0


if __name__ == "__main__":
    sys.exit(main())
