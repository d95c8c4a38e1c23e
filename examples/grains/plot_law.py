"""The rebound law of the example grains against the four families, at one incident state (docs/model.md §9).

    python examples/grains/plot_law.py [--n 20000] [--alpha1 45] [--speed 150] [--seed 1] [--out grains_law.png]

Each shape's rebounds come from the direct model (``direct_model.simulate``) at α1 (degrees from the wall) and
|V⁻| (m/s), Ω⁻ = 0: the grains of ``grains.toml`` (their meshes' convex hulls, fixed proportions) and the
families with their b/a, c/b law. The figure shows, per shape, the distribution of the in-plane rebound angle α2
(degrees from the wall, 0–180) and of s = |V⁺|/|V⁻|; the legend gives the mean of each. Needs
the ``build`` and ``plots`` extras (trimesh reads the meshes, matplotlib draws).
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from direct_model.shapes import SHAPES
from direct_model.simulate import simulate
from tablegen.tabulation.config import load_config

HERE = Path(__file__).resolve().parent


def rebound_samples(n: int, alpha1: float, speed: float, seed: int) -> dict:
    """{shape name: (α2 in degrees from +X, the incident side's wall direction, s)} of the rebounded particles,
    families first, then the grains of grains.toml."""
    grains = load_config(HERE / "grains.toml").grains
    out = {}
    for k, shape in enumerate((*SHAPES, *grains)):
        samples = simulate(shape, alpha1, speed, n, seed=seed + k)
        ok = samples.rebounded
        out[getattr(shape, "name", shape)] = (np.degrees(samples.alpha2[ok]), samples.speed_ratio[ok])
    return out


def plot(samples: dict, alpha1: float, speed: float, path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (ax_a, ax_s) = plt.subplots(1, 2, figsize=(11, 4.2))
    for name, (alpha2, s) in samples.items():
        style = dict(histtype="step", density=True, lw=2.0 if name in SHAPES else 1.0,
                     ls="-" if name in SHAPES else "--")
        ax_a.hist(alpha2, bins=np.linspace(0.0, 180.0, 61), label=f"{name} ({np.mean(alpha2):.1f}°)", **style)
        ax_s.hist(s, bins=np.linspace(0.0, 1.0, 41), label=f"{name} ({np.mean(s):.3f})", **style)
    ax_a.set_xlabel("α2, degrees from the wall (in-plane, 0–180)")
    ax_s.set_xlabel("s = |V⁺| / |V⁻|")
    for ax in (ax_a, ax_s):
        ax.set_ylabel("density")
        ax.legend(fontsize=7)
    fig.suptitle(f"Rebounds at α1 = {alpha1:g}°, |V⁻| = {speed:g} m/s, Ω⁻ = 0: families (solid), "
                 f"example grains (dashed)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=20000)
    parser.add_argument("--alpha1", type=float, default=45.0)
    parser.add_argument("--speed", type=float, default=150.0)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--out", type=Path, default=Path("grains_law.png"))
    args = parser.parse_args(argv)
    samples = rebound_samples(args.n, args.alpha1, args.speed, args.seed)
    plot(samples, args.alpha1, args.speed, args.out)
    for name, (alpha2, s) in samples.items():
        print(f"{name:12s} rebounded {len(s):6d}  mean alpha2 {np.mean(alpha2):6.2f} deg  mean s {np.mean(s):.4f}")
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
