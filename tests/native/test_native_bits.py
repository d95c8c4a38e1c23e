"""The native library draws the same bits as surrogate's numba kernels, for the same uniforms.

Over random incident states (random unit normals; α1 and |V⁻| over and beyond the table's grid; exact
normal impact, grazing, trapped cells, invalid input), every shape alone, the equal mix and a weighted
mix, both interpolations: V⁺, Ω⁺ and the status of rbs_draw_many equal those of
surrogate.kernels.table_rebound_many; rbs_rebound under RBS_METHOD_TABLE row by row equals rbs_draw_many and
table_rebound; the mixes draw the shapes of surrogate.mix_cdf (bit for bit at the cdf's boundaries); the local
draw, the derived kernel arrays, the table's sizes, grids and wall, and the random numbers equal surrogate's. The
largest ulp difference is printed (run with -s to see it) and must be 0.
"""

from __future__ import annotations

import numpy as np
import pytest

from tests.helpers import python_side as py
from tests.helpers.native_library import (INTERPOLATION_SCALED, INTERPOLATION_STOCHASTIC, INVALID, METHOD_TABLE,
                                          PATH_NONE, PATH_TABLE, mix_probes)
from tests.helpers.states import incident_states, max_ulp, uniforms

KERNEL_ARRAYS = ("alpha1_axis", "speed_axis", "cells", "clusters", "dictionary", "speed_restitution",
                 "restitution_pieces", "work_rows", "work_dictionary", "work_cells")
STATES_PER_CASE = 100_000
SCALED, STOCHASTIC = INTERPOLATION_SCALED, INTERPOLATION_STOCHASTIC
INTERPOLATIONS = {"scaled": SCALED, "stochastic": STOCHASTIC}


def _mixes(table):
    shapes = list(table.shapes)
    weights = dict(zip(shapes, np.linspace(1.0, 2.0, len(shapes)) / np.linspace(1.0, 2.0, len(shapes)).sum()))
    return [(s, s) for s in shapes] + [("mix", "mix"), ("weighted", weights)]


def _native_mix(native_table, spec):
    return native_table.mix(spec)


def test_derived_kernel_arrays_equal_surrogate(table_pair):
    table, native_table = table_pair
    data = table.kernel_data
    for name in KERNEL_ARRAYS:
        expected, got = np.asarray(getattr(data, name)), native_table.kernel_array(name)
        assert got.dtype == expected.dtype and got.shape == expected.shape, name
        assert np.array_equal(got.view(np.uint8), expected.view(np.uint8)), f"{name} differs"
    assert data.has_work and data.work_rows.size > 0, "the work arrays compared are empty"
    info = native_table.info()
    assert (info.n_shapes, info.n_alpha1, info.n_speed) == (data.n_shapes, data.n_alpha1, data.n_speed)
    assert (info.n_clusters, info.n_levels, info.n_dictionary, info.n_pieces) == \
        (data.n_clusters, data.n_levels, data.n_dictionary, data.n_pieces)
    assert info.kernel_bytes == data.nbytes
    assert (info.particles_per_cell, info.n_max) == (table.particles_per_cell, table.n_max)
    assert native_table.shapes == tuple(table.shapes)
    assert native_table.ranges() == (table.alpha1_range, table.speed_range)
    alpha1, speed = native_table.grids()
    assert alpha1.tobytes() == np.asarray(table.alpha1_deg).tobytes()
    assert speed.tobytes() == np.asarray(table.speed_m_s).tobytes()
    assert native_table.lib.c.rbs_table_path(native_table.handle).decode() == str(native_table.path) == table.path


def test_the_wall_is_the_table_s(table_pair):
    """rbs_table_wall: the wall's law family, its name and its parameters by name in the family's order, as
    data_schema reads them from the table (group /wall), bit for bit; no arrays (the exponential family's)."""
    from data_schema.table import read_table
    from direct_model.wall import wall_family
    table, native_table = table_pair
    stored = read_table(table.path).wall
    family = wall_family(stored.family)
    wall = native_table.wall()
    assert (wall["family"], wall["name"]) == (family.name, stored.name), wall
    assert list(wall["parameters"]) == list(family.parameter_names), wall
    assert np.array(list(wall["parameters"].values())).tobytes() == \
        np.array(list(stored.parameters().values()), float).tobytes()
    assert wall["arrays"] == {} == stored.arrays()


def test_mixes_equal_mix_cdf(table_pair):
    """Each mix draws, for every u[0], the shape surrogate's mix_shape draws from surrogate.mix_cdf: at and just
    below every boundary of the cdf (so its values are the same bits) and at random; rbs_result.shape says which."""
    table, native_table = table_pair
    rng = np.random.default_rng(12)
    for _, spec in _mixes(table):
        mix = _native_mix(native_table, spec)
        expected = py.mix_cdf(table, spec)
        u0 = np.concatenate([mix_probes(expected), rng.random(200)])
        got = native_table.shapes_drawn(mix, u0)
        assert got.tolist() == [py.mix_shape(expected, x) for x in u0], spec
    cdf = py.mix_cdf(table, "mix")
    for spec in (None, "mix"):      # rbs_mix_new_equal, and rbs_mix_new_from_shape's "mix"
        mix, message = native_table.mix_new(spec)
        assert mix is not None, message
        u0 = mix_probes(cdf)
        assert native_table.shapes_drawn(mix, u0).tolist() == [py.mix_shape(cdf, x) for x in u0], spec


@pytest.mark.parametrize("interpolation", sorted(INTERPOLATIONS))
def test_rebound_many_bit_identical(table_pair, interpolation):
    """1e5 random incident states per mix (six mixes), rbs_draw_many against surrogate.kernels.table_rebound_many."""
    table, native_table = table_pair
    (a_lo, a_hi), (v_lo, v_hi) = table.alpha1_range, table.speed_range
    worst = {}
    for k, (label, spec) in enumerate(_mixes(table)):
        rng = np.random.default_rng(1000 + k)
        V, n, a = incident_states(rng, STATES_PER_CASE, (0.0, 90.0), (0.2 * v_lo, 1.5 * v_hi))
        u = uniforms(rng, STATES_PER_CASE, hostile=0.01)
        cdf = py.mix_cdf(table, spec)
        V_py, W_py = np.empty((STATES_PER_CASE, 3)), np.empty((STATES_PER_CASE, 3))
        status_py = np.empty(STATES_PER_CASE, dtype=np.int8)
        py.table_rebound_many(table.kernel_data, cdf, V, n, a, u, V_py, W_py, status_py, interpolation == "scaled")
        status, V_c, W_c = native_table.draw_many(_native_mix(native_table, spec), V, n, a, u,
                                                  interpolation=INTERPOLATIONS[interpolation])
        assert np.array_equal(status, status_py), label
        counts = {s: int(np.sum(status == s)) for s in (py.STATUS_REBOUNDED, py.STATUS_TRAPPED, py.STATUS_INVALID)}
        assert counts[py.STATUS_REBOUNDED] > 0.7 * STATES_PER_CASE and counts[py.STATUS_INVALID] > 0
        if label in ("ellipsoid", "mix"):
            assert counts[py.STATUS_TRAPPED] > 0, "no trapped draw: the trapped cells are not exercised"
        worst[label] = (max_ulp(V_c, V_py), max_ulp(W_c, W_py))
        rebounded = status == py.STATUS_REBOUNDED       # finite and leaving the wall, whatever the input
        assert np.isfinite(V_c[rebounded]).all() and np.isfinite(W_c[rebounded]).all(), label
        assert (np.einsum("ij,ij->i", V_c[rebounded], n[rebounded]) > 0.0).all(), label
        assert np.isnan(V_c[~rebounded]).all() and np.isnan(W_c[~rebounded]).all(), label
    print(f"\nlargest ulp difference, {interpolation}, {STATES_PER_CASE} states per mix (V+, Omega+): {worst}")
    assert all(v == (0.0, 0.0) for v in worst.values()), worst


def test_single_calls_equal_many_and_rebound_tuple(table_pair):
    """rbs_rebound under RBS_METHOD_TABLE row by row = rbs_draw_many = surrogate's table_rebound, both
    interpolations; each result says the table path answered (n_collisions −1) and which shape the mix gave, and
    an invalid hit says no path and no shape."""
    table, native_table = table_pair
    rng = np.random.default_rng(7)
    count = 3000
    (v_lo, v_hi) = table.speed_range
    V, n, a = incident_states(rng, count, (0.0, 90.0), (0.2 * v_lo, 1.5 * v_hi))
    u = uniforms(rng, count, hostile=0.01)
    mix = native_table.mix()
    cdf = py.mix_cdf(table, "mix")
    omega = np.zeros(3)
    for interpolation in (SCALED, STOCHASTIC):
        status, V_many, W_many = native_table.draw_many(mix, V, n, a, u, interpolation=interpolation)
        for i in range(count):
            result, _ = native_table.hit(mix, V[i], omega, n[i], a[i], u[i], method=METHOD_TABLE,
                                         interpolation=interpolation)
            st, v, w = result.status, np.array(result.V[:]), np.array(result.Omega[:])
            hit = py.table_rebound(table.kernel_data, cdf, tuple(V[i]), tuple(n[i]), a[i], u[i],
                                   interpolation == SCALED)
            st_py, v_py, w_py = hit.status, hit.V, hit.Omega
            assert st == status[i] == st_py, i
            assert max_ulp(v, V_many[i]) == 0 and max_ulp(w, W_many[i]) == 0, i
            assert max_ulp(v, np.array(v_py)) == 0 and max_ulp(w, np.array(w_py)) == 0, i
            if st == INVALID:
                assert (result.path, result.shape, result.n_collisions) == (PATH_NONE, -1, -1), i
            else:
                assert (result.path, result.n_collisions) == (PATH_TABLE, -1), i
                assert result.shape == py.mix_shape(cdf, u[i][0]), i


def test_draw_local_bit_identical(table_pair):
    table, native_table = table_pair
    rng = np.random.default_rng(11)
    count = 20000
    (v_lo, v_hi) = table.speed_range
    alpha1 = rng.uniform(0.0, 95.0, count)
    speed = rng.uniform(0.5 * v_lo, 1.5 * v_hi, count)
    alpha1[:50] = table.alpha1_deg[rng.integers(0, len(table.alpha1_deg), 50)]      # on the grid
    speed[50:100] = table.speed_m_s[rng.integers(0, len(table.speed_m_s), 50)]
    hostile = np.array([np.nan, -5.0, 0.0, np.inf, 1e30, 1e-300, -np.inf, 1e25])      # refused, or the grid's edge
    alpha1[100:200], speed[200:300] = rng.choice(hostile, 100), rng.choice(hostile, 100)
    u = uniforms(rng, count, hostile=0.01)
    worst = 0.0
    for label, spec in _mixes(table)[-2:]:
        mix, cdf = _native_mix(native_table, spec), py.mix_cdf(table, spec)
        for interpolation in (SCALED, STOCHASTIC):
            for i in range(0, count, 2 if interpolation == SCALED else 4):
                st, out = native_table.draw_local(mix, alpha1[i], speed[i], u[i], interpolation)
                expected = py.draw_local(table.kernel_data, cdf, alpha1[i], speed[i], u[i], interpolation == SCALED)
                assert st == expected[0], (label, i)
                worst = max(worst, max_ulp(out, np.array(expected[1:])))
    print(f"\nlargest ulp difference of the local draw: {worst}")
    assert worst == 0.0


SEEDS = [0, 1, 2, 12345, 2**31 - 1, 2**32 - 1, 2**32, 2**32 + 1, 2**53 + 7, 2**63, 2**64 - 1]


def test_seeds_equal_seed_state(native):
    seeds = SEEDS + [int(s) for s in np.random.default_rng(3).integers(0, 2**63, 200, dtype=np.uint64)]
    seeds += [int(s) for s in np.random.default_rng(4).integers(0, 2**32, 100, dtype=np.uint64)]
    for seed in seeds:
        assert np.array_equal(native.seed(seed), py.seed_state(seed)), seed
        streams = py.seed_state(seed, n_streams=5)
        for k in range(5):
            assert np.array_equal(native.seed(seed, k), streams[k]), (seed, k)
    for seed in SEEDS[:4]:
        streams = py.seed_state(seed, n_streams=70)
        for k in (0, 1, 33, 69):
            assert np.array_equal(native.seed(seed, k), streams[k]), (seed, k)


def test_uniforms_equal_fill_uniforms(native):
    for seed in SEEDS:
        state = py.seed_state(seed)
        u_py = np.empty(1000)
        py_state = state.copy()
        py.fill_uniforms(py_state, u_py)
        u_c, c_state = native.fill(state, 1000)
        assert np.array_equal(u_c, u_py) and np.array_equal(c_state, py_state), seed
        x, after = native.uniform(state)
        assert x == u_py[0]


def test_block_uniforms_and_rebound_many_rng(table_pair, native):
    """rbs_draw_many_uniforms = table_rebound_uniforms and rbs_draw_many with an rng = table_rebound_many_rng, bit
    for bit (the rng advanced alike), for row counts on and off the 32-row blocks."""
    table, native_table = table_pair
    mix, cdf = native_table.mix(), py.mix_cdf(table, "mix")
    rng = np.random.default_rng(5)
    for count in (0, 1, 31, 32, 33, 1000, 20001):
        state = py.seed_state(count + 9)
        u_py = py.table_rebound_uniforms(state.copy(), count)
        u_c, _ = native.draw_many_uniforms(state, count)
        assert np.array_equal(u_c, u_py), count
        V, n, a = incident_states(rng, count)
        for interpolation in (SCALED, STOCHASTIC):
            V_py, W_py, status_py = np.empty((count, 3)), np.empty((count, 3)), np.empty(count, dtype=np.int8)
            py_state = state.copy()
            py.table_rebound_many_rng(table.kernel_data, cdf, V, n, a, py_state, V_py, W_py, status_py,
                                interpolation == SCALED)
            status, V_c, W_c, c_state = native_table.draw_many(mix, V, n, a, state=state, interpolation=interpolation)
            assert np.array_equal(status, status_py) and np.array_equal(c_state, py_state), count
            assert max_ulp(V_c, V_py) == 0 and max_ulp(W_c, W_py) == 0, count


def test_baseline_build_gives_the_same_bits(native_baseline, table_pair, small_table_path):
    """Built without the x86-64-v3 versions (fma() from the C library instead of the instruction), the
    library still gives numba's bits."""
    table, _ = table_pair
    baseline = native_baseline.table(small_table_path)
    rng = np.random.default_rng(21)
    count = 50_000
    V, n, a = incident_states(rng, count)
    u = uniforms(rng, count, hostile=0.01)
    cdf = py.mix_cdf(table, "mix")
    for interpolation in (SCALED, STOCHASTIC):
        V_py, W_py, status_py = np.empty((count, 3)), np.empty((count, 3)), np.empty(count, dtype=np.int8)
        py.table_rebound_many(table.kernel_data, cdf, V, n, a, u, V_py, W_py, status_py, interpolation == SCALED)
        mix = baseline.mix()
        status, V_c, W_c = baseline.draw_many(mix, V, n, a, u, interpolation=interpolation)
        assert np.array_equal(status, status_py)
        assert max_ulp(V_c, V_py) == 0 and max_ulp(W_c, W_py) == 0
        for i in range(0, count, 500):
            st, v, w = baseline.rebound(mix, V[i], np.zeros(3), n[i], a[i], u[i], method=METHOD_TABLE,
                                        interpolation=interpolation)
            assert st == status_py[i] and max_ulp(v, V_py[i]) == 0 and max_ulp(w, W_py[i]) == 0
