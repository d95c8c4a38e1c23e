"""The loaded table: read-only, the file's law in the kernel arrays, the alias tables, the runtime's imports."""

import subprocess
import sys

import numpy as np
import pytest

import surrogate
from data_schema.samples import STATUS_REBOUNDED, STATUS_TRAPPED
from surrogate.kernels.layout import (CELL_MEAN, CELL_SD, CELL_SIZE, ROW_LOC, ROW_SCALE, ROW_SHAPE, ROW_SLOPE,
                                      WORK_CELL_MEAN, WORK_CELL_SD, WORK_CELL_SIZE, WORK_CELL_TRAPPED, WORK_ROW_LOC,
                                      WORK_ROW_SCALE, WORK_ROW_SHAPE, WORK_ROW_SIZE, WORK_ROW_SLOPE, alias_table)


def test_runtime_does_not_import_tablegen():
    """surrogate and the direct model (every module of both) run without tablegen: the plain install."""
    code = ("import pkgutil, importlib, sys, surrogate, direct_model; "
            "[importlib.import_module(m.name) for p in (surrogate, direct_model) "
            "for m in pkgutil.walk_packages(p.__path__, p.__name__ + '.')]; "
            "sys.exit(any(m == 'tablegen' or m.startswith('tablegen.') for m in sys.modules))")
    assert subprocess.run([sys.executable, "-c", code]).returncode == 0


def test_loaded_table_is_immutable(small_table):
    with pytest.raises(ValueError):
        small_table.kernel_data.clusters[0] = 1.0
    with pytest.raises(ValueError):
        small_table.kernel_data.rows()[0, 0, 0, 0, 0] = 1.0
    arrays = [a for a in small_table.kernel_data if isinstance(a, np.ndarray)]
    assert len(arrays) == 10 and all(a.flags.c_contiguous and not a.flags.writeable for a in arrays)


def test_kernel_arrays_hold_the_file_s_law(small_table_path, small_table):
    """The kernel layout is the file's cells rearranged: the dictionary level-major (S_k,m(i/L) at
    [..., k, i, m]), each row's residual shape indices m, location, scale and slopes, each cell's trapped
    fraction, means and standard deviations; both large arrays start on a 64-byte cache line."""
    from data_schema.table import read_table
    cells = read_table(small_table_path).cells
    data = small_table.kernel_data
    rows = data.rows()
    np.testing.assert_array_equal(data.shape_dictionary(), np.swapaxes(cells["shape_dictionary"], -1, -2))
    np.testing.assert_array_equal(rows[..., ROW_SHAPE:ROW_SHAPE + 6], cells["cluster_shape"])
    np.testing.assert_array_equal(rows[..., ROW_LOC:ROW_LOC + 6], cells["cluster_loc"])
    np.testing.assert_array_equal(rows[..., ROW_SCALE:ROW_SCALE + 6], cells["cluster_scale"])
    np.testing.assert_array_equal(rows[..., ROW_SLOPE:ROW_SLOPE + 15], cells["cluster_slope"])
    records = data.cells.reshape(data.cell_shape() + (CELL_SIZE,))
    np.testing.assert_array_equal(records[..., CELL_MEAN:CELL_MEAN + 6], cells["mean"])
    np.testing.assert_array_equal(records[..., CELL_SD:CELL_SD + 6], cells["std"])
    counts = cells["status_counts"]
    np.testing.assert_allclose(data.p_trapped() * (counts[..., STATUS_REBOUNDED] + counts[..., STATUS_TRAPPED]),
                               counts[..., STATUS_TRAPPED], rtol=1e-12)
    assert data.dictionary.ctypes.data % 64 == 0 and data.clusters.ctypes.data % 64 == 0
    # the work on the wall: each component's two work variables, their dictionary level-major, each cell's moments
    # and the trapped particles' mean work
    work = data.work_rows.reshape(data.cell_shape() + (data.n_clusters, WORK_ROW_SIZE))
    for at, name in ((WORK_ROW_LOC, "work_loc"), (WORK_ROW_SCALE, "work_scale"), (WORK_ROW_SHAPE, "work_shape")):
        np.testing.assert_array_equal(work[..., at:at + 2], cells[name])
    np.testing.assert_array_equal(work[..., WORK_ROW_SLOPE:WORK_ROW_SLOPE + 13], cells["work_slope"])
    np.testing.assert_array_equal(data.work_dictionary.reshape(data.cell_shape() + (2, data.n_levels, -1)),
                                  np.swapaxes(cells["work_dictionary"], -1, -2))
    records = data.work_cells.reshape(data.cell_shape() + (WORK_CELL_SIZE,))
    for at, name in ((WORK_CELL_MEAN, "work_mean"), (WORK_CELL_SD, "work_std"), (WORK_CELL_TRAPPED, "trapped_work")):
        np.testing.assert_array_equal(records[..., at:at + 2], cells[name])


def test_a_tabulated_wall_law_is_stored_read_and_drawn_from(tabulated_table_path, tmp_path):
    """A table built with a tabulated wall law: /wall holds its arrays and reads back as the configuration's law;
    the direct model's parameters hold its kernel array, the speed interpolation its a_nc at normal contact at
    the grid speeds; both paths answer hits; a stored a_nc outside (0, 1] is refused naming the dataset."""
    import h5py

    from data_schema.table import DataFormatError, read_table
    from direct_model.runtime import P_WALL
    from surrogate.kernels.fastmath import restitution_factor
    from tablegen.tabulation.config import parse_config
    from tests.helpers.tables import TABULATED_WALL, edited_copy

    wall = parse_config(TABULATED_WALL).wall
    assert read_table(tabulated_table_path).wall == wall
    table = surrogate.load(tabulated_table_path)
    array = wall.as_array()
    np.testing.assert_array_equal(table.direct_parameters[P_WALL:P_WALL + array.size], array)
    assert not table.direct_parameters[P_WALL + array.size:].any()
    # a(V, 1) between the nodes 40 and 120, and 120 and 300 m/s
    expected = [0.5 + 0.05 * (120.0 - 100.0) / 80.0, 0.5 - 0.08 * (200.0 - 120.0) / 180.0]
    np.testing.assert_allclose(table.kernel_data.speed_restitution, expected, rtol=1e-15)
    assert restitution_factor(100.0, array) == table.kernel_data.speed_restitution[0]
    n = 400
    rng = np.random.default_rng(8)
    alpha = np.radians(rng.uniform(30.0, 70.0, n))
    speed = rng.uniform(100.0, 200.0, n)
    velocity = np.stack([np.cos(alpha) * speed, -np.sin(alpha) * speed, np.zeros(n)], axis=1)
    for method in ("table", "direct"):
        out = surrogate.sample_global(table, velocity, [0.0, 1.0, 0.0], 1e-4, shape="prism", random_state=3,
                                      method=method)
        rebounded = out.status == 0
        assert rebounded.mean() > 0.9 and np.all(out.V[rebounded, 1] > 0.0)
        assert np.all(np.linalg.norm(out.V[rebounded], axis=1) <= speed[rebounded] * (1 + 1e-12))

    def corrupt(f):
        del f["wall/restitution"]
        f["wall"].create_dataset("restitution", data=np.array([[1.0, 0.8, 0.55], [1.0, 0.75, 1.5], [1.0, 0.7, 0.4]]))
    with pytest.raises(DataFormatError, match=r"group 'wall': The wall law parameter 'restitution' must be in "
                                              r"\(0, 1\] at every node; got 1.5 at \[1\]\[2\]"):
        read_table(edited_copy(tabulated_table_path, tmp_path, "bad.h5", corrupt))
    with h5py.File(tabulated_table_path) as f:
        assert f["wall/contact_sine"].attrs["units"] == "1" and f["wall/restitution"].shape == (3, 3)


@pytest.mark.parametrize("weights", [[0.25, 0.25, 0.25, 0.25], [0.7, 0.0, 0.2, 0.1, 0.0], [1.0, 0.0, 0.0],
                                     np.random.default_rng(3).dirichlet(np.ones(500))])
def test_alias_table_reproduces_the_weights(weights):
    """Exact probability of each component under the alias draw: (keep[c] + Σ_{alias[d]=c} (1 − keep[d]))/C."""
    keep, alias = alias_table(np.asarray(weights))
    C = len(weights)
    prob = keep.copy()
    np.add.at(prob, alias, 1.0 - keep)
    np.testing.assert_allclose(prob / C, weights, atol=1e-14)
    assert np.all(keep[np.asarray(weights) == 0] == 0)


def test_shape_missing_from_the_table(tmp_path):
    from tablegen import build_table, parse_config
    path = build_table(parse_config("[grid]\nalpha1_deg=[45.0]\nspeed_m_s=[100.0]\nshapes=[\"prism\"]\n"
                                    "[simulation]\nparticles_per_cell=3000\n"), tmp_path / "p.h5", workers=1)
    table = surrogate.load(path)
    with pytest.raises(ValueError, match="'tetrahedron' is not in the table"):
        surrogate.sample_local(table, 45.0, 100.0, "tetrahedron")
