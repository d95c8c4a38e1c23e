"""A user's grain in the direct model (docs/model.md §9): a mesh of a family's body rebounds as the family does,
and a moved, turned and rescaled copy of a grain's file rebounds as the grain does.

Per-particle comparisons: the same orientations and the same draws, so two bodies that are one body up to
round-off give the same rebound up to round-off, but for the rare particle whose collision sequence amplifies a
last-bit difference (a tie between vertices decided the other way, say); the law is compared too, by KS per
component with the bound of tests/helpers/direct_law.py (Bonferroni over the comparisons of this module).
"""

import numpy as np
import pytest
from scipy import stats
from scipy.spatial.transform import Rotation

from data_schema.samples import STATUS_REBOUNDED
from direct_model.body_rebound import body_rebound_batch
from direct_model.registry import grain
from direct_model.shape_arrays import family_shape_arrays, shape_arrays
from direct_model.shapes import SHAPES, AspectRatioLaw, second_moment_factors, shape_vertices
from direct_model.simulate import (DEFAULT_CONTACT_TOL, DEFAULT_MAX_STEPS, DEFAULT_N_MAX, DEFAULT_SET_TOL,
                                   incident_velocity, simulate)
from direct_model.wall import CORUNDUM_ON_STEEL
from tablegen.tabulation.grain_files import convex_hull

from tests.helpers.direct_law import ks_bound
from tests.helpers.grains import cloud_grain

N = 4000
RATIOS = (0.8, 0.7)                 # b/a, c/b of the family's body and of its mesh
COMPARISONS = 3 * 2 * 6 + 6         # KS comparisons here: 3 meshes at 2 states and a moved grain, 6 components each


def _batch(arrays, shape, hands, quats, alpha1, omega):
    """body_rebound_batch for every particle at (α1, 150 m/s), Ω⁻ = ``omega`` |V⁻|/a: (V⁺, Ω⁺, status)."""
    n = len(quats)
    speed = 150.0
    out = [np.empty((n, 3)), np.empty((n, 3)), np.empty(n), np.empty(n, np.int32), np.empty(n, np.int8),
           np.empty(n, np.int8), np.empty(n, np.int32), np.empty(n, np.int32), np.empty(n), np.empty(n)]
    body_rebound_batch(arrays, np.full(n, shape, np.int8), np.tile(RATIOS, (n, 1)), hands, quats,
                       incident_velocity(alpha1, speed), np.asarray(omega, dtype=float) * speed,
                       CORUNDUM_ON_STEEL.as_array(), DEFAULT_N_MAX, DEFAULT_CONTACT_TOL, DEFAULT_SET_TOL,
                       DEFAULT_MAX_STEPS, *out)
    return out[0] / speed, out[1] / speed, out[4]


def _same_rebounds(one, other, comparisons):
    """Nearly every particle the same rebound (1e-9 of |V⁻|), and one law (KS per component, bound from n)."""
    (V1, W1, s1), (V2, W2, s2) = one, other
    ok = (s1 == STATUS_REBOUNDED) & (s2 == STATUS_REBOUNDED)
    same = np.all(np.abs(np.hstack([V1 - V2, W1 - W2])[ok]) < 1e-9, axis=1)
    assert (s1 == s2).mean() > 0.99 and same.mean() > 0.99, (same.mean(), (s1 == s2).mean())
    a, b = s1 == STATUS_REBOUNDED, s2 == STATUS_REBOUNDED
    bound = ks_bound(a.sum(), b.sum(), comparisons)
    for X, Y in ((V1, V2), (W1, W2)):
        for k in range(3):
            assert stats.ks_2samp(X[a, k], Y[b, k]).statistic < bound
    return same.mean()


@pytest.mark.parametrize("name", ["prism", "cut_prism", "tetrahedron"])
def test_a_mesh_of_a_family_s_body_rebounds_as_the_family(name):
    """The hull of the family's body at b/a = 0.8, c/b = 0.7 given as a grain of fixed proportions (its
    canonical frame, its own vertex order and mass properties) against the family at those ratios, the same
    orientations, hands and incident states (Ω⁻ = 0 and spinning)."""
    vertices = shape_vertices(name, 1.0, RATIOS[0], RATIOS[0] * RATIOS[1])
    hull, triangles, _ = convex_hull(vertices, f"{name} mesh")
    mesh = grain(f"{name}_mesh", hull, triangles, both_hands=name == "tetrahedron")
    families = family_shape_arrays(0.3, AspectRatioLaw(), second_moment_factors(0.3))
    rng = np.random.default_rng(SHAPES.index(name))
    quats = rng.normal(size=(N, 4))
    hands = np.where(rng.random(N) < 0.5, 1, -1).astype(np.int8) if name == "tetrahedron" else np.ones(N, np.int8)
    for alpha1, omega in ((40.0, (0.0, 0.0, 0.0)), (70.0, (0.1, -0.3, 0.2))):
        family = _batch(families, SHAPES.index(name), hands, quats, alpha1, omega)
        given = _batch(shape_arrays([mesh]), 0, hands, quats, alpha1, omega)
        _same_rebounds(family, given, COMPARISONS)


def test_a_moved_copy_of_a_grain_is_the_same_grain_and_rebounds_alike():
    """A grain's points turned, shifted by a few sizes and scaled by 37: the same canonical vertices (1e-12 of a)
    and, with the same seed, the same rebounds from simulate (a law per grain, both hands)."""
    law = AspectRatioLaw(0.85, 0.1, 0.6, 1.0)
    original = cloud_grain("sand", 400, seed=5, aspect=law, both_hands=True)
    turn = Rotation.random(random_state=6).as_matrix()
    moved_points = (original.vertices @ turn.T + np.array([3.0, -7.0, 2.5])) * 37.0
    hull, triangles, _ = convex_hull(moved_points, "moved")
    moved = grain("sand", hull, triangles, aspect=law, both_hands=True)
    np.testing.assert_allclose(moved.vertices, original.vertices, rtol=0, atol=1e-12)
    runs = [simulate(record, 50.0, 150.0, N, seed=7, omega_in=(0.0, 0.2, 0.1)) for record in (original, moved)]
    assert np.array_equal(runs[0].extra["hand"], runs[1].extra["hand"]) and 0 < (runs[0].extra["hand"] < 0).mean() < 1
    _same_rebounds(*[(r.velocity / r.speed, r.omega, r.status) for r in runs], COMPARISONS)
