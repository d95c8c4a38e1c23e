"""The contact search's derivatives (direct_model.flight.lowest_points, curvature) against the exact flight: h' and
h'' of every candidate point match central differences of h and h' along rotation_at's orientation."""

import numpy as np
import pytest

from direct_model.flight import curvature, lowest_points
from direct_model.rotation import ROT_PARAMS_SIZE, rotation_at, rotation_init
from direct_model.shape_arrays import KIND_ELLIPSOID, KIND_POLYHEDRON


def _random_rotation(rng):
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    q *= np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else -q


def _heights(kind, verts, semi, K, params, t, y0, v):
    """h, h', h'' of every candidate at time t (the ellipsoid's support point is found again at t)."""
    R, W = np.empty((3, 3)), np.empty(3)
    rotation_at(params, t, R, W)
    h, h1, curv = np.empty(len(verts)), np.empty(len(verts)), np.empty(3)
    work = verts.copy()
    n = lowest_points(kind, work, len(verts), semi, K, R, W, y0 + v * t, v, h, h1, curv)
    return h[:n], h1[:n], np.array([curvature(kind, work, i, curv) for i in range(n)])


@pytest.mark.parametrize("kind", [KIND_POLYHEDRON, KIND_ELLIPSOID])
def test_rates_and_curvatures_match_central_differences_along_the_flight(kind):
    """Random bodies, spins and times: h' and h'' against the central differences of h and h' with step
    δ = 1e-4 / |Ω|. A difference's error is (δ²/6)·(the next derivative), about 2e-9 of the scale ω^k, plus
    the rounding ε|h|/δ ≈ 2e-12; the bound 1e-6 of the scale leaves a factor of about 500."""
    rng = np.random.default_rng(11 + kind)
    for _ in range(20):
        K = rng.uniform(0.2, 1.0, 3)
        semi = rng.uniform(0.5, 1.0, 3)
        verts = rng.normal(size=(8, 3))
        R0 = _random_rotation(rng)
        omega = rng.normal(size=3)
        ell = R0 @ (K * (R0.T @ omega))
        params = np.zeros(ROT_PARAMS_SIZE)
        rotation_init(K, R0, ell, params)
        w = np.linalg.norm(omega)
        delta = 1e-4 / w
        t = rng.uniform(0.0, 3.0 / w)
        lo, mid, hi = (_heights(kind, verts, semi, K, params, t + s * delta, 2.0, -0.7) for s in (-1, 0, 1))
        for order in range(2):
            difference = (hi[order] - lo[order]) / (2.0 * delta)
            scale = np.max(np.abs(mid[order + 1])) + w ** (order + 1)
            assert np.max(np.abs(difference - mid[order + 1])) <= 1e-6 * scale, (order, difference, mid[order + 1])
