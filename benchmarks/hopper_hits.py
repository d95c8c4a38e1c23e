"""Extract a deterministic sample of wall hits from a finished hopperRebound run, with each hit's Ω⁻.

    PYTHONPATH=. python benchmarks/hopper_hits.py CASE [--out benchmarks/data/hopper_hits.csv] [--max 3000]

CASE is a run of integrations/openfoam/cases/hopperRebound (a colliding cloud, written with ``writeHits
true``). Its hits files (postProcessing/lagrangian/<cloud>/stochasticRebound/hits_<rank>.csv, read by
``compare_rebounds.read_hits``) give per hit V⁻ relative to the wall (m/s), the unit normal n into the gas,
the half-size a (m) and the Ω⁺ (rad/s) the stochasticRebound model set. They do not give Ω⁻: it is the
Ω⁺ of the same parcel's previous hit (parcels keyed by origProc, origId, hits in time then file order),
0 at its first hit. That holds because the case runs with ``collisionModel none``: in OpenFOAM v1912
``CollidingParcel::move`` changes the angular momentum only in its half velocity steps, by ½Δt times the
torque; the torque starts at zero and only the collision model's ``collide`` sets it (``NoCollision``'s
does nothing), so nothing turns a parcel between two wall hits. The script checks it against the run's own record,
the column spin_ratio = |Ω⁻|a/|V⁻|, and refuses a run where the two differ by more than 1e-7 relative
(spin_ratio is written with 9 digits; Ω goes through the angular momentum I Ω and back).

The sample is every k-th hit in file order, k = ceil(hits / --max), so that it spans the whole run; it is
written with %.17g, so the benchmark reads back the run's bits. Columns: Vx, Vy, Vz (m/s), nx, ny, nz,
a (m), Wx, Wy, Wz (Ω⁻, rad/s), spin_ratio (|Ω⁻|a/|V⁻|, recomputed).
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "integrations" / "openfoam"))

from compare_rebounds import read_hits  # noqa: E402  (integrations/openfoam: the hits files' reader)

DEFAULT_OUT = HERE / "data" / "hopper_hits.csv"
COLUMNS = ("Vx", "Vy", "Vz", "nx", "ny", "nz", "a", "Wx", "Wy", "Wz", "spin_ratio")
SPIN_RATIO_TOLERANCE = 1e-7       # relative (9 written digits, Ω through I Ω and back)


def incident_spins(hits: dict) -> np.ndarray:
    """Ω⁻ (rad/s) of every hit: the Ω⁺ of the same parcel's previous hit it rebounded from, else 0."""
    order = np.lexsort((np.arange(len(hits["time"])), hits["rank"], hits["time"]))
    omega_in = np.zeros((len(order), 3))
    last = {}
    for i in order:
        key = (int(hits["origProc"][i]), int(hits["origId"][i]))
        omega_in[i] = last.get(key, (0.0, 0.0, 0.0))
        if np.all(np.isfinite(hits["Wout"][i])):       # an invalid hit (NaN outputs) leaves the spin as it was
            last[key] = hits["Wout"][i]
    return omega_in


def spin_ratios(hits: dict, omega_in: np.ndarray) -> np.ndarray:
    """|Ω⁻| a / |V⁻| per hit, as the adapter writes it (0 for a parcel at rest)."""
    speed = np.linalg.norm(hits["V"], axis=1)
    return np.where(speed > 0, np.linalg.norm(omega_in, axis=1) * hits["a"] / np.where(speed > 0, speed, 1.0), 0.0)


def extract(case: Path, out: Path, most: int) -> dict:
    hits, headers = read_hits(case)
    omega_in = incident_spins(hits)
    ratio = spin_ratios(hits, omega_in)
    worst = float(np.max(np.abs(ratio - hits["spin_ratio"]) / np.maximum(hits["spin_ratio"], 1e-300)))
    if worst > SPIN_RATIO_TOLERANCE:
        raise SystemExit(f"{case}: Omega- reconstructed from the previous hits does not match the run's spin_ratio "
                         f"(worst relative difference {worst:.3g} > {SPIN_RATIO_TOLERANCE:g}): a run with a collision "
                         "model, or hits missing from the files?")
    count = len(hits["time"])
    stride = max(1, math.ceil(count / most))
    rows = np.arange(0, count, stride)
    table = np.column_stack([hits["V"][rows], hits["n"][rows], hits["a"][rows], omega_in[rows], ratio[rows]])
    out.parent.mkdir(parents=True, exist_ok=True)
    spinning = ratio[rows] > 0
    with open(out, "w") as f:
        f.write("# Wall hits of a hopperRebound run (integrations/openfoam/cases/hopperRebound, collisionModel none), "
                "written by benchmarks/hopper_hits.py\n")
        f.write(f"# run: {case.name}, {count} hits, table mix {headers[0]['shape']}, seed {headers[0]['seed']}; every "
                f"{stride}th hit in file order: {len(rows)} rows, {spinning.mean():.1%} spinning, median "
                f"|Omega-|a/|V-| of those {np.median(ratio[rows][spinning]) if spinning.any() else 0.0:.3g}\n")
        f.write("# Omega- = Omega+ of the parcel's previous hit (0 at its first); spin_ratio matches the run's "
                f"column to {worst:.2g} relative. Units: V m/s, n unit (into the gas), a m, W rad/s\n")
        f.write(",".join(COLUMNS) + "\n")
        for r in table:
            f.write(",".join(f"{x:.17g}" for x in r) + "\n")
    return {"hits": count, "rows": len(rows), "stride": stride, "spinning": float(spinning.mean()),
            "worst_spin_ratio_difference": worst}


def read_sample(path: Path = DEFAULT_OUT) -> dict:
    """The sample as arrays: V (m, 3) m/s, n (m, 3), a (m,) m, omega (m, 3) rad/s, spin_ratio (m,)."""
    with open(path) as f:
        lines = [line for line in f if not line.startswith("#")]
    if lines[0].strip() != ",".join(COLUMNS):
        raise ValueError(f"{path}: the columns must be {','.join(COLUMNS)}; got {lines[0].strip()!r}")
    data = np.array([[float(x) for x in line.split(",")] for line in lines[1:]], dtype=np.float64)
    return {"V": np.ascontiguousarray(data[:, 0:3]), "n": np.ascontiguousarray(data[:, 3:6]),
            "a": np.ascontiguousarray(data[:, 6]), "omega": np.ascontiguousarray(data[:, 7:10]),
            "spin_ratio": data[:, 10]}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("case", type=Path, help="a finished hopperRebound run (with its hits files)")
    parser.add_argument("--out", type=Path, default=DEFAULT_OUT, help=f"the CSV to write (default {DEFAULT_OUT})")
    parser.add_argument("--max", type=int, default=3000, help="rows at most (default 3000)")
    args = parser.parse_args(argv)
    if args.max < 1:
        print(f"hopper_hits.py: --max must be >= 1; got {args.max}", file=sys.stderr)
        return 2
    summary = extract(args.case, args.out, args.max)
    print(f"{args.out}: {summary['rows']} of {summary['hits']} hits (every {summary['stride']}th), "
          f"{summary['spinning']:.1%} spinning; spin_ratio matches to {summary['worst_spin_ratio_difference']:.2g}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
