"""Statistical comparison of table draws with the direct model.

At one incident state (shape or mix, α1, |V⁻|) draw reflected states from a
table (:mod:`surrogate`) and from the direct model (:func:`tablegen.simulate.simulate`,
an independent seed), and compare the rebounded states
X = (α2, β2, s, Ω_x a/|V⁻|, Ω_y a/|V⁻|, Ω_z a/|V⁻|):

* each marginal: the two-sample Kolmogorov–Smirnov statistic;
* the joint law: a classifier two-sample test. A gradient-boosting
  classifier learns to tell the two samples apart on half of them; its
  accuracy on the other half is 0.5 when the laws are the same (standard error
  √(0.25/n_test));
* means, standard deviations and correlation matrices.
"""

from __future__ import annotations

import numpy as np
from scipy.stats import ks_2samp
from sklearn.ensemble import HistGradientBoostingClassifier
from sklearn.model_selection import train_test_split

import surrogate
from data_schema.samples import STATUS_REBOUNDED
from data_schema.table import STATE_NAMES
from tablegen.simulate import simulate


def classifier_accuracy(X: np.ndarray, Y: np.ndarray, seed: int = 0) -> float:
    """Held-out accuracy of a classifier telling rows of X from rows of Y (0.5: indistinguishable).

    Stratified 50/50 split; scikit-learn's HistGradientBoostingClassifier with
    200 iterations and a fixed random state, so the figure is reproducible.
    """
    Z = np.vstack([X, Y])
    labels = np.r_[np.zeros(len(X)), np.ones(len(Y))]
    Z_train, Z_test, y_train, y_test = train_test_split(Z, labels, test_size=0.5, random_state=seed,
                                                        stratify=labels)
    model = HistGradientBoostingClassifier(max_iter=200, random_state=seed).fit(Z_train, y_train)
    return float(model.score(Z_test, y_test))


def table_states(table, shape, alpha1: float, speed: float, n: int, seed: int,
                 interpolation: str = "scaled") -> np.ndarray:
    """(m, 6) rebounded states drawn from a table (m ≤ n: trapped draws are dropped)."""
    d = surrogate.sample_local(table, np.full(n, alpha1), speed, shape, random_state=seed,
                               interpolation=interpolation)
    ok = d.status == STATUS_REBOUNDED
    return np.column_stack([d.alpha2[ok], d.beta2[ok], d.speed_ratio[ok], d.omega[ok]])


def direct_states(shape: str, alpha1: float, speed: float, n: int, seed: int, **model) -> np.ndarray:
    """(m, 6) rebounded states of the direct model."""
    s = simulate(shape, alpha1, speed, n, seed=seed, **model)
    ok = s.rebounded
    return np.column_stack([s.alpha2[ok], s.beta2[ok], s.speed_ratio[ok], s.omega[ok]])


def compare(T: np.ndarray, D: np.ndarray, joint: bool = True, seed: int = 0) -> dict:
    """KS per marginal, classifier accuracy (if ``joint``), moments of table (T) vs direct (D) states."""
    result = {"ks": {name: float(ks_2samp(T[:, i], D[:, i]).statistic) for i, name in enumerate(STATE_NAMES)},
              "mean_table": T.mean(axis=0), "mean_direct": D.mean(axis=0),
              "std_table": T.std(axis=0), "std_direct": D.std(axis=0),
              "corr_table": np.corrcoef(T.T), "corr_direct": np.corrcoef(D.T)}
    if joint:
        result["classifier_accuracy"] = classifier_accuracy(T, D, seed)
    return result
