"""The run-time kernel's random inputs and parameters (direct_model.runtime): the same laws as the batch's."""

import math

import numpy as np
import pytest
from scipy import stats
from scipy.special import ndtri

from direct_model.body_rebound import quaternion_to_matrix
from direct_model.runtime import (N_PARAMS, P_CDF_HIGH, P_CDF_LOW, P_KFAC, aspect_ratio, model_parameters,
                                  normal_quantile, uniform_quaternion)
from direct_model.shapes import AspectRatioLaw, second_moment_factors
from direct_model.wall import CORUNDUM_ON_STEEL

LAW = AspectRatioLaw(0.8, 0.2, 0.5, 1.0)


def _params(aspect=LAW, kappa=0.3):
    return model_parameters(aspect, kappa, 1000, CORUNDUM_ON_STEEL, 1e-10, 1e-9, 100_000,
                            second_moment_factors(kappa))


def test_normal_quantile_is_scipy_s_to_round_off():
    p = np.concatenate([np.geomspace(1e-300, 1e-3, 200), np.linspace(1e-3, 1 - 1e-3, 20001),
                        1 - np.geomspace(1e-3, 1e-15, 200)])
    mine = np.array([normal_quantile(x) for x in p])
    np.testing.assert_allclose(mine, ndtri(p), rtol=4e-15, atol=1e-300)


@pytest.mark.parametrize("law", [LAW, AspectRatioLaw(0.6, 0.05, 0.55, 0.9), AspectRatioLaw(0.99, 0.5, 0.3, 1.0)])
def test_aspect_ratio_is_the_batch_s_inverse_cdf(law):
    """The kernel's quantile equals AspectRatioLaw.ppf (the batch's draw) to round-off, so both draw one law."""
    params = _params(law)
    rows = params[:P_CDF_LOW], params[P_CDF_LOW:P_CDF_HIGH + 1]       # the law and its CDF bounds
    u = np.random.default_rng(3).random(20_000)
    mine = np.array([aspect_ratio(*rows, x) for x in u])
    np.testing.assert_allclose(mine, law.ppf(u), rtol=0, atol=1e-14)
    assert mine.min() >= law.low and mine.max() <= law.high


def test_orientation_is_haar():
    """Shoemake's quaternion gives Haar-uniform rotations: the rotation angle θ has CDF (θ − sin θ)/π and each
    column of R is uniform on the sphere (its y component uniform on [−1, 1]). KS at n = 20000; the bound
    1.63/√n is the 1 % critical value of the one-sample KS statistic (fixed seed)."""
    n = 20_000
    u = np.random.default_rng(7).random((n, 3))
    q, R = np.empty(4), np.empty((3, 3))
    theta, y = np.empty(n), np.empty((n, 3))
    for i in range(n):
        uniform_quaternion(u[i, 0], u[i, 1], u[i, 2], q)
        quaternion_to_matrix(q, R)
        theta[i] = math.acos(min(1.0, max(-1.0, (np.trace(R) - 1.0) / 2.0)))
        y[i] = R[1]
    bound = 1.63 / math.sqrt(n)
    assert stats.kstest(theta, lambda t: (t - np.sin(t)) / np.pi).statistic < bound
    for k in range(3):
        assert stats.kstest(y[:, k], stats.uniform(-1.0, 2.0).cdf).statistic < bound


def test_parameters_hold_the_law_and_the_second_moments():
    params = _params()
    assert params.shape == (N_PARAMS,) and not params.flags.writeable
    np.testing.assert_allclose(params[[P_CDF_LOW, P_CDF_HIGH]], stats.norm.cdf([-1.5, 1.0]), rtol=1e-15)
    np.testing.assert_array_equal(params[P_KFAC:P_KFAC + 4], second_moment_factors(0.3))


@pytest.mark.parametrize("change, message", [
    (dict(kappa=1.0), "'kappa' parameter must be in [0, 1); got 1.0"),
    (dict(n_max=0), "'n_max' parameter must be an integer in [1, 2**53); got 0"),
    (dict(contact_tol=0.0), "'contact_tol' parameter must be finite and > 0 (units of a); got 0.0"),
    (dict(second_moment_factors=(0.2, 0.3)), "'second_moment_factors' parameter must be 4 numbers in (0, 1)"),
])
def test_bad_parameters_are_one_line_errors(change, message):
    args = dict(aspect=LAW, kappa=0.3, n_max=1000, wall=CORUNDUM_ON_STEEL, contact_tol=1e-10, set_tol=1e-9,
                max_steps=100_000, second_moment_factors=second_moment_factors(0.3))
    args.update(change)
    with pytest.raises(ValueError) as error:
        model_parameters(**args)
    assert message in str(error.value) and "\n" not in str(error.value)
