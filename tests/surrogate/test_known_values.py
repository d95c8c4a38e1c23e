"""Known values of the runtime: a grain key's uniforms and grain, and draws of the table path and of the direct
path at fixed uniforms, pinned as literals (hex floats: every bit); and the independence of a grain's shape and
proportions over many keys.

The bit-for-bit tests elsewhere compare two kernels of today's code (one particle and the pipeline, Python and
C), so a change that moves both alike passes them; these literals do not move with the code. They rest on what
the project's bits rest on (docs/native.md, "What the bits still rest on"): integer hashing for the keys; the
table path's own arithmetic (fused multiply-adds, no libm on its hot path) and its table; glibc's libm for the
table's build, the aspect-ratio quantile (log) and the direct model (sin, cos, atan2, exp, pow); nothing
depends on numpy's SIMD dispatch. They hold on any x86-64 CPU with FMA.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats

import surrogate
from data_schema.table import table_fingerprint
from surrogate.kernels import METHOD_DIRECT, METHOD_TABLE, direct_rebound, draw_velocity, rebound, table_rebound
from surrogate.kernels.grain import SLOT_HAND, SLOT_RATIO_BA, SLOT_RATIO_CB, SLOT_SHAPE
from surrogate.kernels.locate import mix_shapes
from surrogate.kernels.rng import grain_uniform
from tablegen import build_table, parse_config
from tests.helpers.tables import written_out_config

# 2 × 2 grid, two shapes; ~1.5 s to build
TABLE_CONFIG = written_out_config([40.0, 70.0], [60.0, 120.0], ["prism", "tetrahedron"], seed=20250102)
# table format 4.0 (the format alone: in the 3.4 layout the same table hashed as before, 1df2f289…bb54a), then the
# wall's speed_range_m_s (8143ad6f…978d0 without it), then format 4.1 (af2fd8aa…8c603 before): the work on the
# wall, whose variables the components are partitioned on too, so the rebound's datasets moved with it
TABLE_FINGERPRINT = "9675742d1216433065cb2a4d36a7f4b47b7cfae59a7bc8e7a6d5c4b46901f714"
MIX = {"prism": 0.5, "tetrahedron": 0.5}


@pytest.fixture(scope="module")
def table(tmp_path_factory):
    path = tmp_path_factory.mktemp("known_values") / "table.h5"
    build_table(parse_config(TABLE_CONFIG), path, workers=1)
    return surrogate.load(path)


def test_the_table_s_fingerprint_known_value(table):
    """The fingerprint of the table the table path's draws below read (if it moved, so do they).

    Update the literal only for a deliberate change of the law a build computes, of the seed derivation or of
    the format (as tests/tabulation/test_known_values.py's fingerprint); never to make the test pass after an
    unexplained change."""
    assert table_fingerprint(table.path) == TABLE_FINGERPRINT


def _hex(values):
    return tuple(float.fromhex(h) for h in values)


# key: its uniforms of the slots shape, b/a, c/b, hand (surrogate.kernels.rng.grain_uniform)
KEYED_UNIFORMS = {
    0: ("0x1.4e0dba5e9a32fp-1", "0x1.6705460be8829p-1", "0x1.8c6a4553eeafcp-2", "0x1.501575190cc81p-1"),
    1: ("0x1.7906ac21d0e58p-2", "0x1.e31ad9d27ad9ep-1", "0x1.72becda64fd10p-5", "0x1.8e0c363726645p-1"),
    2: ("0x1.91a1313c3f5e0p-2", "0x1.5afa6cc984168p-4", "0x1.af36373b7ae1cp-1", "0x1.1d44c9a024b90p-1"),
    3: ("0x1.799bfb392d431p-1", "0x1.2fc944df497a8p-1", "0x1.44388cb648d28p-1", "0x1.966af395eb288p-1"),
    12345: ("0x1.035808208fee0p-6", "0x1.007bea91bc742p-1", "0x1.6b8af24d1da94p-3", "0x1.6932432080327p-1"),
    2 ** 62 + 7: ("0x1.ad2e115f51b80p-4", "0x1.e37a16b88dd5cp-2", "0x1.01bd5869d6e0ep-2", "0x1.b1d630b899570p-4"),
    2 ** 63 - 1: ("0x1.a727662a1b172p-2", "0x1.fe11c628b87b4p-2", "0x1.d154b09245784p-3", "0x1.c68371d181360p-6"),
    4764729254052721200: ("0x1.5a5f8499e719ep-1", "0x1.a820c1e52b730p-3", "0x1.4a8deabe463d3p-1",
                          "0x1.5e7a10296594cp-2"),
}
# grain_of(table, key, MIX): (key, shape, b/a, c/b, hand); the prism comes in one hand (NaN), the tetrahedron in two
GRAINS = [
    (0, "tetrahedron", "0x1.b62e79076aa68p-1", "0x1.76b54933a0834p-1", -1.0),
    (1, "prism", "0x1.eeeb5a9d5f3e6p-1", "0x1.177286a22ce7ep-1", None),
    (2, "prism", "0x1.276bd5fbb4609p-1", "0x1.d504ceae6eff7p-1", None),
    (3, "tetrahedron", "0x1.a05f54903c2edp-1", "0x1.a85a60141f005p-1", -1.0),
    (12345, "prism", "0x1.8df9ae120fda4p-1", "0x1.44fab9394d47ep-1", None),
    (2 ** 62 + 7, "prism", "0x1.8830eaf39969fp-1", "0x1.58467853a0f24p-1", None),
    (2 ** 63 - 1, "prism", "0x1.8d68a222ca25fp-1", "0x1.5230f82fa3846p-1", None),
    (4764729254052721200, "tetrahedron", "0x1.4cff6715a4bcap-1", "0x1.aad7b0c089e4bp-1", 1.0),
]


def test_keyed_uniforms_known_values():
    """Each slot's uniform of a key (splitmix64 of the key, then of that plus (slot + 1)·γ, 53 bits), and which
    slot decides the shape, b/a, c/b and the hand. Integer arithmetic: the same in C (rbs_grain_key).

    Update the literals only for a deliberate change of the key derivation or of the slots, which changes every
    keyed grain (say so in the change; native/ must follow); never to make the test pass after an unexplained
    change. The failure message gives the new values as hex."""
    assert (SLOT_SHAPE, SLOT_RATIO_BA, SLOT_RATIO_CB, SLOT_HAND) == (0, 1, 2, 3)
    for key, expected in KEYED_UNIFORMS.items():
        got = tuple(grain_uniform(key, slot) for slot in range(4))
        assert got == _hex(expected), (key, [x.hex() for x in got])
    assert surrogate.grain_key(7, 0, 3) == 4764729254052721200


def test_grain_of_known_values(table):
    """The grain of fixed keys in an even mix of the prism and the tetrahedron: shape, b/a, c/b (the aspect-ratio
    law's quantile at the key's uniforms), hand.

    Update the literals only for a deliberate change of the keyed uniforms (test above), of the aspect-ratio
    law or its quantile, or of how a shape is drawn from a mix; never to make the test pass after an
    unexplained change. The failure message gives the new values as hex."""
    keys = [g[0] for g in GRAINS]
    grains = surrogate.grain_of(table, keys, MIX)
    for i, (key, shape, ratio_ba, ratio_cb, hand) in enumerate(GRAINS):
        got = (grains.shape[i], grains.ratio_ba[i].hex(), grains.ratio_cb[i].hex(), grains.hand[i])
        assert grains.shape[i] == shape, (key, got)
        assert (grains.ratio_ba[i], grains.ratio_cb[i]) == _hex((ratio_ba, ratio_cb)), (key, got)
        assert (math.isnan(grains.hand[i]) if hand is None else grains.hand[i] == hand), (key, got)


# fixed uniforms, one row per draw (each the double nearest its decimal literal: the same on every platform)
U = np.array([[0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 0.15, 0.25, 0.35, 0.45],
              [0.9, 0.8, 0.7, 0.05, 0.125, 0.375, 0.625, 0.875, 0.0625, 0.5625, 0.3125, 0.8125, 0.03125]])
V_IN = (30.0, -70.0, 20.0)          # m/s: α1 62.8°, |V⁻| 78.7 m/s, between the grid points in both
NORMAL = (0.0, 1.0, 0.0)
A = 1e-3                            # half-size, m
KEY = 4764729254052721200           # GRAINS' last key
# per path: (status, V⁺ (m/s), Ω⁺ (rad/s)) for each row of U; "node": draw_velocity at the grid point
# (40°, 60 m/s), local frame (status, V⁺ in units of |V⁻|, Ω⁺ in units of |V⁻|/a)
DRAWS = {
    "table": [
        (0, ("0x1.6d4aff1abd552p+2", "0x1.5beaf5245542ep+4", "-0x1.8903554fe0139p+3", "0x1.18e49f89b41d0p+9",
             "0x1.5d33825df68a6p+13", "0x1.41bf7eac8b893p+10")),
        (0, ("-0x1.ffa5560a2b5cep+1", "0x1.3eb58cccdffcep+3", "0x1.934589d455f3bp+4", "0x1.f65f14f3279c3p+14",
             "0x1.8da163feb5b52p+13", "-0x1.bd61b726c190ap+7")),
    ],
    "node": [
        (0, ("0x1.8f9b08018b510p-2", "0x1.6a145854b4c90p-2", "-0x1.0eeffe7a3b327p-2", "0x1.8218c451dd1dap-9",
             "0x1.094166469036dp-2", "-0x1.09b43ff0a6dd6p-4")),
        (0, ("0x1.271f2db4e7c84p-2", "0x1.b4396962bb71dp-3", "0x1.7f1187eb1835ap-2", "0x1.c4ddf008b4295p-2",
             "0x1.fa7915705289bp-3", "-0x1.bd17ce49713b6p-2")),
    ],
    "direct": [
        (0, ("0x1.50bff2003dd58p+4", "0x1.92e8e97163a38p+3", "0x1.85d0d1f0f5977p+4", "0x1.0e0bba219f044p+15",
             "0x1.5165db6c562a9p+11", "-0x1.e070669fe9a55p+14")),
        (0, ("0x1.2f64f7368cec6p+4", "0x1.67ea4b48739a0p+4", "0x1.86e92209cbb16p+3", "0x1.4f1cd40070b68p+14",
             "0x1.1322cf874a2f6p+11", "-0x1.02106286cccb5p+15")),
    ],
    "keyed_direct": [
        (0, ("0x1.2c73b12bd50acp+4", "0x1.09ec9b19cf0a4p+4", "0x1.aa3449a9c4728p+4", "0x1.386f42ec89f1cp+15",
             "0x1.d4c3545c6fdc8p+8", "-0x1.e39880a12092bp+14")),
        (0, ("0x1.3822a9979e300p+4", "0x1.68973bcb6d075p+2", "0x1.06ce09c6c3ebcp+2", "-0x1.d3f6f49b7e134p+12",
             "-0x1.872c758b6102cp+13", "0x1.1dcef846d6451p+9")),
    ],
    "keyed_table": [
        (0, ("0x1.834cc2407c8a9p+4", "0x1.9078a20e74150p+3", "0x1.0498fcf20b221p+1", "-0x1.162c7b5729a45p+11",
             "-0x1.c14e2106c6e8cp+12", "0x1.2bce2503f47e3p+11")),
        (0, ("-0x1.ffa5560a2b5cep+1", "0x1.3eb58cccdffcep+3", "0x1.934589d455f3bp+4", "0x1.f65f14f3279c3p+14",
             "0x1.8da163feb5b52p+13", "-0x1.bd61b726c190ap+7")),
    ],
}


# per path with a hit record: (W_n, W_t) in m²/s² for each row of U, the work on the wall of the draws above
WORK = {
    "table": [("0x1.7d9f15be9e24cp+10", "0x1.22a03d342daf0p+10"), ("0x1.ab52435351a77p+10", "0x1.a62c3be857039p+9")],
    "direct": [("0x1.e963a9f10cb8ep+10", "0x1.4df3b9fc7d525p+5"), ("0x1.12096f2d7071cp+11", "0x1.ff2f769f15ff5p+5")],
    "keyed_table": [("0x1.002670969acb4p+11", "0x1.4b95b6659973fp+9"),
                    ("0x1.b12e51c29fd7fp+10", "0x1.99aca6f54d08cp+9")],
}


def _draw(table, path, u):
    """(status, the six output numbers) of one draw along ``path`` (DRAWS' keys), and its work on the wall (W_n,
    W_t) where it has a hit record (None at the node)."""
    cdf = surrogate.mix_cdf(table, MIX)
    zero = (0.0, 0.0, 0.0)
    if path == "node":
        status, *values = draw_velocity(table.kernel_data, cdf, 40.0, 60.0, u, True)
        return status, tuple(values), None
    if path == "table":
        hit = table_rebound(table.kernel_data, cdf, V_IN, NORMAL, A, u, True)
    elif path == "direct":          # the prism (the direct model's shape 1), u[1..7] as in rebound
        hit = direct_rebound(table.direct_parameters, table.shape_arrays, 1, V_IN, zero, NORMAL, A, u[1:8])
    else:
        method = METHOD_DIRECT if path == "keyed_direct" else METHOD_TABLE
        hit = rebound(table.kernel_data, table.direct_parameters, table.shape_arrays, table.model_shapes, cdf,
                      V_IN, zero, NORMAL, A, u, method, True, KEY)
    return hit.status, tuple(hit.V) + tuple(hit.Omega), (hit.wall_work_normal, hit.wall_work_tangential)


@pytest.mark.parametrize("path", list(DRAWS))
def test_draws_at_fixed_uniforms_known_values(table, path):
    """Draws of the table path (between grid points in α1 and |V⁻|, and at a grid point), of the direct path,
    and of a grain key on either path, at the fixed uniforms U, every bit; their work on the wall too.

    Update the literals only for a deliberate change of the model (the direct model; the table's
    representation, its build or its draw: locate, gather, arithmetic), of the key derivation or of the
    format, and say so in the change; never to make the test pass after an unexplained change (find the first
    stage that moved). The failure message gives the new values as hex."""
    for k, (u, (status, values)) in enumerate(zip(U, DRAWS[path])):
        *got, work = _draw(table, path, u)
        got = tuple(got)
        assert got == (status, _hex(values)), (path, u, got[0], [x.hex() for x in got[1]])
        if path in WORK:
            assert work == _hex(WORK[path][k]), (path, u, [float(x).hex() for x in work])


def test_a_grain_s_shape_and_proportions_are_independent(small_table):
    """Over 10⁴ keys (grain_key of a fixed seed and 0 … 9999) in a mix of the four families, the shape and the
    b/a quintile are independent: χ² test of independence on the 4 × 5 contingency table (bins: the pooled b/a
    quintiles), 12 degrees of freedom, significance 10⁻³ (bound χ²₀.₉₉₉(12) = 32.9).

    Tolerance from n: every expected count is ≥ 0.1 · 10⁴ / 5 = 200, far above the 5 the χ² approximation
    needs, so under independence the statistic exceeds the bound with probability 10⁻³; the keys are fixed, so
    the test passes or fails the same way every run. With n = 10⁴ it detects a dependence of Cramér's V above
    √(32.9 / (n · 3)) ≈ 0.033; a shape drawn from the b/a slot's uniform (the control) has V ≈ 0.78
    (χ² ≈ 1.8·10⁴)."""
    n, mix = 10_000, {"ellipsoid": 0.1, "prism": 0.2, "cut_prism": 0.3, "tetrahedron": 0.4}
    keys = surrogate.grain_key(20250103, np.arange(n))
    grains = surrogate.grain_of(small_table, keys, mix)
    edges = np.quantile(grains.ratio_ba, [0.2, 0.4, 0.6, 0.8])
    bins = np.searchsorted(edges, grains.ratio_ba)
    bound = stats.chi2.isf(1e-3, 12)

    def statistic(shapes):
        counts = np.zeros((4, 5))
        np.add.at(counts, (shapes, bins), 1)
        result = stats.chi2_contingency(counts, correction=False)
        assert result.dof == 12 and result.expected_freq.min() >= 190
        return result.statistic

    shapes = np.array([list(mix).index(s) for s in grains.shape])
    assert statistic(shapes) < bound
    # the control: the shape drawn from the mix with the b/a slot's uniform instead of its own
    cdf = surrogate.mix_cdf(small_table, mix)
    in_mix = np.empty(len(mix), dtype=np.int64)        # a table shape index → its index in mix
    in_mix[[small_table.shapes.index(s) for s in mix]] = np.arange(len(mix))
    drawn = mix_shapes(cdf, np.array([grain_uniform(int(k), SLOT_RATIO_BA) for k in keys]))
    assert statistic(in_mix[drawn]) > 100 * bound
