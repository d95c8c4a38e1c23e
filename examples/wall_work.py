"""The work of the four-family mix's hits on the wall, from a table against the direct model (docs/model.md §4.7,
docs/design/table_representation.md "The work on the wall").

At |V⁻| = 100 and 200 m/s and α1 from grazing to normal, draws ``--n`` hits of the mix (equal parts of the four
families, no spin) from the table (:func:`surrogate.sample_global`, ``method="table"``) and from the direct model
the table was built with (:func:`surrogate.sample_direct`, another seed), and prints per case the mean normal and
tangential work W_n, W_t per hit in units of E⁻ = ½|V⁻|² (the work per unit mass in J/kg is that times ½|V⁻|²) from
both, and the two-sample KS statistic of each. Writes the mean curves and the distributions at three angles to
docs/wall_work.png (or ``--figure``; none with ``--no-figure``).

    python examples/wall_work.py                   # builds a small table into ./wall_work_output (~1 min)
    python examples/wall_work.py --table TABLE.h5  # any table of the four families with the work (format 4.1)
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
from scipy.stats import ks_2samp

import surrogate
from example_table import load_or_build

REPO = Path(__file__).resolve().parents[1]
HALF_SIZE = 1e-4                                            # m: the work per unit mass does not depend on it
SPEEDS = (100.0, 200.0)                                     # m/s
ALPHA1_DEG = (5.0, 10.0, 15.0, 20.0, 30.0, 45.0, 60.0, 75.0, 85.0, 90.0)
PROFILES = (15.0, 45.0, 85.0)                               # α1 of the figure's distributions, at the higher speed
TABLE_TOML = """\
# Small table for examples/wall_work.py: the four families, both speeds on the grid.
[grid]
alpha1_deg = [2.5, 5.0, 10.0, 15.0, 20.0, 30.0, 45.0, 60.0, 75.0, 85.0, 90.0]
speed_m_s = [100.0, 200.0]

[simulation]
particles_per_cell = 5000
seed = 56
"""


def work(hits, speed: float) -> tuple:
    """(W_n/E⁻, W_t/E⁻) of the hits that rebounded or were trapped."""
    kept = (hits.status == surrogate.STATUS_REBOUNDED) | (hits.status == surrogate.STATUS_TRAPPED)
    energy = 0.5 * speed * speed
    return hits.wall_work_normal[kept] / energy, hits.wall_work_tangential[kept] / energy


def run(table, n: int, seed: int) -> dict:
    """{(|V⁻|, α1): {"table": (W_n/E⁻, W_t/E⁻), "direct": (...)}}."""
    cases = {}
    for speed in SPEEDS:
        for alpha1 in ALPHA1_DEG:
            a1 = np.radians(alpha1)
            V = np.tile([speed * np.cos(a1), -speed * np.sin(a1), 0.0], (n, 1))
            drawn = surrogate.sample_global(table, V, [0, 1, 0], HALF_SIZE, "mix", random_state=seed, method="table",
                                            clamp=True)
            direct = surrogate.sample_direct(table, V, [0, 1, 0], HALF_SIZE, "mix", random_state=seed + 1)
            cases[speed, alpha1] = {"table": work(drawn, speed), "direct": work(direct, speed)}
    return cases


def report(cases: dict, n: int) -> None:
    print(f"{n} hits per case, the mix, no spin; W in units of 1/2 |V-|^2 (table / direct model, KS)")
    print("|V-|  alpha1     W_n table  direct      KS     W_t table  direct      KS")
    for (speed, alpha1), c in cases.items():
        (tn, tt), (dn, dt) = c["table"], c["direct"]
        print(f"{speed:4g}  {alpha1:6g}   {tn.mean():10.4f} {dn.mean():7.4f}  {ks_2samp(tn, dn).statistic:6.4f}   "
              f"{tt.mean():10.4f} {dt.mean():7.4f}  {ks_2samp(tt, dt).statistic:6.4f}")


def figure(cases: dict, path: Path) -> None:
    from matplotlib.figure import Figure

    fig = Figure(figsize=(14, 7.6), layout="constrained")
    axes = fig.subplots(2, 4)
    alpha1 = np.array(ALPHA1_DEG)
    for k, name in enumerate(("normal $W_n$", "tangential $W_t$")):
        ax = axes[k, 0]
        for speed, style in zip(SPEEDS, ("--", "-")):
            for source, marker in (("table", None), ("direct", "o")):
                means = [cases[speed, a][source][k].mean() for a in alpha1]
                ax.plot(alpha1, means, ls=style if source == "table" else "none", marker=marker, mfc="none",
                        color="C0" if source == "table" else "k", label=f"{source}, {speed:g} m/s")
        ax.set(xlabel=r"$\alpha_1$ (deg)", ylabel=f"mean {name} / $E^-$")
        ax.legend(fontsize=7)
        for j, a in enumerate(PROFILES):
            ax = axes[k, j + 1]
            c = cases[SPEEDS[-1], a]
            both = np.concatenate([c["table"][k], c["direct"][k]])
            bins = np.linspace(np.quantile(both, 0.002), np.quantile(both, 0.998), 60)
            ax.hist(c["table"][k], bins=bins, density=True, histtype="step", color="C0", label="table")
            ax.hist(c["direct"][k], bins=bins, density=True, histtype="step", color="k", label="direct model")
            ax.set(xlabel=f"{name} / $E^-$", title=f"$\\alpha_1$ = {a:g}°, {SPEEDS[-1]:g} m/s")
            ax.legend(fontsize=7)
    fig.suptitle("Work on the wall per hit, the four-family mix: table against the direct model")
    fig.savefig(path, dpi=110)
    print(f"figure written to {path}")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--table", help="a table of the four families (default: build a small one)")
    parser.add_argument("--out", default="wall_work_output", help="folder of the small table it builds")
    parser.add_argument("--n", type=int, default=20_000, help="hits per case (default 20000)")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--figure", default=str(REPO / "docs" / "wall_work.png"))
    parser.add_argument("--no-figure", action="store_true")
    args = parser.parse_args(argv)
    table = load_or_build(args.table, Path(args.out), "wall_work_table.h5", TABLE_TOML)
    if not table.kernel_data.has_work:
        parser.error(f"the table {table.path} holds no work on the wall (format 4.0); rebuild it")
    cases = run(table, args.n, args.seed)
    report(cases, args.n)
    if not args.no_figure:
        figure(cases, Path(args.figure))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
