"""The facets of a rough wall (docs/model.md §12): under each hit, the mean wall tilted at random.

The facet normal is the mean normal n rotated in the hit's impact frame (ex, n, ez;
:func:`surrogate.kernels.frame.impact_frame`) by γx about ez and γz about ex,

    n_f = −sin γx ex + cos γx cos γz n + cos γx sin γz ez,

γx, γz ~ N(0, Δγ²), Δγ the roughness (degrees). Shadow effect: a facet is hit with probability proportional to
its area seen along V⁻, p = −V̂⁻·n_f = cos α1 sin γx + sin α1 cos γx cos γz (never if p ≤ 0). :func:`facet_normal`
draws from that law exactly, by rejection from the proposal N(γz) · N(γx) (cos α1 |γx| + sin α1) (a mixture of a
normal and a two-sided Rayleigh law for γx), which bounds p: each draw is kept with probability
p / (cos α1 |γx| + sin α1): at least 0.38 of them for Δγ ≤ 45° at any α1 (0.5 at grazing incidence, where
keeping a draw of N(0, Δγ²)² with probability p alone keeps about Δγ/√(2π) of them, 0.7 % at Δγ = 1°).

Random numbers: a rough hit never takes more of the caller's stream than a smooth one. Its facets, and the
uniforms of the hits after the first, are keyed uniforms (:func:`surrogate.kernels.rng.grain_uniform`) of the
hit's *facet key*, a hash of the hit's own uniforms (:func:`facet_key`), numbered from 0 in the order they are
used: a pure function of the hit, whatever the threads, ranks or redraws.
"""

import math

import numba
import numpy as np

from direct_model.elementary import sincos
from surrogate.kernels.draw import U_PER_DRAW
from surrogate.kernels.frame import impact_frame
from surrogate.kernels.options import JIT
from surrogate.kernels.rng import grain_uniform, hit_key

MAX_FACET_DRAWS = 64        # draws of one facet: each is kept with probability ≥ 0.38, so 64 all fail < 1e-13
U_PER_FACET = 6             # keyed uniforms of one draw: the mixture's branch, γx (2), γz (2), keep or not
_FACET_DOMAIN = np.uint64(0x6A09E667F3BCC909)   # the facet keys' start: unrelated to the grain keys' hashes
_SQRT_2_OVER_PI = math.sqrt(2.0 / math.pi)      # E|γx| / Δγ
_DEG = math.pi / 180.0                         # as math.radians and RBS_DEG_TO_RAD


@numba.njit(inline="always", **JIT)
def facet_key(u):
    """The facet key of a hit of uniforms ``u`` (its U_PER_DRAW = 13): :func:`surrogate.kernels.rng.hit_key` from
    _FACET_DOMAIN."""
    return hit_key(u, U_PER_DRAW, _FACET_DOMAIN)


@numba.njit(inline="always", **JIT)
def _normal_radius(u):
    """The radius of a Box–Muller pair, sqrt(−2 ln(1 − u)), u in [0, 1): a standard Rayleigh deviate."""
    return math.sqrt(-2.0 * math.log1p(-u))


@numba.njit(inline="always", **JIT)
def facet_normal(V, n, roughness_deg, key, slot):
    """A facet under the hit V⁻ (m/s) on the mean wall of unit normal n (3-tuples), roughness Δγ =
    ``roughness_deg`` > 0, from the keyed uniforms of ``key`` numbered from ``slot`` (module doc).

    Returns (found, n_f, next slot): n_f the facet's unit normal (a 3-tuple; V⁻·n_f < 0), ``found`` False after
    MAX_FACET_DRAWS draws kept none (n_f then n). Uses one uniform for the frame's ex at normal impact, then
    U_PER_FACET per draw."""
    spread = roughness_deg * _DEG
    _, _, cos_a1, sin_a1, ex, ez = impact_frame(V, n, grain_uniform(key, slot))
    slot += 1
    flat, tilted = sin_a1, cos_a1 * spread * _SQRT_2_OVER_PI      # the proposal's two weights
    for _ in range(MAX_FACET_DRAWS):
        u0, u1, u2 = grain_uniform(key, slot), grain_uniform(key, slot + 1), grain_uniform(key, slot + 2)
        u3, u4, u5 = grain_uniform(key, slot + 3), grain_uniform(key, slot + 4), grain_uniform(key, slot + 5)
        slot += U_PER_FACET
        r = spread * _normal_radius(u1)
        if u0 * (flat + tilted) < flat:
            gx = r * sincos(2.0 * math.pi * u2)[1]
        else:
            gx = r if u2 < 0.5 else -r
        cz = sincos(2.0 * math.pi * u4)[1]
        gz = spread * _normal_radius(u3) * cz
        sin_x, cos_x = sincos(gx)
        sin_z, cos_z = sincos(gz)
        seen = cos_a1 * sin_x + sin_a1 * cos_x * cos_z
        if u5 * (cos_a1 * abs(gx) + sin_a1) < seen:
            tilt, along = cos_x * cos_z, cos_x * sin_z
            return True, (tilt * n[0] - sin_x * ex[0] + along * ez[0], tilt * n[1] - sin_x * ex[1] + along * ez[1],
                          tilt * n[2] - sin_x * ex[2] + along * ez[2]), slot
    return False, (float(n[0]), float(n[1]), float(n[2])), slot
