"""Summary statistics of a set of rebounds (docs/model.md §6).

Statistics are over the particles that rebounded; trapped and failed ones are
counted, not averaged. "Most probable" values are histogram modes; several
rebound distributions have two near-equal peaks or sharp edges, so a mode is
fragile: compare whole distributions when it matters.
"""

from __future__ import annotations

import numpy as np

from data_schema.samples import FAILURE_NAMES, STATUS_NAMES, SampleSet

COLLISION_CLASSES = ("1", "2", "3", "4", "5", ">5")


def most_probable(x: np.ndarray) -> float:
    """Histogram mode of ``x``: centre of the fullest bin.

    Bins by the Freedman–Diaconis rule (width 2·IQR·n^(−1/3)), 10 to 200 of them,
    over the 0.1–99.9 percentile range so isolated outliers do not set the grid.
    """
    x = np.asarray(x, dtype=float)
    if x.size == 0:
        return float("nan")
    lo, q1, q3, hi = np.percentile(x, [0.1, 25, 75, 99.9])
    if hi <= lo:
        return float(np.median(x))
    width = 2.0 * (q3 - q1) * x.size ** (-1.0 / 3.0)
    nbins = int(np.clip(np.ceil((hi - lo) / width) if width > 0 else 10, 10, 200))
    counts, edges = np.histogram(x, bins=nbins, range=(lo, hi))
    i = int(np.argmax(counts))
    return float(0.5 * (edges[i] + edges[i + 1]))


def collision_histogram(n_collisions: np.ndarray) -> np.ndarray:
    """Percentages of rebounds with 1, 2, 3, 4, 5 and more than 5 collisions."""
    n = np.asarray(n_collisions)
    counts = np.array([np.sum(n == k) for k in range(1, 6)] + [np.sum(n > 5)], dtype=float)
    return 100.0 * counts / max(n.size, 1)


def summarize(samples: SampleSet) -> dict:
    """Counts by status, means and modes of the reflected state, collision histogram."""
    ok = samples.rebounded
    speed = samples.speed
    quantities = {
        "u+/V": samples.velocity[ok, 0] / speed,
        "v+/V": samples.velocity[ok, 1] / speed,
        "Omega_z a/V": samples.omega[ok, 2],
        "E_V+/E_V-": samples.e_trans_ratio[ok],
    }
    if "e_rot_ratio" in samples.extra:
        quantities["E_Omega+/E_V-"] = samples.extra["e_rot_ratio"][ok]
    reasons = samples.extra.get("failure_reason", np.zeros(0, dtype=np.int8))
    return {
        "counts": {name: int(np.sum(samples.status == code)) for code, name in STATUS_NAMES.items()},
        "failures": {name: int(np.sum(reasons == code)) for code, name in FAILURE_NAMES.items()
                     if np.any(reasons == code)},
        "multiple_root_collisions": int(samples.extra.get("n_multiple_roots", np.zeros(1)).sum()),
        "mean": {k: float(np.mean(v)) if v.size else float("nan") for k, v in quantities.items()},
        "most_probable": {k: most_probable(v) for k, v in quantities.items()},
        "collisions_percent": dict(zip(COLLISION_CLASSES, collision_histogram(samples.n_collisions[ok]))),
    }


def format_summary(samples: SampleSet, stats: dict) -> str:
    """Human-readable text of :func:`summarize`."""
    lines = [f"shape {samples.shape}, alpha1 = {samples.alpha1:g} deg, |V-| = {samples.speed:g} m/s, "
             f"n = {len(samples)}, seed = {samples.seed}"]
    lines.append("status: " + ", ".join(f"{k} {v}" for k, v in stats["counts"].items()))
    if stats["failures"]:
        lines.append("failures: " + ", ".join(f"{k}: {v}" for k, v in stats["failures"].items()))
    lines.append(f"collisions resolved with the smallest of 3 positive roots: {stats['multiple_root_collisions']}")
    lines.append(f"{'quantity':<16}{'mean':>12}{'most probable':>16}")
    for key, mean in stats["mean"].items():
        lines.append(f"{key:<16}{mean:>12.4f}{stats['most_probable'][key]:>16.4f}")
    lines.append("collisions per rebound (% of rebounded):")
    lines.append("  " + "  ".join(f"{k}: {v:.2f}" for k, v in stats["collisions_percent"].items()))
    return "\n".join(lines)
