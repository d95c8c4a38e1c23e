"""The solver-neutral comparison (tablegen.study.solver_comparison): a solver's hits against surrogate on the
same incident states. The "solver" here is surrogate itself (another seed: one law, every bound met) and the
specular bounce (another law, found); the paired classifier split; the record's checks; the path rule."""

import math

import numpy as np
import pytest

import surrogate
from surrogate.kernels import PATH_DIRECT, PATH_TABLE
from tablegen.study import solver_comparison as sc

N_HITS = 3000
A = 1e-4      # half-size, m


def _hits(table, seed, spinning=True):
    """N_HITS hits at random incident states inside the small table's grid (α1 35–85°, 60–240 m/s, random
    normals), with ``spinning`` every other one spinning (|Ω⁻|a/|V⁻| = 0.5), answered by surrogate with
    method auto: a stand-in for a solver that calls the runtime."""
    rng = np.random.default_rng(seed)
    normal = rng.standard_normal((N_HITS, 3))
    normal /= np.linalg.norm(normal, axis=1)[:, None]
    tangent = np.cross(normal, rng.standard_normal((N_HITS, 3)))
    tangent /= np.linalg.norm(tangent, axis=1)[:, None]
    alpha1 = np.radians(rng.uniform(35.0, 85.0, N_HITS))
    speed = rng.uniform(60.0, 240.0, N_HITS)
    V = (np.cos(alpha1)[:, None] * tangent - np.sin(alpha1)[:, None] * normal) * speed[:, None]
    Omega = np.zeros((N_HITS, 3))
    if spinning:
        Omega[::2] = (np.cross(normal, tangent) * (0.5 * speed / A)[:, None])[::2]
    hits = surrogate.sample_global(table, V, normal, A, shape="mix", random_state=seed,
                                   omega=Omega)
    V_out, Omega_out, status, path = hits.V, hits.Omega, hits.status, hits.path
    return sc.SolverHits(V=V, Omega=Omega, n=normal, a=np.full(N_HITS, A), shape="mix", V_out=V_out,
                         Omega_out=Omega_out, status=status, path=path)


@pytest.fixture(scope="module")
def hits(small_table):
    return _hits(small_table, seed=7)


def test_the_same_law_meets_every_bound_on_both_paths(small_table, hits):
    report = sc.compare_hits(hits, small_table, seed=8)
    # half of the hits spin (the direct model), the others lie inside the grid (the table)
    assert report.hits_per_path == {"table": N_HITS // 2, "direct": N_HITS // 2, "invalid": 0}
    assert set(report.agreement) == {"table", "direct"}
    for name, a in report.agreement.items():
        assert a.ok, (name, a)
        assert a.n_solver > 0.9 * N_HITS // 2 and a.n_reference > 0.9 * N_HITS // 2
        # the grouped split holds out about half of the rows, and the bound follows from n_test
        assert abs(a.classifier_n_test - (a.n_solver + a.n_reference) / 2) < 0.1 * a.n_solver
        assert a.classifier_bound == pytest.approx(sc.classifier_bound(a.classifier_n_test, sc.FAMILY_ALPHA / 2))
    assert report.ok and report.as_dict()["ok"]
    assert "table path: solver vs surrogate" in report.lines()
    # surrogate's answers took the solver's paths, row for row
    np.testing.assert_array_equal(report.answers.path, hits.path)


def test_a_solver_bouncing_specularly_is_found(small_table, hits):
    specular = sc.specular_answers(hits)
    report = sc.compare_hits(specular, small_table, seed=8, classifier=False)
    a = report.agreement["table"]
    # s = 1 exactly against the model's s ≈ 0.4–0.8, β2 = 0 against a spread: KS near 1, far above the bound
    assert a.ks["speed_ratio"] > 0.9 and a.ks["beta2"] > 0.3, a
    assert not a.ks_ok and not report.ok
    assert math.isnan(a.classifier_accuracy) and a.classifier_ok


def test_grouped_split_keeps_a_paired_sample_at_chance():
    """Two samples that share their incident states row for row (a solver's hits and a redraw on the same
    states) and the same law. Split row by row, the classifier learns each training row's incident state
    with its label and gives the twin in the test half the other label: below chance. Split by hit, it
    scores chance. n_test = N pairs (2N rows, half held out): chance's standard error √(0.25/N) = 0.0079;
    the bounds are 3 of them (a false alarm rate of 1e-3 each)."""
    rng = np.random.default_rng(3)
    n = 4000
    incident = rng.uniform(0.0, 1.0, (n, 2))
    law = lambda: incident[:, :1] + 0.3 * rng.standard_normal((n, 1))       # noqa: E731  one law per state
    X, Y = np.column_stack([incident, law()]), np.column_stack([incident, law()])
    se = math.sqrt(0.25 / n)
    row_by_row = sc.classifier_accuracy(X, Y, seed=0)
    grouped = sc.classifier_accuracy(X, Y, seed=0, groups=np.r_[np.arange(n), np.arange(n)])
    assert row_by_row < 0.5 - 3 * se, row_by_row
    assert abs(grouped - 0.5) < 3 * se, grouped


def test_bounds_follow_the_stated_formulas():
    # c(α = 1e-3) = √(−ln(5e-4)/2) = 1.9495; z(1e-3) = 3.0902
    assert sc.ks_bound(100, 100, 1e-3) == pytest.approx(1.9495 * math.sqrt(2 / 100), rel=1e-4)
    assert sc.classifier_bound(2500, 1e-3) == pytest.approx(0.5 + 3.0902 * 0.01, rel=1e-4)


def test_path_rule_counts_hits_the_wrong_path_answered(small_table, hits):
    rule = sc.path_rule(hits, small_table)
    assert rule["spinning"] == N_HITS // 2 and rule["still_inside"] == N_HITS // 2 and rule["outside"] == 0
    assert rule["spinning_not_direct"] == rule["still_inside_not_table"] == 0
    swapped = sc.SolverHits(**{**vars(hits), "path": np.where(hits.path == PATH_TABLE, PATH_DIRECT, PATH_TABLE)})
    rule = sc.path_rule(swapped, small_table)
    assert rule["spinning_not_direct"] == rule["still_inside_not_table"] == N_HITS // 2


def test_per_hit_shapes_are_redrawn_shape_by_shape(small_table):
    """One shape name per hit: surrogate answers each hit with its own shape."""
    hits = _hits(small_table, seed=9, spinning=False)
    names = np.array(["prism", "tetrahedron"], dtype=object)[np.arange(N_HITS) % 2]
    per_hit = sc.SolverHits(**{**vars(hits), "shape": names})
    answers = sc.surrogate_answers(small_table, per_hit, seed=1)
    prism = surrogate.sample_global(small_table, hits.V[::2], hits.n[::2], A, shape="prism",
                                    random_state=np.random.default_rng(1), method="table", clamp=True)
    assert np.all(hits.path == PATH_TABLE)
    np.testing.assert_array_equal(answers.V_out[::2], prism.V)


def test_grain_keys_are_drawn_as_the_particles_grains(small_table):
    """Hits of keyed particles (grain kept): surrogate answers each as its particle's grain, the bits of
    sample_global with the same keys; the keys' shapes differ from the unkeyed draw's."""
    hits = _hits(small_table, seed=9, spinning=False)
    keys = surrogate.grain_key(5, 0, np.arange(N_HITS) // 3)        # three hits per particle
    keyed = sc.SolverHits(**{**vars(hits), "grain_key": keys})
    answers = sc.surrogate_answers(small_table, keyed, seed=1)
    reference = surrogate.sample_global(small_table, hits.V, hits.n, A, shape="mix", method="table", clamp=True,
                                        random_state=np.random.default_rng(1), grain_key=keys)
    assert np.all(hits.path == PATH_TABLE)
    np.testing.assert_array_equal(answers.V_out, reference.V)
    assert not np.array_equal(answers.V_out, sc.surrogate_answers(small_table, hits, seed=1).V_out)
    # take keeps the keys row for row, and a record without them stays without
    np.testing.assert_array_equal(keyed.take(slice(3, 9)).grain_key, keys[3:9])
    assert hits.take(slice(3, 9)).grain_key is None


@pytest.mark.parametrize("field, value", [("V", np.zeros((3, 3))), ("a", np.zeros((N_HITS, 1))),
                                          ("shape", np.array(["prism"] * 3, dtype=object)),
                                          ("grain_key", np.arange(3)), ("grain_key", np.full(N_HITS, -1)),
                                          ("grain_key", np.zeros(N_HITS))])
def test_a_record_without_one_row_per_hit_is_refused(hits, field, value):
    with pytest.raises(ValueError, match=f"SolverHits.{field} must"):
        sc.SolverHits(**{**vars(hits), field: value})
