"""A table built from a configuration's user grains (tests/conftest.py, grain_table_path: a mesh file and a list of
points) loads in C with the records Python reads, and each grain drawn by name gives the same bits in C and numba,
on the table path (1000 draws, stochastic and scaled interpolation) and on the direct path (spinning or not)."""

from __future__ import annotations

import numpy as np
import pytest

from tests.helpers import python_side as py
from tests.helpers.native_library import (FAMILY_NONE, INTERPOLATION_SCALED, INTERPOLATION_STOCHASTIC,
                                          METHOD_DIRECT)

NAMES = ("sand_a", "sand_b")


def test_the_grain_table_loads_alike_in_c(native, grain_table_path):
    table, c_table = py.load(grain_table_path), native.table(grain_table_path)
    arrays = table.shape_datasets
    try:
        assert c_table.shapes == table.shapes == NAMES
        for i in range(len(NAMES)):
            info = c_table.shape_info(i)
            start, stop = arrays["vertex_start"][i], arrays["vertex_start"][i + 1]
            assert info["family"] == FAMILY_NONE and table.model_shapes[i] == 4 + i
            assert info["vertices"].tobytes() == arrays["vertices"][start:stop].tobytes()
            assert info["inertia"].tobytes() == arrays["inertia"][i].tobytes()
    finally:
        c_table.close()


@pytest.mark.parametrize("interpolation", [INTERPOLATION_SCALED, INTERPOLATION_STOCHASTIC])
def test_each_grain_draws_the_same_bits_in_c_and_numba_on_the_table_path(native, grain_table_path, interpolation):
    table, c_table = py.load(grain_table_path), native.table(grain_table_path)
    n = 1000
    rng = np.random.default_rng(35)
    alpha1 = np.radians(rng.uniform(30.0, 70.0, n))
    speed = rng.uniform(100.0, 200.0, n)
    V = np.stack([speed * np.cos(alpha1), -speed * np.sin(alpha1), np.zeros(n)], axis=1)
    normal, a = np.tile([0.0, 1.0, 0.0], (n, 1)), np.full(n, 1e-4)
    try:
        for name in NAMES:
            u = rng.random((n, py.U_PER_DRAW))
            mix, message = c_table.mix_new(name)
            assert mix is not None, message
            status, c_V, c_W = c_table.draw_many(mix, V, normal, a, u, interpolation=interpolation)
            V_out, W_out, py_status = np.empty((n, 3)), np.empty((n, 3)), np.empty(n, dtype=np.int8)
            py.table_rebound_many(table.kernel_data, py.mix_cdf(table, name), V, normal, a, u, V_out, W_out,
                                  py_status, interpolation == INTERPOLATION_SCALED)
            assert np.array_equal(status, py_status) and c_V.tobytes() == V_out.tobytes(), name
            assert c_W.tobytes() == W_out.tobytes(), name
            assert np.mean(status == py.STATUS_REBOUNDED) > 0.9, name
    finally:
        c_table.close()


def test_each_grain_rebounds_the_same_bits_in_c_and_numba_on_the_direct_path(native, grain_table_path):
    table, c_table = py.load(grain_table_path), native.table(grain_table_path)
    rng = np.random.default_rng(36)
    try:
        for name in NAMES:
            mix, message = c_table.mix_new(shape=name)
            assert mix is not None, message
            cdf = py.mix_cdf(table, name)
            for alpha1, omega in ((20.0, (0.0, 0.0, 0.0)), (55.0, (0.0, 0.0, 3e5)), (85.0, (2e5, -1e5, 0.0))):
                for _ in range(5):
                    V = np.array([120.0 * np.cos(np.radians(alpha1)), -120.0 * np.sin(np.radians(alpha1)), 0.0])
                    u = rng.random(py.U_PER_DRAW)
                    c = c_table.rebound(mix, V, np.array(omega), np.array([0.0, 1.0, 0.0]), 1e-4, u,
                                        method=METHOD_DIRECT)
                    p = py.rebound(table.kernel_data, table.direct_parameters, table.shape_arrays, table.model_shapes,
                                   cdf, tuple(V), omega, (0.0, 1.0, 0.0), 1e-4, u, py.METHOD_DIRECT)
                    assert c[0] == p.status != py.STATUS_INVALID, (name, alpha1, c[0], p.status)
                    assert np.array_equal(c[1], np.array(p.V), equal_nan=True), (name, alpha1)
                    assert np.array_equal(c[2], np.array(p.Omega), equal_nan=True), (name, alpha1)
    finally:
        c_table.close()
