"""Do two samples of rebounds follow one law? The incident states and statistics of the direct model's law
tests (tests/surrogate/test_direct_law.py: numba's run-time kernel against ``tablegen simulate``;
tests/native/test_native_direct_law.py: the C library's kernel against both).

A state is given in the model frame (shape, α1, |V⁻|, Ω⁻a/|V⁻|) and run in a random caller's frame; the
outputs are rotated back. Compared per state, over the rebounded particles:

* KS: the largest two-sample statistic over the six components of V⁺/|V⁻| and Ω⁺a/|V⁻|. Under one law
  each exceeds c·√((n+m)/(nm)) with probability at most α', c = √(−ln(α'/2)/2) (Kolmogorov's asymptotic
  tail, which bounds the exact one at these n); α' = FAMILY_ALPHA / (number of comparisons a test module
  makes), so that all of them pass together with probability ≥ 1 − FAMILY_ALPHA (Bonferroni).
* Classifier: :func:`tablegen.study.solver_comparison.classifier_accuracy` (gradient boosting, held-out half) on
  (α2, β2, s, Ω⁺a/|V⁻|), on the first min(n, m) rows of each sample so that guessing scores 0.5. Under one
  law the held-out accuracy over n_test rows has mean 0.5 and standard deviation √(0.25/n_test); the bound
  is 0.5 + z·√(0.25/n_test), z = Φ⁻¹(1 − α'), α' as above (one-sided).
* The trapped fractions: within 4 standard deviations of their difference (binomial).
"""

import math

import numpy as np
from scipy import stats
from scipy.spatial.transform import Rotation

import surrogate
from data_schema.samples import STATUS_REBOUNDED, STATUS_TRAPPED, rebound_angles
from direct_model.simulate import simulate
from tablegen.study import solver_comparison
from tablegen.study.solver_comparison import classifier_accuracy

FAMILY_ALPHA = 1e-3         # probability that one law fails any comparison of a test module
N = 4000                    # particles per sample
A = 2e-4                    # half-size, m (results do not depend on it: docs/model.md §7)

# (shape, α1 deg, |V⁻| m/s, Ω⁻a/|V⁻| in the model frame): every shape at |Ω⁻|a/|V⁻| ∈ {0, 0.02, 0.3, 1.0},
# Ω⁻ along ex, n (= ey), ez and between them, 60–280 m/s
STATES = [
    ("ellipsoid", 30.0, 150.0, (0.0, 0.0, 0.0)),
    ("prism", 45.0, 200.0, (0.0, 0.0, 0.0)),
    ("cut_prism", 70.0, 100.0, (0.0, 0.0, 0.0)),
    ("tetrahedron", 20.0, 250.0, (0.0, 0.0, 0.0)),
    ("ellipsoid", 75.0, 100.0, (0.0, 0.02, 0.0)),
    ("prism", 45.0, 200.0, (0.02, 0.0, 0.0)),
    ("cut_prism", 20.0, 150.0, (0.012, 0.0, -0.016)),
    ("tetrahedron", 85.0, 270.0, (0.0, 0.0, 0.02)),
    ("ellipsoid", 60.0, 80.0, (0.0, 0.0, -0.3)),
    ("prism", 45.0, 200.0, (0.18, 0.0, -0.24)),
    ("cut_prism", 35.0, 280.0, (0.0, 0.3, 0.0)),
    ("tetrahedron", 75.0, 120.0, (0.3, 0.0, 0.0)),
    ("ellipsoid", 50.0, 220.0, (0.6, 0.0, 0.8)),
    ("prism", 25.0, 60.0, (0.0, -1.0, 0.0)),
    ("cut_prism", 80.0, 180.0, (-0.48, 0.6, 0.64)),
    ("tetrahedron", 40.0, 160.0, (0.0, 0.8, -0.6)),
]


def state_id(state) -> str:
    shape, alpha1, speed, omega = state
    return f"{shape}-{alpha1:g}deg-{speed:g}-spin{math.hypot(*omega):g}"


def ks_bound(n: int, m: int, comparisons: int) -> float:
    """The KS statistic's bound for samples of n and m draws, one of ``comparisons`` (module doc)."""
    return solver_comparison.ks_bound(n, m, FAMILY_ALPHA / comparisons)


def classifier_bound(n_test: int, comparisons: int) -> float:
    """The held-out accuracy's bound over n_test rows, one of ``comparisons`` (module doc)."""
    return solver_comparison.classifier_bound(n_test, FAMILY_ALPHA / comparisons)


def random_frame(seed: int) -> np.ndarray:
    """A random rotation Q (caller's axes = Q · model axes)."""
    return Rotation.random(random_state=seed).as_matrix()


def frame_of(state) -> np.ndarray:
    """The caller's frame a state runs in (fixed per state)."""
    shape, alpha1, speed, _ = state
    return random_frame(len(shape) + int(alpha1) + int(speed))


def incident(alpha1, speed, omega_in, Q):
    """A hit given in the model frame, in the caller's frame Q: V⁻ (m/s), n, Ω⁻ (rad/s) for a = A."""
    t = math.radians(alpha1)
    V = Q @ np.array([math.cos(t), -math.sin(t), 0.0]) * speed
    return V, Q[:, 1].copy(), Q @ np.asarray(omega_in, dtype=float) * speed / A


def to_model_frame(V_out, W_out, Q, speed):
    """Outputs (N, 3) in the caller's frame Q back to the model frame: V⁺/|V⁻|, Ω⁺a/|V⁻|."""
    return V_out @ Q / speed, W_out @ Q * A / speed


def kernel_in_frame(table, shape, alpha1, speed, omega_in, Q, seed, n=N):
    """``surrogate.sample_direct`` at one incident state given in the model frame, run in the caller's frame Q;
    outputs rotated back to the model frame: (V⁺/|V⁻|, Ω⁺a/|V⁻|, status)."""
    V, normal, W = incident(alpha1, speed, omega_in, Q)
    hits = surrogate.sample_direct(table, np.tile(V, (n, 1)), normal, A, shape, random_state=seed, omega=W)
    Vo, Wo, status = hits.V, hits.Omega, hits.status
    return (*to_model_frame(Vo, Wo, Q, speed), status)


def simulated(shape, alpha1, speed, omega_in, seed, n=N):
    """``tablegen simulate`` (direct_model.simulate) at the state, model frame: (V⁺/|V⁻|, Ω⁺a/|V⁻|, status)."""
    ref = simulate(shape, alpha1, speed, n, seed=seed, omega_in=omega_in)
    return ref.velocity / speed, ref.omega, ref.status


def one_law(mine, theirs, comparisons: int) -> dict:
    """The statistics of two samples (V⁺/|V⁻|, Ω⁺a/|V⁻|, status), each in the model frame, and their bounds
    for a test module making ``comparisons`` comparisons of each kind (module doc)."""
    (V1, W1, s1), (V2, W2, s2) = mine, theirs
    ok1, ok2 = s1 == STATUS_REBOUNDED, s2 == STATUS_REBOUNDED
    n, m = int(ok1.sum()), int(ok2.sum())
    X1, X2 = np.column_stack([V1[ok1], W1[ok1]]), np.column_stack([V2[ok2], W2[ok2]])
    ks = max(stats.ks_2samp(X1[:, k], X2[:, k]).statistic for k in range(6))
    rows = min(n, m)
    features = []
    for V, W in ((V1[ok1][:rows], W1[ok1][:rows]), (V2[ok2][:rows], W2[ok2][:rows])):
        alpha2, beta2, s = rebound_angles(V)
        features.append(np.column_stack([alpha2, beta2, s, W]))
    accuracy = classifier_accuracy(*features, seed=0)
    n_test = rows                       # the held-out half of 2·rows
    t1, t2 = np.mean(s1 == STATUS_TRAPPED), np.mean(s2 == STATUS_TRAPPED)
    p = (t1 + t2) / 2
    return {"ks": float(ks), "ks_bound": ks_bound(n, m, 6 * comparisons), "accuracy": accuracy,
            "accuracy_bound": classifier_bound(n_test, comparisons), "n": n, "m": m,
            "trapped": (float(t1), float(t2)),
            "trapped_bound": 4 * math.sqrt(p * (1 - p) * (1 / len(s1) + 1 / len(s2))) + 1e-12}


def assert_one_law(result: dict) -> None:
    assert result["ks"] < result["ks_bound"], result
    assert result["accuracy"] < result["accuracy_bound"], result
    assert abs(result["trapped"][0] - result["trapped"][1]) <= result["trapped_bound"], result
