"""Shapes and mass properties (docs/model.md §3) against closed forms."""

import numpy as np
import pytest
from scipy import stats

from direct_model.shape_arrays import KIND_ELLIPSOID, KIND_POLYHEDRON, bounding_radius, scanned_hull
from direct_model.shapes import (
    AspectRatioLaw, body_vertices, polyhedron_mass_properties,
    second_moment_factor, shape_code, shape_vertices, MAX_VERTICES,
)

RNG = np.random.default_rng(20261121)
SEMI_AXES = [tuple(x) for x in RNG.uniform(0.2, 3.0, size=(5, 3))]


@pytest.mark.parametrize("abc", SEMI_AXES)
def test_box_mass_properties_match_closed_form(abc):
    a, b, c = abc
    vol, centroid, K = polyhedron_mass_properties(shape_vertices("prism", a, b, c))
    assert vol == pytest.approx(8 * a * b * c, rel=1e-12)
    np.testing.assert_allclose(centroid, 0.0, atol=1e-12 * a)
    expected = np.diag([b * b + c * c, a * a + c * c, a * a + b * b]) / 3.0
    np.testing.assert_allclose(K, expected, rtol=1e-12, atol=1e-12 * a * a)


@pytest.mark.parametrize("hand", [1, -1])
@pytest.mark.parametrize("abc", SEMI_AXES)
def test_tetrahedron_mass_properties_match_closed_form(abc, hand):
    a, b, c = abc
    vol, centroid, K = polyhedron_mass_properties(shape_vertices("tetrahedron", a, b, c, hand=hand))
    assert vol == pytest.approx(8 * a * b * c / 3, rel=1e-12)   # cube 8abc minus 4 corners of abc·8/6
    np.testing.assert_allclose(centroid, 0.0, atol=1e-12 * a)
    expected = np.diag([b * b + c * c, a * a + c * c, a * a + b * b]) / 5.0
    np.testing.assert_allclose(K, expected, rtol=1e-12, atol=1e-12 * a * a)


def _cut_cube_factor(kappa):
    """s(κ) of the unit cut cube by direct integration: cube minus 8 corner simplices.

    Corner (1,1,1) loses {u, v, w ≥ 0, u + v + w < κ} with x = 1 − u:
    volume κ³/6 and ∫x² = ∫(1 − u)² = κ³/6 − 2κ⁴/24 + κ⁵/60.
    """
    moment = 8.0 / 3.0 - 8.0 * (kappa ** 3 / 6 - kappa ** 4 / 12 + kappa ** 5 / 60)
    volume = 8.0 - 8.0 * kappa ** 3 / 6
    return moment / volume


@pytest.mark.parametrize("kappa", [0.05, 0.3, 0.5, 0.9])
def test_cut_prism_factor_matches_direct_integration(kappa):
    assert second_moment_factor("cut_prism", kappa) == pytest.approx(_cut_cube_factor(kappa), rel=1e-12)


@pytest.mark.parametrize("abc", SEMI_AXES)
def test_cut_prism_scaling_law(abc):
    """J/m of a stretched cut prism = s(κ)·(b²+c², a²+c², a²+b²), no products of inertia."""
    a, b, c = abc
    kappa = 0.3
    vol, centroid, K = polyhedron_mass_properties(shape_vertices("cut_prism", a, b, c, kappa=kappa))
    s = second_moment_factor("cut_prism", kappa)
    np.testing.assert_allclose(centroid, 0.0, atol=1e-12 * a)
    np.testing.assert_allclose(K, s * np.diag([b * b + c * c, a * a + c * c, a * a + b * b]),
                               rtol=1e-12, atol=1e-12 * a * a)
    assert vol == pytest.approx(8 * a * b * c * (1 - kappa ** 3 / 6), rel=1e-12)


def test_cut_prism_tends_to_prism():
    errors = [abs(second_moment_factor("cut_prism", k) - 1.0 / 3.0) for k in (0.1, 0.05, 0.025)]
    # leading term of the removed moment is O(κ³): halving κ divides the error by ~8
    assert errors[0] / errors[1] == pytest.approx(8.0, rel=0.1)
    assert errors[1] / errors[2] == pytest.approx(8.0, rel=0.05)
    assert second_moment_factor("cut_prism", 0.0) == pytest.approx(1.0 / 3.0, rel=1e-14)


def test_vertex_counts_and_bounding_radius():
    out = np.empty((MAX_VERTICES, 3))
    a, b, c = 1.0, 0.7, 0.4
    for name, count, radius in [("prism", 8, np.sqrt(a * a + b * b + c * c)),
                                ("tetrahedron", 4, np.sqrt(a * a + b * b + c * c)),
                                ("cut_prism", 24, np.sqrt(a * a + b * b + (0.7 * c) ** 2))]:
        n = body_vertices(shape_code(name), a, b, c, 0.3, 1.0, out)
        assert n == count
        assert len(np.unique(out[:n], axis=0)) == count
        assert bounding_radius(KIND_POLYHEDRON, np.array([a, b, c]), out, n, scanned_hull(out)) == pytest.approx(
            radius, rel=1e-15)
    assert bounding_radius(KIND_ELLIPSOID, np.array([a, b, c]), out, 0, scanned_hull(out)) == a


def test_tetrahedron_hands_are_mirror_images():
    right = shape_vertices("tetrahedron", 1.0, 0.8, 0.6, hand=1)
    left = shape_vertices("tetrahedron", 1.0, 0.8, 0.6, hand=-1)
    np.testing.assert_array_equal(left, right * np.array([1.0, 1.0, -1.0]))
    # no proper rotation maps one onto the other: signed volumes of the vertex order differ
    det = lambda v: np.linalg.det(v[1:] - v[0])   # noqa: E731
    assert det(right) == pytest.approx(-det(left))


def test_aspect_ratio_law_is_the_truncated_normal():
    law = AspectRatioLaw()
    n = 40_000
    x = law.sample(np.random.default_rng(1), n)
    assert x.shape == (n, 2)
    assert x.min() >= 0.5 and x.max() <= 1.0
    ref = stats.truncnorm((0.5 - 0.8) / 0.2, (1.0 - 0.8) / 0.2, loc=0.8, scale=0.2)
    for col in x.T:
        # KS p-value below 1e-3 would mean a different law (fixed seed: deterministic)
        assert stats.kstest(col, ref.cdf).pvalue > 1e-3
    # the two ratios are independent: correlation within 4 standard errors (1/√n) of 0
    assert abs(np.corrcoef(x.T)[0, 1]) < 4 / np.sqrt(n)


@pytest.mark.parametrize("kwargs, word", [({"low": 0.0}, "low"), ({"high": 1.2}, "high"),
                                          ({"sd": 0.0}, "sd"), ({"mean": np.nan}, "mean")])
def test_aspect_ratio_law_rejects_bad_parameters(kwargs, word):
    with pytest.raises(ValueError, match=word):
        AspectRatioLaw(**kwargs)


def test_bad_shape_and_kappa():
    with pytest.raises(ValueError, match="'shape'.*ellipsoid, prism, cut_prism, tetrahedron"):
        shape_code("sphere")
    with pytest.raises(ValueError, match=r"'kappa'.*\[0, 1\)"):
        shape_vertices("cut_prism", kappa=1.0)
