"""What spin memory does: hopperRebound's kinematic cloud with ``spinRelaxation auto`` against ``off``.

    python spin_memory_figure.py --with WITH_CASE --without WITHOUT_CASE -o FILE.png

reads the hits files of two runs of hopperRebound with the plain kinematic cloud
(``uncoupledKinematicParcelFoam``, tests/openfoam/cases.py's ``kinematic`` and ``kinematic_off``; docs/openfoam.md
"Spin memory"), WITH_CASE run with spin memory (``spinRelaxation auto`` or a time), WITHOUT_CASE with
``spinRelaxation off``, prints the numbers it plots and draws, side by side:

* the distribution of the incoming spin ratio |Ω⁻|a/|V⁻| (the hits files' ``spin_ratio``) of all hits with
  memory, on a log axis, with the table's tolerance :data:`surrogate.SPIN_TOLERANCE` marked (above it, under
  ``method auto``, the direct model answers); the hits that arrive without spin (a parcel's first) are counted
  in the legend, a log axis having no 0;
* the distributions of the rebound angle α2 (deg, from the wall in the plane of V⁻ and n, as
  tablegen.study.solver_comparison.impact_states) and of s = |V⁺|/|V⁻| of the rebounded hits of both runs.

A run of the wrong spin memory (WITH_CASE run with ``off``, WITHOUT_CASE not) is refused with one line
(exit 2), as is a case without hits files.

Copyright (C) 2026 the rebound-scatter authors. License: GPL-3.0-or-later
(see LICENSE in this folder).
"""

from __future__ import annotations

import argparse
import re
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from compare_rebounds import HITS_TITLE, hits_dir, read_hits  # noqa: E402
from rbs_api import STATUS_REBOUNDED, impact_states, rank_files  # noqa: E402
from surrogate import SPIN_TOLERANCE  # noqa: E402

LABELS = {"with": "with spin memory", "without": "without spin memory"}
COLOURS = {"with": "C0", "without": "C3"}


def spin_memory(case: Path) -> str:
    """What the run's spinRelaxation did, as its hits files' second header line says (``Spin memory: auto: ...``):
    ``auto``, ``off`` or the time given; ValueError if the rank files say different things or nothing."""
    modes = set()
    for f in rank_files(hits_dir(Path(case))):
        with open(f) as fh:
            fh.readline()
            m = re.search(r"Spin memory: ([^:]+):", fh.readline())
        modes.add(m.group(1).strip() if m else "not stated")
    if len(modes) != 1 or "not stated" in modes:
        raise ValueError(f"{case}: its hits files do not state one spin memory ({', '.join(sorted(modes))})")
    return modes.pop()


def run_figures(case: Path) -> dict:
    """The spin ratio of all drawn hits, α2 (deg) and s of the rebounded ones, and the counts."""
    hits, _ = read_hits(Path(case))
    drawn = hits["interaction"] == HITS_TITLE
    ratio = hits["spin_ratio"][drawn]
    ok = drawn & (hits["status"] == STATUS_REBOUNDED)
    states = impact_states(hits["V"][ok], hits["n"][ok], hits["a"][ok], hits["Vout"][ok], hits["Wout"][ok])
    return {"hits": int(drawn.sum()), "rebounded": int(ok.sum()), "spin_ratio": ratio,
            "above_tolerance": float(np.mean(ratio > SPIN_TOLERANCE)), "spinning": int(np.sum(ratio > 0)),
            "spin_ratio_mean": float(ratio.mean()), "alpha2": np.degrees(states[:, 0]), "s": states[:, 2]}


def summary(with_case: Path, without_case: Path) -> dict:
    """Both runs' figures (:func:`run_figures`), their spin memory and the KS distances of α2 and s."""
    from scipy.stats import ks_2samp

    out = {}
    for label, case in (("with", with_case), ("without", without_case)):
        mode = spin_memory(case)
        if (mode == "off") != (label == "without"):
            raise ValueError(f"{case} was run with spinRelaxation {mode}, "
                             + ("not with spin memory" if label == "with" else "not off"))
        out[label] = dict(run_figures(case), mode=mode)
    out["ks"] = {k: float(ks_2samp(out["with"][k], out["without"][k]).statistic) for k in ("alpha2", "s")}
    return out


def report(res: dict) -> str:
    lines = []
    for label in ("with", "without"):
        r = res[label]
        lines.append(f"{LABELS[label]} (spinRelaxation {r['mode']}): {r['hits']} hits, {r['spinning']} arrived "
                     f"spinning, {r['above_tolerance']:.3f} above the tolerance {SPIN_TOLERANCE:g}; mean spin ratio "
                     f"|Omega|a/|V| {r['spin_ratio_mean']:.3f}; {r['rebounded']} rebounded: mean alpha2 "
                     f"{r['alpha2'].mean():.1f} deg, mean |V+|/|V-| {r['s'].mean():.3f}")
    lines.append(f"KS distance with vs without: alpha2 {res['ks']['alpha2']:.3f}, |V+|/|V-| {res['ks']['s']:.3f}")
    return "\n".join(lines)


def plot(res: dict, png: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (spin, angle, speed) = plt.subplots(1, 3, figsize=(13, 3.9))
    r = res["with"]
    ratio = r["spin_ratio"][r["spin_ratio"] > 0]
    if len(ratio):
        bins = np.logspace(np.floor(np.log10(ratio.min())), np.ceil(np.log10(ratio.max())), 41)
        spin.hist(ratio, bins=bins, color=COLOURS["with"], alpha=0.8,
                  label=f"{len(ratio)} hits arriving spinning\n({r['hits'] - len(ratio)} more without spin: "
                        "first hits)")
    spin.set_xscale("log")
    spin.set_xlim(left=SPIN_TOLERANCE / 3)
    spin.axvline(SPIN_TOLERANCE, color="k", ls="--", lw=1,
                 label=f"table's tolerance {SPIN_TOLERANCE:g}\n({r['above_tolerance']:.1%} of all hits above)")
    spin.set_xlabel("incoming spin ratio |Ω⁻|a/|V⁻|")
    spin.set_ylabel("hits")
    spin.set_title(f"with spin memory (spinRelaxation {r['mode']}), mean {r['spin_ratio_mean']:.3f}", fontsize=9)
    spin.legend(fontsize=7.5)
    for ax, key, bins, xlabel in ((angle, "alpha2", np.linspace(0, 180, 37), "rebound angle α2 (deg)"),
                                  (speed, "s", np.linspace(0, max(1.2, float(np.ceil(10 * max(
                                      res["with"]["s"].max(), res["without"]["s"].max())) / 10)), 41),
                                   "|V⁺|/|V⁻|")):
        for label in ("with", "without"):
            x = res[label][key]
            ax.hist(x, bins=bins, density=True, histtype="step", lw=1.5, color=COLOURS[label],
                    label=f"{LABELS[label]}: mean {x.mean():.3f}" if key == "s" else
                    f"{LABELS[label]}: mean {x.mean():.1f}°")
        ax.set_xlabel(xlabel)
        ax.set_ylabel("density")
        ax.set_ylim(0, 1.3 * ax.get_ylim()[1])
        ax.legend(fontsize=7.5, loc="upper right" if key == "alpha2" else "upper left",
                  title=f"{res['with']['rebounded']} / {res['without']['rebounded']} rebounds, "
                  f"KS distance {res['ks'][key]:.3f}", title_fontsize=7.5)
    angle.set_title("hopperRebound, kinematic cloud: the rebounds", fontsize=9)
    fig.tight_layout()
    fig.savefig(png, dpi=100)
    plt.close(fig)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--with", dest="with_case", type=Path, required=True,
                        help="hopperRebound run with spin memory (spinRelaxation auto or a time)")
    parser.add_argument("--without", dest="without_case", type=Path, required=True,
                        help="hopperRebound run with spinRelaxation off")
    parser.add_argument("-o", "--output", type=Path, help="write the figure here (PNG)")
    args = parser.parse_args(argv)
    try:
        res = summary(args.with_case, args.without_case)
    except (ValueError, FileNotFoundError) as exc:
        print(f"spin_memory_figure.py: {exc}", file=sys.stderr)
        return 2
    print(report(res))
    if args.output:
        plot(res, args.output)
        print(f"wrote {args.output}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
