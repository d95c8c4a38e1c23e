"""Compare the rebounds an OpenFOAM run applied with the Python implementations, the stock bounce and,
for erosion, a run with the stock bounce.

    python compare_rebounds.py CASE [--table T.h5] [--png FILE.png] [--json FILE.json] [--check]
                               [--no-classifier] [--erosion-against SPECULAR_CASE [--erosion-png FILE.png]]

Reads the per-hit records the stochasticRebound adapter wrote
(CASE/postProcessing/lagrangian/<cloud>/stochasticRebound/hits_<rank>.csv:
incident velocity relative to the wall V⁻, incident angular velocity Ω⁻,
wall normal n into the gas, half-size a, the status, the path that answered
(the table or the direct model) and the rebound V⁺, Ω⁺ the C runtime gave)
and the records of OpenFOAM's own patchPostProcessing function object (the
parcel's state at each wall hit, taken before the patch interaction acts),
then:

1. checks that both record the same hits: the same number per patch, and
   per parcel the same sequence of incident velocities;
2. checks the path of every hit against the rule of method auto, and
   compares each path's answers with Python at the same incident states:
   the table's with `surrogate.sample_global` (same table, shape mix and
   interpolation as the run, method "table"), the direct model's with
   `surrogate.sample_direct` (Ω⁻ included). The two samples of reflected
   states are compared in the impact frame, (α2, β2, s = |V⁺|/|V⁻|,
   Ω⁺a/|V⁻| along ex, n, ez): the two-sample KS statistic per variable, a
   classifier two-sample test on the incident and reflected states
   together, and the trapped (or failed) fractions. Both samples are draws
   of one conditional law at the same incident states, so the thresholds
   are those of equal laws at these sample sizes (as docs/VALIDATION.md
   states its precision): KS below its 99.9 % point
   c(0.001)·√((n+m)/(n·m)), c = 1.949; classifier accuracy below 0.5 + 4
   standard errors √(0.25/n_test); the trapped fractions within 4 standard
   errors of their difference;
3. compares the spinning hits with the table-only rebound (Ω⁻ ignored, as
   the adapter did before it passed Ω⁻) and the table's hits with the stock
   bounce (standardWallInteraction rebound, e = 1, mu = 0: specular,
   α2 = α1, β2 = 0, s = 1) on the same incident states;
4. plots the table's hits against the sampler and the specular line, and the
   spinning hits against the direct model and the table alone (--png);
5. with --erosion-against, reads OpenFOAM's particleErosion field of both
   runs and maps the volume each wall face lost side by side (--erosion-png).

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

from rbs_api import (STATUS_FAILED, STATUS_INVALID, STATUS_REBOUNDED, STATUS_TRAPPED,  # noqa: E402
                     load, sample_direct, sample_global)

KS_C_999 = 1.949          # two-sample KS: c(α) for α = 0.001
CLASSIFIER_SE = 4.0       # classifier threshold: 0.5 + this many standard errors
TRAPPED_SE = 4.0          # trapped fractions: |difference| within this many standard errors
STATE_NAMES = ("alpha2", "beta2", "speed_ratio", "omega_x", "omega_y", "omega_z")

HIT_COLUMNS = ("time,rank,patch,origProc,origId,d,a,Vx,Vy,Vz,Winx,Winy,Winz,nx,ny,nz,Uwx,Uwy,Uwz,status,path,"
               "Voutx,Vouty,Voutz,Wx,Wy,Wz,spin_ratio,u0").split(",")
PATH_TABLE, PATH_DIRECT = 0, 1   # the hits file's path column (rbs_rebound_path; -1: invalid)


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
                 r"halfSizeFactor (\S+), interpolation (\w+), method (\w+), spin tolerance (\S+)$", line.strip())
    if not m:
        raise ValueError(f"not a stochasticRebound hits header: {line!r}")
    mix = m.group(4)
    if mix.startswith("weights ("):
        shape = {k: float(v) for k, v in (item.split() for item in mix[len("weights ("):-1].split(", "))}
    else:
        shape = mix
    return {"seed": int(m.group(1)), "stream": int(m.group(2)), "table": m.group(3), "shape": shape,
            "half_size_factor": float(m.group(5)), "interpolation": m.group(6), "method": m.group(7),
            "spin_tolerance": float(m.group(8))}


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
        elif name in ("rank", "origProc", "origId", "status", "path"):
            cols[name] = np.array(values, dtype=np.int64)
        else:
            cols[name] = np.array(values, dtype=float)
    cols["V"] = np.column_stack([cols["Vx"], cols["Vy"], cols["Vz"]])
    cols["Win"] = np.column_stack([cols["Winx"], cols["Winy"], cols["Winz"]])
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


def classifier_accuracy(X, Y, seed: int = 0, groups=None) -> tuple[float, int]:
    """Held-out accuracy of a gradient-boosting classifier telling rows of X from rows of Y; n_test.

    ``groups`` (the hit of each row of X, then of each row of Y): the rows of one hit go to the same half.
    Both samples share their incident features row for row; split apart, the twin of a training row is
    recognised and given the other label, which pulls the accuracy below ½ and weakens the test."""
    from sklearn.ensemble import HistGradientBoostingClassifier
    from sklearn.model_selection import train_test_split
    Z = np.vstack([X, Y])
    labels = np.r_[np.zeros(len(X)), np.ones(len(Y))]
    if groups is None:
        Z_train, Z_test, y_train, y_test = train_test_split(Z, labels, test_size=0.5, random_state=seed,
                                                            stratify=labels)
    else:
        ids = np.unique(groups)
        train = np.isin(groups, np.random.default_rng(seed).permutation(ids)[:len(ids) // 2])
        Z_train, Z_test, y_train, y_test = Z[train], Z[~train], labels[train], labels[~train]
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


def _shapes_of(table, shape, count: int, seed: int):
    """The shape of each of ``count`` direct-model rebounds: the run's shape, or drawn from its mix."""
    if isinstance(shape, str) and shape != "mix":
        return shape
    weights = shape if isinstance(shape, dict) else {s: 1.0 / len(table.shapes) for s in table.shapes}
    names = list(weights)
    p = np.array([weights[k] for k in names]) / sum(weights.values())
    return np.array(names, dtype=object)[np.random.default_rng(seed).choice(len(names), count, p=p)]


def _agreement(feats_a, X_a, feats_b, X_b, classifier: bool, hits_a, hits_b) -> dict:
    """Two samples of reflected states at the same incident states (``hits_a``, ``hits_b``: the hit of each
    row): KS per variable and a classifier on (incident features, state), with the thresholds of equal laws
    at these sample sizes."""
    n1, n2 = len(X_a), len(X_b)
    ks = {name: ks_2samp(X_a[:, j], X_b[:, j]) for j, name in enumerate(STATE_NAMES)}
    ks_lim = ks_threshold(n1, n2)
    if classifier:
        acc, n_test = classifier_accuracy(np.column_stack([feats_a, X_a]), np.column_stack([feats_b, X_b]),
                                          groups=np.r_[hits_a, hits_b])
    else:
        acc, n_test = float("nan"), n1
    acc_lim = 0.5 + CLASSIFIER_SE * math.sqrt(0.25 / n_test)
    return {"n_solver": n1, "n_sampler": n2, "ks": ks, "ks_threshold": ks_lim,
            "ks_ok": bool(max(ks.values()) <= ks_lim), "classifier_accuracy": acc, "classifier_n_test": n_test,
            "classifier_threshold": acc_lim, "classifier_ok": bool(acc <= acc_lim) if classifier else True}


def _trapped_fraction(st_solver, st_other) -> dict:
    """Fractions not rebounded (trapped or failed) of two samples at the same incident states."""
    p1, p2 = float(np.mean(st_solver != STATUS_REBOUNDED)), float(np.mean(st_other != STATUS_REBOUNDED))
    pool = (p1 + p2) / 2
    se = math.sqrt(max(pool * (1 - pool), 1e-300) * 2 / max(len(st_solver), 1))
    return {"solver": p1, "sampler": p2, "se": se, "ok": bool(abs(p1 - p2) <= TRAPPED_SE * se or p1 == p2)}


def _spin_features(V, n, a, W):
    """Ω⁻a/|V⁻| along (ex, n, ez) of each hit: the incident spin as the classifier sees it."""
    speed = np.linalg.norm(V, axis=1)
    vn = np.einsum("ij,ij->i", V, n)
    t = V - vn[:, None] * n
    ex = t / np.maximum(np.linalg.norm(t, axis=1), 1e-300)[:, None]
    ez = np.cross(ex, n)
    return np.column_stack([np.einsum("ij,ij->i", W, e) * a / speed for e in (ex, n, ez)])


def incidence(hits: dict):
    """α1 (deg) and |V⁻| (m/s) of every hit record."""
    speed = np.linalg.norm(hits["V"], axis=1)
    return np.degrees(np.arcsin(np.clip(-np.einsum("ij,ij->i", hits["V"], hits["n"]) / speed, -1, 1))), speed


def check_paths(hits: dict, settings: dict, table) -> dict:
    """Which path answered the hits, against the rule of rbs_rebound_path under method auto: counts per path,
    and the spinning hits, the hits outside the grid and the non-spinning hits inside it that went elsewhere.
    A relative margin of 1e-9 keeps the states this script's NumPy arithmetic could put on the other side of
    a grid edge, and 1e-6 those the file's 9 digits of |Ω⁻|a/|V⁻| could put on the other side of the spin
    tolerance, out of the check."""
    status, path = hits["status"], hits["path"]
    valid = status != STATUS_INVALID
    speed_lo, speed_hi = float(np.min(table.speed_m_s)), float(np.max(table.speed_m_s))
    a_lo, a_hi = float(np.min(table.alpha1_deg)), float(np.max(table.alpha1_deg))
    tolerance = settings["spin_tolerance"]
    alpha1_all, speed_all = incidence(hits)
    margin = 1e-9
    inside = ((speed_all >= speed_lo * (1 + margin)) & (speed_all <= speed_hi * (1 - margin))
              & (alpha1_all >= a_lo * (1 + margin)) & (alpha1_all <= a_hi * (1 - margin)))
    outside = ((speed_all < speed_lo * (1 - margin)) | (speed_all > speed_hi * (1 + margin))
               | (alpha1_all < a_lo * (1 - margin)) | (alpha1_all > a_hi * (1 + margin)))
    spinning = hits["spin_ratio"] > tolerance * (1 + 1e-6)
    still = hits["spin_ratio"] < tolerance * (1 - 1e-6)
    return {
        "method": settings["method"], "spin_tolerance": tolerance,
        "table": int(np.sum(path == PATH_TABLE)), "direct": int(np.sum(path == PATH_DIRECT)),
        "invalid": int(np.sum(path == STATUS_INVALID)), "spinning": int(np.sum(spinning & valid)),
        "spinning_not_direct": int(np.sum(spinning & valid & (path != PATH_DIRECT))),
        "outside_not_direct": int(np.sum(outside & valid & (path != PATH_DIRECT))),
        "still_inside": int(np.sum(still & inside & valid)),
        "still_inside_not_table": int(np.sum(still & inside & valid & (path != PATH_TABLE))),
    }


def compare_paths(case: Path, table_path: Path | None = None) -> dict:
    """:func:`check_paths` of a run's hit records (the table from the path the run recorded)."""
    hits, headers = read_hits(case)
    return check_paths(hits, headers[0], load(Path(table_path or headers[0]["table"])))


def compare(case: Path, table_path: Path | None = None, seed: int = 1, classifier: bool = True) -> dict:
    """The comparisons 2 and 3 of the module docstring (``classifier=False``: KS and trapped fractions only).

    Hits the table answered are compared with ``sample_global`` at their incident states, hits the direct
    model answered with ``sample_direct`` at theirs (Ω⁻ included); the spinning ones among the latter also
    with the table-only rebound the adapter drew before it passed Ω⁻ (``sample_global``, clamped at the
    grid's edge): how far off that was."""
    hits, headers = read_hits(case)
    settings = headers[0]
    table_path = Path(table_path or settings["table"])
    table = load(table_path)
    status, path = hits["status"], hits["path"]
    n_hits = len(status)
    valid = status != STATUS_INVALID
    speed_lo, speed_hi = float(np.min(table.speed_m_s)), float(np.max(table.speed_m_s))
    a_lo, a_hi = float(np.min(table.alpha1_deg)), float(np.max(table.alpha1_deg))
    tolerance = settings["spin_tolerance"]

    res = {"case": str(case), "table": str(table_path), "settings": settings,
           "ranks": sorted({int(h["stream"]) for h in headers}),
           "hits": n_hits, "rebounded": int(np.sum(status == STATUS_REBOUNDED)),
           "trapped": int(np.sum(status == STATUS_TRAPPED)), "failed": int(np.sum(status == STATUS_FAILED)),
           "invalid": int(np.sum(~valid))}

    res["paths"] = check_paths(hits, settings, table)
    alpha1_all, speed_all = incidence(hits)
    spinning = hits["spin_ratio"] > tolerance * (1 + 1e-6)     # the file's 9 digits

    # hits the table answered, against the sampler at the same incident states
    on_table = valid & (path == PATH_TABLE)
    V, n, a = hits["V"][on_table], hits["n"][on_table], hits["a"][on_table]
    st_of = status[on_table]
    V_py, W_py, st_py = sample_global(table, V, n, a, shape=settings["shape"], random_state=seed,
                                      interpolation=settings["interpolation"], clamp=True, method="table")
    res["trapped_fraction"] = _trapped_fraction(st_of, st_py)
    ok_of, ok_py = st_of == STATUS_REBOUNDED, st_py == STATUS_REBOUNDED
    alpha1_of, speed_of, X_of = impact_states(V[ok_of], n[ok_of], a[ok_of], hits["Vout"][on_table][ok_of],
                                              hits["Wout"][on_table][ok_of])
    alpha1_py, speed_py, X_py = impact_states(V[ok_py], n[ok_py], a[ok_py], V_py[ok_py], W_py[ok_py])
    in_range = (speed_of >= speed_lo) & (speed_of <= speed_hi)
    res["incidence"] = {
        "hits_outside_grid": int(np.sum(valid & ((speed_all < speed_lo) | (speed_all > speed_hi)
                                                 | (alpha1_all < a_lo) | (alpha1_all > a_hi)))),
        "alpha1_deg_percentiles_5_50_95": np.percentile(alpha1_all[valid], [5, 50, 95]).round(2).tolist(),
        "speed_m_s_percentiles_5_50_95": np.percentile(speed_all[valid], [5, 50, 95]).round(1).tolist(),
        "table_speed_range_m_s": [speed_lo, speed_hi],
        "fraction_outside_speed_range": float(np.mean((speed_all[valid] < speed_lo) | (speed_all[valid] > speed_hi))),
        "spin_ratio_mean_max": [float(np.mean(hits["spin_ratio"])), float(np.max(hits["spin_ratio"]))],
    }
    rows = np.flatnonzero(on_table)
    s = _agreement(np.column_stack([alpha1_of, speed_of]), X_of, np.column_stack([alpha1_py, speed_py]), X_py,
                   classifier, rows[ok_of], rows[ok_py])
    in_py = (speed_py >= speed_lo) & (speed_py <= speed_hi)
    s["ks_in_speed_range"] = {name: ks_2samp(X_of[in_range, j], X_py[in_py, j]) for j, name in enumerate(STATE_NAMES)}
    s["ks_in_speed_range_threshold"] = ks_threshold(int(in_range.sum()), int(in_py.sum()))
    res["solver_vs_sampler"] = s

    # hits the direct model answered, against surrogate.sample_direct at the same incident states (Ω⁻ too)
    direct = valid & (path == PATH_DIRECT)
    res["direct_hits"] = int(direct.sum())
    if direct.sum() > 0:
        Vd, nd, ad, Wd = hits["V"][direct], hits["n"][direct], hits["a"][direct], hits["Win"][direct]
        st_d = status[direct]
        Vr, Wr, st_r = sample_direct(table, Vd, nd, ad, omega=Wd,
                                      shape=_shapes_of(table, settings["shape"], len(Vd), seed), random_state=seed)
        res["direct_trapped_fraction"] = _trapped_fraction(st_d, st_r)
        ok_d, ok_r = st_d == STATUS_REBOUNDED, st_r == STATUS_REBOUNDED
        spin_d = _spin_features(Vd, nd, ad, Wd)
        a1_d, sp_d, X_d = impact_states(Vd[ok_d], nd[ok_d], ad[ok_d], hits["Vout"][direct][ok_d],
                                        hits["Wout"][direct][ok_d])
        a1_r, sp_r, X_r = impact_states(Vd[ok_r], nd[ok_r], ad[ok_r], Vr[ok_r], Wr[ok_r])
        rows = np.flatnonzero(direct)
        res["solver_vs_direct_model"] = _agreement(np.column_stack([a1_d, sp_d, spin_d[ok_d]]), X_d,
                                                   np.column_stack([a1_r, sp_r, spin_d[ok_r]]), X_r, classifier,
                                                   rows[ok_d], rows[ok_r])
        # the spinning ones: what the table alone (the adapter before it passed Ω⁻) gave them
        spin_sel = spinning[direct]
        Vt, Wt, st_t = sample_global(table, Vd[spin_sel], nd[spin_sel], ad[spin_sel], shape=settings["shape"],
                                     random_state=seed + 1, interpolation=settings["interpolation"], clamp=True,
                                     method="table")
        ok_s = ok_d & spin_sel
        ok_t = st_t == STATUS_REBOUNDED
        a1_s, sp_s, X_s = impact_states(Vd[ok_s], nd[ok_s], ad[ok_s], hits["Vout"][direct][ok_s],
                                        hits["Wout"][direct][ok_s])
        a1_t, sp_t, X_t = impact_states(Vd[spin_sel][ok_t], nd[spin_sel][ok_t], ad[spin_sel][ok_t], Vt[ok_t], Wt[ok_t])
        far = _agreement(np.column_stack([a1_s, sp_s, spin_d[ok_s]]), X_s,
                         np.column_stack([a1_t, sp_t, spin_d[spin_sel][ok_t]]), X_t, classifier, rows[ok_s],
                         rows[spin_sel][ok_t])
        far["mean_speed_ratio"] = {"direct": float(np.mean(X_s[:, 2])), "table_only": float(np.mean(X_t[:, 2]))}
        far["mean_alpha2_minus_alpha1_deg"] = {"direct": float(np.mean(np.degrees(X_s[:, 0]) - a1_s)),
                                               "table_only": float(np.mean(np.degrees(X_t[:, 0]) - a1_t))}
        res["spinning_direct_vs_table_only"] = far
        res["_plot_spin"] = (a1_s, X_s, a1_r[spin_sel[ok_r]], X_r[spin_sel[ok_r]], a1_t, X_t)

    # the stock bounce: e = 1, mu = 0 reflects the normal component, α2 = α1, β2 = 0, s = 1
    Vin_of, nin_of, ain_of = V[ok_of], n[ok_of], a[ok_of]
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
    checks = [s["ks_ok"], s["classifier_ok"], res["trapped_fraction"]["ok"]]
    if "solver_vs_direct_model" in res:
        d = res["solver_vs_direct_model"]
        checks += [d["ks_ok"], d["classifier_ok"], res["direct_trapped_fraction"]["ok"]]
    res["checks_passed"] = bool(all(checks))
    res["_plot"] = (alpha1_of, X_of, alpha1_py, X_py)
    return res


def _density(ax, values, edges, color, label):
    ax.hist(values, edges, density=True, histtype="step", color=color, lw=1.5, label=label)


def plot(res: dict, png: Path) -> None:
    """Top row: the hits the table answered, against the sampler and the specular bounce; bottom row (when
    the direct model answered spinning hits): those hits against the direct model run again on their
    incident states and against the table-only rebound."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    spin = "_plot_spin" in res and len(res["_plot_spin"][0]) > 0
    alpha1_of, X_of, alpha1_py, X_py = res["_plot"]
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
    s = res["solver_vs_sampler"]
    title = (f"hopperRebound ({res['hits']} wall hits, {res['settings']['shape']}, method "
             f"{res['settings']['method']}): table hits vs sampler KS ≤ {max(s['ks'].values()):.3f} (threshold "
             f"{s['ks_threshold']:.3f}), classifier {s['classifier_accuracy']:.3f} (threshold "
             f"{s['classifier_threshold']:.3f})")
    if spin:
        a1_s, X_s, a1_r, X_r, a1_t, X_t = res["_plot_spin"]
        d, far = res["solver_vs_direct_model"], res["spinning_direct_vs_table_only"]
        curves = ((X_s, a1_s, "tab:blue", "OpenFOAM + stochasticRebound (direct model)"),
                  (X_r, a1_r, "tab:green", "surrogate.sample_direct, same incident states"),
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
        axes[1, 1].set_title(f"direct hits vs sample_direct: classifier {d['classifier_accuracy']:.3f} "
                             f"(≤ {d['classifier_threshold']:.3f})", fontsize=9)
        axes[1, 2].set_title(f"spinning hits vs table only: classifier {far['classifier_accuracy']:.3f}", fontsize=9)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(png, dpi=110)
    plt.close(fig)


def _agreement_line(name: str, s: dict, thresholds: bool = True) -> str:
    verdict = (lambda ok: (": met" if ok else ": NOT met") if thresholds else "")
    classifier = (f"classifier {s['classifier_accuracy']:.4f} (n_test {s['classifier_n_test']}, threshold "
                  f"{s['classifier_threshold']:.4f}{verdict(s['classifier_ok'])})"
                  if s["classifier_accuracy"] == s["classifier_accuracy"] else "classifier not run")
    return (f"{name} ({s['n_solver']} vs {s['n_sampler']} rebounds): KS "
            + ", ".join(f"{k} {v:.4f}" for k, v in s["ks"].items())
            + f" (threshold {s['ks_threshold']:.4f}{verdict(s['ks_ok'])}); " + classifier)


def report(res: dict) -> str:
    s, sp, inc, pa = res["solver_vs_sampler"], res["solver_vs_specular"], res["incidence"], res["paths"]
    lines = [f"case {res['case']}: {res['hits']} wall hits on {len(res['ranks'])} rank(s): "
             f"{res['rebounded']} rebounded, {res['trapped']} trapped, {res['failed']} failed, "
             f"{res['invalid']} invalid",
             f"paths (method {pa['method']}, spin tolerance {pa['spin_tolerance']:g}): table {pa['table']}, direct "
             f"model {pa['direct']}; spinning hits {pa['spinning']} ({pa['spinning_not_direct']} not direct), "
             f"hits outside the grid not direct {pa['outside_not_direct']}, non-spinning hits inside the grid "
             f"{pa['still_inside']} ({pa['still_inside_not_table']} not table)",
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
    lines.append(_agreement_line("table hits: solver vs sample_global", s))
    lines.append("  within the table's speed range: KS "
                 + ", ".join(f"{k} {v:.4f}" for k, v in s["ks_in_speed_range"].items())
                 + f" (threshold {s['ks_in_speed_range_threshold']:.4f})")
    t = res["trapped_fraction"]
    lines.append(f"  trapped fraction: solver {t['solver']:.4f}, sampler {t['sampler']:.4f} "
                 f"(SE {t['se']:.4f}: {'met' if t['ok'] else 'NOT met'})")
    if "solver_vs_direct_model" in res:
        lines.append(_agreement_line("direct-model hits: solver vs sample_direct", res["solver_vs_direct_model"]))
        t = res["direct_trapped_fraction"]
        lines.append(f"  trapped or failed fraction: solver {t['solver']:.4f}, sample_direct {t['sampler']:.4f} "
                     f"(SE {t['se']:.4f}: {'met' if t['ok'] else 'NOT met'})")
        far = res["spinning_direct_vs_table_only"]
        lines.append(_agreement_line("spinning hits: solver (direct model) vs the table alone", far, False)
                     + f"; mean s {far['mean_speed_ratio']['direct']:.3f} vs "
                     f"{far['mean_speed_ratio']['table_only']:.3f}, mean alpha2-alpha1 "
                     f"{far['mean_alpha2_minus_alpha1_deg']['direct']:.1f} vs "
                     f"{far['mean_alpha2_minus_alpha1_deg']['table_only']:.1f} deg")
    lines.append("table hits vs stock specular bounce: KS "
                 + ", ".join(f"{k} {v:.3f}" for k, v in sp["ks"].items())
                 + f"; mean alpha2-alpha1 {sp['mean_alpha2_minus_alpha1_deg']['solver']:.1f} deg (specular 0), "
                 f"mean s {sp['mean_speed_ratio']['solver']:.3f} (specular 1), mean |beta2| "
                 f"{sp['mean_abs_beta2_deg']['solver']:.1f} deg (specular 0)")
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


def wall_face_centres(case: Path, patch: str) -> np.ndarray:
    """(n_faces, 3) centres (vertex means, m) of the faces of ``patch``, from the case's ASCII polyMesh."""
    mesh = case / "constant" / "polyMesh"
    points = np.array(_foam_list((mesh / "points").read_text(), "points"), dtype=float)
    faces = _foam_list((mesh / "faces").read_text(), "faces")
    block = re.search(rf"\n\s*{re.escape(patch)}\s*\{{([^}}]*)\}}", (mesh / "boundary").read_text()).group(1)
    start = int(re.search(r"startFace\s+(\d+);", block).group(1))
    count = int(re.search(r"nFaces\s+(\d+);", block).group(1))
    return np.array([points[np.array(faces[f], dtype=int)].mean(axis=0) for f in range(start, start + count)])


def read_erosion(case: Path, patch: str = "walls", cloud: str = "kinematicCloud") -> np.ndarray:
    """The volume each face of ``patch`` lost (m³), from OpenFOAM's particleErosion field <cloud>Q at the
    last write time of a serial run."""
    times = [p for p in case.iterdir() if re.fullmatch(r"[0-9.e+-]+", p.name) and (p / f"{cloud}Q").is_file()]
    if not times:
        raise FileNotFoundError(f"{case}: no {cloud}Q field (particleErosion) in a time folder")
    text = (max(times, key=lambda p: float(p.name)) / f"{cloud}Q").read_text()
    block = text[re.search(rf"\n\s*{re.escape(patch)}\s*\n\s*\{{", text).end():]
    m = re.search(r"value\s+(uniform\s+([-0-9.eE+]+)|nonuniform\s+List<scalar>\s*(\d+)\s*\(([^)]*)\))", block)
    if m.group(2) is not None:
        n_faces = len(wall_face_centres(case, patch))
        return np.full(n_faces, float(m.group(2)))
    return np.array(m.group(4).split(), dtype=float)


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


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("case", type=Path)
    parser.add_argument("--table", type=Path, help="the table (default: the path the run recorded)")
    parser.add_argument("--seed", type=int, default=1, help="seed of the sampler's draws")
    parser.add_argument("--png", type=Path, help="write the figure here")
    parser.add_argument("--json", type=Path, help="write the figures here")
    parser.add_argument("--no-classifier", action="store_true", help="KS and trapped fractions only (faster)")
    parser.add_argument("--check", action="store_true", help="exit 1 if a threshold is not met")
    parser.add_argument("--erosion-against", type=Path, metavar="CASE",
                        help="a run of the same case with standardWallInteraction: compare the erosion of both")
    parser.add_argument("--erosion-png", type=Path, help="write the two erosion maps side by side here")
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
    if args.erosion_against:
        res["erosion"] = {"stochasticRebound": erosion_summary(args.case),
                          "standardWallInteraction": erosion_summary(args.erosion_against)}
        for label, e in res["erosion"].items():
            print(f"erosion ({label}): {e['faces_eroded']} of {e['faces']} wall faces, total {e['total_m3']:.3e} m3")
        if args.erosion_png:
            plot_erosion({"standardWallInteraction (specular)": args.erosion_against,
                          f"stochasticRebound, method {res['settings']['method']}": args.case}, args.erosion_png)
            print(f"wrote {args.erosion_png}")
    if args.json:
        args.json.write_text(json.dumps({k: v for k, v in res.items() if not k.startswith("_")}, indent=2))
    if args.check and not res["checks_passed"]:
        print("comparison thresholds NOT met", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
