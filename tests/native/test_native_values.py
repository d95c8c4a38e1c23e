"""Tables rewritten as a hostile user would, with valid checksums: both loaders refuse the same files.

For every dataset a draw reads (its work on the wall's too), one element set out of the range docs/format.md
("What makes a table valid") allows, the chunk's Fletcher-32 rewritten by HDF5: surrogate.load and rbs_table_open
both refuse the file with a message naming the dataset (the known case: a cells/shape_dictionary entry of 1e6
loaded in both and gave rebounds faster than they came). An attribute stored with the wrong type is refused by both
alike (the parameter rows of groups model and wall: tests/native/test_native_format.py). A table whose values are in
range but absurd loads, and then both runtimes report status 0 only for rebounds that leave the wall no faster than
they came.
"""

from __future__ import annotations


import h5py
import numpy as np
import pytest

from tests.helpers import python_side as py
from tests.helpers.native_library import ERR_FORMAT, OK
from tests.helpers.tables import edited_copy

# element (shape, α1, speed, cluster, chain variable) of a used cluster: the first cluster of the first cell
CLUSTER, VARIABLE = (0, 0, 0, 0), (0, 0, 0, 0, 2)
OUT_OF_RANGE = {      # dataset: (element, values outside its allowed range)
    "grid/alpha1_deg": ((0,), (np.nan, -1.0, 1e6)),
    "grid/speed_m_s": ((0,), (np.nan, 0.0, -1.0, 1e6)),
    "cells/cluster_weight": (CLUSTER, (np.nan, np.inf, -1.0, 1e6)),
    "cells/cluster_loc": (VARIABLE, (np.nan, np.inf, -np.inf, 2e6, -1e30)),
    "cells/cluster_scale": (VARIABLE, (np.nan, np.inf, -1.0, 2e6)),
    "cells/cluster_shape": (VARIABLE, (16, 255)),
    "cells/cluster_slope": ((0, 0, 0, 0, 3), (np.nan, -np.inf, 2e6, 1e30)),
    "cells/cluster_regime": (CLUSTER, (2, 255)),
    "cells/shape_dictionary": ((0, 0, 0, 2, 0, 12), (np.nan, np.inf, 1e6, -1e6, 5.0)),
    "cells/status_counts": ((0, 0, 0, 0), (-1,)),
    "cells/mean": ((0, 0, 0, 2), (np.nan, np.inf, 2e6)),
    "cells/std": ((0, 0, 0, 2), (np.nan, -1.0, 2e6)),
    # the work on the wall (format 4.1)
    "cells/work_loc": ((0, 0, 0, 0, 1), (np.nan, np.inf, -2e6)),
    "cells/work_scale": ((0, 0, 0, 0, 0), (np.nan, -1.0, 2e6)),
    "cells/work_shape": ((0, 0, 0, 0, 1), (16, 255)),
    "cells/work_slope": ((0, 0, 0, 0, 12), (np.nan, -np.inf, 2e6)),
    "cells/work_dictionary": ((0, 0, 0, 1, 0, 12), (np.nan, 1e6, -5.0)),
    "cells/work_mean": ((0, 0, 0, 1), (np.nan, 2e6)),
    "cells/work_std": ((0, 0, 0, 0), (np.nan, -1.0, 2e6)),
    "cells/trapped_work": ((0, 0, 0, 1), (np.nan, -0.1, 1.5)),
}


def _set(name, index, value):
    def edit(f):
        values = f[name][()]
        values[index] = value
        f[name][...] = values           # HDF5 writes the chunk with a fresh Fletcher-32
    return edit


def _same_verdict(native, path, expected, names):
    code, table, message = native.open(path)
    if expected == OK:
        assert code == OK, (path.name, message)
        py.load(path)
        return
    assert code == expected and table is None, (path.name, code, message)
    assert message.startswith(str(path)) and names in message, (names, message)
    with pytest.raises(ValueError) as info:
        py.load(path)
    assert str(path) in str(info.value) and names in str(info.value), (path.name, str(info.value))


def test_every_value_a_draw_reads_is_bounded_in_both_loaders(native, small_table_path, tmp_path):
    with h5py.File(small_table_path, "r") as f:
        assert f["cells/cluster_weight"][CLUSTER] > 0      # the edited cluster is drawn
    for name, (element, values) in OUT_OF_RANGE.items():
        for i, value in enumerate(values):
            path = edited_copy(small_table_path, tmp_path, f"{name.replace('/', '_')}_{i}.h5", _set(name, element, value))
            _same_verdict(native, path, ERR_FORMAT, name)


def test_a_decreasing_quantile_function_is_refused(native, small_table_path, tmp_path):
    def decreasing(f):
        values = f["cells/shape_dictionary"][()]
        row = values[0, 0, 0, 2, 0]
        row[0] = row[-1] + 0.5 if row[-1] + 0.5 < 4.8 else row[-1]    # within ±√24, above the last knot
        row[1] = row[0] - 1.0
        f["cells/shape_dictionary"][...] = values

    _same_verdict(native, edited_copy(small_table_path, tmp_path, "decreasing.h5", decreasing), ERR_FORMAT,
                  "cells/shape_dictionary")


@pytest.mark.parametrize("group, name, value, wanted", [
    ("grid", "particles_per_cell", 20000.0, "as one integer"), ("grid", "particles_per_cell", "20000", "as one integer"),
    ("resolution", "clusters", np.array([80, 80]), "as one integer"), ("resolution", "levels", 24.0, "as one integer")])
def test_an_attribute_of_the_wrong_type_is_refused_alike(native, small_table_path, tmp_path, group, name, value,
                                                          wanted):
    def retype(f):
        f[group].attrs[name] = value

    _same_verdict(native, edited_copy(small_table_path, tmp_path, f"type_{group}_{name}.h5", retype), ERR_FORMAT,
                  f"the attribute '{name}' of group '{group}' {wanted}")


def _draws(native, path, n=20_000):
    """(status, V⁺) of n hits at (30°, 150 m/s, Ω⁻ = 0) from both runtimes with the same uniforms."""
    rng = np.random.default_rng(3)
    u = rng.random((n, py.U_PER_DRAW))
    V = np.tile([150.0 * np.cos(np.radians(30.0)), -150.0 * np.sin(np.radians(30.0)), 0.0], (n, 1))
    normal = np.tile([0.0, 1.0, 0.0], (n, 1))
    a = np.full(n, 1e-4)
    table = native.table(path)
    try:
        c_status, c_V, _ = table.draw_many(table.mix(), V, normal, a, u)
    finally:
        table.close()
    surrogate_table = py.load(path)
    V_out, W_out, status = np.empty((n, 3)), np.empty((n, 3)), np.empty(n, dtype=np.int8)
    py.table_rebound_many(surrogate_table.kernel_data, py.mix_cdf(surrogate_table, "mix"), V, normal, a, u, V_out, W_out,
                    status)
    return (c_status, c_V), (status, V_out), 150.0


def test_status_0_leaves_the_wall_no_faster_whatever_the_table(native, small_table_path, tmp_path):
    """Every cluster's speed ratio moved to 900 (in range: loads) and its slope on α2 to 900: draws far outside
    the fold's reach. Both runtimes give the same statuses, and a status-0 rebound has V⁺·n > 0 and
    |V⁺| ≤ |V⁻| (Ω⁻ = 0)."""
    def absurd(f):
        loc = f["cells/cluster_loc"][()]
        loc[..., 2] = 900.0
        f["cells/cluster_loc"][...] = loc
        slope = f["cells/cluster_slope"][()]
        slope[..., 1] = 900.0
        f["cells/cluster_slope"][...] = slope

    path = edited_copy(small_table_path, tmp_path, "absurd.h5", absurd)
    (c_status, c_V), (status, V), speed = _draws(native, path)
    assert np.array_equal(c_status, status)
    assert np.count_nonzero(status == py.STATUS_INVALID) > 0.9 * len(status)
    for s, v in ((c_status, c_V), (status, V)):
        ok = s == py.STATUS_REBOUNDED
        assert np.all(v[ok, 1] > 0.0)
        assert np.all(np.einsum("ij,ij->i", v[ok], v[ok]) <= speed ** 2 * (1.0 + 1e-9))
