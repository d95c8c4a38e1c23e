"""Tables rewritten as a hostile user would, with valid checksums: both loaders refuse the same files.

For every dataset a draw reads, one element set out of the range docs/format.md ("What makes a table valid")
allows, the chunk's Fletcher-32 rewritten by HDF5: surrogate.load and rbs_table_open both refuse the file
with a message naming the dataset (the known case: a cells/shape_dictionary entry of 1e6 loaded in both and
gave rebounds faster than they came). An attribute that decides a law stored with the wrong type, or with
one bit flipped, is refused by both alike. A table whose values are in range but absurd loads, and then
both runtimes report status 0 only for rebounds that leave the wall no faster than they came. A table of
format 3.2 (grid/law holding restitution_k, restitution_p only, no group shapes) loads and draws the bits of
the same cells in format 3.4.
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
}
# grid attributes that decide a law (data_schema.table.LAW_ATTRIBUTES)
LAW_ATTRIBUTES = ("restitution_k", "restitution_p", "friction_q", "kappa", "n_max", "aspect_ratio_mean",
                  "aspect_ratio_sd", "aspect_ratio_low", "aspect_ratio_high", "contact_tol", "set_tol", "max_steps",
                  "second_moment_factors")


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


@pytest.mark.parametrize("name", LAW_ATTRIBUTES)
def test_a_flipped_bit_of_any_law_attribute_fails_to_load(native, small_table_path, tmp_path, name):
    def flip(f):
        value = np.array(f["grid"].attrs[name])
        bits = value.view(np.uint64 if value.dtype.itemsize == 8 else np.uint32)
        bits.reshape(-1)[0] ^= 1 << 3
        f["grid"].attrs[name] = value

    _same_verdict(native, edited_copy(small_table_path, tmp_path, f"flip_{name}.h5", flip), ERR_FORMAT, "grid/law")


@pytest.mark.parametrize("name, value, wanted", [
    ("restitution_p", "0.61", "as one number"), ("kappa", "0.3", "as one number"), ("n_max", 1000.0, "as one integer"),
    ("max_steps", "100000", "as one integer"), ("second_moment_factors", "0.2", "as 1 to 8 numbers"),
    ("aspect_ratio_sd", np.array([0.2, 0.2]), "as one number")])
def test_an_attribute_of_the_wrong_type_is_refused_alike(native, small_table_path, tmp_path, name, value, wanted):
    def retype(f):
        f["grid"].attrs[name] = value

    _same_verdict(native, edited_copy(small_table_path, tmp_path, f"type_{name}.h5", retype), ERR_FORMAT,
                  f"the attribute '{name}' of group 'grid' {wanted}")


def test_a_missing_direct_model_attribute_is_refused_since_3_3(native, small_table_path, tmp_path):
    _same_verdict(native, edited_copy(small_table_path, tmp_path, "no_set_tol.h5",
                                lambda f: f["grid"].attrs.__delitem__("set_tol")), ERR_FORMAT, "set_tol")


def _draws(native, path, n=20_000):
    """(status, V⁺) of n hits at (30°, 150 m/s, Ω⁻ = 0) from both runtimes with the same uniforms."""
    rng = np.random.default_rng(3)
    u = rng.random((n, py.U_PER_DRAW))
    V = np.tile([150.0 * np.cos(np.radians(30.0)), -150.0 * np.sin(np.radians(30.0)), 0.0], (n, 1))
    normal = np.tile([0.0, 1.0, 0.0], (n, 1))
    a = np.full(n, 1e-4)
    table = native.table(path)
    try:
        c_status, c_V, _ = table.table_rebound_many(table.mix_equal(), V, normal, a, u)
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


def test_a_table_of_format_3_2_draws_the_same_bits(native, small_table_path, tmp_path):
    def format_3_2(f):
        f.attrs["format_version"] = np.array([3, 2], dtype=np.int64)
        del f["shapes"]
        law = f["grid/law"][:2]
        del f["grid/law"]
        f["grid"].create_dataset("law", data=law, fletcher32=True)

    old = edited_copy(small_table_path, tmp_path, "v3_2.h5", format_3_2)
    (c_new, c_V_new), (py_new, V_new), _ = _draws(native, small_table_path, n=2_000)
    (c_old, c_V_old), (py_old, V_old), _ = _draws(native, old, n=2_000)
    assert np.array_equal(c_new, c_old) and np.array_equal(py_new, py_old)
    assert c_V_new.tobytes() == c_V_old.tobytes() and V_new.tobytes() == V_old.tobytes()
