"""Compare the rebounds an OpenFOAM run applied with the Python sampler and the stock bounce.

    python compare_rebounds.py CASE [--table T.h5] [--png FILE.png] [--json FILE.json] [--check]
                               [--no-classifier]

Reads the per-hit records the stochasticRebound adapter wrote
(CASE/postProcessing/lagrangian/<cloud>/stochasticRebound/hits_<rank>.csv:
incident velocity relative to the wall V⁻, wall normal n into the gas,
half-size a, the status and the rebound V⁺, Ω⁺ the C runtime drew) and the
records of OpenFOAM's own patchPostProcessing function object (the parcel's
state at each wall hit, taken before the patch interaction acts), then:

1. checks that both record the same hits: the same number per patch, and
   per parcel the same sequence of incident velocities;
2. draws `surrogate.sample_global` on the same incident states (same table,
   shape mix and interpolation as the run) and compares the two samples of
   reflected states in the impact frame, (α2, β2, s = |V⁺|/|V⁻|,
   Ω⁺a/|V⁻| along ex, n, ez): the two-sample KS statistic per variable and a
   classifier two-sample test on (α1, |V⁻|, α2, β2, s, Ω) together, and the
   trapped fractions. Both samples are draws of one conditional law at the
   same incident states, so the thresholds are those of equal laws at these
   sample sizes (as docs/VALIDATION.md states its precision): KS below its
   99.9 % point c(0.001)·√((n+m)/(n·m)), c = 1.949; classifier accuracy
   below 0.5 + 4 standard errors √(0.25/n_test); the trapped fractions within
   4 standard errors of their difference;
3. compares with the stock bounce (standardWallInteraction rebound, e = 1,
   mu = 0: specular, α2 = α1, β2 = 0, s = 1) on the same incident states;
4. plots the rebound direction against the incidence angle, the solver's and
   the sampler's draws against the specular line (--png).

--check exits with status 1 if a threshold of 1 or 2 is not met.

Copyright (C) 2026 the rebound-scatter authors. License: GPL-3.0-or-later
(see LICENSE in this folder).
"""

from __future__ import annotations

import argparse
import json
import math
import re
import sys
from collections import defaultdict
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from rbs_api import STATUS_INVALID, STATUS_REBOUNDED, STATUS_TRAPPED, load, sample_global  # noqa: E402

KS_C_999 = 1.949          # two-sample KS: c(α) for α = 0.001
CLASSIFIER_SE = 4.0       # classifier threshold: 0.5 + this many standard errors
TRAPPED_SE = 4.0          # trapped fractions: |difference| within this many standard errors
STATE_NAMES = ("alpha2", "beta2", "speed_ratio", "omega_x", "omega_y", "omega_z")

HIT_COLUMNS = ("time,rank,patch,origProc,origId,d,a,Vx,Vy,Vz,nx,ny,nz,Uwx,Uwy,Uwz,status,"
               "Voutx,Vouty,Voutz,Wx,Wy,Wz,spin_ratio,u0").split(",")


# ----------------------------------------------------------------------------- reading

def hits_dir(case: Path) -> Path:
    found = sorted(case.glob("postProcessing/lagrangian/*/stochasticRebound"))
    if not found:
        raise FileNotFoundError(f"{case}: no postProcessing/lagrangian/<cloud>/stochasticRebound folder "
                                "(run the case with writeHits true)")
    return found[0]


def parse_header(line: str) -> dict:
    """The run's settings from the first line of a hits file."""
    m = re.match(r"# stochasticRebound hits: seed (\d+), stream (\d+), table (.*), mix (.*), "
                 r"halfSizeFactor (\S+), interpolation (\w+)", line.strip())
    if not m:
        raise ValueError(f"not a stochasticRebound hits header: {line!r}")
    mix = m.group(4)
    if mix.startswith("weights ("):
        shape = {k: float(v) for k, v in (item.split() for item in mix[len("weights ("):-1].split(", "))}
    else:
        shape = mix
    return {"seed": int(m.group(1)), "stream": int(m.group(2)), "table": m.group(3), "shape": shape,
            "half_size_factor": float(m.group(5)), "interpolation": m.group(6)}


def read_hits(case: Path) -> tuple[dict, list]:
    """All ranks' hit records as columns, and each file's header settings."""
    files = sorted(hits_dir(case).glob("hits_*.csv"), key=lambda p: int(p.stem.split("_")[1]))
    if not files:
        raise FileNotFoundError(f"{hits_dir(case)}: no hits_<rank>.csv")
    headers, rows = [], []
    for f in files:
        with open(f) as fh:
            headers.append(parse_header(fh.readline()))
            fh.readline()
            if fh.readline().strip().split(",") != HIT_COLUMNS:
                raise ValueError(f"{f}: unexpected columns")
            rows.extend(line.rstrip("\n").split(",") for line in fh if line.strip())
    cols = {}
    for j, name in enumerate(HIT_COLUMNS):
        values = [r[j] for r in rows]
        if name == "patch":
            cols[name] = np.array(values, dtype=object)
        elif name in ("rank", "origProc", "origId", "status"):
            cols[name] = np.array(values, dtype=np.int64)
        else:
            cols[name] = np.array(values, dtype=float)
    cols["V"] = np.column_stack([cols["Vx"], cols["Vy"], cols["Vz"]])
    cols["n"] = np.column_stack([cols["nx"], cols["ny"], cols["nz"]])
    cols["Uw"] = np.column_stack([cols["Uwx"], cols["Uwy"], cols["Uwz"]])
    cols["Vout"] = np.column_stack([cols["Voutx"], cols["Vouty"], cols["Voutz"]])
    cols["Wout"] = np.column_stack([cols["Wx"], cols["Wy"], cols["Wz"]])
    return cols, headers


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


# ----------------------------------------------------------------------------- frames and statistics

def impact_states(V, n, a, Vout, Wout):
    """(α1 deg, |V⁻|, α2, β2, s, Ω⁺a/|V⁻| along ex, n, ez) of each hit (angles in rad but α1)."""
    speed = np.linalg.norm(V, axis=1)
    vn = np.einsum("ij,ij->i", V, n)
    alpha1 = np.degrees(np.arcsin(np.clip(-vn / speed, -1.0, 1.0)))
    t = V - vn[:, None] * n
    tn = np.linalg.norm(t, axis=1)
    ex = np.where(tn[:, None] > 1e-12 * speed[:, None], t / np.maximum(tn, 1e-300)[:, None], 0.0)
    ez = np.cross(ex, n)
    u, v, w = (np.einsum("ij,ij->i", Vout, e) for e in (ex, n, ez))
    vmag = np.sqrt(u * u + v * v + w * w)
    scale = a / speed
    omega = np.column_stack([np.einsum("ij,ij->i", Wout, e) * scale for e in (ex, n, ez)])
    X = np.column_stack([np.arctan2(v, u), np.arcsin(np.clip(w / vmag, -1, 1)), vmag / speed, omega])
    return alpha1, speed, X


def ks_2samp(x, y) -> float:
    x, y = np.sort(x), np.sort(y)
    grid = np.concatenate([x, y])
    return float(np.max(np.abs(np.searchsorted(x, grid, side="right") / len(x)
                               - np.searchsorted(y, grid, side="right") / len(y))))


def ks_threshold(n: int, m: int) -> float:
    return KS_C_999 * math.sqrt((n + m) / (n * m))


def classifier_accuracy(X, Y, seed: int = 0) -> tuple[float, int]:
    """Held-out accuracy of a gradient-boosting classifier telling rows of X from rows of Y; n_test."""
    from sklearn.ensemble import HistGradientBoostingClassifier
    from sklearn.model_selection import train_test_split
    Z = np.vstack([X, Y])
    labels = np.r_[np.zeros(len(X)), np.ones(len(Y))]
    Z_train, Z_test, y_train, y_test = train_test_split(Z, labels, test_size=0.5, random_state=seed,
                                                        stratify=labels)
    model = HistGradientBoostingClassifier(max_iter=200, random_state=seed).fit(Z_train, y_train)
    return float(model.score(Z_test, y_test)), len(y_test)


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


def compare(case: Path, table_path: Path | None = None, seed: int = 1, classifier: bool = True) -> dict:
    """The comparisons 2 and 3 of the module docstring (``classifier=False``: KS and trapped fractions only)."""
    hits, headers = read_hits(case)
    settings = headers[0]
    table_path = Path(table_path or settings["table"])
    table = load(table_path)
    status = hits["status"]
    n_hits = len(status)
    valid = status != STATUS_INVALID
    V, n, a = hits["V"][valid], hits["n"][valid], hits["a"][valid]
    V_py, W_py, st_py = sample_global(table, V, n, a, shape=settings["shape"], random_state=seed,
                                      interpolation=settings["interpolation"], clamp=True, method="table")
    st_of = status[valid]
    speed_lo, speed_hi = float(np.min(table.speed_m_s)), float(np.max(table.speed_m_s))

    res = {"case": str(case), "table": str(table_path), "settings": settings,
           "ranks": sorted({int(h["stream"]) for h in headers}),
           "hits": n_hits, "rebounded": int(np.sum(status == STATUS_REBOUNDED)),
           "trapped": int(np.sum(status == STATUS_TRAPPED)), "invalid": int(np.sum(~valid))}

    # trapped fractions
    p1, p2 = float(np.mean(st_of == STATUS_TRAPPED)), float(np.mean(st_py == STATUS_TRAPPED))
    pool = (p1 + p2) / 2
    se = math.sqrt(max(pool * (1 - pool), 1e-300) * 2 / len(st_of))
    res["trapped_fraction"] = {"solver": p1, "sampler": p2, "se": se,
                               "ok": bool(abs(p1 - p2) <= TRAPPED_SE * se or p1 == p2)}

    ok_of, ok_py = st_of == STATUS_REBOUNDED, st_py == STATUS_REBOUNDED
    Vin_of, nin_of, ain_of = V[ok_of], n[ok_of], a[ok_of]
    alpha1_of, speed_of, X_of = impact_states(Vin_of, nin_of, ain_of, hits["Vout"][valid][ok_of],
                                              hits["Wout"][valid][ok_of])
    alpha1_py, speed_py, X_py = impact_states(V[ok_py], n[ok_py], a[ok_py], V_py[ok_py], W_py[ok_py])
    in_range = (speed_of >= speed_lo) & (speed_of <= speed_hi)
    # every drawn hit (rebounded or trapped) outside the grid: the adapter's own count
    speed_all = np.linalg.norm(V, axis=1)
    alpha1_all = np.degrees(np.arcsin(np.clip(-np.einsum("ij,ij->i", V, n) / speed_all, -1, 1)))
    a_lo, a_hi = float(np.min(table.alpha1_deg)), float(np.max(table.alpha1_deg))
    outside_grid = ((speed_all < speed_lo) | (speed_all > speed_hi) | (alpha1_all < a_lo) | (alpha1_all > a_hi))
    res["incidence"] = {
        "hits_outside_grid": int(np.sum(outside_grid)),
        "alpha1_deg_percentiles_5_50_95": np.percentile(alpha1_of, [5, 50, 95]).round(2).tolist(),
        "speed_m_s_percentiles_5_50_95": np.percentile(speed_of, [5, 50, 95]).round(1).tolist(),
        "table_speed_range_m_s": [speed_lo, speed_hi],
        "fraction_outside_speed_range": float(1 - np.mean(in_range)),
        "spin_ratio_mean_max": [float(np.mean(hits["spin_ratio"])), float(np.max(hits["spin_ratio"]))],
    }

    n1, n2 = len(X_of), len(X_py)
    ks = {name: ks_2samp(X_of[:, j], X_py[:, j]) for j, name in enumerate(STATE_NAMES)}
    ks_lim = ks_threshold(n1, n2)
    in_py = (speed_py >= speed_lo) & (speed_py <= speed_hi)
    ks_in = {name: ks_2samp(X_of[in_range, j], X_py[in_py, j]) for j, name in enumerate(STATE_NAMES)}
    feats_of = np.column_stack([alpha1_of, speed_of, X_of])
    feats_py = np.column_stack([alpha1_py, speed_py, X_py])
    if classifier:
        acc, n_test = classifier_accuracy(feats_of, feats_py)
    else:
        acc, n_test = float("nan"), len(feats_of)
    acc_lim = 0.5 + CLASSIFIER_SE * math.sqrt(0.25 / n_test)
    res["solver_vs_sampler"] = {
        "n_solver": n1, "n_sampler": n2,
        "ks": ks, "ks_threshold": ks_lim, "ks_ok": bool(max(ks.values()) <= ks_lim),
        "ks_in_speed_range": ks_in,
        "ks_in_speed_range_threshold": ks_threshold(int(in_range.sum()), int(in_py.sum())),
        "classifier_accuracy": acc, "classifier_n_test": n_test, "classifier_threshold": acc_lim,
        "classifier_ok": bool(acc <= acc_lim) if classifier else True,
    }

    # the stock bounce: e = 1, mu = 0 reflects the normal component, α2 = α1, β2 = 0, s = 1
    vn = np.einsum("ij,ij->i", Vin_of, nin_of)
    V_spec = Vin_of - 2 * vn[:, None] * nin_of
    _, _, X_spec = impact_states(Vin_of, nin_of, ain_of, V_spec, np.zeros_like(V_spec))
    res["solver_vs_specular"] = {
        "ks": {name: ks_2samp(X_of[:, j], X_spec[:, j]) for j, name in enumerate(STATE_NAMES[:3])},
        "mean_alpha2_minus_alpha1_deg": {
            "solver": float(np.mean(np.degrees(X_of[:, 0]) - alpha1_of)),
            "specular": float(np.mean(np.degrees(X_spec[:, 0]) - alpha1_of))},
        "mean_speed_ratio": {"solver": float(np.mean(X_of[:, 2])), "specular": float(np.mean(X_spec[:, 2]))},
        "mean_abs_beta2_deg": {"solver": float(np.mean(np.degrees(np.abs(X_of[:, 1])))), "specular": 0.0},
    }
    res["checks_passed"] = bool(res["solver_vs_sampler"]["ks_ok"] and res["solver_vs_sampler"]["classifier_ok"]
                                and res["trapped_fraction"]["ok"])
    res["_plot"] = (alpha1_of, X_of, alpha1_py, X_py)
    return res


def plot(res: dict, png: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    alpha1_of, X_of, alpha1_py, X_py = res["_plot"]
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.6))
    ax = axes[0]
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
    ax.set_title("rebound direction against incidence")
    bins = np.linspace(0, 90, 19)
    centres = (bins[1:] + bins[:-1]) / 2
    ax = axes[1]
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
    ax.set_title("speed ratio")
    ax = axes[2]
    edges = np.linspace(-60, 60, 61)
    ax.hist(np.degrees(X_of[:, 1]), edges, density=True, histtype="step", color="tab:blue", lw=1.5,
            label="OpenFOAM + stochasticRebound")
    ax.hist(np.degrees(X_py[:, 1]), edges, density=True, histtype="step", color="tab:orange", lw=1.5,
            label="sample_global")
    ax.axvline(0.0, color="k", lw=1.5, label="specular (β2 = 0)")
    ax.set_xlabel("out-of-plane angle β2 (deg)")
    ax.set_ylabel("density (1/deg)")
    ax.legend(fontsize=7)
    ax.set_title("out-of-plane scattering")
    s = res["solver_vs_sampler"]
    fig.suptitle(f"hopperRebound ({res['hits']} wall hits, {res['settings']['shape']}): "
                 f"solver vs sampler KS ≤ {max(s['ks'].values()):.3f} (threshold {s['ks_threshold']:.3f}), "
                 f"classifier {s['classifier_accuracy']:.3f} (threshold {s['classifier_threshold']:.3f})",
                 fontsize=10)
    fig.tight_layout()
    fig.savefig(png, dpi=110)
    plt.close(fig)


def report(res: dict) -> str:
    s, sp, inc = res["solver_vs_sampler"], res["solver_vs_specular"], res["incidence"]
    lines = [f"case {res['case']}: {res['hits']} wall hits on {len(res['ranks'])} rank(s): "
             f"{res['rebounded']} rebounded, {res['trapped']} trapped, {res['invalid']} invalid",
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
    lines.append(f"solver vs sample_global ({s['n_solver']} vs {s['n_sampler']} rebounds): KS "
                 + ", ".join(f"{k} {v:.4f}" for k, v in s["ks"].items())
                 + f" (threshold {s['ks_threshold']:.4f}: {'met' if s['ks_ok'] else 'NOT met'}); "
                 + (f"classifier {s['classifier_accuracy']:.4f} (n_test {s['classifier_n_test']}, threshold "
                    f"{s['classifier_threshold']:.4f}: {'met' if s['classifier_ok'] else 'NOT met'})"
                    if s["classifier_accuracy"] == s["classifier_accuracy"] else "classifier not run"))
    lines.append("  within the table's speed range: KS "
                 + ", ".join(f"{k} {v:.4f}" for k, v in s["ks_in_speed_range"].items())
                 + f" (threshold {s['ks_in_speed_range_threshold']:.4f})")
    t = res["trapped_fraction"]
    lines.append(f"trapped fraction: solver {t['solver']:.4f}, sampler {t['sampler']:.4f} "
                 f"(SE {t['se']:.4f}: {'met' if t['ok'] else 'NOT met'})")
    lines.append("solver vs stock specular bounce: KS " + ", ".join(f"{k} {v:.3f}" for k, v in sp["ks"].items())
                 + f"; mean alpha2-alpha1 {sp['mean_alpha2_minus_alpha1_deg']['solver']:.1f} deg (specular 0), "
                 f"mean s {sp['mean_speed_ratio']['solver']:.3f} (specular 1), mean |beta2| "
                 f"{sp['mean_abs_beta2_deg']['solver']:.1f} deg (specular 0)")
    return "\n".join(lines)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("case", type=Path)
    parser.add_argument("--table", type=Path, help="the table (default: the path the run recorded)")
    parser.add_argument("--seed", type=int, default=1, help="seed of the sampler's draws")
    parser.add_argument("--png", type=Path, help="write the figure here")
    parser.add_argument("--json", type=Path, help="write the figures here")
    parser.add_argument("--no-classifier", action="store_true", help="KS and trapped fractions only (faster)")
    parser.add_argument("--check", action="store_true", help="exit 1 if a threshold is not met")
    args = parser.parse_args(argv)
    res = compare(args.case, args.table, args.seed, classifier=not args.no_classifier)
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
    if args.json:
        args.json.write_text(json.dumps({k: v for k, v in res.items() if not k.startswith("_")}, indent=2))
    if args.check and not res["checks_passed"]:
        print("comparison thresholds NOT met", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
