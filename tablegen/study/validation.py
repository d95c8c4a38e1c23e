"""Statistical comparison of table draws with the direct model.

At one incident state (shape or mix, α1, |V⁻|) draw reflected states from a
table (:mod:`surrogate`) and from the direct model (:func:`direct_model.simulate.simulate`,
an independent seed; :func:`compare_point` runs the model the table was built with, on
any shape it holds: a family, a user's grain, their mix), and compare the rebounded states
X = (α2, β2, s, Ω_x a/|V⁻|, Ω_y a/|V⁻|, Ω_z a/|V⁻|) and, at the validation matrix's points
(:func:`compare_point`), the work of the rebound on the wall W_n/(½|V⁻|²), W_t/(½|V⁻|²) after them:

* each marginal: the two-sample Kolmogorov–Smirnov statistic;
* the joint law: a classifier two-sample test
  (:func:`tablegen.study.solver_comparison.classifier_accuracy`). A gradient-boosting
  classifier learns to tell the two samples apart on half of them; its
  accuracy on the other half is 0.5 when the laws are the same (standard error
  √(0.25/n_test));
* means, standard deviations and correlation matrices.
"""

from __future__ import annotations

import numpy as np
from scipy.stats import ks_2samp

import surrogate
from data_schema.samples import STATUS_REBOUNDED, rebound_angles
from data_schema.table import STATE_NAMES
from direct_model.runtime import model_settings
from direct_model.shapes import MIX, SHAPES
from direct_model.simulate import simulate
from tablegen.tabulation.cells import derive_seed
from tablegen.study.solver_comparison import classifier_accuracy


def table_states(table, shape, alpha1: float, speed: float, n: int, seed: int,
                 interpolation: str = "scaled") -> np.ndarray:
    """(m, 6) rebounded states drawn from a table (m ≤ n: trapped draws are dropped)."""
    d = surrogate.sample_local(table, np.full(n, alpha1), speed, shape, random_state=seed,
                               interpolation=interpolation)
    ok = d.status == STATUS_REBOUNDED
    return np.column_stack([d.alpha2[ok], d.beta2[ok], d.speed_ratio[ok], d.omega[ok]])


HALF_SIZE = 1e-4     # m, of table_hits' particles: any value (the states are given in units of |V⁻| and |V⁻|/a)


def table_hits(table, shape, alpha1: float, speed: float, n: int, seed: int, omega=(0.0, 0.0, 0.0),
               method: str = "table") -> np.ndarray:
    """(m, 8) rebounded hits of :func:`surrogate.sample_global` at one incident state given in the lab frame (wall
    y = 0, normal +Y, V⁻ in the XY plane: also the impact frame of the hit), Ω⁻a/|V⁻| = ``omega``: the state
    (α2, β2, s, Ω⁺a/|V⁻|) and the work on the wall W_n, W_t in units of ½|V⁻|² (:data:`WORK_COLUMNS`)."""
    a1 = np.radians(alpha1)
    V = np.tile([speed * np.cos(a1), -speed * np.sin(a1), 0.0], (n, 1))
    # clamp: α1 recomputed from V may fall a rounding error below the grid's first point
    hits = surrogate.sample_global(table, V, (0.0, 1.0, 0.0), HALF_SIZE, shape, random_state=seed,
                                   omega=np.asarray(omega) * speed / HALF_SIZE, method=method, clamp=True)
    ok = hits.status == STATUS_REBOUNDED
    alpha2, beta2, v = rebound_angles(hits.V[ok])
    energy = 0.5 * speed ** 2
    return np.column_stack([alpha2, beta2, v / speed, hits.Omega[ok] * HALF_SIZE / speed,
                            hits.wall_work_normal[ok] / energy, hits.wall_work_tangential[ok] / energy])


# the work on the wall as table_hits and direct_states(work=True) give it: W_n and W_t in units of ½|V⁻|²
WORK_COLUMNS = ("work_normal", "work_tangential")


def direct_states(shape, alpha1: float, speed: float, n: int, seed: int, work: bool = False, **model) -> np.ndarray:
    """(m, 6) rebounded states of the direct model (``shape`` and ``model`` as
    :func:`direct_model.simulate.simulate` takes them); with ``work``, (m, 8): the work on the wall after them, as
    :func:`table_hits` gives it."""
    s = simulate(shape, alpha1, speed, n, seed=seed, **model)
    ok = s.rebounded
    columns = [s.alpha2[ok], s.beta2[ok], s.speed_ratio[ok], s.omega[ok]]
    if work:
        columns += [s.extra[f"wall_{name}"][ok] / (0.5 * speed ** 2) for name in WORK_COLUMNS]
    return np.column_stack(columns)


def table_model(table) -> dict:
    """The direct model ``table`` (:func:`surrogate.load`) was built with, as keywords of
    :func:`direct_model.simulate.simulate`: κ, the b/a and c/b law, n_max, the wall law and the search's
    tolerances, from its direct parameters (:func:`direct_model.runtime.model_settings`)."""
    return model_settings(table.direct_parameters)


def table_direct_states(table, shape: str, alpha1: float, speed: float, n: int, seed: int,
                        work: bool = False) -> np.ndarray:
    """(m, 6) rebounded states of the direct model ``table`` was built with (:func:`table_model`) for its shape
    ``shape``: one of the paper's four families by name, any other (a user's grain, a later family) by the
    record the table holds, ``"mix"`` each particle's shape drawn with equal weights among the table's shapes
    (as its mix draws them); with ``work`` (m, 8), as :func:`direct_states`."""
    model = table_model(table)
    records = dict(zip(table.shapes, table.records))
    if shape != MIX:
        return direct_states(shape if shape in SHAPES else records[shape], alpha1, speed, n, seed, work, **model)
    counts = np.random.default_rng(seed).multinomial(n, np.full(len(table.shapes), 1.0 / len(table.shapes)))
    parts = [direct_states(s if s in SHAPES else records[s], alpha1, speed, int(c), derive_seed(seed, k), work,
                           **model)
             for k, (s, c) in enumerate(zip(table.shapes, counts)) if c]
    return np.concatenate(parts)


def compare(T: np.ndarray, D: np.ndarray, joint: bool = True, seed: int = 0) -> dict:
    """KS per marginal, classifier accuracy (if ``joint``), moments of table (T) vs direct (D) states: 6 columns
    (:data:`data_schema.table.STATE_NAMES`), or 8 with the work on the wall (:data:`WORK_COLUMNS`)."""
    names = (STATE_NAMES + WORK_COLUMNS)[:T.shape[1]]
    result = {"ks": {name: float(ks_2samp(T[:, i], D[:, i]).statistic) for i, name in enumerate(names)},
              "mean_table": T.mean(axis=0), "mean_direct": D.mean(axis=0),
              "std_table": T.std(axis=0), "std_direct": D.std(axis=0),
              "corr_table": np.corrcoef(T.T), "corr_direct": np.corrcoef(D.T)}
    if joint:
        result["classifier_accuracy"] = classifier_accuracy(T, D, seed)
    return result


# ----------------------------------------------------------------------------- the validation matrix

ALPHA1_TARGETS = (3.0, 12.0, 30.0, 60.0, 85.0)   # deg: grazing, low, middle, high, near normal
# m/s: low end, middle (off grid in the default's 100–150 interval, its widest where the law moves fast), high end
SPEED_TARGETS = (75.0, 150.0, 275.0)


def grid_points(grid, targets) -> list:
    """The grid values nearest to ``targets`` (each once, in grid order)."""
    grid = np.asarray(grid, dtype=float)
    return sorted({float(grid[np.argmin(np.abs(grid - t))]) for t in targets})


def midpoints(grid, targets) -> list:
    """Midpoints of the grid intervals holding (or nearest to) ``targets`` (each once, increasing)."""
    grid = np.asarray(grid, dtype=float)
    if len(grid) < 2:
        return []
    j = np.clip(np.searchsorted(grid, targets) - 1, 0, len(grid) - 2)
    return sorted({float((grid[i] + grid[i + 1]) / 2) for i in j})


def matrix_points(table) -> list:
    """(where, α1, speed) of the validation matrix.

    On grid: the grid values nearest to ALPHA1_TARGETS × SPEED_TARGETS. Off
    grid (between grid points in both coordinates): the midpoint of every α1
    interval × the midpoints of the speed intervals nearest to SPEED_TARGETS.
    Every α1 interval is tested because one too wide is found nowhere else
    (docs/design/grids.md).
    """
    alpha1 = np.asarray(table.alpha1_deg, dtype=float)
    on = [("on grid", a, v) for a in grid_points(alpha1, ALPHA1_TARGETS)
          for v in grid_points(table.speed_m_s, SPEED_TARGETS)]
    off = [("off grid", float(a), v) for a in (alpha1[1:] + alpha1[:-1]) / 2
           for v in midpoints(table.speed_m_s, SPEED_TARGETS)]
    return on + off


def compare_point(table, shape: str, alpha1: float, speed: float, n: int, seed: int) -> dict:
    """One row of the matrix: table draws (seed) against direct states (independent seed) at one point.

    Returns the KS statistics, the classifier accuracy, the largest error of
    a mean in units of its standard error (of the difference of two sample
    means) and the largest difference of a correlation coefficient.
    """
    columns = 8 if table.kernel_data.has_work else 6       # a table of format 4.0 holds no work
    T = table_hits(table, shape, alpha1, speed, n, seed=seed)[:, :columns]
    D = table_direct_states(table, shape, alpha1, speed, n, seed=seed + 1, work=True)[:, :columns]
    r = compare(T, D, seed=seed % 2 ** 31)
    se = np.sqrt(r["std_table"] ** 2 / len(T) + r["std_direct"] ** 2 / len(D))
    return {"shape": shape, "alpha1": alpha1, "speed": speed, "n_table": len(T), "n_direct": len(D),
            "ks": r["ks"], "classifier_accuracy": r["classifier_accuracy"],
            "mean_error_se": float(np.max(np.abs(r["mean_table"] - r["mean_direct"]) / se)),
            "corr_error": float(np.nanmax(np.abs(r["corr_table"] - r["corr_direct"])))}
