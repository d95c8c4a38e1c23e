"""Wall hits a flow solver answered, against :mod:`surrogate` on the same incident states.

A solver adapter (integrations/openfoam, or any other) records every wall hit: its incident state (V⁻, Ω⁻,
n, a, the shape or mix) and what the runtime answered inside the solver (V⁺, Ω⁺, the status and the path:
table or direct model). Put them in a :class:`SolverHits` record and call :func:`compare_hits`. It draws
surrogate's answers at the same incident states, each hit by the path the solver took
(:func:`surrogate_answers`), and compares the two samples path by path (:func:`agreement`):

* the reflected states in the impact frame, X = (α2, β2, s = |V⁺|/|V⁻|, Ω⁺a/|V⁻| along ex, n, ez)
  (:func:`impact_states`);
* each variable: the two-sample Kolmogorov–Smirnov statistic. Under one law it exceeds
  c·√((n+m)/(nm)), c = √(−ln(α/2)/2), with probability at most α (Kolmogorov's asymptotic tail, which
  bounds the exact one at these sizes): :func:`ks_bound`;
* the joint law: a classifier two-sample test on (α1, |V⁻|, Ω⁻a/|V⁻|, X) (:func:`classifier_accuracy`).
  Under one law the held-out accuracy over n_test rows has mean ½ and standard deviation √(0.25/n_test);
  the bound is ½ + z·√(0.25/n_test), z = Φ⁻¹(1 − α), one-sided: :func:`classifier_bound`. Both samples
  share their incident states, so the two rows of one hit go to the same side of the train/test split
  (``groups``): split row by row, the classifier learns a training row's incident state and gives its twin
  in the test half the other label, which pulls the accuracy below ½ and blinds the test;
* the fractions not rebounded (trapped or failed): within z standard errors of their difference (pooled
  binomial), z = Φ⁻¹(1 − α/2).

α is ``family_alpha`` shared evenly by every bound a call checks (Bonferroni), so that two samples of one law
pass them all with probability at least 1 − ``family_alpha``.

Needs scipy and scikit-learn (the ``build`` extra).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field, fields, replace
from statistics import NormalDist

import numpy as np
from scipy.stats import ks_2samp
from sklearn.ensemble import HistGradientBoostingClassifier
from sklearn.model_selection import GroupShuffleSplit, train_test_split
from threadpoolctl import threadpool_limits

import surrogate
from data_schema.samples import STATUS_INVALID, STATUS_REBOUNDED
from data_schema.table import STATE_NAMES
from surrogate.kernels import PATH_DIRECT, PATH_TABLE

__all__ = ["FAMILY_ALPHA", "PATHS", "Agreement", "ComparisonReport", "SolverHits", "agreement",
           "classifier_accuracy", "classifier_bound", "compare_hits", "hits_per_path", "impact_states",
           "incident_states", "ks_bound", "path_rule", "specular_answers", "surrogate_answers"]

FAMILY_ALPHA = 1e-3     # probability that one law fails any bound of one call
PATHS = {"table": PATH_TABLE, "direct": PATH_DIRECT}   # path name: the hits' path code


# ----------------------------------------------------------------------------- the records

@dataclass(frozen=True)
class SolverHits:
    """Wall hits and their answers, one row per hit, in the solver's frame.

    Parameters
    ----------
    V : (N, 3) incident velocity relative to the wall V⁻, m/s, moving into the wall.
    Omega : (N, 3) incident angular velocity Ω⁻, rad/s.
    n : (N, 3) unit wall normal into the gas.
    a : (N,) half-size, m (half the largest extent).
    shape : the shape or mix every hit drew from (a name, ``"mix"`` or weights, as
        :func:`surrogate.mix_cdf` takes it), or (N,) shape names, one per hit.
    V_out : (N, 3) reflected velocity V⁺, m/s (NaN unless rebounded).
    Omega_out : (N, 3) reflected angular velocity Ω⁺, rad/s (NaN unless rebounded).
    status : (N,) ``surrogate.STATUS_*``.
    path : (N,) the path that answered: ``surrogate.kernels.PATH_TABLE`` or ``PATH_DIRECT``
        (``STATUS_INVALID`` for a hit nothing answered).
    grain_key : None (every hit drew a new grain from ``shape``) or (N,) the grain key of each hit's particle
        (:func:`surrogate.grain_key`, integers in [0, 2**63)): the particle hit as the grain of its key in
        ``shape``, and :func:`surrogate_answers` draws it so (docs/model.md §11). Where particles keep their
        grain, the hits at an incident state are not the mix's: the grains that hit more often, or slower,
        are over-represented there, so the reference must hold the same grains.
    """

    V: np.ndarray
    Omega: np.ndarray
    n: np.ndarray
    a: np.ndarray
    shape: object
    V_out: np.ndarray
    Omega_out: np.ndarray
    status: np.ndarray
    path: np.ndarray
    grain_key: np.ndarray | None = None

    def __post_init__(self):
        count = len(np.asarray(self.status))
        for name, columns, dtype in (("V", 3, float), ("Omega", 3, float), ("n", 3, float), ("a", 0, float),
                                     ("V_out", 3, float), ("Omega_out", 3, float), ("status", 0, np.int64),
                                     ("path", 0, np.int64)):
            value = np.asarray(getattr(self, name), dtype=dtype)
            expected = (count, columns) if columns else (count,)
            if value.shape != expected:
                raise ValueError(f"SolverHits.{name} must have shape {expected} (one row per hit); "
                                 f"got {value.shape}.")
            object.__setattr__(self, name, value)
        if not isinstance(self.shape, (str, dict)):
            names = np.asarray(self.shape, dtype=object)
            if names.shape != (count,):
                raise ValueError(f"SolverHits.shape must be a name, a mix or one name per hit ({count}); "
                                 f"got shape {names.shape}.")
            object.__setattr__(self, "shape", names)
        if self.grain_key is not None:
            keys = np.asarray(self.grain_key)
            if keys.shape != (count,) or keys.dtype.kind not in "iu" or (keys.size and keys.min() < 0):
                raise ValueError(f"SolverHits.grain_key must be None or one integer >= 0 per hit ({count}); "
                                 f"got {keys.dtype} of shape {keys.shape}.")
            object.__setattr__(self, "grain_key", keys.astype(np.int64))

    def __len__(self) -> int:
        return len(self.status)

    def take(self, rows) -> SolverHits:
        """The hits at ``rows`` (a boolean mask or indices)."""
        per_hit = {f.name: getattr(self, f.name)[rows] for f in fields(self)
                   if isinstance(getattr(self, f.name), np.ndarray)}
        return replace(self, **per_hit)


@dataclass(frozen=True)
class Agreement:
    """Two samples of answers at the same incident states (the solver's and a reference's) and the bounds
    one law keeps their statistics in (module doc). ``classifier_accuracy`` is NaN when the classifier was
    not run; then ``classifier_ok`` holds."""

    n_solver: int               # rebounded hits compared, solver side
    n_reference: int            # rebounded hits compared, reference side
    ks: dict                    # variable name (data_schema.table.STATE_NAMES): KS statistic
    ks_bound: float
    classifier_accuracy: float
    classifier_n_test: int
    classifier_bound: float
    not_rebounded: tuple        # fractions trapped or failed: (solver, reference)
    not_rebounded_bound: float  # bound on their difference
    mean_speed_ratio: tuple     # mean s = |V⁺|/|V⁻|: (solver, reference)
    mean_deflection_deg: tuple  # mean α2 − α1 in degrees: (solver, reference)

    @property
    def ks_ok(self) -> bool:
        return bool(max(self.ks.values()) <= self.ks_bound)

    @property
    def classifier_ok(self) -> bool:
        return bool(math.isnan(self.classifier_accuracy) or self.classifier_accuracy <= self.classifier_bound)

    @property
    def not_rebounded_ok(self) -> bool:
        return bool(abs(self.not_rebounded[0] - self.not_rebounded[1]) <= self.not_rebounded_bound)

    @property
    def ok(self) -> bool:
        return self.ks_ok and self.classifier_ok and self.not_rebounded_ok

    def as_dict(self) -> dict:
        """The record and its verdicts as plain numbers (for JSON)."""
        out = {f.name: getattr(self, f.name) for f in fields(self)}
        out.update(ks_ok=self.ks_ok, classifier_ok=self.classifier_ok, not_rebounded_ok=self.not_rebounded_ok,
                   ok=self.ok)
        return out

    def line(self, name: str) -> str:
        """One line of text: the statistics against their bounds."""
        verdict = {True: "met", False: "NOT met"}
        classifier = ("classifier not run" if math.isnan(self.classifier_accuracy) else
                      f"classifier {self.classifier_accuracy:.4f} (n_test {self.classifier_n_test}, bound "
                      f"{self.classifier_bound:.4f}: {verdict[self.classifier_ok]})")
        return (f"{name} ({self.n_solver} vs {self.n_reference} rebounds): KS "
                + ", ".join(f"{k} {v:.4f}" for k, v in self.ks.items())
                + f" (bound {self.ks_bound:.4f}: {verdict[self.ks_ok]}); {classifier}; not rebounded "
                f"{self.not_rebounded[0]:.4f} vs {self.not_rebounded[1]:.4f} (bound on the difference "
                f"{self.not_rebounded_bound:.4f}: {verdict[self.not_rebounded_ok]})")


@dataclass(frozen=True)
class ComparisonReport:
    """:func:`compare_hits`'s result: hits per path, and per path with hits, the solver's answers against
    surrogate's (:class:`Agreement`); ``answers``: surrogate's answers, row for row with ``hits``."""

    hits_per_path: dict         # "table", "direct", "invalid": number of hits
    agreement: dict             # path name: Agreement
    family_alpha: float
    hits: SolverHits = field(repr=False)
    answers: SolverHits = field(repr=False)

    @property
    def ok(self) -> bool:
        return all(a.ok for a in self.agreement.values())

    def as_dict(self) -> dict:
        return {"hits_per_path": self.hits_per_path, "family_alpha": self.family_alpha, "ok": self.ok,
                "agreement": {name: a.as_dict() for name, a in self.agreement.items()}}

    def lines(self) -> str:
        counts = ", ".join(f"{k} {v}" for k, v in self.hits_per_path.items())
        return "\n".join([f"hits per path: {counts}"]
                         + [a.line(f"{name} path: solver vs surrogate") for name, a in self.agreement.items()])


# ----------------------------------------------------------------------------- frames

def _impact_axes(V, n):
    """The impact frame's tangential axes (ex along V⁻'s tangential part, ez = ex × n) of each hit."""
    speed = np.linalg.norm(V, axis=1)
    vn = np.einsum("ij,ij->i", V, n)
    t = V - vn[:, None] * n
    tn = np.linalg.norm(t, axis=1)
    # a normal hit has no tangential part: any ex does, zero keeps it out of the statistics' way
    ex = np.where(tn[:, None] > 1e-12 * speed[:, None], t / np.maximum(tn, 1e-300)[:, None], 0.0)
    return ex, np.cross(ex, n), speed, vn


def incident_states(V, n, a, Omega):
    """(α1 in degrees from the wall, |V⁻| in m/s, Ω⁻a/|V⁻| along (ex, n, ez) as (N, 3)) of each hit."""
    ex, ez, speed, vn = _impact_axes(V, n)
    alpha1 = np.degrees(np.arcsin(np.clip(-vn / speed, -1.0, 1.0)))
    spin = np.column_stack([np.einsum("ij,ij->i", Omega, e) * a / speed for e in (ex, n, ez)])
    return alpha1, speed, spin


def impact_states(V, n, a, V_out, Omega_out) -> np.ndarray:
    """(N, 6) reflected states in each hit's impact frame: α2, β2 (rad), s = |V⁺|/|V⁻|, Ω⁺a/|V⁻| along
    (ex, n, ez) (the order of data_schema.table.STATE_NAMES)."""
    ex, ez, speed, _ = _impact_axes(V, n)
    u, v, w = (np.einsum("ij,ij->i", V_out, e) for e in (ex, n, ez))
    magnitude = np.sqrt(u * u + v * v + w * w)
    omega = np.column_stack([np.einsum("ij,ij->i", Omega_out, e) * a / speed for e in (ex, n, ez)])
    return np.column_stack([np.arctan2(v, u), np.arcsin(np.clip(w / magnitude, -1, 1)), magnitude / speed,
                            omega])


# ----------------------------------------------------------------------------- statistics and their bounds

def ks_bound(n: int, m: int, alpha: float) -> float:
    """The two-sample KS statistic of n and m draws of one law exceeds this with probability at most
    ``alpha`` (Kolmogorov's asymptotic tail)."""
    return math.sqrt(-math.log(alpha / 2) / 2) * math.sqrt((n + m) / (n * m))


def classifier_bound(n_test: int, alpha: float) -> float:
    """The held-out accuracy over ``n_test`` rows of two samples of one law exceeds this with probability
    about ``alpha`` (normal approximation, one-sided)."""
    return 0.5 + NormalDist().inv_cdf(1 - alpha) * math.sqrt(0.25 / n_test)


def _classifier(X, Y, seed: int, groups) -> tuple[float, int]:
    """(held-out accuracy, n_test) of :func:`classifier_accuracy`."""
    Z = np.vstack([X, Y])
    labels = np.r_[np.zeros(len(X)), np.ones(len(Y))]
    if groups is None:
        Z_train, Z_test, y_train, y_test = train_test_split(Z, labels, test_size=0.5, random_state=seed,
                                                            stratify=labels)
    else:
        train, test = next(GroupShuffleSplit(n_splits=1, test_size=0.5, random_state=seed)
                           .split(Z, labels, groups=np.asarray(groups)))
        Z_train, Z_test, y_train, y_test = Z[train], Z[test], labels[train], labels[test]
    # one OpenMP thread: on some thousands of rows the threads mostly spin at barriers against the machine's other
    # jobs (docs/design/test_time.md), and the figure is the same whatever the number of cores
    with threadpool_limits(1, user_api="openmp"):
        model = HistGradientBoostingClassifier(max_iter=200, random_state=seed).fit(Z_train, y_train)
        return float(model.score(Z_test, y_test)), len(y_test)


def classifier_accuracy(X: np.ndarray, Y: np.ndarray, seed: int = 0, groups=None) -> float:
    """Held-out accuracy of a classifier telling rows of X from rows of Y (0.5: indistinguishable).

    scikit-learn's HistGradientBoostingClassifier with 200 iterations, a fixed random state and one thread, so the
    figure is reproducible, trained on half of the rows and scored on the other half. Without ``groups``, a
    stratified split row by row. ``groups`` (one label per row of X, then of Y): the rows of a group go to
    the same half; give it whenever rows of X and Y share their features in part (the same incident state),
    or the split pulls the accuracy below 0.5 (module doc).
    """
    return _classifier(X, Y, seed, groups)[0]


def agreement(hits: SolverHits, reference: SolverHits, comparisons: int = 1, family_alpha: float = FAMILY_ALPHA,
              classifier: bool = True, seed: int = 0) -> Agreement:
    """The solver's answers (``hits``) against a reference's at the same incident states, row for row
    (``reference``: surrogate's, say, from :func:`surrogate_answers`), with the bounds of one law at
    ``family_alpha`` shared by ``comparisons`` such calls (module doc)."""
    if len(hits) != len(reference) or not np.array_equal(hits.V, reference.V):
        raise ValueError("agreement compares answers at the same incident states: the two records must hold "
                         f"the same hits row for row (got {len(hits)} and {len(reference)} rows).")
    alpha = family_alpha / comparisons
    alpha1, speed, spin = incident_states(hits.V, hits.n, hits.a, hits.Omega)
    incident = np.column_stack([alpha1, speed, spin])
    samples = []
    for answers in (hits, reference):
        ok = answers.status == STATUS_REBOUNDED
        samples.append((ok, impact_states(hits.V[ok], hits.n[ok], hits.a[ok], answers.V_out[ok],
                                          answers.Omega_out[ok])))
    (ok1, X1), (ok2, X2) = samples
    n1, n2 = len(X1), len(X2)
    ks = {name: float(ks_2samp(X1[:, k], X2[:, k]).statistic) for k, name in enumerate(STATE_NAMES)}
    accuracy, n_test = math.nan, max(n1, 1)
    if classifier:
        rows = np.arange(len(hits))
        accuracy, n_test = _classifier(np.column_stack([incident[ok1], X1]), np.column_stack([incident[ok2], X2]),
                                       seed, np.r_[rows[ok1], rows[ok2]])
    p1, p2 = 1.0 - np.mean(ok1), 1.0 - np.mean(ok2)
    pooled = (p1 + p2) / 2
    z = NormalDist().inv_cdf(1 - alpha / 2)
    # + 1e-12: two samples with no trapped hit at all differ by 0, which meets a bound of 0
    not_rebounded_bound = z * math.sqrt(pooled * (1 - pooled) * 2 / len(hits)) + 1e-12
    deflection = [float(np.mean(np.degrees(X[:, 0]) - alpha1[ok])) for ok, X in samples]
    return Agreement(n_solver=n1, n_reference=n2, ks=ks, ks_bound=ks_bound(n1, n2, alpha / len(STATE_NAMES)),
                     classifier_accuracy=accuracy, classifier_n_test=n_test,
                     classifier_bound=classifier_bound(n_test, alpha),
                     not_rebounded=(float(p1), float(p2)), not_rebounded_bound=not_rebounded_bound,
                     mean_speed_ratio=(float(np.mean(X1[:, 2])), float(np.mean(X2[:, 2]))),
                     mean_deflection_deg=tuple(deflection))


# ----------------------------------------------------------------------------- reference answers

def _shape_groups(shape, count: int):
    """(shape or mix, rows) pairs: one for a shape or mix every hit shares, one per name otherwise."""
    if isinstance(shape, (str, dict)):
        return [(shape, np.arange(count))]
    return [(str(name), np.flatnonzero(shape == name)) for name in sorted(set(shape))]


def surrogate_answers(table, hits: SolverHits, seed: int = 1, interpolation: str = "scaled",
                      method: str | None = None) -> SolverHits:
    """surrogate's answers at the incident states of ``hits``, row for row.

    ``method`` None: each hit by the path the solver took, the table's hits by
    :func:`surrogate.sample_global` with ``method="table"`` (``clamp=True``, as the runtime at a grid's
    edge), the direct model's by ``method="direct"`` with their Ω⁻; ``"table"``: every hit by the table,
    Ω⁻ ignored (what a solver that does not pass Ω⁻ would get); ``"direct"``: every hit by the direct model. Invalid hits stay NaN and invalid.
    ``table``: the loaded table the solver drew from (:func:`surrogate.load`); ``seed``: the draws'. With
    ``hits.grain_key``, each hit is drawn as its particle's grain (``sample_global``'s ``grain_key``).
    """
    if method not in (None, *PATHS):
        raise ValueError(f"The 'method' parameter must be None (the solver's path), 'table' or 'direct'; "
                         f"got {method!r}.")
    taken = hits.path if method is None else np.where(hits.path == STATUS_INVALID, STATUS_INVALID, PATHS[method])
    V_out, Omega_out = np.full_like(hits.V_out, np.nan), np.full_like(hits.Omega_out, np.nan)
    status = np.full(len(hits), STATUS_INVALID, dtype=np.int64)
    rng = np.random.default_rng(seed)
    for name, code in PATHS.items():
        for shape, rows in _shape_groups(hits.shape, len(hits)):
            rows = rows[taken[rows] == code]
            if len(rows):
                with warnings.catch_warnings():      # the solver's summary counted them: the same hits again
                    warnings.simplefilter("ignore", surrogate.WallLawRangeWarning)
                    answered = surrogate.sample_global(
                        table, hits.V[rows], hits.n[rows], hits.a[rows], shape=shape, random_state=rng, clamp=True,
                        interpolation=interpolation, omega=hits.Omega[rows] if name == "direct" else None,
                        method=name, grain_key=None if hits.grain_key is None else hits.grain_key[rows])
                V_out[rows], Omega_out[rows], status[rows] = answered.V, answered.Omega, answered.status
    return replace(hits, V_out=V_out, Omega_out=Omega_out, status=status, path=taken)


def specular_answers(hits: SolverHits) -> SolverHits:
    """The specular bounce at the incident states of ``hits`` (restitution 1, no friction: V⁺ = V⁻ with its
    normal component reversed, Ω⁺ = 0, every valid hit rebounded): the stock bounce of most solvers."""
    vn = np.einsum("ij,ij->i", hits.V, hits.n)
    valid = hits.path != STATUS_INVALID
    return replace(hits, V_out=hits.V - 2 * vn[:, None] * hits.n, Omega_out=np.zeros_like(hits.Omega),
                   status=np.where(valid, STATUS_REBOUNDED, STATUS_INVALID))


# ----------------------------------------------------------------------------- the comparison

def hits_per_path(hits: SolverHits) -> dict:
    """The number of hits each path answered, and of invalid ones."""
    counts = {name: int(np.sum(hits.path == code)) for name, code in PATHS.items()}
    counts["invalid"] = int(np.sum(hits.path == STATUS_INVALID))
    return counts


def path_rule(hits: SolverHits, table, spin_tolerance: float = surrogate.SPIN_TOLERANCE) -> dict:
    """The hits against the rule of ``method="auto"`` (the table iff |Ω⁻|a/|V⁻| ≤ ``spin_tolerance`` and α1,
    |V⁻| inside the table's grid): how many hits spin, how many lie outside the grid, how many neither,
    and how many of each the wrong path answered. A relative margin keeps out of the count the hits a
    recorded state's rounding could move across a grid edge (1e-9) or across the tolerance (1e-6: a hits
    file's 9 significant digits)."""
    valid = hits.path != STATUS_INVALID
    alpha1, speed, spin = incident_states(hits.V, hits.n, hits.a, hits.Omega)
    spin_ratio = np.linalg.norm(spin, axis=1)
    margin = 1e-9
    bounds = [(speed, float(np.min(table.speed_m_s)), float(np.max(table.speed_m_s))),
              (alpha1, float(np.min(table.alpha1_deg)), float(np.max(table.alpha1_deg)))]
    inside = np.logical_and.reduce([(x >= lo * (1 + margin)) & (x <= hi * (1 - margin)) for x, lo, hi in bounds])
    outside = np.logical_or.reduce([(x < lo * (1 - margin)) | (x > hi * (1 + margin)) for x, lo, hi in bounds])
    spinning = spin_ratio > spin_tolerance * (1 + 1e-6)
    still = spin_ratio < spin_tolerance * (1 - 1e-6)
    return {"spin_tolerance": spin_tolerance, "spinning": int(np.sum(spinning & valid)),
            "spinning_not_direct": int(np.sum(spinning & valid & (hits.path != PATH_DIRECT))),
            "outside": int(np.sum(outside & valid)),
            "outside_not_direct": int(np.sum(outside & valid & (hits.path != PATH_DIRECT))),
            "still_inside": int(np.sum(still & inside & valid)),
            "still_inside_not_table": int(np.sum(still & inside & valid & (hits.path != PATH_TABLE)))}


def compare_hits(hits: SolverHits, table, seed: int = 1, interpolation: str = "scaled", classifier: bool = True,
                 family_alpha: float = FAMILY_ALPHA) -> ComparisonReport:
    """The solver's answers against surrogate's on the same incident states, path by path (module doc).

    ``table``: the loaded table the solver drew from; ``interpolation``: the solver's; ``seed``: surrogate's
    draws; ``classifier=False``: KS and fractions not rebounded only (the classifier takes seconds per
    10⁴ hits). The bounds hold together with probability 1 − ``family_alpha`` under one law.
    """
    answers = surrogate_answers(table, hits, seed, interpolation)
    used = [(name, hits.path == code) for name, code in PATHS.items() if np.any(hits.path == code)]
    result = {name: agreement(hits.take(rows), answers.take(rows), len(used), family_alpha, classifier)
              for name, rows in used}
    return ComparisonReport(hits_per_path=hits_per_path(hits), agreement=result, family_alpha=family_alpha,
                            hits=hits, answers=answers)
