"""Whole rebounds (docs/model.md §5, §9): sphere limit, contacts, symmetry, convergence, energy and the angular
momentum about each contact point, for the four families and for user grains (hulls of 8 to 256 vertices)."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from data_schema.samples import STATUS_REBOUNDED, STATUS_TRAPPED
from direct_model.rotation import ROT_PARAMS_SIZE, rotation_at, rotation_init
from direct_model.shape_arrays import KIND_ELLIPSOID

from tests.helpers.grains import hull_grain
from tests.helpers.one_particle import MIRROR, body, random_bodies, rebound_one, run_one

GRAINS = [hull_grain(f"grain_{n}", n, seed=n, both_hands=True) for n in (8, 24, 64, 256)]
BODIES = random_bodies(200, seed=7) + random_bodies(40, seed=8, shapes=GRAINS)


def _name(body_):
    return body_[0] if isinstance(body_[0], str) else body_[0].name


@pytest.mark.parametrize("alpha1", [5.0, 30.0, 60.0, 90.0])
def test_sphere_single_collision_no_scatter(alpha1):
    """A sphere bounces once, in the impact plane, identically for every orientation (closed form)."""
    speed = 200.0
    rng = np.random.default_rng(0)
    results = []
    for _ in range(20):
        R0 = Rotation.from_quat(rng.standard_normal(4)).as_matrix()
        V, W, status, ncoll, _, _ = run_one("ellipsoid", (1.0, 1.0), R0, alpha1=alpha1, speed=speed)
        assert status == STATUS_REBOUNDED and ncoll == 1
        results.append(np.concatenate([V, W]))
    results = np.array(results)
    a1 = np.radians(alpha1)
    u, v = speed * np.cos(a1), speed * np.sin(a1)
    a_nc = 1 - (1 - np.exp(-0.1 * speed ** 0.61)) * v / speed
    lam = (1 + a_nc) * v
    cf = np.exp(v / speed)
    du = -cf * lam * u / (speed + 1.75 * cf * lam)     # derivation in test_collision.py
    expected = [u + du, -v + lam, 0.0, 0.0, 0.0, 2.5 * du]
    np.testing.assert_allclose(results, np.tile(expected, (20, 1)), rtol=1e-12, atol=1e-12 * speed)
    # its work on the wall (docs/model.md §4.7): v_c from −v to a_nc v, u_c = u_p + Ω_z a from u to u + 3.5 Δu_p;
    # at normal impact (u = |V⁻| cos 90°, 1e-14 |V⁻|) no tangential work
    done, _ = rebound_one("ellipsoid", (1.0, 1.0), R0, alpha1=alpha1, speed=speed)
    assert done.wall_work_normal == pytest.approx(0.5 * (1 - a_nc ** 2) * v ** 2, rel=1e-12)
    assert done.wall_work_tangential == pytest.approx(-0.5 * du * (2 * u + 3.5 * du), rel=1e-11,
                                                      abs=1e-13 * speed ** 2)
    assert done.wall_work_tangential >= 0.0
    assert alpha1 != 90.0 or done.wall_work_tangential < 1e-20 * done.wall_work_normal


def _vertex_heights(b, y, R):
    if b.kind == KIND_ELLIPSOID:     # support function
        return np.array([y - np.linalg.norm(b.semi * R[1])])
    return y + b.vertices @ R[1]


@pytest.mark.parametrize("particle", BODIES[:120] + BODIES[200:220], ids=_name)
def test_no_missed_contact_against_fine_time_stepping(particle):
    """Between recorded collisions, no point of the body dips below the wall.

    Each flight is replayed with 4000 uniform time steps from its start to the
    next recorded collision (or, for the last flight, until the centre is above
    the bounding radius): a contact the search had stepped over would show as a
    height below −1e-9 a (far above the 1e-10 a contact tolerance).
    """
    shape, ratios, R0, hand = particle
    V, W, status, ncoll, _, hist = run_one(shape, ratios, R0, alpha1=45.0, omega_in=(0.0, 0.0, 0.3),
                                           hand=hand, history_rows=200)
    assert status == STATUS_REBOUNDED
    b = body(shape, ratios, hand)
    K = b.K
    params = np.empty(ROT_PARAMS_SIZE)
    R, Wt = np.empty((3, 3)), np.empty(3)
    nflights = ncoll + 1
    rb = b.radius
    for k in range(nflights):
        row = hist[k]
        t0, y0, Vk, Wk, Rk = row[0], row[1], row[2:5], row[5:8], row[8:17].reshape(3, 3)
        ell = Rk @ np.diag(K) @ Rk.T @ Wk
        rotation_init(K, Rk, ell, params)
        if k + 1 < nflights:
            t_end = hist[k + 1, 0] - t0
        else:
            assert Vk[1] > 0
            t_end = max(rb - y0, 0.0) / Vk[1]
        lowest = np.inf
        for t in np.linspace(0.0, t_end, 4001)[1:-1]:
            rotation_at(params, t, R, Wt)
            lowest = min(lowest, _vertex_heights(b, y0 + Vk[1] * t, R).min())
        assert lowest > -1e-9, f"flight {k}: body reaches {lowest:.3e} a below the wall"


@pytest.mark.parametrize("particle", BODIES, ids=_name)
def test_mirror_symmetry_per_particle(particle):
    """Reflecting the whole configuration through the impact plane reflects the outcome.

    Body vertex x ↦ P_lab R x = (P_lab R P_body)(P_body x): an achiral body is
    unchanged by P_body, the tetrahedron and a grain change hand. Outcome: w, Ω_x, Ω_y
    change sign (Ω is axial), the rest is equal — to round-off, amplified at
    most ~1e3 times over a rebound's collisions.
    """
    shape, ratios, R0, hand = particle
    omega_in = np.array([0.1, -0.2, 0.3])
    V1, W1, s1, n1, e1, _ = run_one(shape, ratios, R0, alpha1=40.0, omega_in=omega_in, hand=hand)
    chiral = shape == "tetrahedron" or not isinstance(shape, str)
    V2, W2, s2, n2, e2, _ = run_one(shape, ratios, MIRROR @ R0 @ MIRROR, alpha1=40.0,
                                    omega_in=-MIRROR @ omega_in, hand=-hand if chiral else hand)
    assert (s1, n1) == (s2, n2)
    np.testing.assert_allclose(V2, MIRROR @ V1, rtol=0, atol=1e-9 * 200)
    np.testing.assert_allclose(W2, -MIRROR @ W1, rtol=0, atol=1e-9 * 200)
    assert e2 == pytest.approx(e1, rel=1e-9)


@pytest.mark.parametrize("particle", BODIES[:100] + BODIES[200:220], ids=_name)
def test_converges_as_tolerances_are_halved(particle):
    """Halving the contact and contact-set tolerances changes a rebound by < 1e-8 (relative).

    The rotation between collisions is exact (no flight step), so the contact
    tolerances are the only discretisation parameters of a rebound.
    """
    shape, ratios, R0, hand = particle
    V1, W1, s1, n1, _, _ = run_one(shape, ratios, R0, alpha1=45.0, hand=hand)
    V2, W2, s2, n2, _, _ = run_one(shape, ratios, R0, alpha1=45.0, hand=hand, contact_tol=5e-11, set_tol=5e-10)
    assert (s1, n1) == (s2, n2)
    scale = 200.0
    assert np.abs(V1 - V2).max() < 1e-8 * scale
    assert np.abs(W1 - W2).max() < 1e-8 * scale


@pytest.mark.parametrize("particle", BODIES, ids=_name)
def test_energy_does_not_increase(particle):
    """From rest (Ω⁻ = 0) the kinetic energy after, ½|V⁺|² + ½Ω⁺·KΩ⁺, is at most ½|V⁻|² (so |V⁺| <= |V⁻|)."""
    shape, ratios, R0, hand = particle
    speed = 200.0
    V, W, status, ncoll, e_rot, _ = run_one(shape, ratios, R0, alpha1=60.0, speed=speed, hand=hand)
    assert ncoll >= 1
    assert 0.5 * V @ V + e_rot <= 0.5 * speed ** 2 * (1 + 1e-12)


def test_the_wall_work_is_the_kinetic_energy_lost():
    """The work of a rebound on the wall (docs/model.md §4.7), W_n and W_t summed over its collisions, each ≥ 0, is
    the drop of the particle's translational plus rotational kinetic energy, E⁻ − E⁺ (to round-off, 1e-12 E⁻), for
    every other body (the families and the grains), from rest and spinning, and up to the trap for a particle
    trapped after one collision (n_max = 1)."""
    seen = {STATUS_REBOUNDED: 0, STATUS_TRAPPED: 0}
    for k, (shape, ratios, R0, hand) in enumerate(BODIES[::2]):
        for omega_in, n_max in (((0.0, 0.0, 0.0), 1000), ((0.1, -0.2, 0.3), 1000), ((0.0, 0.0, 0.0), 1))[:2 + k % 2]:
            done, e_in = rebound_one(shape, ratios, R0, alpha1=50.0, omega_in=omega_in, hand=hand, n_max=n_max)
            if done.status not in seen:
                continue
            seen[done.status] += 1
            V = np.array(done.V)
            e_out = 0.5 * V @ V + done.rotational_energy
            assert done.wall_work_normal > 0.0 and done.wall_work_tangential >= 0.0, (k, done)
            assert abs(done.wall_work_normal + done.wall_work_tangential - (e_in - e_out)) <= 1e-12 * e_in, (k, done)
    assert seen[STATUS_REBOUNDED] > 200 and seen[STATUS_TRAPPED] > 10, seen


def _lab(R, diagonal):
    return R @ np.diag(diagonal) @ R.T


@pytest.mark.parametrize("particle", BODIES[120:140] + BODIES[200:], ids=_name)
def test_each_collision_keeps_the_angular_momentum_about_its_contact_point(particle):
    """Through each collision of a whole rebound, ℓ − r_c × V (per unit mass, ℓ = KΩ lab) is unchanged (the impulse
    acts at r_c), and r_c is on the wall: a vertex of the body at the wall, or the centre of those at the wall
    (the tie rule), or the ellipsoid's lowest point. ℓ before is the last flight's (torque-free: constant),
    after is the next flight's; to 1e-9 of |V⁻| a (round-off over a few collisions)."""
    shape, ratios, R0, hand = particle
    speed = 200.0
    _, _, status, ncoll, _, hist = run_one(shape, ratios, R0, alpha1=35.0, speed=speed, omega_in=(0.2, -0.1, 0.4),
                                           hand=hand, history_rows=1001)
    assert status == STATUS_REBOUNDED and ncoll >= 1
    b = body(shape, ratios, hand)
    for k in range(ncoll):
        before, after = hist[k], hist[k + 1]
        R_before, R_at = before[8:17].reshape(3, 3), after[8:17].reshape(3, 3)
        ell_before = _lab(R_before, b.K) @ before[5:8]
        ell_after = _lab(R_at, b.K) @ after[5:8]
        dV = after[2:5] - before[2:5]
        if b.kind == KIND_ELLIPSOID:                            # the support point in −n, −A²g/|Ag|
            g = R_at[1]
            candidates = [R_at @ (-b.semi ** 2 * g / np.linalg.norm(b.semi * g))]
        else:
            points = b.vertices @ R_at.T                        # from the centre, lab frame
            heights = after[1] + points[:, 1]
            touching = points[heights <= heights.min() + 1e-9]  # the contact set (set_tol of the lowest)
            candidates = np.vstack([touching, touching.mean(axis=0)])
        misfit = [np.abs(ell_after - ell_before - np.cross(r, dV)).max() for r in candidates]
        assert min(misfit) < 1e-9 * speed, (k, misfit)


def test_trapped_after_n_max():
    """With n_max = 1, a body that needs a second collision is reported trapped."""
    trapped = 0
    for shape, ratios, R0, hand in BODIES[:40] + BODIES[200:]:
        _, _, status_full, ncoll, _, _ = run_one(shape, ratios, R0, hand=hand)
        _, _, status_one, ncoll_one, _, _ = run_one(shape, ratios, R0, hand=hand, n_max=1)
        if ncoll >= 2:
            assert status_one == STATUS_TRAPPED and ncoll_one == 1
            trapped += 1
        else:
            assert status_one == status_full == STATUS_REBOUNDED
    assert trapped > 0
