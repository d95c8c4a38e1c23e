"""The work of the rebounds on the wall in ``tablegen report`` (docs/report.md, "Work on the wall"; docs/model.md
§4.7), its data and the laws drawn beside it (the figure: :func:`tablegen.study.figures.work_figure`): per
(shape, α1, |V⁻|) the normal and tangential work W_n, W_t of every hit that rebounded or was trapped (up to the
trap), in units of the incident energy E⁻ = ½|V⁻|², their means and spread against α1, and beside them
the angle dependence of two classical erosion models of a ductile wall, each scaled to meet the mix's mean curve
at the angle where that curve peaks:

* Finnie (1960), the cutting of a ductile wall by a rigid grain: f(α) = sin 2α − 3 sin²α for tan α ≤ 1/3, and
  cos²α / 3 above, drawn beside W_t;
* Bitter (1963), deformation wear: (V sin α − K)² with the elastic-limit speed K neglected at these speeds, i.e.
  sin²α, drawn beside W_n.

Those models give the volume a sphere's hit removes as a function of its incident angle; the work here is what
the model's grains did to the wall, hit by hit: the comparison is of shapes of curves, not of magnitudes.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from data_schema.samples import STATUS_REBOUNDED, STATUS_TRAPPED

FINNIE_CRITICAL = math.atan(1.0 / 3.0)      # rad: where Finnie's two regimes meet (tan α = 1/3)


@dataclasses.dataclass(frozen=True, eq=False)
class WorkSamples:
    """The work on the wall of the hits at one (shape, α1, |V⁻|) that rebounded or were trapped: W_n/E⁻ and W_t/E⁻
    (m,), E⁻ = ½|V⁻|²."""

    normal: np.ndarray
    tangential: np.ndarray


def work_samples(status, work_normal, work_tangential, speed: float) -> WorkSamples:
    """:class:`WorkSamples` of hits with ``status`` and work (m²/s²) at |V⁻| = ``speed`` m/s (failed and refused hits
    left out)."""
    kept = (np.asarray(status) == STATUS_REBOUNDED) | (np.asarray(status) == STATUS_TRAPPED)
    energy = 0.5 * speed * speed
    return WorkSamples(np.asarray(work_normal)[kept] / energy, np.asarray(work_tangential)[kept] / energy)


def pooled(parts) -> WorkSamples:
    """The union of several shapes' work samples (the equal-weight mix when each has as many hits)."""
    return WorkSamples(np.concatenate([p.normal for p in parts]), np.concatenate([p.tangential for p in parts]))


def finnie(alpha_deg) -> np.ndarray:
    """Finnie's (1960) angle function of ductile erosion at incidence angles α (deg from the wall)."""
    a = np.radians(np.asarray(alpha_deg, dtype=float))
    return np.where(a <= FINNIE_CRITICAL, np.sin(2.0 * a) - 3.0 * np.sin(a) ** 2, np.cos(a) ** 2 / 3.0)


def bitter_deformation(alpha_deg) -> np.ndarray:
    """Bitter's (1963) deformation wear against α (deg from the wall), its elastic-limit speed neglected: sin²α."""
    return np.sin(np.radians(np.asarray(alpha_deg, dtype=float))) ** 2


def scaled_to_meet(law, alpha1, means) -> tuple:
    """(α at which they meet, the factor c): c · law(α) equals the mean curve ``means`` (over ``alpha1``, deg) at its
    peak."""
    at = float(np.asarray(alpha1)[int(np.nanargmax(means))])
    return at, float(np.nanmax(means) / law(at))


def means(work: dict, shape: str, alpha1, speed: float) -> tuple:
    """(mean W_n/E⁻, mean W_t/E⁻) over ``alpha1`` at one shape and speed: two arrays (NaN where no hit)."""
    points = [work[shape, a, speed] for a in alpha1]
    return (np.array([p.normal.mean() if p.normal.size else np.nan for p in points]),
            np.array([p.tangential.mean() if p.tangential.size else np.nan for p in points]))
