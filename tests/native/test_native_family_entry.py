"""A family entered in the registry by the tests alone (tests/helpers/families.py: the octahedron) loads in C from
its table's record, though the C library knows only the paper's four, and is drawn by name with the bits of numba
on the table and on the direct path (spinning or not)."""

from __future__ import annotations

import numpy as np

from tests.helpers import python_side as py
from tests.helpers.native_library import FAMILY_NONE, INTERPOLATION_SCALED, METHOD_DIRECT


def test_c_draws_the_entry_from_its_record_with_the_bits_of_numba(native, octahedron_table_path):
    table, c_table = py.load(octahedron_table_path), native.table(octahedron_table_path)
    rng = np.random.default_rng(45)
    try:
        info = c_table.shape_info(1)
        assert info["family"] == FAMILY_NONE and table.model_shapes[1] == 4
        assert info["vertices"].tobytes() == table.shape_datasets["vertices"][8:14].tobytes()
        mix, message = c_table.mix_new(shape="octahedron")
        assert mix is not None, message
        cdf = py.mix_cdf(table, "octahedron")
        n = 500
        alpha1, speed = np.radians(rng.uniform(30.0, 70.0, n)), rng.uniform(100.0, 200.0, n)
        V = np.stack([speed * np.cos(alpha1), -speed * np.sin(alpha1), np.zeros(n)], axis=1)
        normal, a, u = np.tile([0.0, 1.0, 0.0], (n, 1)), np.full(n, 1e-4), rng.random((n, py.U_PER_DRAW))
        status, c_V, c_W = c_table.draw_many(mix, V, normal, a, u, interpolation=INTERPOLATION_SCALED)
        V_out, W_out, py_status = np.empty((n, 3)), np.empty((n, 3)), np.empty(n, dtype=np.int8)
        py.table_rebound_many(table.kernel_data, cdf, V, normal, a, u, V_out, W_out, py_status, True)
        assert np.array_equal(status, py_status) and np.mean(status == py.STATUS_REBOUNDED) > 0.9
        assert c_V.tobytes() == V_out.tobytes() and c_W.tobytes() == W_out.tobytes()
        for omega in ((0.0, 0.0, 0.0), (0.0, 0.0, 3e5), (2e5, -1e5, 0.0)):
            for k in range(5):
                u1 = rng.random(py.U_PER_DRAW)
                c = c_table.rebound(mix, V[k], np.array(omega), np.array([0.0, 1.0, 0.0]), 1e-4, u1,
                                    method=METHOD_DIRECT)
                p = py.rebound(table.kernel_data, table.direct_parameters, table.shape_arrays, table.model_shapes,
                               cdf, tuple(V[k]), omega, (0.0, 1.0, 0.0), 1e-4, u1, py.METHOD_DIRECT)
                assert c[0] == p.status != py.STATUS_INVALID, (omega, c[0], p.status)
                assert np.array_equal(c[1], np.array(p.V), equal_nan=True), omega
                assert np.array_equal(c[2], np.array(p.Omega), equal_nan=True), omega
    finally:
        c_table.close()
