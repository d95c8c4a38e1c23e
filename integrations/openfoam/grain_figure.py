"""Why a parcel should keep its grain: hopperRebound with the grain kept and with a new grain per hit.

    python grain_figure.py table OUT.h5                                   # the figure's table
    python grain_figure.py plot KEPT_CASE PER_HIT_CASE --png FILE.png [--json FILE.json]

``table`` builds the table of the figure (:data:`FIGURE_TABLE_CONFIG`: the case's grid with prisms and
tetrahedra, n_max = 2, so that a grain that would touch the wall a third time in one impact counts as
trapped and trapping, which depends strongly on the shape, happens at every hit). ``plot`` reads the hits
files of two runs of hopperRebound on it (``weights { prism 0.5; tetrahedron 0.5; }``, ``grain kept`` and
``grain perHit``, docs/openfoam.md "A grain stays itself") and draws, side by side:

* the fraction of parcels still moving after k wall hits, k = 1..5: the product over the hits j ≤ k of the
  fraction of the parcels that made a j-th hit and were not trapped (or failed) at it (Kaplan-Meier: a
  parcel that escapes through the outlet or is still in flight at the end of the run leaves the count
  without being counted as stopped), with Greenwood's standard error; for the kept run also per shape;
* the distribution of α1 (deg, the angle between V⁻ and the wall) at each parcel's second hit, with the
  two-sample KS distance between the runs.

Hits are ordered per parcel (origProc, origId) by time. A run of the wrong grain mode (KEPT_CASE not run
with ``grain kept``, PER_HIT_CASE not with ``grain perHit``) is refused with one line (exit 2).

Copyright (C) 2026 the rebound-scatter authors. License: GPL-3.0-or-later
(see LICENSE in this folder).
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from compare_rebounds import read_hits  # noqa: E402
from make_case_table import CASE_TABLE_CONFIG  # noqa: E402
from rbs_api import STATUS_FAILED, STATUS_TRAPPED, build_table_from_text  # noqa: E402

K_MAX = 5
FIGURE_TABLE_CONFIG = CASE_TABLE_CONFIG.replace('shapes = ["prism"]', 'shapes = ["prism", "tetrahedron"]') \
    + "n_max = 2\n"


def parcel_hits(hits: dict) -> list:
    """Each parcel's hit rows (indices into ``hits``) in time order, one array per parcel (origProc, origId)."""
    # by parcel, then time; lexsort is stable, so hits of one time step keep the files' order
    order = np.lexsort((hits["time"], hits["origId"], hits["origProc"]))
    ids = np.column_stack([hits["origProc"][order], hits["origId"][order]])
    starts = np.flatnonzero(np.r_[True, np.any(ids[1:] != ids[:-1], axis=1)])
    return np.split(order, starts[1:])


def survival(hits: dict, parcels: list, k_max: int = K_MAX) -> dict:
    """The fraction of ``parcels`` still moving after k = 1..k_max hits (Kaplan-Meier over the hits, module
    doc) with Greenwood's standard error, and per k the parcels at risk (made a k-th hit) and stopped at it."""
    stopped_status = np.isin(hits["status"], (STATUS_TRAPPED, STATUS_FAILED))
    at_risk = np.array([sum(len(p) >= k for p in parcels) for k in range(1, k_max + 1)])
    stopped = np.array([sum(len(p) >= k and stopped_status[p[k - 1]] for p in parcels)
                        for k in range(1, k_max + 1)])
    # NaN from the first k no parcel reached (nothing is known beyond it)
    rate = np.divide(stopped, at_risk, out=np.full(k_max, np.nan), where=at_risk > 0)
    greenwood = np.divide(stopped, at_risk * np.maximum(at_risk - stopped, 1), out=np.full(k_max, np.nan),
                          where=at_risk > 0)
    fraction = np.cumprod(1 - rate)
    se = fraction * np.sqrt(np.cumsum(greenwood))
    return {"k": list(range(1, k_max + 1)), "fraction": fraction.tolist(), "se": se.tolist(),
            "at_risk": at_risk.tolist(), "stopped": stopped.tolist()}


def alpha1_deg(hits: dict, rows: np.ndarray) -> np.ndarray:
    """α1 (deg) of the hits ``rows``: the angle between V⁻ and the wall, asin(−V⁻·n/|V⁻|)."""
    V, n = hits["V"][rows], hits["n"][rows]
    sin = -np.sum(V * n, axis=1) / np.linalg.norm(V, axis=1)
    return np.degrees(np.arcsin(np.clip(sin, -1, 1)))


def summary(kept_case: Path, per_hit_case: Path) -> dict:
    """The figures of both runs: survival (all parcels; per shape for the kept run), second-hit α1."""
    from scipy.stats import ks_2samp

    out = {}
    for label, case, mode in (("kept", kept_case, "kept"), ("perHit", per_hit_case, "perHit")):
        hits, headers = read_hits(Path(case))
        modes = {h["grain"] for h in headers}
        if modes != {mode}:
            raise ValueError(f"{case} was run with grain {', '.join(sorted(modes))}, not {mode}")
        parcels = parcel_hits(hits)
        second = np.array([p[1] for p in parcels if len(p) >= 2])
        run = {"parcels": len(parcels), "hits": int(len(hits["time"])), "mix": headers[0]["shape"],
               "survival": survival(hits, parcels), "alpha1_second": alpha1_deg(hits, second)}
        if mode == "kept":
            run["survival_by_shape"] = {
                str(s): survival(hits, [p for p in parcels if hits["shape"][p[0]] == s])
                for s in sorted(set(hits["shape"].tolist()))}
        out[label] = run
    a, b = out["kept"]["alpha1_second"], out["perHit"]["alpha1_second"]
    ks = ks_2samp(a, b)
    out["alpha1_second_ks"] = {"distance": float(ks.statistic), "p_value": float(ks.pvalue),
                               "mean_kept": float(a.mean()), "mean_perHit": float(b.mean()),
                               "n_kept": int(len(a)), "n_perHit": int(len(b))}
    return out


def report(res: dict) -> str:
    lines = []
    for label in ("kept", "perHit"):
        r = res[label]
        s = r["survival"]
        lines.append(f"grain {label}: {r['parcels']} parcels hit walls ({r['hits']} hits); still moving after k hits "
                     + ", ".join(f"k={k} {f:.3f}±{e:.3f}" for k, f, e in zip(s["k"], s["fraction"], s["se"])))
        for shape, ss in r.get("survival_by_shape", {}).items():
            lines.append(f"  {shape}: " + ", ".join(f"k={k} {f:.3f}" for k, f in zip(ss["k"], ss["fraction"]))
                         + f" ({ss['at_risk'][0]} parcels)")
    ks = res["alpha1_second_ks"]
    lines.append(f"second-hit alpha1: mean {ks['mean_kept']:.1f} deg (kept, {ks['n_kept']} parcels), "
                 f"{ks['mean_perHit']:.1f} deg (perHit, {ks['n_perHit']}); KS distance {ks['distance']:.3f}, "
                 f"p = {ks['p_value']:.2g}")
    return "\n".join(lines)


def plot(res: dict, png: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.2))
    colours = {"kept": "C0", "perHit": "C3"}
    names = {"kept": "grain kept", "perHit": "new grain per hit"}
    for label in ("kept", "perHit"):
        s = res[label]["survival"]
        left.errorbar(s["k"], s["fraction"], yerr=s["se"], marker="o", capsize=3, color=colours[label],
                      label=names[label])
    for (shape, s), style in zip(res["kept"].get("survival_by_shape", {}).items(), (":", "--")):
        left.plot(s["k"], s["fraction"], style, color=colours["kept"], lw=1, label=f"grain kept, its {shape} parcels")
    left.set_xlabel("wall hits k")
    left.set_ylabel("fraction of parcels still moving after k hits")
    left.set_xticks(range(1, K_MAX + 1))
    left.set_ylim(0, 1)
    left.legend(fontsize=8)
    left.set_title("hopperRebound, 50/50 prisms and tetrahedra", fontsize=9)
    bins = np.linspace(0, 90, 19)
    for label in ("kept", "perHit"):
        a = res[label]["alpha1_second"]
        right.hist(a, bins=bins, density=True, histtype="step", lw=1.5, color=colours[label],
                   label=f"{names[label]} ({len(a)} parcels, mean {a.mean():.1f}°)")
    ks = res["alpha1_second_ks"]
    right.set_xlabel("α1 at the second hit (deg)")
    right.set_ylabel("density (1/deg)")
    right.legend(fontsize=8, title=f"KS distance {ks['distance']:.3f} (p = {ks['p_value']:.2g})",
                 title_fontsize=8)
    fig.tight_layout()
    fig.savefig(png, dpi=110)
    plt.close(fig)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    table = sub.add_parser("table", help="build the figure's table")
    table.add_argument("out", type=Path)
    fig = sub.add_parser("plot", help="the figure of the two runs")
    fig.add_argument("kept_case", type=Path, help="hopperRebound run with grain kept")
    fig.add_argument("per_hit_case", type=Path, help="hopperRebound run with grain perHit")
    fig.add_argument("--png", type=Path, help="write the figure here")
    fig.add_argument("--json", type=Path, help="write the figures here")
    args = parser.parse_args(argv)
    if args.command == "table":
        build_table_from_text(FIGURE_TABLE_CONFIG, args.out)
        print(f"wrote {args.out}")
        return 0
    try:
        res = summary(args.kept_case, args.per_hit_case)
    except (ValueError, FileNotFoundError) as exc:
        print(f"grain_figure.py: {exc}", file=sys.stderr)
        return 2
    print(report(res))
    if args.png:
        plot(res, args.png)
        print(f"wrote {args.png}")
    if args.json:
        plain = {k: {kk: vv for kk, vv in v.items() if kk != "alpha1_second"} for k, v in res.items()}
        args.json.write_text(json.dumps(plain, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
