"""Exact counterparts of statistical tests of the runtime: where a test compares a draw's law with a tolerance
in standard errors, the draw is a deterministic function of its uniforms, and the function is checked here.

* grain keys: each key's shape, b/a, c/b and hand against a reference of the keyed uniforms (splitmix64 in
  Python integers), and a keyed hit as the unkeyed hit with those uniforms in its slots (test_grain_key's χ²
  of the shapes against the mix and its Kolmogorov–Smirnov test of a population of keys);
* the trapped outcome: trapped iff u[3] < the drawn cell's P(trapped) (test_law's binomial 4σ test);
* the mirror: u[11] < 1/2 changes the sign of V⁺_z, Ω_x, Ω_y and nothing else (test_law's symmetry at 4 SE);
* normal impact: the draw's azimuth in the wall is 2π u[12] exactly, the rest unchanged (test_law's KS test).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import surrogate
from data_schema.samples import STATUS_REBOUNDED, STATUS_TRAPPED
from direct_model.runtime import U_HAND, U_RATIOS, aspect_ratio
from surrogate.kernels import METHOD_DIRECT, METHOD_TABLE, U_PER_DRAW, draw_velocity, locate, rebound, table_rebound
from surrogate.kernels.layout import CELL_P_TRAPPED, CELL_SIZE
from surrogate.kernels.rng import grain_uniform

GOLDEN = 0x9E3779B97F4A7C15
MASK = 2 ** 64 - 1
MIX = {"ellipsoid": 0.1, "prism": 0.2, "cut_prism": 0.3, "tetrahedron": 0.4}
NORMAL = (0.0, 1.0, 0.0)
A = 1e-3


def _splitmix64(x: int) -> int:
    z = x & MASK
    z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & MASK
    z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & MASK
    return z ^ (z >> 31)


def keyed_uniform(key: int, slot: int) -> float:
    """The reference: splitmix64 of the key plus γ, plus (slot + 1)·γ, splitmix64 again, its top 53 bits · 2⁻⁵³
    (docs/runtime.md, "Grain keys"; slots: 0 the shape, 1 b/a, 2 c/b, 3 the hand)."""
    x = (_splitmix64(key + GOLDEN) + (slot + 1) * GOLDEN) & MASK
    return (_splitmix64(x) >> 11) * 2.0 ** -53


def _from_mix(cdf, u):
    """The first shape k with u < cdf[k] (table order)."""
    return int(sum(u >= c for c in cdf[:-1]))


def _keys(n, seed):
    return [int(k) for k in surrogate.grain_key(seed, np.arange(n))]


def test_a_key_s_grain_is_its_keyed_uniforms(small_table):
    """For 2000 keys: every slot's uniform equals the reference bit for bit; grain_of's shape is the mix's at
    the shape slot's uniform, b/a and c/b the aspect-ratio law's quantiles at theirs, the hand (the tetrahedron's
    alone) +1 iff the hand slot's uniform < 1/2."""
    keys = _keys(2000, 41)
    cdf = surrogate.mix_cdf(small_table, MIX)
    grains = surrogate.grain_of(small_table, keys, MIX)
    arrays = small_table.shape_arrays
    for i, key in enumerate(keys):
        u = [keyed_uniform(key, slot) for slot in range(4)]
        assert [grain_uniform(key, slot) for slot in range(4)] == u, key
        shape = _from_mix(cdf, u[0])
        assert grains.shape[i] == small_table.shapes[shape], key
        model = small_table.model_shapes[shape]
        law, law_cdf = arrays.aspect[model], arrays.aspect_cdf[model]
        assert grains.ratio_ba[i] == aspect_ratio(law, law_cdf, u[1]), key
        assert grains.ratio_cb[i] == aspect_ratio(law, law_cdf, u[2]), key
        if small_table.shapes[shape] == "tetrahedron":
            assert grains.hand[i] == (1.0 if u[3] < 0.5 else -1.0), key
        else:
            assert math.isnan(grains.hand[i]), key
    assert set(grains.shape) == set(MIX)


@pytest.mark.parametrize("method", [METHOD_TABLE, METHOD_DIRECT], ids=["table", "direct"])
def test_a_keyed_hit_is_the_hit_with_the_key_s_uniforms(small_table, method):
    """rebound with a key is rebound without one with the key's uniforms in their slots: u[0] (the shape) on
    either path, and on the direct path u[1 + U_RATIOS], u[2 + U_RATIOS], u[1 + U_HAND] (b/a, c/b, hand)."""
    data, cdf = small_table.kernel_data, surrogate.mix_cdf(small_table, MIX)
    rng = np.random.default_rng(42)
    args = (data, small_table.direct_parameters, small_table.shape_arrays, small_table.model_shapes, cdf)
    rebounded = 0
    for key in _keys(150, 43):
        u = rng.random(U_PER_DRAW)
        a1, phi, speed = math.radians(rng.uniform(30.0, 90.0)), rng.uniform(0, 2 * math.pi), rng.uniform(50, 250)
        V = (speed * math.cos(a1) * math.cos(phi), -speed * math.sin(a1), speed * math.cos(a1) * math.sin(phi))
        keyed = u.copy()
        keyed[0] = keyed_uniform(key, 0)
        if method == METHOD_DIRECT:
            keyed[1 + U_RATIOS], keyed[2 + U_RATIOS], keyed[1 + U_HAND] = (keyed_uniform(key, s) for s in (1, 2, 3))
        got = rebound(*args, V, (0.0, 0.0, 0.0), NORMAL, A, u, method, True, key)
        want = rebound(*args, V, (0.0, 0.0, 0.0), NORMAL, A, keyed, method, True)
        # field by field on the bits: NaN fields (the table path's wall work) are equal as bits, not as floats
        assert all(np.array(x).tobytes() == np.array(y).tobytes() for x, y in zip(got, want)), key
        rebounded += got.status == STATUS_REBOUNDED
    assert rebounded > 100


def test_trapped_iff_u3_is_below_the_drawn_cell_s_probability(small_table):
    """The draw is trapped iff u[3] < P(trapped) of the cell it reads: one double below the probability it is,
    at the probability it is not; between grid points the drawn cell's probability decides, not a blend. Every
    cell with trapped particles (the ellipsoid's near normal impact), reached from its grid point and from
    between grid points, either neighbour."""
    data = small_table.kernel_data
    p = data.cells.reshape(-1, CELL_SIZE)[:, CELL_P_TRAPPED]
    reached = set()
    u = np.random.default_rng(44).uniform(0.01, 0.99, U_PER_DRAW)
    for shape in small_table.shapes:
        cdf = surrogate.mix_cdf(small_table, shape)
        for alpha1 in (30.0, 45.0, 60.0, 75.0, 90.0):
            for speed in (50.0, 100.0, 150.0, 200.0, 250.0):
                for u[1], u[2] in ((0.0, 0.0), (0.0, 0.999999), (0.999999, 0.0), (0.999999, 0.999999)):
                    drawn = locate(data, cdf, alpha1, speed, u)[0]
                    if p[drawn] == 0.0:
                        continue
                    u[3] = np.nextafter(p[drawn], 0.0)
                    assert draw_velocity(data, cdf, alpha1, speed, u, True)[0] == STATUS_TRAPPED
                    u[3] = p[drawn]
                    assert draw_velocity(data, cdf, alpha1, speed, u, True)[0] != STATUS_TRAPPED
                    reached.add(drawn)
    assert reached == set(np.flatnonzero(p > 0.0)) and len(reached) >= 2, (reached, np.flatnonzero(p > 0.0))


def test_the_mirror_sign_is_u11_below_one_half(small_table):
    """u[11] < 1/2 mirrors the draw (Z → −Z: V⁺_z, Ω_x, Ω_y change sign), u[11] ≥ 1/2 does not; everything else
    is the same bits. Global frame, wall y = 0, impact plane XY (so ez is ±Z)."""
    data, cdf = small_table.kernel_data, surrogate.mix_cdf(small_table, MIX)
    rng = np.random.default_rng(45)
    for _ in range(300):
        u = rng.uniform(0.01, 0.99, U_PER_DRAW)
        a1, speed = math.radians(rng.uniform(30.0, 90.0)), rng.uniform(50, 250)
        V = (speed * math.cos(a1), -speed * math.sin(a1), 0.0)
        draws = []
        for u11 in (0.25, np.nextafter(0.5, 0.0), 0.5, 0.75):
            u[11] = u11
            hit = table_rebound(data, cdf, V, NORMAL, A, u, True)
            status, v, w = hit.status, hit.V, hit.Omega
            draws.append((status, np.array(v + w)))
        assert draws[0][1].tobytes() == draws[1][1].tobytes() and draws[2][1].tobytes() == draws[3][1].tobytes()
        if draws[0][0] == STATUS_REBOUNDED:
            flip = np.array([1.0, 1.0, -1.0, -1.0, -1.0, 1.0])
            assert (draws[0][1] * flip).tobytes() == draws[3][1].tobytes()
            assert draws[0][1][2] != 0.0


def test_at_normal_impact_the_azimuth_is_u12(small_table):
    """V⁻ along −n: the tangential axis of the frame is at the angle 2π u[12] in the wall, so the draw with u[12]
    is the draw with u[12] = 0 turned by 2π u[12] about n (n = +Z here), to the rounding of the frame's sine
    and cosine (1e-12 relative)."""
    data, cdf = small_table.kernel_data, surrogate.mix_cdf(small_table, MIX)
    V, n = (0.0, 0.0, -200.0), (0.0, 0.0, 1.0)
    rng = np.random.default_rng(46)
    for _ in range(200):
        u = rng.uniform(0.01, 0.99, U_PER_DRAW)
        theta = 2 * math.pi * u[12]
        turned = table_rebound(data, cdf, V, n, A, u, True)
        u[12] = 0.0
        hit = table_rebound(data, cdf, V, n, A, u, True)
        status, v, w = hit.status, hit.V, hit.Omega
        assert turned.status == status
        if status != STATUS_REBOUNDED:
            continue
        c, s = math.cos(theta), math.sin(theta)
        R = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
        np.testing.assert_allclose(turned.V, R @ v, rtol=0, atol=1e-12 * 200)
        np.testing.assert_allclose(turned.Omega, R @ w, rtol=0, atol=1e-12 * np.linalg.norm(w))
