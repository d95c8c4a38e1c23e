"""Contact ties (docs/model.md §4.5) in the numba kernel: a face or an edge exactly down with Ω⁻ = 0 gives one
collision at the centroid of its vertices, and V⁺, Ω⁺ of the closed form.

Closed form (docs/model.md §4 with Ω⁻ = 0, so V_c = V; lab frame, units of a, m/s): a_nc = 1 − [1 − exp(−k|V|^p)]
|v|/|V|, C_f = exp(q cos γ) with cos γ = r_c·V/(|r_c||V|), μ = C_f/|V|; ΔV_c = G ΔV_p with G = I − [r_c]× K⁻¹ [r_c]×;
ΔΩ = K⁻¹(r_c × ΔV_p). For r_c = (0, −h, 0), directly below the centre: r_c × e_y = 0, so G e_y = e_y and the normal
law gives λ = Δv_p = Δv_c = −(1 + a_nc) v at once, with cos γ = |v|/|V|; the tangential laws
Δu_p = −μλ(u + ½Δu_c), Δw_p = −μλ(w + ½Δw_c) are then linear: ΔV_t = −μλ (I + ½μλ G_tt)⁻¹ V_t (t = x, z),
G_tt = I + h² [[K⁻¹_zz, −K⁻¹_zx], [−K⁻¹_xz, K⁻¹_xx]]. Principal axes along the lab axes (a box face down):
Δu_p = −μλu / (1 + ½μλ(1 + h²/K_z)), Δw_p = 0, Ω⁺ = (0, 0, h Δu_p/K_z) (friction tips the body forward);
at α1 = 90° (u = 0) there is no tangential impulse, V⁺ = (0, −a_nc v, 0) and Ω⁺ = 0. A contact point not below
the centre (an edge or face off the centre's vertical) couples λ with the tangential impulse: the same equations
are solved by tests.helpers.ties.reference in 40-digit arithmetic (a 2 × 2 tangential solve per trial λ,
bisection on the normal law), independently of the kernels' cubic.

Tolerance: 1e-12 |V⁻| on V⁺ and 1e-12 |V⁻|/a on Ω⁺. The kernel polishes λ to round-off, and its inputs (the
centroid of the tied vertices, K in the lab frame, a_nc, C_f) differ from the reference's by a few ulps, which the
well-conditioned solve keeps near 1e-15; the contact point moved to one vertex of the face or edge changes V⁺ or
Ω⁺ by 0.09 |V⁻| or more in these states.
"""

import numpy as np
import pytest

from data_schema.samples import STATUS_REBOUNDED
from tests.helpers.ties import MIRROR, SET_TOL, WALL, below_centre, expected, heights, lowest, rebound, tie_states

STATES = tie_states()
BELOW = [s for s in STATES if np.abs(s.r_c[[0, 2]]).max() <= 1e-15]       # the centre right above r_c
OFF_CENTRE = [s for s in STATES if np.abs(s.r_c[[0, 2]]).max() > 1e-15]
SYMMETRIC = [s for s in STATES if s.mirrors]
BOX_FACES = [s for s in STATES if s.name.startswith("box_face")]


def _ids(states):
    return [s.name for s in states]


def _close(V, W, V_ref, W_ref, speed):
    """V⁺ (m/s) and Ω⁺ ((m/s)/a) within 1e-12 |V⁻| of the expected values (module doc)."""
    np.testing.assert_allclose(V, V_ref, rtol=0.0, atol=1e-12 * speed)
    np.testing.assert_allclose(W, W_ref, rtol=0.0, atol=1e-12 * speed)


def test_the_states_cover_every_tie():
    """Edges and faces of 3 to 6 vertices; the box, the tetrahedron, the cut prism and a user's grain each at
    α1 = 90° and below, every face or edge below 90°; exact ties and ties to round-off."""
    assert {len(s.contact) for s in STATES} == {2, 3, 4, 5, 6}
    family = {s.name.split("-")[0]: s.source[0] if isinstance(s.source[0], str) else "grain" for s in STATES}
    assert {family[s.name.split("-")[0]] for s in STATES if s.V[0] == 0.0} == set(family.values()) == {
        "prism", "tetrahedron", "cut_prism", "grain"}
    assert {s.name.split("-")[0] for s in STATES if s.V[0] > 0.0} == set(family)
    spreads = [np.ptp(heights(s.body.vertices, s.R)[list(s.contact)]) for s in STATES]
    assert min(spreads) == 0.0 < max(spreads)


@pytest.mark.parametrize("s", STATES, ids=_ids(STATES))
def test_the_face_or_edge_is_exactly_down(s):
    """The contact set the kernel forms (heights g·p, within set_tol = 1e-9 a of the lowest) is exactly the face's or
    edge's vertices: their heights agree to round-off (1e-15 a), every other vertex is at least 0.2 a higher."""
    tied, gap = lowest(s.body.vertices, s.R, SET_TOL)
    assert tied == s.contact and len(tied) >= 2
    assert np.ptp(heights(s.body.vertices, s.R)[list(tied)]) <= 1e-15
    assert gap >= 0.2


@pytest.mark.parametrize("s", STATES, ids=_ids(STATES))
def test_one_collision_at_the_centroid(s):
    """The body rebounds after one collision, with V⁺ and Ω⁺ of the collision at the centroid of the tied vertices
    (the reference solution, module doc)."""
    V, W, status, n_collisions = rebound(s)
    assert status == STATUS_REBOUNDED and n_collisions == 1
    _close(V, W, *expected(s), np.linalg.norm(s.V))


@pytest.mark.parametrize("s", BELOW, ids=_ids(BELOW))
def test_below_the_centre_the_closed_form(s):
    """A face or a balanced edge with the centre of mass right above its centre: the closed form (module doc),
    which the reference reproduces."""
    speed = np.linalg.norm(s.V)
    V_ref, W_ref = below_centre(s.V, -s.r_c[1], s.K_lab)
    _close(*expected(s), V_ref, W_ref, speed)
    V, W, _, _ = rebound(s)
    _close(V, W, V_ref, W_ref, speed)


@pytest.mark.parametrize("s", BOX_FACES, ids=_ids(BOX_FACES))
def test_a_box_face_in_closed_form(s):
    """A box face down, principal axes along the lab axes, r_c = (0, −h, 0) exactly: λ = −(1 + a_nc) v,
    Δu_p = −μλu/(1 + ½μλ(1 + h²/K_z)), w⁺ = 0, Ω⁺ = (0, 0, hΔu_p/K_z) (module doc)."""
    u, v, _ = s.V
    speed = np.linalg.norm(s.V)
    h, K_z = -s.r_c[1], s.K_lab[2, 2]
    assert s.r_c[0] == 0.0 and s.r_c[2] == 0.0
    a_nc = 1.0 - (1.0 - np.exp(-WALL.k * speed ** WALL.p)) * (-v / speed)
    lam = -(1.0 + a_nc) * v
    mu = np.exp(WALL.q * -v / speed) / speed
    du = -mu * lam * u / (1.0 + 0.5 * mu * lam * (1.0 + h * h / K_z))
    V, W, _, _ = rebound(s)
    _close(V, W, [u + du, v + lam, 0.0], [0.0, 0.0, h * du / K_z], speed)


@pytest.mark.parametrize("s", SYMMETRIC, ids=_ids(SYMMETRIC))
def test_a_symmetric_state_gives_exact_zeros(s):
    """A state that is its own mirror image gives exactly the zeros of that symmetry: in the impact plane (a box
    with a principal axis along Z) w⁺ = Ω_x⁺ = Ω_y⁺ = 0; in the plane YZ (a box face at α1 = 90°, r_c and u⁻ exactly
    0 along X) u⁺ = Ω_y⁺ = Ω_z⁺ = 0: no tangential impulse."""
    V, W, _, _ = rebound(s)
    if "z" in s.mirrors:
        assert V[2] == 0.0 and W[0] == 0.0 and W[1] == 0.0
    if "x" in s.mirrors:
        assert V[0] == 0.0 and W[1] == 0.0 and W[2] == 0.0
        assert V[1] > 0.0


@pytest.mark.parametrize("s", STATES, ids=_ids(STATES))
def test_the_mirror_image_gives_the_mirrored_rebound_exactly(s):
    """The state reflected in the impact plane, the body of hand −1 (for the tetrahedron the other hand; for every
    body its vertices ζ → −ζ row for row) in orientation M R M: one collision, V⁺ → M V⁺ and the pseudovector
    Ω⁺ → −M Ω⁺, to the bit (every operation meets the same magnitudes)."""
    mirrored = s.mirrored()
    assert np.array_equal(mirrored.body.vertices, s.body.vertices * [1.0, 1.0, -1.0])
    assert np.array_equal(mirrored.body.K, s.body.K)
    V, W, _, _ = rebound(s)
    V_m, W_m, status, n_collisions = rebound(mirrored)
    assert status == STATUS_REBOUNDED and n_collisions == 1
    assert np.array_equal(V_m, MIRROR @ V) and np.array_equal(W_m, -(MIRROR @ W))


@pytest.mark.parametrize("s", OFF_CENTRE[::3], ids=_ids(OFF_CENTRE[::3]))
def test_the_reference_solves_the_collision_laws(s):
    """The reference's V⁺, Ω⁺ satisfy docs/model.md §4 at the off-centre contact point: K ΔΩ = r_c × ΔV_p, normal
    restitution of the contact point and the two tangential laws, to 1e-13 |V⁻|."""
    V_ref, W_ref = expected(s)
    speed, r, K = np.linalg.norm(s.V), s.r_c, s.K_lab
    dV, dW = V_ref - s.V, W_ref
    dVc = dV + np.cross(dW, r)
    a_nc = 1.0 - (1.0 - np.exp(-WALL.k * speed ** WALL.p)) * (-s.V[1] / speed)
    mu = np.exp(WALL.q * (r @ s.V) / (np.linalg.norm(r) * speed)) / speed
    tol = 1e-13 * speed
    np.testing.assert_allclose(K @ dW, np.cross(r, dV), rtol=0.0, atol=tol)
    assert dVc[1] == pytest.approx(-(1.0 + a_nc) * s.V[1], abs=tol)
    assert dV[0] == pytest.approx(-mu * dV[1] * (s.V[0] + 0.5 * dVc[0]), abs=tol)
    assert dV[2] == pytest.approx(-mu * dV[1] * (s.V[2] + 0.5 * dVc[2]), abs=tol)
    assert abs(r[0]) + abs(r[2]) > 0.01 and abs(dW).max() > 1e-3 * speed
