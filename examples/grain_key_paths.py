"""How far the table path and the direct path differ for a keyed population (issue 35, docs/runtime.md "Grain keys").

A grain key fixes a particle's shape on either path, and on the direct path its proportions (b/a, c/b) and hand
too; the table path draws them from the shape's law at every hit (the table holds each shape's law over its
random proportions). So under the table path the grains of one shape differ only by chance, under the direct path
each grain keeps a mean of its own. This script hits ``--keys`` grains ``--hits`` times each at one incident state
(α1 = 45°, |V⁻| = 100 m/s, no spin, a 50/50 mix of prisms and tetrahedra), by each path, and reports per grain
the mean rebound angle α2 and speed ratio |V⁺|/|V⁻|: their spread over the grains of each shape (the standard
deviation of the per-grain means, and what sampling alone gives, the within-grain sd / √hits) and the population
law (all hits of all grains), which the two paths must share up to the table's fit. Writes
docs/grain_key_paths.png (or ``--figure``).

    python examples/grain_key_paths.py                  # builds a small table into ./grain_key_output (~1 min)
    python examples/grain_key_paths.py --table TABLE.h5 # a table with prism and tetrahedron, α1 45° and 100 m/s
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

import surrogate
from example_table import load_or_build

REPO = Path(__file__).resolve().parents[1]
ALPHA1_DEG, SPEED = 45.0, 100.0          # the incident state, deg and m/s
HALF_SIZE = 1e-4                         # m
MIX = {"prism": 0.5, "tetrahedron": 0.5}
TABLE_TOML = """\
# Small table for examples/grain_key_paths.py: the incident state (45 deg, 100 m/s) on its grid.
[grid]
alpha1_deg = [30.0, 45.0, 60.0]
speed_m_s = [100.0, 150.0]
shapes = ["prism", "tetrahedron"]

[simulation]
particles_per_cell = 20000
seed = 35
"""


def get_table(path, out: Path):
    """Load ``path``, or build (once) the small table into ``out``."""
    return load_or_build(path, out, "grain_key_table.h5", TABLE_TOML)


def keyed_hits(table, keys: np.ndarray, hits: int, method: str, seed: int):
    """(α2 deg, |V⁺|/|V⁻|, rebounded) of every hit, (keys, hits): each key hits ``hits`` times at the state."""
    n = len(keys) * hits
    a1 = np.radians(ALPHA1_DEG)
    V = np.tile([SPEED * np.cos(a1), -SPEED * np.sin(a1), 0.0], (n, 1))
    # clamp: |V⁻| rounds to just above a grid speed of 100 m/s; the table path reads that edge's law
    hits = surrogate.sample_global(table, V, (0.0, 1.0, 0.0), HALF_SIZE, MIX, random_state=seed,
                                   method=method, clamp=True, grain_key=np.repeat(keys, hits))
    V_out, status = hits.V, hits.status
    with np.errstate(invalid="ignore"):
        alpha2 = np.degrees(np.arctan2(V_out[:, 1], np.hypot(V_out[:, 0], V_out[:, 2])))
    ratio = np.linalg.norm(V_out, axis=1) / SPEED
    shape = (len(keys), hits)
    return alpha2.reshape(shape), ratio.reshape(shape), (status == surrogate.STATUS_REBOUNDED).reshape(shape)


def grain_means(values, rebounded):
    """Per grain: the mean over its rebounded hits, and the sd within it."""
    count = rebounded.sum(axis=1)
    x = np.where(rebounded, values, 0.0)
    mean = x.sum(axis=1) / count
    sd = np.sqrt(np.where(rebounded, (values - mean[:, None]) ** 2, 0.0).sum(axis=1) / (count - 1))
    return mean, sd, count


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--table", type=Path, default=None, help="a table with prism and tetrahedron")
    parser.add_argument("--keys", type=int, default=2000)
    parser.add_argument("--hits", type=int, default=50)
    parser.add_argument("--seed", type=int, default=35)
    parser.add_argument("--out", type=Path, default=Path("grain_key_output"))
    parser.add_argument("--figure", type=Path, default=REPO / "docs" / "grain_key_paths.png")
    args = parser.parse_args(argv)
    table = get_table(args.table, args.out)
    keys = surrogate.grain_key(args.seed, np.arange(args.keys))
    grains = surrogate.grain_of(table, keys, MIX)
    start = time.perf_counter()
    results = {method: keyed_hits(table, keys, args.hits, method, args.seed + 1) for method in ("table", "direct")}
    print(f"{args.keys} keys x {args.hits} hits at alpha1 = {ALPHA1_DEG:g} deg, |V-| = {SPEED:g} m/s, "
          f"{', '.join(f'{k} {v:g}' for k, v in MIX.items())}: {time.perf_counter() - start:.1f} s")

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(2, 2, figsize=(10, 7.5))
    quantities = (("alpha2 (deg)", 0), ("|V+|/|V-|", 1))
    for row, (label, q) in enumerate(quantities):
        print(f"{label}:")
        for shape_name, color in zip(MIX, ("tab:blue", "tab:red")):
            rows = grains.shape == shape_name
            for method, style in (("table", "-"), ("direct", "--")):
                values, rebounded = results[method][q], results[method][2]
                mean, sd, count = grain_means(values[rows], rebounded[rows])
                chance = np.sqrt(np.mean(sd ** 2 / count))       # the spread of the means by sampling alone
                pooled = values[rows][rebounded[rows]]
                own = np.sqrt(max(np.var(mean) - chance ** 2, 0.0))     # what the grains themselves add
                print(f"  {shape_name:<12} {method:<6}: {rows.sum():4d} grains, sd of the per-grain means "
                      f"{np.std(mean):.4f} (chance alone {chance:.4f}, the grains' own {own:.4f}); population "
                      f"mean {pooled.mean():.4f}, sd {pooled.std():.4f}")
                axes[row, 0].hist(mean, bins=40, histtype="step", linestyle=style, color=color,
                                  label=f"{shape_name}, {method} path")
                axes[row, 1].hist(pooled, bins=60, histtype="step", linestyle=style, color=color, density=True,
                                  label=f"{shape_name}, {method} path")
        axes[row, 0].set_xlabel(f"per-grain mean {label} ({args.hits} hits)")
        axes[row, 0].set_ylabel("grains")
        axes[row, 1].set_xlabel(f"{label}, every hit")
        axes[row, 1].set_ylabel("density")
    axes[0, 0].legend(fontsize=8)
    fig.suptitle(f"{args.keys} grains x {args.hits} hits, alpha1 = {ALPHA1_DEG:g} deg, |V-| = {SPEED:g} m/s: "
                 f"a grain's own mean (left), the population law (right)", fontsize=10)
    fig.tight_layout()
    fig.savefig(args.figure, dpi=110)
    print(f"figure written to {args.figure}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
