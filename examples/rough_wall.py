"""The rebound law of the four-family mix on rough walls (docs/model.md §12).

For α1 = 10°, 30°, 60° at 150 m/s and roughness Δγ = 0 (smooth), 5°, 10°, 20°, draws ``--n`` hits of the mix
(equal parts of the four families, no spin) with :func:`surrogate.sample_global` and reports, per case, the mean
and standard deviation of the rebound angles α2 (from the wall) and β2 (out of the impact plane), the share of hits
that hit the wall again (a rebound off a facet into the mean wall), the hits that reached the cap of
MAX_WALL_HITS facet hits, and the cost per hit. Writes the distributions of α2 and β2 to docs/rough_wall.png (or
``--figure``; none with ``--no-figure``).

    python examples/rough_wall.py                   # builds a small table into ./rough_wall_output (~1 min)
    python examples/rough_wall.py --table TABLE.h5  # any table of the four families
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

import surrogate
from example_table import load_or_build

REPO = Path(__file__).resolve().parents[1]
SPEED, HALF_SIZE = 150.0, 1e-4          # m/s, m
ALPHA1_DEG = (10.0, 30.0, 60.0)
ROUGHNESS_DEG = (0.0, 5.0, 10.0, 20.0)
# facets meet the particle at any α1: the grid spans grazing to normal, so the table answers most facet hits
TABLE_TOML = """\
# Small table for examples/rough_wall.py: the four families, 150 m/s between grid speeds.
[grid]
alpha1_deg = [1.0, 2.5, 5.0, 10.0, 15.0, 20.0, 30.0, 40.0, 50.0, 60.0, 70.0, 80.0, 90.0]
speed_m_s = [100.0, 200.0]

[simulation]
particles_per_cell = 5000
seed = 55
"""


def get_table(path, out: Path):
    """Load ``path``, or build (once) the small table into ``out``."""
    return load_or_build(path, out, "rough_wall_table.h5", TABLE_TOML)


def rebound_angles(V: np.ndarray) -> tuple:
    """(α2, β2) in degrees of rebounds V (N, 3) from the wall y = 0, impact plane XY."""
    return (np.degrees(np.arctan2(V[:, 1], np.hypot(V[:, 0], V[:, 2]))),
            np.degrees(np.arctan2(V[:, 2], V[:, 0])))


def run(table, n: int, seed: int) -> dict:
    """{(α1, Δγ): dict of the case's draws and figures}."""
    cases = {}
    for alpha1 in ALPHA1_DEG:
        a1 = np.radians(alpha1)
        V = np.tile([SPEED * np.cos(a1), -SPEED * np.sin(a1), 0.0], (n, 1))
        for roughness in ROUGHNESS_DEG:
            surrogate.sample_global(table, V[:10], [0, 1, 0], HALF_SIZE, "mix", random_state=seed,
                                    roughness_deg=roughness)       # compiled before it is timed
            start = time.perf_counter()
            hits = surrogate.sample_global(table, V, [0, 1, 0], HALF_SIZE, "mix", random_state=seed,
                                           roughness_deg=roughness)
            seconds = time.perf_counter() - start
            ok = hits.status == surrogate.STATUS_REBOUNDED
            alpha2, beta2 = rebound_angles(hits.V[ok])
            cases[alpha1, roughness] = {
                "alpha2": alpha2, "beta2": beta2, "trapped": float(np.mean(hits.status == surrogate.STATUS_TRAPPED)),
                "again": float(np.mean(hits.wall_hits > 1)),
                "capped": int(np.count_nonzero(hits.wall_hits == surrogate.MAX_WALL_HITS)),
                "direct": float(np.mean(hits.path == 1)), "us_per_hit": 1e6 * seconds / n}
    return cases


def report(cases: dict, n: int) -> None:
    print(f"{n} hits per case, the mix, |V-| = {SPEED:g} m/s, no spin")
    print("alpha1  dgamma   alpha2 mean   sd    beta2 mean   sd   hit again  capped  trapped  direct  us/hit")
    for (alpha1, roughness), c in cases.items():
        print(f"{alpha1:6g}  {roughness:6g}   {c['alpha2'].mean():11.2f} {c['alpha2'].std():5.2f}  "
              f"{c['beta2'].mean():11.2f} {c['beta2'].std():5.2f}   {100 * c['again']:7.2f} % {c['capped']:6d}  "
              f"{100 * c['trapped']:6.2f} % {100 * c['direct']:5.1f} % {c['us_per_hit']:7.2f}")


def figure(cases: dict, path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, len(ALPHA1_DEG), figsize=(12, 6.5), constrained_layout=True)
    for j, alpha1 in enumerate(ALPHA1_DEG):
        for roughness in ROUGHNESS_DEG:
            c = cases[alpha1, roughness]
            label = "smooth" if roughness == 0 else f"Δγ = {roughness:g}°"
            axes[0, j].hist(c["alpha2"], bins=np.linspace(0, 90, 46), density=True, histtype="step", label=label)
            axes[1, j].hist(c["beta2"], bins=np.linspace(-90, 90, 61), density=True, histtype="step", label=label)
        axes[0, j].set_title(f"α1 = {alpha1:g}°, {SPEED:g} m/s, the mix")
        axes[0, j].set_xlabel("α2 (deg)")
        axes[1, j].set_xlabel("β2 (deg)")
    axes[0, 0].set_ylabel("density")
    axes[1, 0].set_ylabel("density")
    axes[0, -1].legend()
    fig.savefig(path, dpi=110)
    print(f"figure written to {path}")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--table", type=Path, default=None, help="a table of the four families")
    parser.add_argument("--out", type=Path, default=Path("rough_wall_output"), help="where the built table goes")
    parser.add_argument("--n", type=int, default=20000, help="hits per case (default 20000)")
    parser.add_argument("--seed", type=int, default=12)
    parser.add_argument("--figure", type=Path, default=REPO / "docs" / "rough_wall.png")
    parser.add_argument("--no-figure", action="store_true")
    args = parser.parse_args(argv)
    table = get_table(args.table, args.out)
    cases = run(table, args.n, args.seed)
    report(cases, args.n)
    if not args.no_figure:
        figure(cases, args.figure)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
