"""The work of a table draw on the wall in C (since 1.4; docs/model.md §4.7, docs/native.md "What a hit does to the
wall"): rbs_rebound on the table path gives W_n and W_t (rbs_result.wall_work_normal, wall_work_tangential) drawn
jointly with the rebound, the bits of numba's surrogate.kernels.work.draw_with_work (native/src/work.h).

- Hits on the session's small table (format 4.1), on its grid points, between them and beyond its edges, both
  interpolations, trapped draws among them (u[3] below the trapping cells' P(trapped)): every field of rbs_result is
  numba's Hit, the work byte for byte; a rebound's work >= 0 and at most E⁻ = |V⁻|²/2 in all, a trapped draw's its
  cell's mean fractions of E⁻.
- A rough wall answered by the table (RBS_METHOD_TABLE; grazing hits, many of several facet hits): the work summed
  over the facet hits, numba's bit for bit.
- A table of format 4.0 (the work datasets dropped, format_version (4, 0)): opens in both, its work arrays empty,
  the table path's rebound the 4.1 table's bits with NaN work in both, on a smooth and a rough wall; the direct path
  keeps its work.
- A table holding only some of the work datasets: refused by both loaders, word for word.
"""

from __future__ import annotations

import numpy as np
import pytest

from tests.helpers import python_side as py
from tests.helpers.bad_files import WORK_DATASETS, _drop_cells
from tests.helpers.native_library import (ERR_FORMAT, INTERPOLATION_SCALED, INTERPOLATION_STOCHASTIC, INVALID,
                                          METHOD_DIRECT, METHOD_TABLE, OK, TRAPPED, U_PER_DRAW)
from tests.helpers.tables import edited_copy

HITS = 3000                 # hits per interpolation on the smooth wall
ROUGH_HITS = 400            # per interpolation on the rough wall
ROUGHNESS = 20.0            # degrees
A = 1e-4                    # half-size, m
ZERO = np.zeros(3)
INTERPOLATIONS = {"scaled": INTERPOLATION_SCALED, "stochastic": INTERPOLATION_STOCHASTIC}
WORK_ARRAYS = ("work_rows", "work_dictionary", "work_cells")


@pytest.fixture(scope="module")
def pair(table_pair):
    """(numba's table, C's table, C's equal mix, its cdf) of the session's small table."""
    table, c_table = table_pair
    assert table.kernel_data.has_work and c_table.info().format_minor == 1
    return table, c_table, c_table.mix(), py.mix_cdf(table, "mix")


@pytest.fixture(scope="module")
def pair_4_0(native, small_table_path, tmp_path_factory):
    """The same of a copy of the small table as format 4.0 wrote it: no work datasets, format_version (4, 0)."""
    path = edited_copy(small_table_path, tmp_path_factory.mktemp("work"), "format_4_0.h5",
                       _drop_cells(*WORK_DATASETS, version=(4, 0)))
    table, c_table = py.load(path), native.table(path)
    yield table, c_table, c_table.mix(), py.mix_cdf(table, "mix")
    c_table.close()


def _fields(record) -> tuple:
    """Every field of an rbs_result or a Hit, the floats as bytes."""
    return (int(record.status), int(record.path), int(record.shape), int(record.n_collisions), int(record.wall_hits),
            np.array(record.V[:], dtype=np.float64).tobytes(), np.array(record.Omega[:], dtype=np.float64).tobytes(),
            _work(record).tobytes())


def _work(record) -> np.ndarray:
    return np.array([record.wall_work_normal, record.wall_work_tangential], dtype=np.float64)


def _unit(rng, n):
    """A random unit vector orthogonal to the unit vector n."""
    t = rng.standard_normal(3)
    t -= (t @ n) * n
    return t / np.linalg.norm(t)


def _hits(table, seed, count):
    """(V, n, u) of ``count`` hits on random walls: a third on the table's grid points (every fourth of them exactly:
    normal impact on an axis-aligned wall at a grid speed), a third between them and beyond the grid's edges (α1 in
    [20, 90]°, |V⁻| from 0.8 times the grid's first to 1.1 times its last), a third of the ellipsoid near its
    trapping cells (α1 in [55, 90]°, |V⁻| in [140, 260] m/s) with u[3] below their P(trapped)."""
    rng = np.random.default_rng(seed)
    (v_lo, v_hi) = table.speed_range
    u = rng.random((count, U_PER_DRAW))
    V, n = np.empty((count, 3)), np.empty((count, 3))
    for k in range(count):
        n[k] = rng.standard_normal(3)
        n[k] /= np.linalg.norm(n[k])
        if k % 3 == 0:
            alpha1, speed = rng.choice(table.alpha1_deg), rng.choice(table.speed_m_s)
            if k % 4 == 0:
                n[k], V[k] = (0.0, 1.0, 0.0), (0.0, -speed, 0.0)
                continue
        elif k % 3 == 1:
            alpha1, speed = rng.uniform(20.0, 90.0), rng.uniform(0.8 * v_lo, 1.1 * v_hi)
        else:
            alpha1, speed = rng.uniform(55.0, 90.0), rng.uniform(140.0, 260.0)
            u[k, 0], u[k, 3] = rng.uniform(0.0, 0.25), rng.uniform(0.0, 2e-3)    # the ellipsoid of the equal mix
        a1 = np.radians(alpha1)
        V[k] = speed * (np.cos(a1) * _unit(rng, n[k]) - np.sin(a1) * n[k])
    return V, n, u


def _grazing_hits(seed, count):
    """(V, n, u) of ``count`` hits on random walls, three in four grazing (α1 in [1, 5]°: a rebound often hits a
    second facet), the rest in [5, 90]°, |V⁻| in [40, 300] m/s."""
    rng = np.random.default_rng(seed)
    for k in range(count):
        n = rng.standard_normal(3)
        n /= np.linalg.norm(n)
        alpha1 = np.radians(rng.uniform(5.0, 90.0) if k % 4 == 3 else rng.uniform(1.0, 5.0))
        V = rng.uniform(40.0, 300.0) * (np.cos(alpha1) * _unit(rng, n) - np.sin(alpha1) * n)
        yield V, n, rng.random(U_PER_DRAW)


def _numba_rough(table, cdf, V, n, u, method, scaled, roughness):
    return py.rebound(table.kernel_data, table.direct_parameters, table.shape_arrays, table.model_shapes, cdf,
                      np.ascontiguousarray(V), ZERO, tuple(float(x) for x in n), A, u, int(method), scaled, None,
                      float(roughness))


# ---------------------------------------------------------------- the work arrays, the table path


def test_the_work_arrays_are_numbas(pair):
    """work_rows (each component's row of 20 float32, its last a zero), work_dictionary (level-major) and work_cells:
    numba's kernel data byte for byte (tests/native/test_native_bits.py compares them with the other arrays)."""
    table, c_table, _, _ = pair
    data = table.kernel_data
    for name in WORK_ARRAYS:
        expected, got = np.asarray(getattr(data, name)), c_table.kernel_array(name)
        assert got.size > 0 and got.dtype == expected.dtype and got.tobytes() == expected.tobytes(), name
    rows = c_table.kernel_array("work_rows").reshape(-1, 20)
    assert not rows[:, 19].any()


@pytest.mark.parametrize("interpolation", sorted(INTERPOLATIONS))
def test_table_work_is_numbas_bit_for_bit(pair, interpolation):
    table, c_table, mix, cdf = pair
    code = INTERPOLATIONS[interpolation]
    V, n, u = _hits(table, 900 + code, HITS)
    counts = {OK: 0, TRAPPED: 0, INVALID: 0}
    for k in range(HITS):
        result, _ = c_table.hit(mix, V[k], ZERO, n[k], A, u[k], method=METHOD_TABLE, interpolation=code)
        expected = py.table_rebound(table.kernel_data, cdf, tuple(V[k]), tuple(n[k]), A, u[k],
                                    code == INTERPOLATION_SCALED)
        assert _fields(result) == _fields(expected), (k, _fields(result)[:5], _work(result), _work(expected))
        counts[result.status] += 1
        work, energy = _work(result), 0.5 * float(V[k] @ V[k])
        if result.status == INVALID:
            assert np.isnan(work).all(), k
        elif result.status == TRAPPED:
            assert ((work >= 0.0) & (work <= energy * (1.0 + 1e-12))).all(), (k, work, energy)
        else:
            assert (work >= 0.0).all() and work.sum() <= energy * (1.0 + 1e-12), (k, work, energy)
    print(f"\n{interpolation}: {HITS} table hits' work equal to numba's: {counts}")
    assert counts[OK] > 0.6 * HITS and counts[TRAPPED] >= 20, counts


@pytest.mark.parametrize("interpolation", sorted(INTERPOLATIONS))
def test_rough_table_work_is_numbas_bit_for_bit(pair, interpolation):
    """Rough hits answered by the table: the facet hits' work summed (in their order), numba's bits."""
    table, c_table, mix, cdf = pair
    code = INTERPOLATIONS[interpolation]
    multi = 0
    for k, (V, n, u) in enumerate(_grazing_hits(910 + code, ROUGH_HITS)):
        result, _ = c_table.hit(mix, V, ZERO, n, A, u, method=METHOD_TABLE, interpolation=code,
                                roughness_deg=ROUGHNESS)
        expected = _numba_rough(table, cdf, V, n, u, METHOD_TABLE, code == INTERPOLATION_SCALED, ROUGHNESS)
        assert _fields(result) == _fields(expected), (k, _fields(result)[:5], _work(result), _work(expected))
        multi += result.wall_hits > 1 and np.isfinite(_work(result)).all()
    print(f"\n{interpolation}: {ROUGH_HITS} rough hits equal, {multi} of several facet hits with their work")
    assert multi > 0


# ---------------------------------------------------------------- a table of format 4.0, and a partial one


def test_a_table_of_format_4_0_opens_in_both_and_draws_no_work(pair, pair_4_0):
    """No work arrays (count 0); the table path's rebounds are the 4.1 table's bits (the work takes nothing of a
    hit's uniforms), their work NaN in both, on a smooth and a rough wall; the direct path's work is the 4.1 table's."""
    table, c_table, mix, cdf = pair_4_0
    _, c_work, work_mix, _ = pair
    assert not table.kernel_data.has_work and c_table.info().format_minor == 0
    for name in WORK_ARRAYS:
        got, expected = c_table.kernel_array(name), np.asarray(getattr(table.kernel_data, name))
        assert got.size == expected.size == 0 and got.dtype == expected.dtype, name
    states = _hits(table, 920, 600)
    rebounded = 0
    for V, n, u in zip(*states):
        for code in INTERPOLATIONS.values():
            result, _ = c_table.hit(mix, V, ZERO, n, A, u, method=METHOD_TABLE, interpolation=code)
            expected = py.table_rebound(table.kernel_data, cdf, tuple(V), tuple(n), A, u, code == INTERPOLATION_SCALED)
            with_work, _ = c_work.hit(work_mix, V, ZERO, n, A, u, method=METHOD_TABLE, interpolation=code)
            assert _fields(result) == _fields(expected) and _fields(result)[:7] == _fields(with_work)[:7], V
            assert np.isnan(_work(result)).all(), V
            rebounded += result.status == OK
    assert rebounded > 0
    for k, (V, n, u) in enumerate(_grazing_hits(921, 60)):
        result, _ = c_table.hit(mix, V, ZERO, n, A, u, method=METHOD_TABLE, roughness_deg=ROUGHNESS)
        expected = _numba_rough(table, cdf, V, n, u, METHOD_TABLE, True, ROUGHNESS)
        assert _fields(result) == _fields(expected) and np.isnan(_work(result)).all(), k
    for V, n, u in list(zip(*states))[:20]:
        result, _ = c_table.hit(mix, V, ZERO, n, A, u, method=METHOD_DIRECT)
        with_work, _ = c_work.hit(work_mix, V, ZERO, n, A, u, method=METHOD_DIRECT)
        assert _fields(result) == _fields(with_work), V
        assert result.status != OK or (_work(result) > 0.0).any(), V


@pytest.mark.parametrize("dropped", [("trapped_work",), ("work_loc", "work_dictionary", "work_std"),
                                     WORK_DATASETS[1:]])
def test_some_work_datasets_without_the_others_are_refused_word_for_word(native, small_table_path, tmp_path,
                                                                         dropped):
    path = edited_copy(small_table_path, tmp_path, "partial.h5", _drop_cells(*dropped))
    code, c_table, message = native.open(path)
    assert code == ERR_FORMAT and c_table is None, (code, message)
    with pytest.raises(ValueError) as info:
        py.load(path)
    kept = sorted(set(WORK_DATASETS) - set(dropped))
    assert message == str(info.value) == (f"{path}: inconsistent table: ReboundTable has the work datasets {kept} but "
                                          f"not {sorted(dropped)}: all or none")
