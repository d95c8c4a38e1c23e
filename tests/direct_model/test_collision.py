"""One collision (docs/model.md §4): the equations and invariants on random inputs."""

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st
from scipy.spatial.transform import Rotation

from direct_model.collision import (
    COLLISION_FAILED, COLLISION_MULTIPLE_ROOTS, COLLISION_NOT_APPROACHING, COLLISION_OK,
    collide, smallest_positive_root, wall_work,
)
from direct_model.wall import CORUNDUM_ON_STEEL

WALL = CORUNDUM_ON_STEEL.as_array()


def _random_case(seed):
    """A body with random inertia and orientation, an approaching contact below its centre."""
    rng = np.random.default_rng(seed)
    Rm = Rotation.random(random_state=rng).as_matrix()
    K = Rm @ np.diag(rng.uniform(0.05, 0.7, 3)) @ Rm.T
    r = rng.uniform(-1.2, 1.2, 3)
    r[1] = -rng.uniform(0.05, 1.2)
    speed = rng.uniform(50.0, 300.0)
    alpha = rng.uniform(0.02, np.pi / 2)
    V = speed * np.array([np.cos(alpha), -np.sin(alpha), 0.0])
    V[2] = rng.uniform(-0.3, 0.3) * speed
    W = rng.normal(0.0, 0.5, 3) * speed
    return V, W, r, K


def _apply(V, W, r, K):
    dV, dW = np.empty(3), np.empty(3)
    code = collide(V, W, r, np.linalg.inv(K), WALL, dV, dW)
    return code, dV, dW


def _approaching_case(seed):
    V, W, r, K = _random_case(seed)
    if (V + np.cross(W, r))[1] >= 0:       # make the contact point approach
        W = -W
    return V, W, r, K


@settings(max_examples=300, deadline=None)
@given(st.integers(0, 2 ** 32 - 1))
def test_equations_hold(seed):
    V, W, r, K = _approaching_case(seed)
    code, dV, dW = _apply(V, W, r, K)
    assert code in (COLLISION_OK, COLLISION_MULTIPLE_ROOTS)
    Vc = V + np.cross(W, r)
    dVc = dV + np.cross(dW, r)
    speed_c = np.linalg.norm(Vc)
    a_nc = 1 - (1 - np.exp(-0.1 * speed_c ** 0.61)) * abs(Vc[1]) / speed_c
    cf = np.exp(r @ V / (np.linalg.norm(r) * np.linalg.norm(V)))
    scale = np.linalg.norm(V) + np.linalg.norm(W) * np.linalg.norm(r)
    tol = 1e-12 * scale
    np.testing.assert_allclose(K @ dW, np.cross(r, dV), atol=tol)                 # K ΔΩ = r × ΔV
    assert dVc[1] == pytest.approx(-(1 + a_nc) * Vc[1], abs=tol)                   # restitution
    assert dV[0] == pytest.approx(-cf * dV[1] * (Vc[0] + 0.5 * dVc[0]) / speed_c, abs=tol)
    assert dV[2] == pytest.approx(-cf * dV[1] * (Vc[2] + 0.5 * dVc[2]) / speed_c, abs=tol)
    assert dV[1] > 0                                                               # the wall pushes


@settings(max_examples=300, deadline=None)
@given(st.integers(0, 2 ** 32 - 1))
def test_invariants(seed):
    V, W, r, K = _approaching_case(seed)
    code, dV, dW = _apply(V, W, r, K)
    V2, W2 = V + dV, W + dW
    scale = np.linalg.norm(V) + np.linalg.norm(W) * np.linalg.norm(r)
    # angular momentum about the contact point (per unit mass): K Ω − r × V
    np.testing.assert_allclose(K @ W2 - np.cross(r, V2), K @ W - np.cross(r, V), atol=1e-12 * scale)
    # kinetic energy does not increase, and changes by S·(V_c⁻ + V_c⁺)/2
    energy = lambda v, w: 0.5 * v @ v + 0.5 * w @ K @ w  # noqa: E731
    Vc1, Vc2 = V + np.cross(W, r), V2 + np.cross(W2, r)
    change = energy(V2, W2) - energy(V, W)
    assert change == pytest.approx(dV @ (Vc1 + Vc2) / 2, abs=1e-10 * scale ** 2)
    assert change <= 1e-12 * scale ** 2
    # the contact point leaves the wall: v_c⁺ = −a_nc v_c⁻ > 0
    assert Vc2[1] > 0
    # the work on the wall (docs/model.md §4.7): minus the normal and the tangential parts of the change, each ≥ 0
    normal, tangential = wall_work(V, W, r, dV, dW)
    assert normal >= 0.0 and tangential >= 0.0
    assert normal == pytest.approx(-dV[1] * (Vc1[1] + Vc2[1]) / 2, rel=1e-12, abs=1e-13 * scale ** 2)
    assert normal + tangential == pytest.approx(-change, rel=1e-10, abs=1e-12 * scale ** 2)


def test_not_approaching_changes_nothing():
    V, W, r, K = _random_case(3)
    W = W * 0
    V[1] = abs(V[1])
    code, dV, dW = _apply(V, W, r, K)
    assert code == COLLISION_NOT_APPROACHING
    assert not dV.any() and not dW.any()


@pytest.mark.parametrize("speed, alpha_deg", [(50.0, 10.0), (200.0, 45.0), (300.0, 80.0), (150.0, 90.0)])
def test_sphere_closed_form(speed, alpha_deg):
    """Sphere (K = 2/5 a² I), contact r = −a e_y, Ω⁻ = 0, solved by hand.

    G = I − (5/2)[r]×² = diag(7/2, 1, 7/2); λ = Δv_p = (1 + a_nc) v;
    Δu_p (1 + (7/4) C_f λ/|V|) = −C_f λ u/|V|; Δw_p = 0; ΔΩ = (5/2) r × ΔV = (0, 0, 5/2 Δu_p);
    C_f = exp(v/|V|) since r·V = v, with v = |V| sin α1.
    """
    a1 = np.radians(alpha_deg)
    u, v = speed * np.cos(a1), speed * np.sin(a1)
    V, W, r = np.array([u, -v, 0.0]), np.zeros(3), np.array([0.0, -1.0, 0.0])
    code, dV, dW = _apply(V, W, r, 0.4 * np.eye(3))
    a_nc = 1 - (1 - np.exp(-0.1 * speed ** 0.61)) * v / speed
    lam = (1 + a_nc) * v
    cf = np.exp(v / speed)
    du = -cf * lam * u / (speed + 1.75 * cf * lam)
    assert code == COLLISION_OK
    np.testing.assert_allclose(dV, [du, lam, 0.0], rtol=1e-13, atol=1e-13 * speed)
    np.testing.assert_allclose(dW, [0.0, 0.0, 2.5 * du], rtol=1e-13, atol=1e-13 * speed)
    # the work on the wall: v_c = v_p from −v to a_nc v, u_c = u_p + Ω_z a from u to u + 3.5 Δu_p
    normal, tangential = wall_work(V, W, r, dV, dW)
    assert normal == pytest.approx(0.5 * (1.0 - a_nc ** 2) * v ** 2, rel=1e-13)
    assert tangential == pytest.approx(-0.5 * du * (2.0 * u + 3.5 * du), rel=1e-12, abs=1e-13 * speed ** 2)
    assert tangential >= 0.0 and (alpha_deg != 90.0 or tangential < 1e-20 * normal)    # u = |V| cos 90° ~ 1e-14 |V|


def test_root_finder_takes_smallest_of_three_positive_roots():
    # (λ − 1)(λ − 2)(λ − 3)
    root, multiple, ok = smallest_positive_root(-6.0, 11.0, -6.0, 1.0)
    assert ok and multiple
    assert root == pytest.approx(1.0, rel=1e-15)


@settings(max_examples=300, deadline=None)
@given(st.floats(-10, 10), st.floats(-10, 10), st.floats(0.01, 10), st.floats(0.01, 10))
def test_root_finder_against_numpy(c1, c2, c3, minus_c0):
    c0 = -minus_c0
    root, multiple, ok = smallest_positive_root(c0, c1, c2, c3)
    roots = np.roots([c3, c2, c1, c0])
    positive = np.sort(roots[(np.abs(roots.imag) < 1e-7 * (1 + np.abs(roots))) & (roots.real > 0)].real)
    assert ok
    assert root == pytest.approx(positive[0], rel=1e-6, abs=1e-9)
    # the cubic's own residual at the returned root is at round-off level
    assert abs(((c3 * root + c2) * root + c1) * root + c0) <= 1e-12 * (
        abs(c3) * root ** 3 + abs(c2) * root ** 2 + abs(c1) * root + abs(c0))
    if len(positive) == 3 and positive[1] - positive[0] > 1e-3 * positive[2]:
        assert multiple


def test_failure_code_is_reported_not_hidden():
    """A non-finite state cannot be solved: the code says so and nothing changes."""
    V, W, r, K = _approaching_case(5)
    V[0] = np.nan
    code, dV, dW = _apply(V, W, r, K)
    assert code in (COLLISION_FAILED, COLLISION_NOT_APPROACHING)
    assert not dV.any() and not dW.any()
