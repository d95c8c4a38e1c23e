"""A grain of 10 000 hull vertices (tests/conftest.py, big_grain_table_path): numba searches its contact by walks
over the hull's vertex graph (direct_model.hull_walk), C scans every vertex with its work space on the heap
(native/src/runtime.c, above MAX_STACK_VERTICES); both give the same bits. C loads the table with the grain's
10 000 vertices, and its hits on the direct path, spinning or not, and on the table path equal numba's, field by
field (status, path, shape, collisions, V⁺, Ω⁺)."""

from __future__ import annotations

import numpy as np

from tests.helpers import python_side as py
from tests.helpers.native_library import FAMILY_NONE, METHOD_DIRECT, METHOD_TABLE, PATH_DIRECT, PATH_TABLE
from direct_model.shape_arrays import particle_hull
from tests.helpers.tables import BIG_GRAIN_VERTICES

HITS = 150      # half of them spinning; C scans the 10 000 vertices at every search step (about a millisecond a hit)


def test_the_big_grain_loads_in_c_with_its_vertices(native, big_grain_table_path):
    table, c_table = py.load(big_grain_table_path), native.table(big_grain_table_path)
    arrays = table.shape_datasets
    try:
        assert c_table.shapes == table.shapes == ("scan",)
        info = c_table.shape_info(0)
        assert info["n_vertices"] == BIG_GRAIN_VERTICES == len(arrays["vertices"]) and info["family"] == FAMILY_NONE
        assert info["vertices"].tobytes() == arrays["vertices"].tobytes()
        assert info["inertia"].tobytes() == arrays["inertia"][0].tobytes()
        # numba walks this hull: the hits below set the walk against C's scan
        shape = table.model_shapes[0]
        assert shape == 4 and len(particle_hull.py_func(table.shape_arrays, shape, np.ones(3))[2]) > 0
    finally:
        c_table.close()


def _hits(rng):
    """HITS incident states in random frames: V⁻ (m/s) at α1 in [3°, 89°] and 50..300 m/s onto a random wall
    normal n, half-size a (m), Ω⁻ (rad/s) zero for the even rows, of |Ω⁻|a/|V⁻| in [0.01, 1] for the odd ones."""
    n = rng.normal(size=(HITS, 3))
    n /= np.linalg.norm(n, axis=1)[:, None]
    along = rng.normal(size=(HITS, 3))
    along -= np.einsum("ij,ij->i", along, n)[:, None] * n
    along /= np.linalg.norm(along, axis=1)[:, None]
    alpha1, speed = np.radians(rng.uniform(3.0, 89.0, HITS)), rng.uniform(50.0, 300.0, HITS)
    V = speed[:, None] * (np.cos(alpha1)[:, None] * along - np.sin(alpha1)[:, None] * n)
    a = 10.0 ** rng.uniform(-5.0, -3.0, HITS)
    axis = rng.normal(size=(HITS, 3))
    axis /= np.linalg.norm(axis, axis=1)[:, None]
    omega = (rng.uniform(0.01, 1.0, HITS) * speed / a)[:, None] * axis
    omega[::2] = 0.0
    return V, omega, n, a


def test_the_big_grain_rebounds_with_the_bits_of_numba_s_walk(native, big_grain_table_path):
    """rbs_rebound under RBS_METHOD_DIRECT and RBS_METHOD_TABLE, the same hits and uniforms: numba's rebound's
    record, bit for bit; at least 9 in 10 direct hits rebound, spinning and not."""
    table, c_table = py.load(big_grain_table_path), native.table(big_grain_table_path)
    rng = np.random.default_rng(56)
    V, omega, n, a = _hits(rng)
    u = rng.random((HITS, py.U_PER_DRAW))
    cdf = py.mix_cdf(table, "scan")
    try:
        mix = c_table.mix()
        for method, path in ((METHOD_DIRECT, PATH_DIRECT), (METHOD_TABLE, PATH_TABLE)):
            rebounded = np.zeros(HITS, dtype=bool)
            for i in range(HITS):
                result, _ = c_table.hit(mix, V[i], omega[i], n[i], a[i], u[i], method=method)
                mine = py.rebound(table.kernel_data, table.direct_parameters, table.shape_arrays, table.model_shapes,
                                  cdf, tuple(V[i]), tuple(omega[i]), tuple(n[i]), a[i], u[i], method)
                assert (result.status, result.path, result.shape, result.n_collisions) == tuple(mine[:4]), (i, method)
                assert result.path == path, (i, method)
                assert np.array(result.V[:]).tobytes() == np.array(mine.V, dtype=np.float64).tobytes(), (i, method)
                assert np.array(result.Omega[:]).tobytes() == np.array(mine.Omega, dtype=np.float64).tobytes(), \
                    (i, method)
                rebounded[i] = result.status == py.STATUS_REBOUNDED
            if method == METHOD_DIRECT:
                assert rebounded[::2].mean() >= 0.9 and rebounded[1::2].mean() >= 0.9, rebounded
    finally:
        c_table.close()
