"""A wall of the tabulated law family (direct_model.wall.TabulatedWall: a_nc bilinear between nodes of contact speed
and contact sine, constant beyond the speed nodes) in C as in Python, on the session's tabulated table (the prism on
a 2 × 2 grid; tests/helpers/tables.py, TABULATED_TABLE_CONFIG):

- the loader's wall array in its direct parameters, its restitution factor at and between the grid speeds and
  rbs_table_wall's record (the law's arrays; a record of the 1.0 size gets its 1.0 fields alone) are Python's, bit
  for bit; rbs_restitution_factor is surrogate's restitution_factor at, between and beyond the nodes;
- every hit on the table (the table path in bulk, and the table, direct and auto paths one by one, spinning and
  not) gives numba's bits (one collision under random tabulated walls: tests/native/test_native_direct.py);
- a file whose wall arrays break the law's rules is refused by both readers (tests/helpers/bad_files.py,
  tabulated_wall_cases): the same message.
"""

from __future__ import annotations

import ctypes

import numpy as np
import pytest

from tests.helpers import python_side as py
from tests.helpers.bad_files import _corrupt_chunk, tabulated_wall_cases
from tests.helpers.native_library import (INTERPOLATION_SCALED, INTERPOLATION_STOCHASTIC, METHOD_AUTO, METHOD_DIRECT,
                                          METHOD_TABLE, OK, PATH_DIRECT, PATH_TABLE, WallInfo, ref)
from tests.helpers.states import incident_states, max_ulp, uniforms
from tests.helpers.tables import edited_copy

KERNEL_ARRAYS = ("alpha1_axis", "speed_axis", "cells", "clusters", "dictionary", "speed_restitution",
                 "restitution_pieces", "work_rows", "work_dictionary", "work_cells")
BULK = 5_000          # table-path states per interpolation
ONE_BY_ONE = 200      # states per method, hit by hit (the direct path runs the model, in numba and in C)


@pytest.fixture(scope="module")
def tabulated_pair(native, tabulated_table_path):
    """(surrogate's table, the native table) of the session's tabulated table."""
    return py.load(tabulated_table_path), native.table(tabulated_table_path)


def _same(a, b) -> bool:
    return np.asarray(a, dtype=np.float64).tobytes() == np.asarray(b, dtype=np.float64).tobytes()


# -- what the loader reads and derives -----------------------------------------------------------------------


def test_the_wall_array_and_the_derived_arrays_are_python_s(tabulated_pair):
    """"direct_parameters" is surrogate's table.direct_parameters bit for bit: the wall array
    (direct_model.wall.Wall.as_array: code, q, node counts, nodes, a_nc) from P_WALL, zero after it; the restitution
    factor at the grid speeds and its pieces between them (the law's a_nc at normal contact) are the kernel data's."""
    python, c_table = tabulated_pair
    assert python.wall.family == "tabulated" and python.wall.speed_range_m_s == (0.0, np.inf)
    params = c_table.kernel_array("direct_parameters")
    assert _same(params, python.direct_parameters)
    wall, start = python.wall.as_array(), py.direct_runtime.P_WALL
    assert wall[:4].tolist() == [1.0, 0.8, 3.0, 3.0]
    assert _same(params[start:start + wall.size], wall) and not params[start + wall.size:].any()
    for name in KERNEL_ARRAYS:
        assert c_table.kernel_array(name).tobytes() == np.asarray(getattr(python.kernel_data, name)).tobytes(), name


def test_rbs_table_wall_gives_the_law_s_arrays(tabulated_pair):
    """rbs_table_wall: the family, the name, q, and the nodes and a_nc as the table stores them (row-major speeds ×
    sines); a record of the 1.0 size (up to speed_range_m_s) gets those fields alone, its later bytes untouched."""
    python, c_table = tabulated_pair
    wall = c_table.wall()
    assert (wall["family"], wall["name"], wall["parameters"]) == ("tabulated", python.wall.name, {"q": 0.8})
    expected = python.wall.arrays()
    assert list(wall["arrays"]) == list(expected) == ["contact_speed_m_s", "contact_sine", "restitution"]
    for name, values in expected.items():
        assert wall["arrays"][name].shape == values.shape and _same(wall["arrays"][name], values), name
    full, old = WallInfo(), WallInfo()
    old.size = WallInfo.speed_range_m_s.offset + WallInfo.speed_range_m_s.size
    ctypes.memset(ctypes.addressof(old) + old.size, 0xAB, ctypes.sizeof(WallInfo) - old.size)
    c = c_table.lib.c
    assert c.rbs_table_wall(c_table.handle, ref(full)) == c.rbs_table_wall(c_table.handle, ref(old)) == OK
    assert bytes(old)[8:old.size] == bytes(full)[8:old.size]
    assert bytes(old)[old.size:] == b"\xab" * (ctypes.sizeof(WallInfo) - old.size)


def test_the_restitution_factor_is_surrogate_s(native, tabulated_pair):
    """rbs_restitution_factor (layout.c) against surrogate's restitution_factor on this wall and on the published
    exponential one: at the nodes, just beside them, between, below the first and above the last, 0 and NaN."""
    python = tabulated_pair[0]
    c = native.internal
    rng = np.random.default_rng(3)
    nodes = np.array(python.wall.contact_speed_m_s)
    speeds = np.concatenate([nodes, np.nextafter(nodes, 0.0), np.nextafter(nodes, np.inf), rng.uniform(0.0, 500.0, 2000),
                             [0.0, 1e-300, 1e300, np.inf, np.nan]])
    for wall in (python.wall.as_array(), py.WallMaterial().as_array()):
        mine = [c.rbs_restitution_factor(v, wall.ctypes.data) for v in speeds]
        assert _same(mine, [py.restitution_factor(v, wall) for v in speeds])


# -- the bits of the kernels ----------------------------------------------------------------------------------


@pytest.mark.parametrize("interpolation", ["scaled", "stochastic"])
def test_the_table_path_in_bulk_bit_for_bit(tabulated_pair, interpolation):
    """rbs_draw_many against table_rebound_many over and beyond the grid (the law's restitution factor moves each
    draw to the incident speed): the same statuses and bits."""
    python, c_table = tabulated_pair
    (v_lo, v_hi) = python.speed_range
    rng = np.random.default_rng(31 if interpolation == "scaled" else 32)
    V, n, a = incident_states(rng, BULK, (0.0, 90.0), (0.2 * v_lo, 1.5 * v_hi))
    u = uniforms(rng, BULK, hostile=0.01)
    cdf = py.mix_cdf(python, "mix")
    V_py, W_py, status_py = np.empty((BULK, 3)), np.empty((BULK, 3)), np.empty(BULK, dtype=np.int8)
    py.table_rebound_many(python.kernel_data, cdf, V, n, a, u, V_py, W_py, status_py, interpolation == "scaled")
    status, V_c, W_c = c_table.draw_many(c_table.mix("mix"), V, n, a, u, interpolation={
        "scaled": INTERPOLATION_SCALED, "stochastic": INTERPOLATION_STOCHASTIC}[interpolation])
    assert np.array_equal(status, status_py)
    assert np.sum(status == py.STATUS_REBOUNDED) > 0.7 * BULK
    assert max_ulp(V_c, V_py) == 0.0 and max_ulp(W_c, W_py) == 0.0


@pytest.mark.parametrize("method", [METHOD_AUTO, METHOD_TABLE, METHOD_DIRECT], ids=["auto", "table", "direct"])
def test_every_hit_bit_for_bit(tabulated_pair, method):
    """rbs_rebound against numba's rebound, hit by hit, under each method: states over and beyond the grid (contact
    speeds below the first speed node, between and above the last), Ω⁻ zero, below the spin tolerance and large:
    the same record (status, path, shape, collisions) and the same bits of V⁺ and Ω⁺; both paths rebound."""
    python, c_table = tabulated_pair
    (v_lo, v_hi) = python.speed_range
    rng = np.random.default_rng(40 + method)
    V, n, a = incident_states(rng, ONE_BY_ONE, (0.0, 90.0), (0.3 * v_lo, 1.5 * v_hi))
    with np.errstate(all="ignore"):
        speed = np.linalg.norm(V, axis=1)
        extreme = np.isfinite(speed) & (speed > 0.0) & ((speed < 1e-6) | (speed > 1e6))
        V[extreme] *= (v_hi / speed[extreme])[:, None]      # numba's direct model does not return at 1e-160 m/s
        ratio = rng.choice([0.0, 0.5 * py.SPIN_TOLERANCE, 0.3], ONE_BY_ONE)
        axis = rng.standard_normal((ONE_BY_ONE, 3))
        omega = (ratio * np.linalg.norm(V, axis=1) / a / np.linalg.norm(axis, axis=1))[:, None] * axis
    omega = np.ascontiguousarray(np.where(np.isfinite(omega), omega, 0.0))
    u = uniforms(rng, ONE_BY_ONE, hostile=0.01)
    cdf, mix = py.mix_cdf(python, "mix"), c_table.mix("mix")
    paths = {}
    for i in range(ONE_BY_ONE):
        result, _ = c_table.hit(mix, V[i], omega[i], n[i], a[i], u[i], method=method)
        theirs = py.rebound(python.kernel_data, python.direct_parameters, python.shape_arrays, python.model_shapes,
                            cdf, tuple(V[i]), tuple(omega[i]), tuple(n[i]), a[i], u[i], method, True)
        assert (result.status, result.path, result.shape, result.n_collisions) == tuple(theirs[:4]), i
        assert max_ulp(np.array(result.V[:]), np.array(theirs.V)) == 0.0, i
        assert max_ulp(np.array(result.Omega[:]), np.array(theirs.Omega)) == 0.0, i
        if result.status == py.STATUS_REBOUNDED:
            paths[result.path] = paths.get(result.path, 0) + 1
    expected = {METHOD_AUTO: {PATH_TABLE, PATH_DIRECT}, METHOD_TABLE: {PATH_TABLE},
                METHOD_DIRECT: {PATH_DIRECT}}[method]
    assert set(paths) == expected and min(paths.values()) >= 5, paths


# -- bad files ------------------------------------------------------------------------------------------------


def test_a_bad_tabulated_wall_is_refused_by_both(native, tabulated_table_path, tmp_path):
    """a_nc of 1.5 or 0, sine nodes that do not end at 1, speed nodes out of order, a_nc of the wrong shape or rank,
    a dataset missing, q not finite: RBS_ERR_FORMAT and a message naming the dataset or field, Python's word for
    word; a corrupt
    dataset of the law fails its checksum in both, each naming it."""
    cases = tabulated_wall_cases(tabulated_table_path, tmp_path)
    assert {path.stem for path, *_ in cases} >= {"tabulated_restitution_above_1", "tabulated_sine_not_to_1"}
    for path, expected, message in cases:
        code, table, text = native.open(path)
        assert code == expected and table is None, (path.name, code, text)
        assert text == f"{path}: {message}", path.name
        with pytest.raises(ValueError) as info:
            py.load(path)
        assert str(info.value) == text, path.name
    corrupt = _corrupt_chunk(edited_copy(tabulated_table_path, tmp_path, "corrupt_restitution.h5"), "wall/restitution")
    code, table, text = native.open(corrupt)
    assert code != OK and table is None and "wall/restitution" in text, text
    with pytest.raises(ValueError, match="wall/restitution"):
        py.load(corrupt)
