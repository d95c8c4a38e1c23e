"""What simplifying a scanned grain's hull costs its rebound law (``max_vertices``, docs/design/grains.md).

A scanned-like grain: 4000 points on an ellipsoid of semi-axes 1, 0.8, 0.6 with smooth bumps of 4 % (its own
irregular shape) and 0.3 % of noise per point (the scanner's), a fixed seed; its convex hull has 1566
vertices. It is read as ``tablegen build`` reads a grain (:func:`grain_from_points`), at full size and with
``max_vertices`` = 256, 64 and 16, and the report ``tablegen build`` prints for each simplification is printed.

At α1 = 20°, 45°, 80° and 150 m/s (Ω⁻ = 0) the direct model rebounds ``--n`` particles of each version, the same
seed for every version at one state, and each simplification's rebound states X = (α2, β2, s, Ωa/|V⁻|) are
compared with the full grain's: the classifier two-sample accuracy (0.5: the laws cannot be told apart) and the
largest marginal KS statistic; and each version's wall-clock time per rebound. The baseline is the full grain
against itself with another seed: what sampling noise alone gives. Writes the distributions of α2 and s and the
comparisons to docs/grain_simplification.png (or ``--figure``; none with ``--no-figure``). Needs the ``build``
and ``plots`` extras.

    python examples/grains/simplification.py                     # 2·10⁴ particles a case, about 15 s on 2 cores
    python examples/grains/simplification.py --n 5000 --seed 3 --no-figure
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from direct_model.simulate import simulate
from tablegen.study.solver_comparison import classifier_accuracy, classifier_bound, ks_bound
from tablegen.study.validation import compare
from tablegen.tabulation.grain_files import grain_from_points

REPO = Path(__file__).resolve().parents[2]
GRAIN_SEED = 20261205
POINTS = 4000
SEMI_AXES = np.array([1.0, 0.8, 0.6])
WAVES = 12                  # plane waves on the unit sphere summed into the bumps
WAVE_NUMBER = 2.0           # the spread of their wave vectors: bumps (half waves) about half the grain across
BUMPS = 0.04                # relative radial amplitude of the bumps
SCAN_NOISE = 0.003          # relative radial noise per point
MAX_VERTICES = (256, 64, 16)
ALPHA1_DEG = (20.0, 45.0, 80.0)
SPEED = 150.0               # m/s
BASELINE = "baseline"       # the full grain against itself, another seed
ALPHA = 0.05                # level of the printed noise bounds (one law's statistics exceed them this often)


def scanned_points(seed: int = GRAIN_SEED, points: int = POINTS) -> np.ndarray:
    """(points, 3) points on a bumpy, noisy ellipsoid surface, as a scanner gives a grain's surface."""
    rng = np.random.default_rng(seed)
    u = rng.normal(size=(points, 3))
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    k = rng.normal(size=(WAVES, 3)) * WAVE_NUMBER
    phase = rng.uniform(0.0, 2.0 * np.pi, WAVES)
    bumps = np.sin(u @ k.T + phase).sum(axis=1) / np.sqrt(WAVES)        # unit variance
    radius = 1.0 + BUMPS * bumps + SCAN_NOISE * rng.normal(size=points)
    return u * SEMI_AXES * radius[:, None]


def grain_versions(points) -> tuple[dict, list]:
    """({"full": record, 256: record, 64: record, 16: record}, the simplification reports), each read as
    ``tablegen build`` reads a grain with that ``max_vertices``."""
    reports = []
    versions = {"full": grain_from_points("scan", points, "scanned grain", log=reports.append)}
    for n in MAX_VERTICES:
        versions[n] = grain_from_points("scan", points, f"max_vertices = {n}", log=reports.append, max_vertices=n)
    return versions, reports


def rebounds(record, alpha1: float, n: int, seed: int) -> dict:
    """The rebounded particles' states (m, 6), their indices among the n (the pairs a seed shares), α2 in
    degrees, s, and the wall-clock time per particle in µs."""
    start = time.perf_counter()
    s = simulate(record, alpha1, SPEED, n, seed=seed)
    us = 1e6 * (time.perf_counter() - start) / n
    ok = s.rebounded
    return {"X": np.column_stack([s.alpha2[ok], s.beta2[ok], s.speed_ratio[ok], s.omega[ok]]),
            "rows": np.flatnonzero(ok), "alpha2": np.degrees(s.alpha2[ok]), "s": s.speed_ratio[ok], "us": us}


def against(full: dict, other: dict) -> dict:
    """The classifier accuracy and the largest marginal KS of ``other``'s states against ``full``'s."""
    # a particle's two rebounds from one seed are close (correlation 0.8-0.97 at 256 vertices): split between
    # the halves, a pair is learnt under one label and scored under the other, pulling the accuracy below 0.5
    groups = np.r_[full["rows"], other["rows"]]
    ks = compare(full["X"], other["X"], joint=False)["ks"]
    name = max(ks, key=ks.get)
    n_test = (len(full["X"]) + len(other["X"])) // 2
    return {"accuracy": classifier_accuracy(full["X"], other["X"], groups=groups), "ks": ks[name], "ks_name": name,
            "accuracy_bound": classifier_bound(n_test, ALPHA),
            "ks_bound": ks_bound(len(full["X"]), len(other["X"]), ALPHA / len(ks))}


def run(versions: dict, n: int, seed: int) -> tuple[dict, dict]:
    """({(version, α1): rebounds}, {(BASELINE or N, α1): comparison with the full grain}); state k's seed is
    seed + k for every version, the baseline's seed + len(ALPHA1_DEG) + k."""
    samples, comparisons = {}, {}
    simulate(versions["full"], ALPHA1_DEG[0], SPEED, 16, seed=seed)     # compiles (or loads) the kernels: not timed
    for k, alpha1 in enumerate(ALPHA1_DEG):
        for name, record in versions.items():
            samples[name, alpha1] = rebounds(record, alpha1, n, seed + k)
        full = samples["full", alpha1]
        again = rebounds(versions["full"], alpha1, n, seed + len(ALPHA1_DEG) + k)
        comparisons[BASELINE, alpha1] = against(full, again)
        for m in MAX_VERTICES:
            comparisons[m, alpha1] = against(full, samples[m, alpha1])
    return samples, comparisons


def report(versions: dict, reports: list, samples: dict, comparisons: dict, n: int) -> None:
    print(f"full hull: {len(versions['full'].vertices)} vertices (from {POINTS} scanned points)")
    for line in reports:
        print(line)
    print(f"\n{n} particles a case, {SPEED:g} m/s, no spin; against the full grain (the same seed; baseline: the "
          f"full grain, another seed)")
    print(f"noise alone exceeds accuracy {comparisons[BASELINE, ALPHA1_DEG[0]]['accuracy_bound']:.4f} or max KS "
          f"{comparisons[BASELINE, ALPHA1_DEG[0]]['ks_bound']:.4f} with probability about {ALPHA:g}")
    print("version   alpha1  vertices  us/rebound  mean alpha2  mean s   classifier  max KS  (marginal)")
    for (name, alpha1), c in comparisons.items():
        version = "full" if name == BASELINE else name
        sample = samples[version, alpha1]
        print(f"{name!s:8s}  {alpha1:6g}  {len(versions[version].vertices):8d}  {sample['us']:10.2f}  "
              f"{sample['alpha2'].mean():11.2f}  "
              f"{sample['s'].mean():6.4f}  {c['accuracy']:10.4f}  {c['ks']:6.4f}  ({c['ks_name']})")


def figure(samples: dict, comparisons: dict, versions: dict, path: Path) -> None:
    from matplotlib.figure import Figure

    fig = Figure(figsize=(15, 7), layout="constrained")
    grid = fig.add_gridspec(2, len(ALPHA1_DEG) + 1)
    styles = {"full": dict(color="k", lw=2.0)} | {m: dict(color=f"C{j}", lw=1.2) for j, m in enumerate(MAX_VERTICES)}
    for j, alpha1 in enumerate(ALPHA1_DEG):
        ax_a, ax_s = fig.add_subplot(grid[0, j]), fig.add_subplot(grid[1, j])
        # α2 up to the versions' 99.9 % point, in 10° steps: at grazing incidence α2 stays far below 180°
        top = min(180.0, 10.0 * np.ceil(max(np.quantile(samples[m, alpha1]["alpha2"], 0.999) for m in styles) / 10.0))
        for name, style in styles.items():
            sample = samples[name, alpha1]
            label = f"{'full' if name == 'full' else f'N = {name}'} ({len(versions[name].vertices)} vertices)"
            ax_a.hist(sample["alpha2"], bins=np.linspace(0.0, top, 61), density=True, histtype="step", label=label,
                      **style)
            ax_s.hist(sample["s"], bins=np.linspace(0.0, 1.0, 51), density=True, histtype="step", label=label,
                      **style)
        ax_a.set(title=f"α1 = {alpha1:g}°, {SPEED:g} m/s", xlabel="α2, degrees from the wall", ylabel="density")
        ax_s.set(xlabel="s = |V⁺| / |V⁻|", ylabel="density")
    ax_a.legend(fontsize=7)
    names = (BASELINE, *MAX_VERTICES)
    where = np.arange(len(names))
    for row, (key, title) in enumerate((("accuracy", "classifier accuracy\nagainst the full grain"),
                                        ("ks", "largest marginal KS\nagainst the full grain"))):
        ax = fig.add_subplot(grid[row, -1])
        for j, alpha1 in enumerate(ALPHA1_DEG):
            ax.plot(where, [comparisons[m, alpha1][key] for m in names], marker="o", color=f"C{j + 3}",
                    label=f"α1 = {alpha1:g}°")
        bound = comparisons[BASELINE, ALPHA1_DEG[0]][f"{key}_bound"]
        ax.axhline(bound, color="grey", ls=":", label=f"noise bound ({ALPHA:g})")
        if key == "accuracy":
            ax.axhline(0.5, color="grey", lw=0.8)
        ax.set_xticks(where, ["full, other seed", *(f"N = {m}" for m in MAX_VERTICES)], fontsize=8)
        ax.set(title=title)
        ax.legend(fontsize=7)
    fig.suptitle(f"A scanned-like grain ({len(versions['full'].vertices)} hull vertices) simplified with "
                 f"max_vertices = N: its rebound law at {SPEED:g} m/s, Ω⁻ = 0 (direct model)")
    fig.savefig(path, dpi=110)
    print(f"figure written to {path}")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--n", type=int, default=20_000, help="particles per version and state (default 20000)")
    parser.add_argument("--seed", type=int, default=1, help="seed of the rebounds (the grain's is fixed)")
    parser.add_argument("--figure", type=Path, default=REPO / "docs" / "grain_simplification.png")
    parser.add_argument("--no-figure", action="store_true")
    args = parser.parse_args(argv)
    versions, reports = grain_versions(scanned_points())
    samples, comparisons = run(versions, args.n, args.seed)
    report(versions, reports, samples, comparisons, args.n)
    if not args.no_figure:
        figure(samples, comparisons, versions, args.figure)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
