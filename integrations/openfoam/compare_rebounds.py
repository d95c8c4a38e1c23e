"""Compare the rebounds an OpenFOAM run applied with the Python implementations, the stock bounce and,
for erosion, a run with the stock bounce; map the work of its hits on the walls beside the stock erosion.

    python compare_rebounds.py CASE [--table T.h5] [--png FILE.png] [--json FILE.json] [--check]
                               [--no-classifier] [--erosion-against SPECULAR_CASE [--erosion-png FILE.png]]
                               [--work-png FILE.png]

This file holds what is OpenFOAM's: the readers of the per-hit records the stochasticRebound adapter wrote
(CASE/postProcessing/lagrangian/<cloud>/stochasticRebound/hits_<rank>.csv: incident velocity relative to
the wall V⁻, incident angular velocity Ω⁻, wall normal n into the gas, half-size a, the status, the path
that answered (the table or the direct model) and the rebound V⁺, Ω⁺ the C runtime gave), of OpenFOAM's
own patchPostProcessing records (the parcel's state at each wall hit, taken before the patch interaction
acts) and of the case's mesh and erosion field, and the figures of a run. The statistics are the
solver-neutral ones of the BSD module tablegen.study.solver_comparison (its docstring states them and
their bounds). The script:

1. checks that both OpenFOAM records hold the same hits: the same number per patch, and per parcel the
   same sequence of incident velocities;
2. checks the path of every hit against the rule of method auto (``solver_comparison.path_rule``) and
   compares each path's answers with surrogate's at the same incident states, for the hits a table
   answered on the patches of one wall (``--patch``; a run with a ``patches`` list has a table per wall)
   (``solver_comparison.compare_hits``: the table's hits with ``surrogate.sample_global``, method
   "table", the direct model's with method "direct", Ω⁻ included; KS per variable, a classifier
   two-sample test, the fractions not rebounded, each against the bound of one law); the hits of smooth
   walls only (a patch's ``roughnessDeg`` 0): a rough patch is refused;
3. compares the spinning hits with the table-only rebound (Ω⁻ ignored, as the adapter did before it
   passed Ω⁻) and the table's hits with the stock bounce (standardWallInteraction rebound, e = 1,
   mu = 0: specular, α2 = α1, β2 = 0, s = 1) on the same incident states;
4. plots the table's hits against the sampler and the specular line, and the spinning hits against the
   direct model and the table alone (--png);
5. with --erosion-against, reads OpenFOAM's particleErosion field of both runs and maps the volume each
   wall face lost side by side (--erosion-png);
6. with --work-png, reads the adapter's work fields of the run (<cloud>:stochasticReboundWorkNormal,
   ...WorkTangential, J per wall face, and ...Hits) and its particleErosion field, prints where each one's
   maximum sits, the totals and Spearman's rank correlation of W_t and W_n with Q over the faces hit, and
   maps W_t, W_n and Q side by side (a serial run: the fields of the case's last time folder). The wall
   work records (wallWork_<rank>.csv, a row per row of the hits files: the face, the mass and W_n, W_t of
   each hit) are read by ``read_wall_work``.

--check exits with status 1 if a bound of 1 or 2 is not met.

Copyright (C) 2026 the rebound-scatter authors. License: GPL-3.0-or-later
(see LICENSE in this folder).
"""

from __future__ import annotations

import argparse
import json
import re
import sys
from collections import defaultdict
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from rbs_api import (PATH_DIRECT, PATH_TABLE, STATUS_FAILED, STATUS_INVALID, STATUS_REBOUNDED,  # noqa: E402
                     STATUS_TRAPPED, SolverHits, agreement, compare_hits, impact_states, incident_states, load, path_rule,
                     rank_files, read_hit_files, solver_hits, specular_answers, surrogate_answers)

HITS_TITLE = "stochasticRebound"   # the hits files' header: "# stochasticRebound hits: seed ..."
# the per-patch summary's count columns in the solver's log: key -> column name
PATCH_SUMMARY = {"hits": "hits", "rebounded": "rebounded", "stuck": "stuck", "removed": "removed",
                 "escaped": "escaped", "invalid": "invalid", "trapped": "trapped", "failed": "failed",
                 "table": "table", "direct": "direct", "speed_below": "|V|<grid", "speed_above": "|V|>grid",
                 "alpha1_outside": "alpha1-out", "outside_law": "out-of-law", "hit_again": "hit-again",
                 "at_cap": "at-cap", "no_work": "no-work"}
# the counts of a log written before the work on the wall (no no-work column, nor the mean work per hit), and
# before rough walls (neither hit-again nor at-cap, nor the roughness column)
_PATCH_SUMMARY_ROUGH = dict(list(PATCH_SUMMARY.items())[:-1])
_PATCH_SUMMARY_SMOOTH = dict(list(PATCH_SUMMARY.items())[:-3])
# the mean work on the wall per hit (J/kg) of the summary's last columns: key -> column name
PATCH_SUMMARY_WORK = {"work_normal_mean": "Wn/hit", "work_tangential_mean": "Wt/hit"}
# the work fields' names after the cloud's name and a colon (volScalarFields, J and a count of hits per face)
WORK_FIELDS = {"normal": "stochasticReboundWorkNormal", "tangential": "stochasticReboundWorkTangential",
               "hits": "stochasticReboundHits"}


# ----------------------------------------------------------------------------- reading

def hits_dir(case: Path) -> Path:
    found = sorted(case.glob("postProcessing/lagrangian/*/stochasticRebound"))
    if not found:
        raise FileNotFoundError(f"{case}: no postProcessing/lagrangian/<cloud>/stochasticRebound folder "
                                "(run the case with writeHits true)")
    return found[0]


def read_hits(case: Path) -> tuple[dict, list]:
    """All ranks' hit records as columns, and each file's header settings (tablegen.study.hit_records): with
    ``interaction``, what the hit's patch does (``stochasticRebound``, or ``rebound``: OpenFOAM's stock
    rebound), and ``wall``, the wall of its table (empty for a stock rebound)."""
    return read_hit_files(rank_files(hits_dir(case)), HITS_TITLE)


def select_hits(hits: dict, rows) -> dict:
    """The columns of :func:`read_hits` at ``rows`` (a boolean mask or indices)."""
    return {name: column[rows] for name, column in hits.items()}


def drawn_hits(hits: dict, patches=None) -> dict:
    """The hits a table or the direct model answered (interaction ``stochasticRebound``), of ``patches``
    (names; all if None). ValueError if none is left, or if they are of more than one wall: each wall has
    its table, and a comparison takes one."""
    keep = hits["interaction"] == HITS_TITLE
    if patches is not None:
        keep &= np.isin(hits["patch"], list(patches))
    if not keep.any():
        where = f"the patches {', '.join(patches)}" if patches else "any patch"
        raise ValueError(f"no hit a table answered on {where}")
    walls = sorted(set(hits["wall"][keep].tolist()))
    if len(walls) > 1:
        raise ValueError(f"the hits are of {len(walls)} walls ({', '.join(walls)}): compare the patches of one "
                         "wall at a time (patches, --patch) with its table (--table)")
    return select_hits(hits, keep)


def patch_roughness(case: Path) -> dict:
    """Patch name -> the roughness (deg) its hits were drawn with, for each patch that draws, as the hits files'
    second line states it (``NAME = stochasticRebound, ..., roughness R deg``; {} for files written before rough
    walls, all of whose walls were smooth)."""
    with rank_files(hits_dir(case))[0].open() as fh:
        fh.readline()
        line = fh.readline()
    found = re.findall(r"(?:Patches: |; )(\S+) = stochasticRebound, .*?, roughness ([-0-9.eE+]+) deg", line)
    return {patch: float(roughness) for patch, roughness in found}


def _smooth_only(case: Path, hits: dict) -> None:
    """ValueError if a patch of ``hits`` is rough: surrogate answers the comparison's hits on the smooth wall."""
    drawn = set(hits["patch"].tolist())
    rough = {patch: r for patch, r in patch_roughness(case).items() if r > 0 and patch in drawn}
    if rough:
        raise ValueError(f"the patches {', '.join(f'{p} (roughnessDeg {r:g})' for p, r in rough.items())} are "
                         "rough: the comparison with surrogate is of smooth walls; compare the smooth patches "
                         "(--patch)")


def _table_of(settings: dict, table_path: Path | None) -> Path:
    """The table to compare with: the one given, else the run's global table."""
    if table_path is None and settings["table"] == "none":
        raise ValueError("the run names no global table (every patch entry gives its own): give the table of "
                         "the patches compared (--table)")
    return Path(table_path or settings["table"])


def patch_summary(log: str) -> dict:
    """The adapter's per-patch counts at the last time step of a solver log: patch name -> the counts of
    :data:`PATCH_SUMMARY`'s columns by key, ``roughness``, the wall's roughness Δγ in degrees, the mean work on
    the wall per hit with work of :data:`PATCH_SUMMARY_WORK` (J/kg; each None for a patch that does not draw,
    the means also where no hit gave work), and ``interaction``, what the patch does. A log written before the
    work on the wall has neither ``no_work`` nor the means, one written before rough walls neither
    ``hit_again``, ``at_cap`` nor ``roughness``."""
    block = log[log.rindex("    Per patch ("):].splitlines()
    header = block[1].split()
    layouts = ((_PATCH_SUMMARY_SMOOTH, ()), (_PATCH_SUMMARY_ROUGH, ("roughness",)),
               (PATCH_SUMMARY, ("roughness", *PATCH_SUMMARY_WORK)))
    for columns, extra in layouts:
        names = [PATCH_SUMMARY_WORK.get(key, key) for key in extra]
        if header == ["patch", *columns.values(), *names, "interaction"]:
            break
    else:
        raise ValueError(f"not the per-patch summary's columns: {block[1]!r}")
    out = {}
    for line in block[2:]:
        m = re.match(rf"\s+(\S+)((?:\s+\d+){{{len(columns)}}})((?:\s+\S+){{{len(extra)}}})  (.*)$", line)
        if m is None:
            break
        counts = dict(zip(columns, map(int, m.group(2).split())))
        for key, value in zip(extra, m.group(3).split()):
            counts[key] = None if value == "-" else float(value)
        out[m.group(1)] = dict(counts, interaction=m.group(4))
    return out


def read_patch_post(case: Path) -> dict:
    """patchPostProcessing records per patch: time, origProc, origId, U (all write times)."""
    out = {}
    for folder in sorted(case.glob("postProcessing/lagrangian/*/patchPostProcessing*")):
        for f in sorted(folder.glob("*/*.post"), key=lambda p: float(p.parent.name)):
            with open(f) as fh:
                header = fh.readline()
                names = re.sub(r"[()]", " ", header.lstrip("#")).split()
                rows = [re.sub(r"[()]", " ", line).split() for line in fh if line.strip()]
            idx = {name: i for i, name in enumerate(names)}
            data = np.array(rows, dtype=float).reshape(-1, len(names))
            rec = out.setdefault(f.stem, {"time": [], "origProc": [], "origId": [], "U": []})
            rec["time"].append(data[:, idx["Time"]])
            rec["origProc"].append(data[:, idx["origProc"]].astype(np.int64))
            rec["origId"].append(data[:, idx["origId"]].astype(np.int64))
            rec["U"].append(data[:, [idx["U0"], idx["U1"], idx["U2"]]])
    return {k: {name: np.concatenate(v) for name, v in rec.items()} for k, rec in out.items()}


# ----------------------------------------------------------------------------- the comparison

def check_records(hits: dict, post: dict) -> dict:
    """Hits of the adapter against patchPostProcessing's: counts per patch, incident velocities per parcel."""
    counts_adapter = {str(p): int(np.sum(hits["patch"] == p)) for p in np.unique(hits["patch"])}
    counts_post = {p: int(len(r["time"])) for p, r in post.items()}
    # per parcel, hits in the order (time, patch, order of record): patchPostProcessing keeps one list per
    # patch, so hits of one parcel on two patches within one time step are ordered by patch on both sides
    U_adapter = hits["V"] + hits["Uw"]
    seq_adapter, seq_post = defaultdict(list), defaultdict(list)
    for i in range(len(hits["time"])):
        key = (int(hits["origProc"][i]), int(hits["origId"][i]))
        seq_adapter[key].append((hits["time"][i], str(hits["patch"][i]), i, U_adapter[i]))
    for patch, rec in post.items():
        for i in range(len(rec["time"])):
            key = (int(rec["origProc"][i]), int(rec["origId"][i]))
            seq_post[key].append((rec["time"][i], patch, i, rec["U"][i]))
    seq_adapter = {k: [r[3] for r in sorted(v, key=lambda r: r[:3])] for k, v in seq_adapter.items()}
    seq_post = {k: [r[3] for r in sorted(v, key=lambda r: r[:3])] for k, v in seq_post.items()}
    worst, matched, mismatched = 0.0, 0, 0
    for key, seq in seq_adapter.items():
        other = seq_post.get(key, [])
        if len(other) != len(seq):
            mismatched += 1
            continue
        # patchPostProcessing writes writePrecision (8) digits
        A, B = np.array(seq), np.array(other)
        rel = np.max(np.linalg.norm(A - B, axis=1) / np.maximum(np.linalg.norm(A, axis=1), 1e-300))
        worst = max(worst, float(rel))
        matched += 1
    return {"hits_per_patch_adapter": counts_adapter, "hits_per_patch_patchPostProcessing": counts_post,
            "parcels_matched": matched, "parcels_mismatched": mismatched + len(set(seq_post) - set(seq_adapter)),
            "max_relative_difference_of_incident_velocity": worst}


def compare_paths(case: Path, table_path: Path | None = None, patches=None) -> dict:
    """``solver_comparison.path_rule`` of a run's hit records (:func:`drawn_hits` of ``patches``; the table
    from the path the run recorded)."""
    hits, headers = read_hits(case)
    settings = headers[0]
    hits = drawn_hits(hits, patches)
    _smooth_only(case, hits)
    return path_rule(solver_hits(hits, settings), load(_table_of(settings, table_path)), settings["spin_tolerance"])


def compare(case: Path, table_path: Path | None = None, seed: int = 1, classifier: bool = True,
            patches=None) -> dict:
    """The comparisons 2 and 3 of the module docstring (``classifier=False``: KS and fractions not rebounded
    only) on the hits a table answered (:func:`drawn_hits` of ``patches``, all by default: one wall's):
    ``res["comparison"]`` the solver against surrogate per path (a ``ComparisonReport``),
    ``res["spinning_vs_table_only"]`` the spinning hits against the table alone, ``res["table_vs_specular"]``
    the table's hits against the stock bounce (``Agreement`` records; their classifier is not run)."""
    hits, headers = read_hits(case)
    hits = drawn_hits(hits, patches)
    _smooth_only(case, hits)
    settings = headers[0]
    table_path = _table_of(settings, table_path)
    table = load(table_path)
    record = solver_hits(hits, settings)
    status = record.status
    valid = record.path != STATUS_INVALID
    speed_lo, speed_hi = float(np.min(table.speed_m_s)), float(np.max(table.speed_m_s))
    alpha1, speed, _ = incident_states(record.V, record.n, record.a, record.Omega)
    res = {"case": str(case), "table": str(table_path), "settings": settings,
           "ranks": sorted({int(h["stream"]) for h in headers}),
           "hits": len(record), "rebounded": int(np.sum(status == STATUS_REBOUNDED)),
           "trapped": int(np.sum(status == STATUS_TRAPPED)), "failed": int(np.sum(status == STATUS_FAILED)),
           "invalid": int(np.sum(~valid)),
           "paths": path_rule(record, table, settings["spin_tolerance"]),
           "incidence": {
               "alpha1_deg_percentiles_5_50_95": np.percentile(alpha1[valid], [5, 50, 95]).round(2).tolist(),
               "speed_m_s_percentiles_5_50_95": np.percentile(speed[valid], [5, 50, 95]).round(1).tolist(),
               "table_speed_range_m_s": [speed_lo, speed_hi],
               "fraction_outside_speed_range": float(np.mean((speed[valid] < speed_lo) | (speed[valid] > speed_hi))),
               "spin_ratio_mean_max": [float(np.mean(hits["spin_ratio"])), float(np.max(hits["spin_ratio"]))]}}
    comparison = compare_hits(record, table, seed, settings["interpolation"], classifier)
    res["comparison"] = comparison
    # the spinning hits (the direct model answered them): what the table alone, Ω⁻ ignored, gave them
    spinning = (hits["spin_ratio"] > settings["spin_tolerance"] * (1 + 1e-6)) & (record.path == PATH_DIRECT)
    if spinning.any():
        spin_hits = record.take(spinning)
        table_only = surrogate_answers(table, spin_hits, seed + 1, settings["interpolation"], method="table")
        res["spinning_vs_table_only"] = agreement(spin_hits, table_only, classifier=classifier)
        res["_spinning"] = (spinning, table_only)
    on_table = record.take(record.path == PATH_TABLE)
    res["table_vs_specular"] = agreement(on_table, specular_answers(on_table), classifier=False)
    res["checks_passed"] = comparison.ok
    return res


def _density(ax, values, edges, color, label):
    ax.hist(values, edges, density=True, histtype="step", color=color, lw=1.5, label=label)


def _rebounds(hits: SolverHits, answers: SolverHits):
    """α1 (deg) and the impact-frame states (solver_comparison.impact_states) of the rebounded answers."""
    ok = answers.status == STATUS_REBOUNDED
    alpha1 = incident_states(hits.V[ok], hits.n[ok], hits.a[ok], hits.Omega[ok])[0]
    return alpha1, impact_states(hits.V[ok], hits.n[ok], hits.a[ok], answers.V_out[ok], answers.Omega_out[ok])


def plot(res: dict, png: Path) -> None:
    """Top row: the hits the table answered, against the sampler and the specular bounce; bottom row (when
    the direct model answered spinning hits): those hits against the direct model run again on their
    incident states and against the table-only rebound."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    comparison = res["comparison"]
    on_table = comparison.hits.path == PATH_TABLE
    alpha1_of, X_of = _rebounds(comparison.hits.take(on_table), comparison.hits.take(on_table))
    alpha1_py, X_py = _rebounds(comparison.hits.take(on_table), comparison.answers.take(on_table))
    spin = "_spinning" in res
    fig, axes = plt.subplots(2 if spin else 1, 3, figsize=(15, 9.2 if spin else 4.6), squeeze=False)
    ax = axes[0, 0]
    ax.scatter(alpha1_py, np.degrees(X_py[:, 0]), s=2, alpha=0.25, color="tab:orange",
               label="surrogate.sample_global, same incident states", rasterized=True)
    ax.scatter(alpha1_of, np.degrees(X_of[:, 0]), s=2, alpha=0.25, color="tab:blue",
               label="OpenFOAM + stochasticRebound", rasterized=True)
    ax.plot([0, 90], [0, 90], color="k", lw=1.5, label="specular (standardWallInteraction, e=1, mu=0)")
    ax.set_xlabel("incidence angle α1 (deg, from the wall)")
    ax.set_ylabel("rebound angle α2 (deg, in the impact plane)")
    ax.set_xlim(0, 90)
    ax.set_ylim(0, 180)
    ax.legend(loc="upper left", fontsize=7, markerscale=4)
    ax.set_title("hits the table answered: rebound direction")
    bins = np.linspace(0, 90, 19)
    centres = (bins[1:] + bins[:-1]) / 2
    ax = axes[0, 1]
    for alpha1, X, color, label in ((alpha1_of, X_of, "tab:blue", "OpenFOAM + stochasticRebound"),
                                    (alpha1_py, X_py, "tab:orange", "sample_global")):
        idx = np.digitize(alpha1, bins) - 1
        for q, ls in ((50, "-"), (10, ":"), (90, ":")):
            vals = [np.percentile(X[idx == k, 2], q) if np.sum(idx == k) > 10 else np.nan
                    for k in range(len(centres))]
            ax.plot(centres, vals, ls, color=color, label=f"{label}, median and 10/90 %" if q == 50 else None)
    ax.axhline(1.0, color="k", lw=1.5, label="specular")
    ax.set_xlabel("α1 (deg)")
    ax.set_ylabel("speed ratio s = |V⁺|/|V⁻|")
    ax.set_ylim(0, 1.05)
    ax.legend(fontsize=7)
    ax.set_title("hits the table answered: speed ratio")
    ax = axes[0, 2]
    edges = np.linspace(-60, 60, 61)
    _density(ax, np.degrees(X_of[:, 1]), edges, "tab:blue", "OpenFOAM + stochasticRebound")
    _density(ax, np.degrees(X_py[:, 1]), edges, "tab:orange", "sample_global")
    ax.axvline(0.0, color="k", lw=1.5, label="specular (β2 = 0)")
    ax.set_xlabel("out-of-plane angle β2 (deg)")
    ax.set_ylabel("density (1/deg)")
    ax.legend(fontsize=7)
    ax.set_title("hits the table answered: out-of-plane scattering")
    s = comparison.agreement["table"]
    title = (f"hopperRebound ({res['hits']} wall hits, {res['settings']['shape']}, method "
             f"{res['settings']['method']}): table hits vs sampler KS ≤ {max(s.ks.values()):.3f} (bound "
             f"{s.ks_bound:.3f}), classifier {s.classifier_accuracy:.3f} (bound {s.classifier_bound:.3f})")
    if spin:
        spinning, table_only = res["_spinning"]
        spin_hits = comparison.hits.take(spinning)
        a1_s, X_s = _rebounds(spin_hits, spin_hits)
        a1_r, X_r = _rebounds(spin_hits, comparison.answers.take(spinning))
        a1_t, X_t = _rebounds(spin_hits, table_only)
        d, far = comparison.agreement["direct"], res["spinning_vs_table_only"]
        curves = ((X_s, a1_s, "tab:blue", "OpenFOAM + stochasticRebound (direct model)"),
                  (X_r, a1_r, "tab:green", "surrogate, direct model, same incident states"),
                  (X_t, a1_t, "tab:red", "table only (Ω⁻ ignored), same incident states"))
        for X, a1, color, label in curves:
            _density(axes[1, 0], np.degrees(X[:, 0]) - a1, np.linspace(-60, 120, 73), color, label)
            _density(axes[1, 1], X[:, 2], np.linspace(0, 1.2, 61), color, label)
            _density(axes[1, 2], np.linalg.norm(X[:, 3:6], axis=1), np.linspace(0, 2, 81), color, label)
        for ax, xlabel in zip(axes[1], ("α2 − α1 (deg)", "speed ratio s = |V⁺|/|V⁻|", "|Ω⁺| a/|V⁻|")):
            ax.set_xlabel(xlabel)
            ax.set_ylabel("density")
            ax.legend(fontsize=7)
        axes[1, 0].set_title(f"spinning hits (|Ω⁻|a/|V⁻| > {res['paths']['spin_tolerance']:g}): {len(a1_s)} rebounds")
        axes[1, 1].set_title(f"direct hits vs surrogate: classifier {d.classifier_accuracy:.3f} "
                             f"(≤ {d.classifier_bound:.3f})", fontsize=9)
        axes[1, 2].set_title(f"spinning hits vs table only: classifier {far.classifier_accuracy:.3f}", fontsize=9)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(png, dpi=110)
    plt.close(fig)


def report(res: dict) -> str:
    inc, pa, comparison = res["incidence"], res["paths"], res["comparison"]
    counts = comparison.hits_per_path
    lines = [f"case {res['case']}: {res['hits']} wall hits on {len(res['ranks'])} rank(s): "
             f"{res['rebounded']} rebounded, {res['trapped']} trapped, {res['failed']} failed, "
             f"{res['invalid']} invalid",
             f"paths (method {res['settings']['method']}, spin tolerance {pa['spin_tolerance']:g}): table "
             f"{counts['table']}, direct model {counts['direct']}; spinning hits {pa['spinning']} "
             f"({pa['spinning_not_direct']} not direct), hits outside the grid {pa['outside']} "
             f"({pa['outside_not_direct']} not direct), non-spinning hits inside the grid {pa['still_inside']} "
             f"({pa['still_inside_not_table']} not table)",
             f"incidence: alpha1 5/50/95 % {inc['alpha1_deg_percentiles_5_50_95']} deg, |V| "
             f"{inc['speed_m_s_percentiles_5_50_95']} m/s ({100 * inc['fraction_outside_speed_range']:.1f} % "
             f"outside the table's {inc['table_speed_range_m_s']} m/s); incoming spin |Omega|a/|V| mean "
             f"{inc['spin_ratio_mean_max'][0]:.3f}, max {inc['spin_ratio_mean_max'][1]:.3f}"]
    if "records" in res:
        r = res["records"]
        lines.append(f"records: adapter {r['hits_per_patch_adapter']}, patchPostProcessing "
                     f"{r['hits_per_patch_patchPostProcessing']}; parcels matched {r['parcels_matched']}, "
                     f"mismatched {r['parcels_mismatched']}, incident velocity max rel. difference "
                     f"{r['max_relative_difference_of_incident_velocity']:.2e}")
    for name, a in comparison.agreement.items():
        lines.append(a.line(f"{name} hits: solver vs surrogate"))
    if "spinning_vs_table_only" in res:
        far = res["spinning_vs_table_only"]
        lines.append(f"spinning hits, solver (direct model) vs the table alone, Omega ignored: KS max "
                     f"{max(far.ks.values()):.4f}, classifier {far.classifier_accuracy:.4f}; mean s "
                     f"{far.mean_speed_ratio[0]:.3f} vs {far.mean_speed_ratio[1]:.3f}, mean alpha2-alpha1 "
                     f"{far.mean_deflection_deg[0]:.1f} vs {far.mean_deflection_deg[1]:.1f} deg")
    sp = res["table_vs_specular"]
    lines.append("table hits vs stock specular bounce: KS "
                 + ", ".join(f"{k} {v:.3f}" for k, v in list(sp.ks.items())[:3])
                 + f"; mean alpha2-alpha1 {sp.mean_deflection_deg[0]:.1f} deg (specular 0), mean s "
                 f"{sp.mean_speed_ratio[0]:.3f} (specular 1)")
    return "\n".join(lines)


# ----------------------------------------------------------------------------- erosion

def _foam_list(text: str, what: str) -> list:
    """The entries of the first ASCII list of an OpenFOAM file: 'N (entry entry ...)', each entry a
    parenthesised group of numbers, possibly prefixed by its length (faces: 4(a b c d))."""
    body = text[text.index("(", re.search(r"^\d+\s*$", text, re.M).end()) + 1:]
    entries = re.findall(r"\d*\(([^()]*)\)", body.split("\n)", 1)[0])
    if not entries:
        raise ValueError(f"no {what} list")
    return [e.split() for e in entries]


def wall_faces(case: Path, patch: str) -> list:
    """The faces of ``patch``, each an (n_vertices, 3) array of its vertices (m), from the case's ASCII polyMesh."""
    mesh = case / "constant" / "polyMesh"
    points = np.array(_foam_list((mesh / "points").read_text(), "points"), dtype=float)
    faces = _foam_list((mesh / "faces").read_text(), "faces")
    block = re.search(rf"\n\s*{re.escape(patch)}\s*\{{([^}}]*)\}}", (mesh / "boundary").read_text()).group(1)
    start = int(re.search(r"startFace\s+(\d+);", block).group(1))
    count = int(re.search(r"nFaces\s+(\d+);", block).group(1))
    return [points[np.array(faces[f], dtype=int)] for f in range(start, start + count)]


def wall_face_centres(case: Path, patch: str) -> np.ndarray:
    """(n_faces, 3) centres (vertex means, m) of the faces of ``patch``, from the case's ASCII polyMesh."""
    return np.array([vertices.mean(axis=0) for vertices in wall_faces(case, patch)])


def read_patch_field(case: Path, field: str, patch: str, time: str | None = None) -> np.ndarray:
    """The values on the faces of ``patch`` of the ASCII volScalarField ``field`` at ``time`` (a time folder's
    name; default the last one that holds the field) of ``case``: a case folder, or a processor folder of a
    decomposed run (its own mesh and time folders)."""
    if time is None:
        times = [p for p in case.iterdir() if re.fullmatch(r"[0-9.e+-]+", p.name) and (p / field).is_file()]
        if not times:
            raise FileNotFoundError(f"{case}: no field {field} in a time folder")
        time = max(times, key=lambda p: float(p.name)).name
    text = (case / time / field).read_text()
    block = text[re.search(rf"\n\s*{re.escape(patch)}\s*\n\s*\{{", text).end():]
    m = re.search(r"value\s+(uniform\s+([-0-9.eE+]+)|nonuniform\s+List<scalar>\s*(\d+)\s*\(([^)]*)\))", block)
    if m.group(2) is not None:
        boundary = (case / "constant" / "polyMesh" / "boundary").read_text()
        entry = re.search(rf"\n\s*{re.escape(patch)}\s*\{{([^}}]*)\}}", boundary).group(1)
        return np.full(int(re.search(r"nFaces\s+(\d+);", entry).group(1)), float(m.group(2)))
    values = np.array(m.group(4).split(), dtype=float)
    if len(values) != int(m.group(3)):
        raise ValueError(f"{case / time / field}: {patch} holds {len(values)} values, not {m.group(3)}")
    return values


def read_erosion(case: Path, patch: str = "walls", cloud: str = "kinematicCloud") -> np.ndarray:
    """The volume each face of ``patch`` lost (m³), from OpenFOAM's particleErosion field <cloud>Q at the
    last write time of a serial run."""
    return read_patch_field(case, f"{cloud}Q", patch)


def erosion_summary(case: Path, patch: str = "walls") -> dict:
    """Faces of ``patch`` with erosion, of how many, and the total volume lost (m³)."""
    q = read_erosion(case, patch)
    return {"faces_eroded": int(np.sum(q > 0)), "faces": int(q.size), "total_m3": float(q.sum()),
            "max_face_m3": float(q.max())}


def plot_erosion(cases: dict, png: Path, patch: str = "walls") -> None:
    """Side by side, one panel per run (``cases``: label → case folder): the hopper's wall outline in the
    x-y plane, each point a column of faces across the depth, coloured by the volume those faces lost."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import LogNorm
    data = {}
    for label, case in cases.items():
        centres, q = wall_face_centres(case, patch), read_erosion(case, patch)
        columns = {}
        for c, v in zip(np.round(centres[:, :2], 7), q):
            columns[tuple(c)] = columns.get(tuple(c), 0.0) + v
        xy = np.array(list(columns))
        data[label] = (xy, np.array(list(columns.values())), erosion_summary(case, patch))
    positive = np.concatenate([v[v > 0] for _, v, _ in data.values()])
    norm = LogNorm(vmin=positive.min(), vmax=positive.max())
    fig, axes = plt.subplots(1, len(cases), figsize=(5.2 * len(cases), 6.2), squeeze=False)
    for ax, (label, (xy, v, summary)) in zip(axes[0], data.items()):
        ax.scatter(xy[v <= 0, 0], xy[v <= 0, 1], s=10, color="0.85", label="no erosion")
        im = ax.scatter(xy[v > 0, 0], xy[v > 0, 1], c=v[v > 0], s=22, norm=norm, cmap="inferno_r")
        ax.set_aspect("equal")
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")
        ax.set_title(f"{label}\n{summary['faces_eroded']} of {summary['faces']} faces eroded, total "
                     f"{summary['total_m3']:.2e} m³", fontsize=9)
        ax.legend(fontsize=7, loc="lower right")
    fig.colorbar(im, ax=axes[0].tolist(), label="volume lost per column of wall faces (m³, particleErosion)",
                 shrink=0.8)
    fig.savefig(png, dpi=110)
    plt.close(fig)


# ----------------------------------------------------------------------------- the work on the wall

def read_wall_work(case: Path, hits: dict | None = None) -> dict:
    """The adapter's wall work records (``wallWork_<rank>.csv`` beside the hits files, row i of a rank's file for
    row i of its hits file), all ranks in rank order as :func:`read_hits` reads theirs: columns origProc, origId,
    patch, face (the face hit, its index in the patch), mass (the parcel's particles', kg) and Wn, Wt (the work
    on the wall per unit particle mass, J/kg; NaN for an invalid hit, a stock rebound, a table of format 4.0).
    With ``hits`` (:func:`read_hits` of the case), ValueError unless the rows are the same hits."""
    folder = hits_dir(case)
    files = [folder / f.name.replace("hits_", "wallWork_") for f in rank_files(folder)]
    rows = []
    for f in files:
        with open(f) as fh:
            if not fh.readline().startswith(f"# {HITS_TITLE} wall work:"):
                raise ValueError(f"{f}: line 1 is not a wall work header")
            if fh.readline().strip() != "origProc,origId,patch,face,mass,Wn,Wt":
                raise ValueError(f"{f}: line 2 is not the wall work columns")
            rows += [line.rstrip("\n").split(",") for line in fh if line.strip()]
    columns = list(zip(*rows)) if rows else [()] * 7
    work = {"origProc": np.array(columns[0], dtype=np.int64), "origId": np.array(columns[1], dtype=np.int64),
            "patch": np.array(columns[2], dtype=object), "face": np.array(columns[3], dtype=np.int64),
            "mass": np.array(columns[4], dtype=float), "Wn": np.array(columns[5], dtype=float),
            "Wt": np.array(columns[6], dtype=float)}
    if hits is not None:
        same = len(work["face"]) == len(hits["patch"]) and all(
            np.array_equal(work[name], hits[name]) for name in ("origProc", "origId", "patch"))
        if not same:
            raise ValueError(f"{folder}: the wall work records are not the rows of the hits files")
    return work


def face_sums(patch_names, faces, values, patch: str, n_faces: int) -> np.ndarray:
    """Per face of ``patch`` (``n_faces``), the sum of ``values`` over the records on it (``patch_names`` and
    ``faces`` of each record, as :func:`read_wall_work` gives them)."""
    on = patch_names == patch
    return np.bincount(faces[on], weights=values[on], minlength=n_faces)


def wall_work_maps(case: Path, patches=("walls", "frontAndBack"), cloud: str = "kinematicCloud") -> dict:
    """Per patch, at the last write time of a serial run: its faces' vertices and centres (m) and, per face, the
    work fields (``normal``, ``tangential``: J; ``hits``) and particleErosion's ``Q`` (m³)."""
    out = {}
    for patch in patches:
        maps = {key: read_patch_field(case, f"{cloud}:{name}", patch) for key, name in WORK_FIELDS.items()}
        maps["Q"] = read_patch_field(case, f"{cloud}Q", patch)
        faces = wall_faces(case, patch)
        out[patch] = dict(maps, faces=faces, centres=np.array([f.mean(axis=0) for f in faces]))
    return out


def wall_work_summary(case: Path, patches=("walls", "frontAndBack"), cloud: str = "kinematicCloud") -> dict:
    """The work on the walls of a serial run against particleErosion's Q, from the fields at its last write time:
    per patch (and ``all``, over them) the faces and the faces hit, the totals of W_n and W_t (J) and of Q (m³),
    the face of each one's maximum (its index, centre in m and value), and Spearman's rank correlation of W_t and
    of W_n with Q over the faces hit."""
    from scipy.stats import spearmanr
    maps = wall_work_maps(case, patches, cloud)
    maps["all"] = {key: np.concatenate([maps[p][key] for p in patches]) for key in maps[patches[0]] if key != "faces"}
    out = {}
    for patch, m in maps.items():
        hit = m["hits"] > 0
        s = {"faces": int(hit.size), "faces_hit": int(hit.sum()), "hits": int(m["hits"].sum())}
        for key in ("normal", "tangential", "Q"):
            i = int(np.argmax(m[key]))
            s[key] = {"total": float(m[key].sum()), "max": float(m[key][i]), "max_face": i,
                      "max_centre": m["centres"][i].tolist()}
        for key in ("normal", "tangential"):
            s[f"spearman_{key}_Q"] = float(spearmanr(m[key][hit], m["Q"][hit])[0])
        out[patch] = s
    return out


def _xy_outlines(faces: list, centres: np.ndarray):
    """The faces seen along z, one outline per point of the x-y plane (the faces across the depth share it):
    (index of each face's outline, the outlines: a face edge-on, as the hopper's side walls are, a segment
    between its extreme vertices, else its polygon)."""
    keys, first, index = np.unique(np.round(centres[:, :2], 7), axis=0, return_index=True, return_inverse=True)
    outlines = []
    for i in first:
        xy = faces[i][:, :2]
        edge = xy - xy.mean(axis=0)
        area = 0.5 * abs(np.dot(edge[:, 0], np.roll(edge[:, 1], 1)) - np.dot(edge[:, 1], np.roll(edge[:, 0], 1)))
        if area < 1e-9 * np.ptp(xy, axis=0).max() ** 2:
            far = np.argmax(np.linalg.norm(edge, axis=1))
            xy = np.array([xy[far], xy[np.argmax(np.linalg.norm(xy - xy[far], axis=1))]])
        outlines.append(xy)
    return index.ravel(), outlines


def plot_wall_work(case: Path, png: Path, patches=("walls", "frontAndBack"), cloud: str = "kinematicCloud") -> None:
    """The work on the walls beside particleErosion's Q, from one serial run: a row per patch, the columns W_t,
    W_n (J) and Q (m³), the patch seen along z (the hopper's side walls edge-on, its front and back planes face
    on), each face's value summed with the faces behind it, on one log scale per column; grey, nothing. The
    titles give each patch's total, the face of the maximum (circled) and Spearman's rank correlation with Q
    over the faces hit (:func:`wall_work_summary`)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import LineCollection, PolyCollection
    from matplotlib.colors import LogNorm
    maps, summary = wall_work_maps(case, patches, cloud), wall_work_summary(case, patches, cloud)
    columns = (("tangential", "$W_t$", "J", "tangential work on the wall, $W_t$ (J)"),
               ("normal", "$W_n$", "J", "normal work on the wall, $W_n$ (J)"),
               ("Q", "$Q$", "m³", "particleErosion's volume lost, $Q$ (m³)"))
    views = {}
    for patch in patches:
        index, outlines = _xy_outlines(maps[patch]["faces"], maps[patch]["centres"])
        views[patch] = (outlines, {key: np.bincount(index, weights=maps[patch][key]) for key, *_ in columns})
    norms = {}
    for key, *_ in columns:
        positive = np.concatenate([v[key][v[key] > 0] for _, v in views.values()])
        norms[key] = LogNorm(vmin=positive.min(), vmax=positive.max())
    fig, axes = plt.subplots(len(patches), len(columns), figsize=(4.4 * len(columns), 5.0 * len(patches) + 1),
                             squeeze=False, layout="constrained")
    for row, patch in enumerate(patches):
        outlines, values = views[patch]
        s = summary[patch]
        for col, (key, name, unit, label) in enumerate(columns):
            ax, v = axes[row, col], values[key]
            colours = plt.get_cmap("inferno_r")(norms[key](np.where(v > 0, v, norms[key].vmin)))
            colours[v <= 0] = (0.85, 0.85, 0.85, 1.0)
            if all(len(o) == 2 for o in outlines):
                ax.add_collection(LineCollection(outlines, colors=colours, linewidths=5, capstyle="butt"))
            else:
                ax.add_collection(PolyCollection(outlines, facecolors=colours, edgecolors="none"))
            ax.autoscale_view()
            x, y, _ = s[key]["max_centre"]
            ax.plot(x, y, "o", mfc="none", mec="tab:cyan", ms=12, mew=1.5)
            ax.set_aspect("equal")
            ax.set_xlabel("x (m)")
            ax.set_ylabel("y (m)")
            title = f"{patch}: {name} total {s[key]['total']:.3g} {unit}\nmax face (circled) at x {x:.3f}, y {y:.3f} m"
            if key != "Q":
                title += f"\nSpearman with $Q$ over the faces hit: {s[f'spearman_{key}_Q']:.2f}"
            ax.set_title(title, fontsize=9)
            if row == len(patches) - 1:
                mappable = plt.cm.ScalarMappable(norm=norms[key], cmap="inferno_r")
                fig.colorbar(mappable, ax=axes[:, col].tolist(), label=label, location="bottom", shrink=0.9)
    fig.suptitle(f"{case.name}, stochasticRebound: the work of {summary['all']['hits']} hits on the walls beside "
                 "particleErosion's $Q$ (Finnie), per face, summed across the depth", fontsize=10)
    fig.savefig(png, dpi=110)
    plt.close(fig)


def wall_work_report(summary: dict) -> str:
    """:func:`wall_work_summary` in a few lines."""
    lines = []
    for patch, s in summary.items():
        maxima = "; ".join(f"{key} max {s[key]['max']:.3g} at x {s[key]['max_centre'][0]:.3f}, y "
                           f"{s[key]['max_centre'][1]:.3f}, z {s[key]['max_centre'][2]:.3f} m"
                           for key in ("tangential", "normal", "Q"))
        lines.append(f"wall work ({patch}): {s['hits']} hits on {s['faces_hit']} of {s['faces']} faces; W_n "
                     f"{s['normal']['total']:.4g} J, W_t {s['tangential']['total']:.4g} J, Q {s['Q']['total']:.4g} "
                     f"m3; Spearman W_t-Q {s['spearman_tangential_Q']:.3f}, W_n-Q {s['spearman_normal_Q']:.3f}; "
                     f"{maxima}")
    return "\n".join(lines)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("case", type=Path)
    parser.add_argument("--table", type=Path, help="the table (default: the global one the run recorded)")
    parser.add_argument("--patch", action="append", metavar="NAME",
                        help="compare the hits of this patch only (repeat for several patches of one wall)")
    parser.add_argument("--seed", type=int, default=1, help="seed of the sampler's draws")
    parser.add_argument("--png", type=Path, help="write the figure here")
    parser.add_argument("--json", type=Path, help="write the figures here")
    parser.add_argument("--no-classifier", action="store_true", help="KS and trapped fractions only (faster)")
    parser.add_argument("--check", action="store_true", help="exit 1 if a threshold is not met")
    parser.add_argument("--erosion-against", type=Path, metavar="CASE",
                        help="a run of the same case with standardWallInteraction: compare the erosion of both")
    parser.add_argument("--erosion-png", type=Path, help="write the two erosion maps side by side here")
    parser.add_argument("--work-png", type=Path,
                        help="write the maps of the work on the walls (W_t, W_n) beside particleErosion's Q here")
    args = parser.parse_args(argv)
    try:
        res = compare(args.case, args.table, args.seed, classifier=not args.no_classifier, patches=args.patch)
    except ValueError as exc:
        print(f"compare_rebounds.py: {exc}", file=sys.stderr)
        return 2
    post = read_patch_post(args.case)
    if post:
        hits, _ = read_hits(args.case)
        res["records"] = check_records(hits, post)
        r = res["records"]
        res["records_ok"] = bool(r["hits_per_patch_adapter"] == r["hits_per_patch_patchPostProcessing"]
                                 and r["parcels_mismatched"] == 0
                                 and r["max_relative_difference_of_incident_velocity"] < 1e-5)
        res["checks_passed"] = bool(res["checks_passed"] and res["records_ok"])
    print(report(res))
    if args.png:
        plot(res, args.png)
        print(f"wrote {args.png}")
    if args.erosion_against:
        res["erosion"] = {"stochasticRebound": erosion_summary(args.case),
                          "standardWallInteraction": erosion_summary(args.erosion_against)}
        for label, e in res["erosion"].items():
            print(f"erosion ({label}): {e['faces_eroded']} of {e['faces']} wall faces, total {e['total_m3']:.3e} m3")
        if args.erosion_png:
            plot_erosion({"standardWallInteraction (specular)": args.erosion_against,
                          f"stochasticRebound, method {res['settings']['method']}": args.case}, args.erosion_png)
            print(f"wrote {args.erosion_png}")
    if args.work_png:
        res["wall_work"] = wall_work_summary(args.case)
        print(wall_work_report(res["wall_work"]))
        plot_wall_work(args.case, args.work_png)
        print(f"wrote {args.work_png}")
    if args.json:
        plain = {k: v.as_dict() if hasattr(v, "as_dict") else v for k, v in res.items() if not k.startswith("_")}
        args.json.write_text(json.dumps(plain, indent=2))
    if args.check and not res["checks_passed"]:
        print("comparison thresholds NOT met", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
