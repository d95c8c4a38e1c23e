"""The loaded table: read-only, the file's law in the kernel arrays, the alias tables, the runtime's imports."""

import subprocess
import sys

import numpy as np
import pytest

import surrogate
from data_schema.samples import STATUS_REBOUNDED, STATUS_TRAPPED
from surrogate.kernels.layout import (CELL_MEAN, CELL_SD, CELL_SIZE, ROW_LOC, ROW_SCALE, ROW_SHAPE, ROW_SLOPE,
                                      alias_table)


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
    assert len(arrays) == 7 and all(a.flags.c_contiguous and not a.flags.writeable for a in arrays)


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
