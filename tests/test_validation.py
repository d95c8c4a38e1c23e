"""Table draws against the direct model (fast subset on the session's small table).

Sample sizes: the small table is built from N = 2·10⁴ particles per cell; each
comparison draws n = 2·10⁴ states from the table and m = 2·10⁴ from the direct
model with an independent seed. For a perfect representation the table draws
follow the empirical law of its N build samples, so the two-sample KS
statistic is driven by three independent samples: its 99.9 % quantile is
about 1.95·√(1/N + 1/n + 1/m) = 0.024. The default-table target of the
validation plan, 0.03, leaves 0.006 for the representation itself.
"""

import dataclasses

import numpy as np
import pytest

from tablegen.validation import classifier_accuracy, compare, direct_states, table_states

N_DRAWS = 20_000
KS_TARGET = 0.03


@pytest.mark.parametrize("shape, alpha1, speed", [
    ("prism", 60.0, 150.0), ("tetrahedron", 30.0, 250.0), ("ellipsoid", 90.0, 250.0),
    ("cut_prism", 30.0, 50.0), ("mix", 90.0, 50.0)])
def test_marginals_match_the_direct_model_on_the_grid(small_table, shape, alpha1, speed):
    T = table_states(small_table, shape, alpha1, speed, N_DRAWS, seed=7)
    D = direct_states(shape, alpha1, speed, N_DRAWS, seed=101)
    result = compare(T, D, joint=False)
    worst = max(result["ks"], key=result["ks"].get)
    assert result["ks"][worst] <= KS_TARGET, f"{worst}: KS = {result['ks'][worst]:.4f}"
    # means agree within 5 standard errors of the difference (two samples of ~2e4)
    se = np.sqrt(result["std_table"] ** 2 / len(T) + result["std_direct"] ** 2 / len(D))
    assert np.all(np.abs(result["mean_table"] - result["mean_direct"]) < 5 * se + 1e-12)


def test_two_direct_samples_are_indistinguishable():
    """Calibration of the classifier test: two direct samples score 0.5 within 4 standard errors.

    The test half has 2·10⁴ points, so the standard error of a chance-level
    accuracy is √(0.25/2·10⁴) = 0.0035.
    """
    X = direct_states("prism", 60.0, 150.0, N_DRAWS, seed=1)
    Y = direct_states("prism", 60.0, 150.0, N_DRAWS, seed=2)
    assert abs(classifier_accuracy(X, Y) - 0.5) < 4 * 0.0035


def test_a_table_that_drops_the_alpha2_speed_dependence_is_caught(small_table):
    """A deliberately broken table: s drawn from the wrong α2 bin.

    Reversing the α2-bin axis of the s quantile functions (and spin atoms)
    keeps every marginal but decouples s from α2. The classifier on (α2, s)
    must flag it (intact table measured at 0.526, broken at 0.80), and the
    marginal KS test alone must not be what catches it.
    """
    D = direct_states("prism", 60.0, 150.0, N_DRAWS, seed=101)
    data = small_table.kernel_data
    flip = np.arange(data.speed_q.shape[3])[::-1]
    broken = dataclasses.replace(small_table, kernel_data=data._replace(
        speed_q=np.ascontiguousarray(data.speed_q[:, :, :, flip]),
        spin=np.ascontiguousarray(data.spin[:, :, :, flip])))
    pair = [0, 2]
    intact_T = table_states(small_table, "prism", 60.0, 150.0, N_DRAWS, seed=7)
    broken_T = table_states(broken, "prism", 60.0, 150.0, N_DRAWS, seed=7)
    assert classifier_accuracy(intact_T[:, pair], D[:, pair]) < 0.55
    assert classifier_accuracy(broken_T[:, pair], D[:, pair]) > 0.65
    assert max(compare(broken_T, D, joint=False)["ks"].values()) <= KS_TARGET
