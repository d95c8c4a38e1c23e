"""Extract a deterministic sample of wall hits from a finished hopperRebound run, with each hit's Ω⁻.

    PYTHONPATH=. python integrations/openfoam/sample_hits.py CASE [--out benchmarks/data/hopper_hits.csv] [--max 3000]

CASE is a run of integrations/openfoam/cases/hopperRebound written with ``writeHits true``. Its hits files
(postProcessing/lagrangian/<cloud>/stochasticRebound/hits_<rank>.csv, read by ``compare_rebounds.read_hits``)
give per hit V⁻ relative to the wall (m/s), the incident angular velocity Ω⁻ the adapter passed to the model
(columns Winx, Winy, Winz, rad/s), the unit normal n into the gas and the half-size a (m). The script checks
each hit's Ω⁻ against the run's own record of it, the column spin_ratio = |Ω⁻|a/|V⁻|, and refuses a file where
they differ by more than SPIN_RATIO_TOLERANCE relative (a and spin_ratio are written with 9 digits).

The sample is every k-th hit in file order, k = ceil(hits / --max), so that it spans the whole run; it is
written with %.17g, so a reader gets the run's bits. Its columns (SAMPLE_COLUMNS): Vx, Vy, Vz (m/s), nx, ny,
nz, a (m), Wx, Wy, Wz (Ω⁻, rad/s), spin_ratio (|Ω⁻|a/|V⁻|, recomputed). benchmarks/bench_direct.py times the
direct model on it.

Copyright (C) 2026 the rebound-scatter authors. License: GPL-3.0-or-later
(see LICENSE in this folder).
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from compare_rebounds import read_hits  # noqa: E402

DEFAULT_OUT = Path(__file__).resolve().parents[2] / "benchmarks" / "data" / "hopper_hits.csv"
SAMPLE_COLUMNS = ("Vx", "Vy", "Vz", "nx", "ny", "nz", "a", "Wx", "Wy", "Wz", "spin_ratio")
SPIN_RATIO_TOLERANCE = 2e-8   # relative: a and spin_ratio each rounded to 9 digits (≤ 5e-9 each), with margin


def spin_ratios(V: np.ndarray, a: np.ndarray, omega: np.ndarray) -> np.ndarray:
    """|Ω⁻| a / |V⁻| per hit, as the adapter writes it (0 for a parcel at rest)."""
    speed = np.linalg.norm(V, axis=1)
    moving = speed > 0
    return np.where(moving, np.linalg.norm(omega, axis=1) * a / np.where(moving, speed, 1.0), 0.0)


def extract(case: Path, out: Path, most: int) -> dict:
    """Write every k-th hit of CASE to ``out`` (module doc); return the counts and the spin_ratio check."""
    hits, headers = read_hits(case)
    ratio = spin_ratios(hits["V"], hits["a"], hits["Win"])
    worst = float(np.max(np.abs(ratio - hits["spin_ratio"]) / np.maximum(hits["spin_ratio"], 1e-300)))
    if worst > SPIN_RATIO_TOLERANCE:
        raise SystemExit(f"{case}: the hits' Omega- (Winx, Winy, Winz) does not match the run's spin_ratio "
                         f"(worst relative difference {worst:.3g} > {SPIN_RATIO_TOLERANCE:g})")
    count = len(hits["time"])
    stride = max(1, math.ceil(count / most))
    rows = np.arange(0, count, stride)
    table = np.column_stack([hits["V"][rows], hits["n"][rows], hits["a"][rows], hits["Win"][rows], ratio[rows]])
    spinning = ratio[rows] > 0
    settings = headers[0]
    out.parent.mkdir(parents=True, exist_ok=True)
    with open(out, "w") as f:
        f.write("# Wall hits of a hopperRebound run (integrations/openfoam/cases/hopperRebound, serial), written by "
                "integrations/openfoam/sample_hits.py\n")
        f.write(f"# run: {case.name}, method {settings['method']}, {count} hits, table mix {settings['shape']}, seed "
                f"{settings['seed']}; every {stride}th hit in file order: {len(rows)} rows, {spinning.mean():.1%} "
                f"spinning, median |Omega-|a/|V-| of those "
                f"{np.median(ratio[rows][spinning]) if spinning.any() else 0.0:.3g}\n")
        f.write("# Omega- = the hits file's Winx, Winy, Winz; spin_ratio matches the run's column to "
                f"{worst:.2g} relative. Units: V m/s, n unit (into the gas), a m, W rad/s\n")
        f.write(",".join(SAMPLE_COLUMNS) + "\n")
        for r in table:
            f.write(",".join(f"{x:.17g}" for x in r) + "\n")
    return {"hits": count, "rows": len(rows), "stride": stride, "spinning": float(spinning.mean()),
            "worst_spin_ratio_difference": worst}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("case", type=Path, help="a finished hopperRebound run (with its hits files)")
    parser.add_argument("--out", type=Path, default=DEFAULT_OUT, help=f"the CSV to write (default {DEFAULT_OUT})")
    parser.add_argument("--max", type=int, default=3000, help="rows at most (default 3000)")
    args = parser.parse_args(argv)
    if args.max < 1:
        print(f"sample_hits.py: --max must be >= 1; got {args.max}", file=sys.stderr)
        return 2
    summary = extract(args.case, args.out, args.max)
    print(f"{args.out}: {summary['rows']} of {summary['hits']} hits (every {summary['stride']}th), "
          f"{summary['spinning']:.1%} spinning; spin_ratio matches to {summary['worst_spin_ratio_difference']:.2g}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
