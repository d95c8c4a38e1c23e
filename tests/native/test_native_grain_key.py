"""Grain keys in C (rbs_rebound of a hit with a grain key, its uniforms given or drawn from an rbs_rng;
rbs_grain_info, rbs_grain_key) give the bits of their numba twins (surrogate.kernels.wall_hit.rebound with ``key``,
surrogate.grain_of, surrogate.grain_key): 0 ulp over the hostile states of test_native_spin (spinning and not, the
three methods, both paths), on the families' small table with a weighted mix, on the table of user grains (one of
random proportions in both hands, one fixed) and on a table of 64 shapes.
A key below RBS_NO_KEY (−1, no key) is refused; the 13 uniforms are checked whatever the key fixes; a keyed hit
advances a stream by 13."""

from __future__ import annotations

import numpy as np
import pytest

from tests.helpers import python_side as py
from tests.helpers.native_library import (INVALID, METHOD_AUTO, METHOD_DIRECT, METHOD_TABLE, OK, PATH_NONE, Grain,
                                          ref)
from tests.helpers.states import max_ulp
from tests.native.test_native_spin import spin_states

AUTO, TABLE, DIRECT = METHOD_AUTO, METHOD_TABLE, METHOD_DIRECT
METHODS = {"auto": AUTO, "table": TABLE, "direct": DIRECT}
KEYS = 400      # keys compared per table: every shape of a mix of 2 to 4 shapes is hit many times


def _keys(rng, count):
    """Keys over the whole range [0, 2**63): small, large and the ends."""
    keys = rng.integers(0, 2 ** 63 - 1, count, dtype=np.int64, endpoint=True)
    keys[:4] = 0, 1, 2 ** 63 - 1, 2 ** 62
    return keys


def _numba(table, cdf, V, omega, n, a, u, method, key):
    return py.rebound(table.kernel_data, table.direct_parameters, table.shape_arrays, table.model_shapes, cdf,
                      tuple(V), tuple(omega), tuple(n), a, u, method, True, key)


def test_grain_key_is_surrogates(native):
    rng = np.random.default_rng(351)
    words = rng.integers(0, 2 ** 64 - 1, (200, 3), dtype=np.uint64, endpoint=True)
    words[:3] = [[0, 0, 0], [2 ** 64 - 1] * 3, [1, 0, 2]]
    expected = py.grain_key(words[:, 0], words[:, 1], words[:, 2])
    got = np.array([native.grain_key(*map(int, w)) for w in words])
    assert np.array_equal(got, expected) and np.all(got >= 0)
    assert native.grain_key(7, 3, 11) == py.grain_key(7, 3, 11)


@pytest.fixture(scope="module", params=["small", "grains", "64 shapes"])
def keyed_case(request, native, small_table_path, grain_table_path, tmp_path_factory):
    """(numba's table, C's table, C mix, its cdf) with a weighted mix over every shape of the small table (the
    four families), of the user grains' table, or of a table of 64 shapes (a mix sized by the table, user grains
    of random and fixed proportions, in one hand and both: tests.helpers.python_side.many_shape_table)."""
    path = {"small": small_table_path, "grains": grain_table_path}.get(request.param)
    if path is None:
        path = tmp_path_factory.mktemp("many") / "many_shapes.h5"
        py.many_shape_table(small_table_path, path, 64)
    table, c_table = py.load(path), native.table(path)
    weights = dict(zip(table.shapes, np.arange(1.0, len(table.shapes) + 1) / sum(range(1, len(table.shapes) + 1))))
    mix, message = c_table.mix_new(weights=weights)
    assert mix is not None, message
    yield table, c_table, mix, py.mix_cdf(table, weights)
    c_table.close()


def test_grain_info_is_grain_of(keyed_case):
    table, c_table, mix, cdf = keyed_case
    keys = _keys(np.random.default_rng(352), 4 * KEYS)
    weights = dict(zip(table.shapes, np.diff(cdf, prepend=0.0)))
    grains = py.grain_of(table, keys, weights)
    seen_random = 0
    for i, key in enumerate(keys):
        code, grain = c_table.grain_info(mix, int(key))
        assert code == OK
        assert table.shapes[grain["shape"]] == grains.shape[i], i
        for name in ("ratio_ba", "ratio_cb", "hand"):
            assert np.float64(grain[name]).tobytes() == np.float64(getattr(grains, name)[i]).tobytes(), (i, name)
        seen_random += not np.isnan(grain["ratio_ba"])
    assert seen_random > len(keys) // 5     # shapes of random proportions are a third of the weight or more
    assert len(set(grains.shape)) > 0.8 * len(table.shapes)


@pytest.mark.parametrize("method", sorted(METHODS))
def test_keyed_hits_equal_numba(keyed_case, method):
    """rbs_rebound of a keyed hit = numba's rebound with the key, status and bits, over hostile states and keys; the
    result's shape is the key's (rbs_grain_info's)."""
    table, c_table, mix, cdf = keyed_case
    V, omega, kind, n, a, u = spin_states(table)
    keys = _keys(np.random.default_rng(353), len(a))
    code = METHODS[method]
    statuses = []
    for i in range(0, len(a), 3):
        result, _ = c_table.hit(mix, V[i], omega[i], n[i], a[i], u[i], key=int(keys[i]), method=code)
        st, v, w = result.status, np.array(result.V[:]), np.array(result.Omega[:])
        mine = _numba(table, cdf, V[i], omega[i], n[i], a[i], u[i], code, int(keys[i]))
        assert (st, result.path, result.shape, result.n_collisions) == mine[:4], (i, result, mine)
        assert max_ulp(v, np.array(mine.V)) == 0 and max_ulp(w, np.array(mine.Omega)) == 0, i
        if st == INVALID:
            assert (result.path, result.shape) == (PATH_NONE, -1), i
        else:
            assert result.shape == c_table.grain_info(mix, int(keys[i]))[1]["shape"], i
        statuses.append(st)
    assert np.mean(np.array(statuses) == py.STATUS_REBOUNDED) > 0.4


def test_a_key_fixes_the_grain_not_the_stream(keyed_case, native):
    """Keyed hits of one grain: on the direct path (a spinning particle) the rebound is the same whatever u[0] and
    u[4..6] (the shape, proportions and hand are the key's), on the table path whatever u[0] (the shape); a keyed hit
    drawing from an rng is rbs_rng_fill of 13 uniforms, then the keyed hit with them."""
    table, c_table, mix, cdf = keyed_case
    rng = np.random.default_rng(354)
    V, omega, n = np.array([80.0, -60.0, 5.0]), np.array([0.0, 0.0, 3e5]), np.array([0.0, 1.0, 0.0])
    state = py.seed_state(355)
    for key in _keys(rng, 30):
        u = rng.random(py.U_PER_DRAW)
        for method, keyed_slots in ((AUTO, [0, 4, 5, 6]), (DIRECT, [0, 4, 5, 6]), (TABLE, [0])):
            other = u.copy()
            other[keyed_slots] = rng.random(len(keyed_slots))
            first = c_table.rebound(mix, V, omega, n, 1e-4, u, key=int(key), method=method)
            again = c_table.rebound(mix, V, omega, n, 1e-4, other, key=int(key), method=method)
            assert first[0] == again[0] and first[1].tobytes() == again[1].tobytes(), (key, method)
            u_i, after = native.fill(state, py.U_PER_DRAW)
            st, v, w, advanced = c_table.rebound(mix, V, omega, n, 1e-4, state=state, key=int(key), method=method)
            given = c_table.rebound(mix, V, omega, n, 1e-4, u_i, key=int(key), method=method)
            assert np.array_equal(advanced, after) and st == given[0] and v.tobytes() == given[1].tobytes()
            state = advanced


def test_bad_keys_and_uniforms_are_refused(keyed_case, native, small_table_path):
    """A key < −1 is refused (−1 is RBS_NO_KEY: the hit of a particle without a key), and by rbs_grain_info any key
    < 0, a NULL pointer or a mix of another table, nothing written; a keyed slot's uniform is still checked."""
    table, c_table, mix, cdf = keyed_case
    V, omega, n = np.array([80.0, -60.0, 5.0]), np.zeros(3), np.array([0.0, 1.0, 0.0])
    u = np.full(py.U_PER_DRAW, 0.5)
    unkeyed = c_table.rebound(mix, V, omega, n, 1e-4, u)
    assert unkeyed[0] != INVALID
    assert c_table.rebound(mix, V, omega, n, 1e-4, u, key=-1)[1].tobytes() == unkeyed[1].tobytes()
    for key in (-2, -3, -2 ** 63):
        st, v, w = c_table.rebound(mix, V, omega, n, 1e-4, u, key=key)
        assert st == INVALID and np.isnan(v).all() and np.isnan(w).all()
        assert _numba(table, cdf, V, omega, n, 1e-4, u, AUTO, key)[0] == py.STATUS_INVALID
    for key in (-1, -2, -2 ** 63):
        assert c_table.grain_info(mix, key) == (INVALID, None)
    other = native.table(small_table_path)
    other_mix = other.mix()
    for table_handle, mix_pointer, record in ((None, mix.pointer, Grain()), (c_table.handle, None, Grain()),
                                              (c_table.handle, mix.pointer, None),
                                              (c_table.handle, other_mix.pointer, Grain())):
        if record is not None:
            record.shape, record.ratio_ba = 77, 7.0
        assert native.c.rbs_grain_info(table_handle, mix_pointer, 5, ref(record)) == INVALID
        assert record is None or (record.shape, record.ratio_ba) == (77, 7.0)
    del other_mix
    other.close()
    for k in (0, 4, 5, 6, 12):          # a keyed slot's uniform is replaced, but still checked
        bad = u.copy()
        bad[k] = 1.0
        for method in METHODS.values():
            st, v, _ = c_table.rebound(mix, V, omega, n, 1e-4, bad, key=5, method=method)
            assert st == INVALID and np.isnan(v).all(), (k, method)
            assert _numba(table, cdf, V, omega, n, 1e-4, bad, method, 5)[0] == py.STATUS_INVALID
