"""Statistics of rebounds and the records they are taken from (:class:`PointSamples`, :class:`ReportData`): the one
definition used by ``tablegen simulate`` and ``tablegen report``.

Statistics are over the particles that rebounded; trapped and failed ones are
counted, not averaged (docs/model.md §6). The "most probable" value of a
quantity is the centre of the fullest bin of a histogram of fixed bin width
(:func:`histogram_mode`, width per quantity in :data:`QUANTITIES`). Several
rebound distributions have two near-equal peaks or sharp edges, so a mode is
fragile: compare whole distributions when it matters.

Frame: the lab frame of docs/model.md §2 (wall y = 0, normal +Y into the gas,
impact plane XY, V⁻ = |V⁻|(cos α1, −sin α1, 0)). V stands for |V⁻|; angles
are in radians inside the samples.
"""

from __future__ import annotations

import dataclasses
from typing import NamedTuple

import numpy as np

from data_schema.samples import (
    FAILURE_NAMES, STATUS_FAILED, STATUS_NAMES, STATUS_TRAPPED, SampleSet, angles_to_velocity,
)

COLLISION_CLASSES = ("1", "2", "3", "4", "5", ">5")
NORMAL_IMPACT = 90.0                                   # deg
INDICATRIX_2D_BIN = 2.5                                # deg, α2 bins of I(α2)
INDICATRIX_3D_BIN = 5.0                                # deg, α2 and β2 bins of I(α2, β2)


class Quantity(NamedTuple):
    """A derived quantity: key, text and mathtext labels, histogram bin width of its mode."""

    key: str
    text: str
    tex: str
    mode_bin: float


QUANTITIES = (
    Quantity("u", "u⁺/V", r"$u^+/V$", 0.01),
    Quantity("v", "v⁺/V", r"$v^+/V$", 0.01),
    Quantity("omega_z", "Ω_z a/V", r"$\Omega_z a/V$", 0.02),
    Quantity("e_trans", "E_V⁺/E_V⁻", r"$E_V^+/E_V^-$", 0.005),
    Quantity("e_rot", "E_Ω⁺/E_V⁻", r"$E_\Omega^+/E_V^-$", 0.002),
)


@dataclasses.dataclass(frozen=True, eq=False)
class PointSamples:
    """Rebounded particles at one incident state, lab frame.

    alpha2, beta2 : (m,) rebound angles in rad (docs/model.md §2).
    speed_ratio : (m,) s = |V⁺|/|V⁻|.
    omega : (m, 3) Ω⁺ a/|V⁻|.
    e_rot_ratio : (m,) E_Ω⁺/E_V⁻ (exact from the direct model, approximate from a table).
    status_counts : (3,) particles rebounded, trapped, failed.
    collision_counts : (6,) rebounds with 1, 2, 3, 4, 5 and more than 5 collisions.
    """

    alpha2: np.ndarray
    beta2: np.ndarray
    speed_ratio: np.ndarray
    omega: np.ndarray
    e_rot_ratio: np.ndarray
    status_counts: np.ndarray
    collision_counts: np.ndarray


@dataclasses.dataclass(frozen=True, eq=False)
class ReportData:
    """Everything ``tablegen report`` shows, before statistics: what :mod:`tablegen.study.report` gathers
    and :mod:`tablegen.study.figures` draws.

    source : markdown line naming where the samples come from.
    speed : incident speed |V⁻|, m/s.
    alpha1 : incidence angles, deg, ascending.
    shapes : reported shapes, in the order of the families or the table's shapes, then ``"mix"`` if reported.
    mix_of : the shapes pooled with equal weight into ``"mix"``.
    n : particles (direct model) or draws (table) per (shape, α1).
    seed : the seed of every run.
    counts_note, e_rot_method : markdown sentences on the collision counts and on E_Ω⁺/E_V⁻.
    points : {(shape, α1): PointSamples}.
    rough : {(Δγ deg, α1): RoughSamples} of :attr:`rough_shape` on rough walls (docs/model.md §12); {}: none.
    rough_shape : the shape (or ``"mix"``) of ``rough``.
    work : {(shape, α1, |V⁻| m/s): :class:`tablegen.study.wall_work.WorkSamples`}, the work on the wall at each
        speed of ``work_speeds``, for every reported shape and the mix; {}: none (a table without it).
    work_source : markdown words on where the work's hits come from.
    """

    source: str
    speed: float
    alpha1: tuple
    shapes: tuple
    mix_of: tuple
    n: int
    seed: int
    counts_note: str
    e_rot_method: str
    points: dict
    rough: dict = dataclasses.field(default_factory=dict)
    rough_shape: str = ""
    work: dict = dataclasses.field(default_factory=dict)
    work_speeds: tuple = ()
    work_source: str = ""


@dataclasses.dataclass(frozen=True, eq=False)
class RoughSamples:
    """The rebounds of one (Δγ, α1) on a rough wall: α2 and β2 (rad) of the rebounded particles, the share of
    hits that hit the wall again (a rebound off a facet into the mean wall) and of trapped hits."""

    alpha2: np.ndarray
    beta2: np.ndarray
    again: float
    trapped: float


def lab_velocity(alpha2, beta2, speed_ratio) -> np.ndarray:
    """(m, 3) V⁺/|V⁻| = s (cos β2 cos α2, cos β2 sin α2, sin β2), lab frame; angles in rad."""
    return angles_to_velocity(alpha2, beta2, speed_ratio)


def derived(p: PointSamples) -> dict:
    """{quantity key: (m,) values} of the rebounded particles (keys of :data:`QUANTITIES`)."""
    v = lab_velocity(p.alpha2, p.beta2, p.speed_ratio)
    return {"u": v[:, 0], "v": v[:, 1], "omega_z": p.omega[:, 2], "e_trans": p.speed_ratio ** 2,
            "e_rot": p.e_rot_ratio}


def histogram_mode(x, width: float) -> float:
    """Most probable value: centre of the fullest bin [k·width, (k+1)·width) (the lowest on a tie); NaN if empty."""
    x = np.asarray(x, dtype=float)
    if x.size == 0:
        return float("nan")
    k = np.floor(x / width).astype(np.int64)
    fullest = int(np.argmax(np.bincount(k - k.min()))) + int(k.min())
    return (fullest + 0.5) * width


def collision_classes(n_collisions) -> np.ndarray:
    """(6,) counts of rebounds with 1, 2, 3, 4, 5 and more than 5 collisions (unknown, −1, ignored)."""
    n = np.clip(np.asarray(n_collisions, dtype=np.int64), 0, len(COLLISION_CLASSES))
    return np.bincount(n, minlength=len(COLLISION_CLASSES) + 1)[1:]


def from_sample_set(s: SampleSet) -> PointSamples:
    """The rebounded particles of a direct-model run, with their exact E_Ω⁺/E_V⁻."""
    ok = s.rebounded
    return PointSamples(alpha2=s.alpha2[ok], beta2=s.beta2[ok], speed_ratio=s.speed_ratio[ok], omega=s.omega[ok],
                        e_rot_ratio=s.extra["e_rot_ratio"][ok],
                        status_counts=np.bincount(s.status.astype(np.int64), minlength=len(STATUS_NAMES)),
                        collision_counts=collision_classes(s.n_collisions[ok]))


def point_statistics(p: PointSamples) -> dict:
    """Means and most probable values of the quantities; rebounds; status and collision percentages.

    ``trapped_percent`` and ``failed_percent`` are of all particles,
    ``collision_percent`` (1, 2, 3, 4, 5, > 5 collisions) of the rebounded ones.
    """
    values = derived(p)
    total = max(int(p.status_counts.sum()), 1)
    return {
        "mean": {q.key: float(np.mean(values[q.key])) if p.alpha2.size else float("nan") for q in QUANTITIES},
        "mode": {q.key: histogram_mode(values[q.key], q.mode_bin) for q in QUANTITIES},
        "rebounds": int(p.alpha2.size),
        "trapped_percent": 100.0 * p.status_counts[STATUS_TRAPPED] / total,
        "failed_percent": 100.0 * p.status_counts[STATUS_FAILED] / total,
        "collision_percent": 100.0 * p.collision_counts / max(int(p.collision_counts.sum()), 1),
    }


def summarize(samples: SampleSet) -> dict:
    """:func:`point_statistics` of a direct-model run, with its counts by status and failure reason."""
    reasons = samples.extra.get("failure_reason", np.zeros(0, dtype=np.int8))
    return {
        "counts": {name: int(np.sum(samples.status == code)) for code, name in STATUS_NAMES.items()},
        "failures": {name: int(np.sum(reasons == code)) for code, name in FAILURE_NAMES.items()
                     if np.any(reasons == code)},
        "multiple_root_collisions": int(samples.extra.get("n_multiple_roots", np.zeros(1)).sum()),
        **point_statistics(from_sample_set(samples)),
    }


def format_summary(samples: SampleSet, stats: dict) -> str:
    """Human-readable text of :func:`summarize`."""
    lines = [f"shape {samples.shape}, alpha1 = {samples.alpha1:g} deg, |V-| = {samples.speed:g} m/s, "
             f"n = {len(samples)}, seed = {samples.seed}"]
    lines.append("status: " + ", ".join(f"{k} {v}" for k, v in stats["counts"].items()))
    if stats["failures"]:
        lines.append("failures: " + ", ".join(f"{k}: {v}" for k, v in stats["failures"].items()))
    lines.append(f"collisions resolved with the smallest of 3 positive roots: {stats['multiple_root_collisions']}")
    lines.append(f"{'quantity':<16}{'mean':>12}{'most probable':>16}{'bin':>8}")
    for q in QUANTITIES:
        lines.append(f"{q.text:<16}{stats['mean'][q.key]:>12.4f}{stats['mode'][q.key]:>16.4f}{q.mode_bin:>8g}")
    lines.append("collisions per rebound (% of rebounded):")
    lines.append("  " + "  ".join(f"{k}: {v:.2f}" for k, v in zip(COLLISION_CLASSES, stats["collision_percent"])))
    return "\n".join(lines)


def indicatrix_2d(alpha2, width_deg: float = INDICATRIX_2D_BIN):
    """I(α2) on α2 ∈ [0°, 180°]: (edges in rad, density in 1/rad), ∫ I dα2 = 1 over the rebounds."""
    edges = np.radians(np.arange(0.0, 180.0 + width_deg / 2, width_deg))
    counts, _ = np.histogram(alpha2, bins=edges)
    return edges, counts / (max(len(alpha2), 1) * np.diff(edges))


def indicatrix_3d(alpha2, beta2, width_deg: float = INDICATRIX_3D_BIN):
    """I(α2, β2) on [0°, 180°] × [−90°, 90°]: (α2 edges, β2 edges in rad, density (n_α2, n_β2) in 1/rad²).

    Normalised so that ∫∫ I dα2 dβ2 = 1 over the rebounds (docs/model.md §6).
    """
    a_edges = np.radians(np.arange(0.0, 180.0 + width_deg / 2, width_deg))
    b_edges = np.radians(np.arange(-90.0, 90.0 + width_deg / 2, width_deg))
    counts, _, _ = np.histogram2d(alpha2, beta2, bins=(a_edges, b_edges))
    return a_edges, b_edges, counts / (max(len(alpha2), 1) * np.outer(np.diff(a_edges), np.diff(b_edges)))


def nearest_alpha1(available, wanted) -> tuple:
    """The values of ``available`` nearest to each of ``wanted`` (deg), ascending, without repeats."""
    grid = np.asarray(available, dtype=float)
    return tuple(sorted({float(grid[np.argmin(np.abs(grid - w))]) for w in wanted}))
