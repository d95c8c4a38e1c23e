"""Rough walls in C (docs/model.md §12): rbs_rebound with a roughness Δγ > 0, the table's wall's
(rbs_wall_info.roughness_deg, the optional field roughness_deg of /wall/parameters) or rbs_options.roughness_deg,
gives the bits of numba's surrogate.kernels.wall_hit.rebound(..., roughness_deg) for the same 13 uniforms.

- Facets alone: rbs_facet_key and rbs_facet_normal (the test-only library) are surrogate.kernels.facet's facet_key
  and facet_normal: the key, the facet's normal bit for bit, whether one was found and the next slot.
- Hits: over grazing (α1 1–5°, where a rebound often hits a second facet), oblique and steep hits on random walls,
  spinning and not, with and without grain keys, under the three methods, with the roughness of a rough table, a
  roughness of the options overriding it, and a roughness of the options on a smooth table: every field of
  rbs_result equals numba's Hit (V⁺ and Ω⁺ byte for byte); hits of several facet hits are among them.
- Roughness 0 is the smooth wall, bit for bit; a negative roughness (RBS_ROUGHNESS_OF_TABLE), NULL options and an
  options record of 1.1 (too small to hold the field) are the table's; NaN and above 45° are RBS_INVALID; a rough
  hit takes 13 uniforms of a stream; rbs_draw_many answers the smooth wall only.
"""

from __future__ import annotations

import ctypes

import numpy as np
import pytest

from tests.helpers import python_side as py
from tests.helpers.bad_files import _row_edit
from tests.helpers.native_library import (INVALID, METHOD_AUTO, METHOD_DIRECT, METHOD_TABLE, NO_KEY, OK, PATH_DIRECT,
                                          PATH_NONE, PATH_TABLE, ROUGHNESS_OF_TABLE, U_PER_DRAW, Hits, Options, Result,
                                          Results, Rng, WallInfo, hit, options, ref)
from tests.helpers.tables import edited_copy

METHODS = {"auto": METHOD_AUTO, "table": METHOD_TABLE, "direct": METHOD_DIRECT}
TABLE_ROUGHNESS = 30.0      # the rough table's wall (degrees)
HITS = 240                  # hits compared per case: half grazing
A = 1e-4                    # half-size, m


@pytest.fixture(scope="module")
def rough_pair(native, small_table_path, tmp_path_factory):
    """(numba's table, C's table, C's equal mix, its cdf) of a copy of the small table whose wall is rough
    (TABLE_ROUGHNESS)."""
    path = edited_copy(small_table_path, tmp_path_factory.mktemp("rough"), "rough.h5",
                       _row_edit("wall", dtype={"roughness_deg": "<f8"}, roughness_deg=TABLE_ROUGHNESS))
    table, c_table = py.load(path), native.table(path)
    yield table, c_table, c_table.mix(), py.mix_cdf(table, "mix")
    c_table.close()


@pytest.fixture(scope="module")
def smooth_pair(table_pair):
    """(numba's table, C's table, C's equal mix, its cdf) of the small table (a smooth wall)."""
    table, c_table = table_pair
    return table, c_table, c_table.mix(), py.mix_cdf(table, "mix")


def _numba(table, cdf, V, Omega, n, u, method, key, roughness):
    """numba's Hit (``key`` −1: none, as C's RBS_NO_KEY)."""
    return py.rebound(table.kernel_data, table.direct_parameters, table.shape_arrays, table.model_shapes, cdf,
                      np.ascontiguousarray(V, dtype=np.float64), np.ascontiguousarray(Omega, dtype=np.float64),
                      tuple(float(x) for x in n), A, u, int(method), True, None if key < 0 else int(key),
                      float(roughness))


def _fields(record) -> tuple:
    """Every field of an rbs_result or a Hit, the floats as bytes (the wall work summed over the facet hits, either
    path's)."""
    return (int(record.status), int(record.path), int(record.shape), int(record.n_collisions), int(record.wall_hits),
            np.array(record.V[:], dtype=np.float64).tobytes(), np.array(record.Omega[:], dtype=np.float64).tobytes(),
            np.array([record.wall_work_normal, record.wall_work_tangential], dtype=np.float64).tobytes())


def _hits(seed: int, count: int = HITS):
    """(V, Ω, n, u, key) of ``count`` hits on random walls: half grazing (α1 in [1, 5]°), a quarter in [5, 30]°, a
    quarter in [30, 90]°; |V⁻| in [40, 300] m/s (the grid's 50–250 and beyond); every other one spinning
    (|Ω⁻| a/|V⁻| up to 0.5, random axes); every other pair with a grain key."""
    rng = np.random.default_rng(seed)
    for k in range(count):
        n = rng.standard_normal(3)
        n /= np.linalg.norm(n)
        t = rng.standard_normal(3)
        t -= (t @ n) * n
        t /= np.linalg.norm(t)
        low, high = ((1.0, 5.0), (1.0, 5.0), (5.0, 30.0), (30.0, 90.0))[k % 4]
        alpha1 = np.radians(rng.uniform(low, high))
        speed = rng.uniform(40.0, 300.0)
        V = speed * (np.cos(alpha1) * t - np.sin(alpha1) * n)
        axis = rng.standard_normal(3)
        Omega = (rng.uniform(0.0, 0.5) * speed / A * axis / np.linalg.norm(axis)) if k % 2 else np.zeros(3)
        key = int(rng.integers(0, 2 ** 63 - 1)) if (k // 2) % 2 else NO_KEY
        yield V, Omega, n, rng.random(U_PER_DRAW), key


# ---------------------------------------------------------------- the facets alone


def test_facet_key_and_normal_are_numbas(native):
    c = native.internal
    rng = np.random.default_rng(801)
    for k in range(200):
        u = rng.random(U_PER_DRAW)
        if k < 2:
            u[:] = (0.0, np.nextafter(1.0, 0.0))[k]
        assert c.rbs_facet_key(u.ctypes.data) == py.facet_key(u), k
    found = 0
    for k in range(300):
        n = rng.standard_normal(3)
        n /= np.linalg.norm(n)
        t = rng.standard_normal(3)
        t -= (t @ n) * n
        alpha1 = np.radians(90.0 if k % 10 == 0 else rng.uniform(0.5, 90.0))    # normal impact: ex from a uniform
        V = rng.uniform(1.0, 300.0) * (np.cos(alpha1) * t / np.linalg.norm(t) - np.sin(alpha1) * n)
        roughness = (1e-3, 45.0)[k % 2] if k % 5 == 0 else rng.uniform(0.0, 45.0)
        key, slot = int(rng.integers(0, 2 ** 63 - 1)), int(rng.integers(0, 100))
        c_slot, facet = ctypes.c_int64(slot), np.empty(3)
        c_found = c.rbs_facet_normal(V.ctypes.data, n.ctypes.data, roughness, key, ctypes.byref(c_slot),
                                     facet.ctypes.data)
        expected, normal, next_slot = py.facet_normal(tuple(V), tuple(n), roughness, key, slot)
        assert (bool(c_found), c_slot.value, facet.tobytes()) == (expected, next_slot, np.array(normal).tobytes()), k
        found += expected
        assert facet @ V < 0.0 and abs(facet @ facet - 1.0) < 1e-12, k
    assert found == 300


# ---------------------------------------------------------------- rough hits, C and numba


def _compare(c_table, mix, table, cdf, method, roughness_c, roughness_py, seed):
    """C's and numba's hits of _hits(seed), C's options roughness ``roughness_c`` (None: NULL options' default,
    a callable: per hit) and numba's ``roughness_py``: (hits, hits of several facet hits, paths seen)."""
    multi, paths = 0, set()
    for k, (V, Omega, n, u, key) in enumerate(_hits(seed)):
        asked = roughness_c(k) if callable(roughness_c) else roughness_c
        applied = roughness_py(k) if callable(roughness_py) else roughness_py
        result, _ = c_table.hit(mix, V, Omega, n, A, u, key=key, method=method, roughness_deg=asked)
        expected = _numba(table, cdf, V, Omega, n, u, method, key, applied)
        assert _fields(result) == _fields(expected), (k, _fields(result)[:5], _fields(expected)[:5])
        assert expected.status != OK or np.dot(expected.V, n) > 0.0, k
        multi += expected.wall_hits > 1
        paths.add(int(expected.path))
    return HITS, multi, paths


def _override(k):
    """The options' roughness of hit k overriding the rough table's: 45° (the largest), a tiny one, or uniform."""
    return (45.0, 1e-3)[k % 2] if k % 9 == 0 else float(np.random.default_rng(k).uniform(0.0, 45.0))


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("source", ["table", "options", "options on a smooth table"])
def test_rough_hits_are_numbas_bit_for_bit(rough_pair, smooth_pair, method, source):
    code = METHODS[method]
    if source == "table":
        table, c_table, mix, cdf = rough_pair
        counts = _compare(c_table, mix, table, cdf, code, ROUGHNESS_OF_TABLE, TABLE_ROUGHNESS, 810 + code)
    elif source == "options":
        table, c_table, mix, cdf = rough_pair
        counts = _compare(c_table, mix, table, cdf, code, _override, _override, 820 + code)
    else:
        table, c_table, mix, cdf = smooth_pair
        counts = _compare(c_table, mix, table, cdf, code, 40.0, 40.0, 830 + code)
    hits, multi, paths = counts
    print(f"\n{source}, method {method}: {hits} rough hits equal, {multi} of several facet hits")
    assert multi > 0, "no hit of several facet hits"
    assert paths <= {PATH_TABLE, PATH_DIRECT, PATH_NONE}
    if method == "auto":
        assert {PATH_TABLE, PATH_DIRECT} <= paths


def test_a_rough_table_is_read_by_both(rough_pair, smooth_pair):
    """rbs_wall_info.roughness_deg is the table's (0 for a table without the field); a 1.1 record (too small for it)
    does not get it."""
    table, c_table, _, _ = rough_pair
    assert table.wall.roughness_deg == c_table.wall()["roughness_deg"] == TABLE_ROUGHNESS
    assert smooth_pair[0].wall.roughness_deg == smooth_pair[1].wall()["roughness_deg"] == 0.0
    info = WallInfo()
    ctypes.memset(ctypes.addressof(info), 0xAB, ctypes.sizeof(info))
    info.size = WallInfo.roughness_deg.offset
    assert c_table.lib.c.rbs_table_wall(c_table.handle, ref(info)) == OK
    assert bytes(info)[WallInfo.roughness_deg.offset:] == b"\xab" * 8


# ---------------------------------------------------------------- roughness 0, the table's, refused


def _c_fields(c_table, mix, V, Omega, n, u, key, method, opts):
    """rbs_rebound's fields with the options record ``opts`` (None: NULL)."""
    h, kept = hit(V, Omega, n, A, u, None, key)
    result = Result()
    code = c_table.lib.c.rbs_rebound(c_table.handle, mix.pointer, ref(h), ref(opts), ref(result))
    assert code == result.status
    del kept
    return _fields(result)


def test_roughness_zero_is_the_smooth_wall(rough_pair, smooth_pair):
    """Roughness 0 (or −0) of the options on the rough table: the smooth table's hit, byte for byte (for a keyed hit
    numba's with roughness 0 too; test_native_spin and test_native_grain_key compare the smooth hits with numba),
    one wall hit, 0 for an invalid hit."""
    table, c_smooth, smooth_mix, cdf = smooth_pair
    _, c_rough, rough_mix, _ = rough_pair
    for k, (V, Omega, n, u, key) in enumerate(_hits(840, 120)):
        method = k % 3
        if k % 17 == 0:
            V = V * (np.nan if k % 2 else -1.0)         # invalid: wall_hits 0
        smooth = _c_fields(c_smooth, smooth_mix, V, Omega, n, u, key, method, options(method))
        for zero in (0.0, -0.0):
            assert _c_fields(c_rough, rough_mix, V, Omega, n, u, key, method,
                             options(method, roughness_deg=zero)) == smooth, k
        if key != NO_KEY:
            assert _fields(_numba(table, cdf, V, Omega, n, u, method, key, 0.0)) == smooth, k
        assert smooth[4] == (0 if smooth[0] == INVALID else 1), k


def test_a_negative_roughness_is_the_table_s(rough_pair):
    """RBS_ROUGHNESS_OF_TABLE, any negative roughness, NULL options and a 1.1 options record (without the field): the
    table's roughness."""
    _, c_table, mix, _ = rough_pair
    for k, (V, Omega, n, u, key) in enumerate(_hits(850, 60)):
        method = k % 3
        expected = _c_fields(c_table, mix, V, Omega, n, u, key, method, options(method, roughness_deg=TABLE_ROUGHNESS))
        old = options(method, roughness_deg=7.0)
        old.size = Options.roughness_deg.offset         # a 1.1 caller's record: the field is not read
        for opts in (options(method), options(method, roughness_deg=-0.5), options(method, roughness_deg=-np.inf),
                     old, *([None] if method == METHOD_AUTO else [])):
            assert _c_fields(c_table, mix, V, Omega, n, u, key, method, opts) == expected, (k, opts)


@pytest.mark.parametrize("roughness", [np.nan, np.inf, np.nextafter(45.0, np.inf), 46.0])
def test_a_roughness_out_of_range_is_invalid(rough_pair, smooth_pair, roughness):
    """NaN or above 45°: RBS_INVALID (path none, shape and collisions −1, no wall hit, NaN), rbs_rebound_path
    RBS_PATH_NONE; 45° itself is a rough wall."""
    for _, c_table, mix, _ in (rough_pair, smooth_pair):
        for k, (V, Omega, n, u, key) in enumerate(_hits(860, 8)):
            opts = options(k % 3, roughness_deg=roughness)
            fields = _c_fields(c_table, mix, V, Omega, n, u, key, k % 3, opts)
            assert fields[:5] == (INVALID, PATH_NONE, -1, -1, 0) and np.isnan(np.frombuffer(fields[5])).all(), k
            h, _ = hit(V, Omega, n, A, u)
            assert c_table.lib.c.rbs_rebound_path(c_table.handle, ref(h), ref(opts)) == PATH_NONE
            assert _c_fields(c_table, mix, V, Omega, n, u, key, k % 3, options(k % 3, roughness_deg=45.0))[0] != \
                INVALID, k


def test_a_rough_hit_takes_13_uniforms_of_a_stream(rough_pair):
    """Uniforms drawn from an rbs_rng: the hit of the same uniforms given (surrogate.fill_uniforms), the rng
    advanced by 13 whatever the facet hits."""
    _, c_table, mix, _ = rough_pair
    state = py.seed_state(861)
    for k, (V, Omega, n, _, key) in enumerate(_hits(862, 60)):
        u = np.empty(U_PER_DRAW)
        after = state.copy()
        py.fill_uniforms(after, u)
        drawn, advanced = c_table.hit(mix, V, Omega, n, A, state=state, key=key, method=k % 3)
        given, _ = c_table.hit(mix, V, Omega, n, A, u, key=key, method=k % 3)
        assert _fields(drawn) == _fields(given) and np.array_equal(advanced, after), k
        state = advanced


def _draw_many(c_table, mix, opts, rng_state=(1, 2, 3, 4)):
    """rbs_draw_many of 40 good rows, uniforms from an rng: (code, status, V⁺, the rng state after)."""
    count = 40
    V, n, a = np.tile([80.0, -60.0, 5.0], (count, 1)), np.tile([0.0, 1.0, 0.0], (count, 1)), np.full(count, A)
    rng = Rng()
    rng.s[:] = list(rng_state)
    hits = Hits(count=count, V=V.ctypes.data, n=n.ctypes.data, a=a.ctypes.data, rng=ctypes.addressof(rng))
    V_out, W_out, status = np.full((count, 3), 7.0), np.full((count, 3), 7.0), np.full(count, 77, dtype=np.int8)
    results = Results(V=V_out.ctypes.data, Omega=W_out.ctypes.data, status=status.ctypes.data)
    code = c_table.lib.c.rbs_draw_many(c_table.handle, mix.pointer, ref(hits), ref(opts), ref(results))
    return code, status, V_out, list(rng.s)


def test_draw_many_answers_the_smooth_wall_only(rough_pair, smooth_pair):
    """A rough table (its default, any roughness > 0 of the options), or a smooth one with a roughness of the options:
    RBS_INVALID, every row RBS_INVALID and NaN, the rng not advanced; roughness 0 on the rough table: the smooth
    table's draws."""
    _, c_rough, rough_mix, _ = rough_pair
    _, c_smooth, smooth_mix, _ = smooth_pair
    for c_table, mix, opts in ((c_rough, rough_mix, None), (c_rough, rough_mix, Options()),
                               (c_rough, rough_mix, options(roughness_deg=5.0)),
                               (c_smooth, smooth_mix, options(roughness_deg=10.0))):
        code, status, V_out, state = _draw_many(c_table, mix, opts)
        assert code == INVALID and np.all(status == INVALID) and np.isnan(V_out).all() and state == [1, 2, 3, 4]
    smooth = _draw_many(c_smooth, smooth_mix, None)
    zero = _draw_many(c_rough, rough_mix, options(roughness_deg=0.0))
    assert smooth[0] == zero[0] == OK and np.all(smooth[1] == OK)
    assert smooth[1].tobytes() == zero[1].tobytes() and smooth[2].tobytes() == zero[2].tobytes()
    assert smooth[3] == zero[3] != [1, 2, 3, 4]
