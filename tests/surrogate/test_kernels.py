"""The numba kernels: one particle, the pipeline and the parallel kernels give the same bits, whatever the thread count; called from a solver's loop."""

import math

import numba
import numpy as np
import pytest

import surrogate
from data_schema.samples import STATUS_REBOUNDED, STATUS_TRAPPED
from surrogate.kernels import (BLOCK, STATUS_INVALID, U_PER_DRAW, draw_local, draw_local_parallel,
                               draw_local_parallel_rng, table_rebound, table_rebound_many, table_rebound_many_rng,
                               table_rebound_parallel, table_rebound_parallel_rng, table_rebound_uniforms)
from surrogate.kernels.rng import CHUNK_ROWS, seed_state, chunk_states


def test_api_draws_do_not_depend_on_the_thread_count(small_table):
    """sample_global and sample_local draw the rows of chunk j from the xoshiro256+ state j of
    chunk_states: the same bits on one and on two threads, and the same as table_rebound_many and draw_local
    on the uniforms those states give row after row (2 full chunks and a partial one)."""
    m = 2 * CHUNK_ROWS + 77
    rng = np.random.default_rng(4)
    speed, a1 = rng.uniform(50, 250, m), np.radians(rng.uniform(30, 90, m))
    V = np.column_stack([speed * np.cos(a1), -speed * np.sin(a1), np.zeros(m)])
    n, a = np.tile([0.0, 1.0, 0.0], (m, 1)), np.full(m, 1e-4)
    before = numba.get_num_threads()
    runs = []
    try:
        for threads in sorted({1, min(2, numba.config.NUMBA_NUM_THREADS)}):
            numba.set_num_threads(threads)
            runs.append((surrogate.sample_global(small_table, V, n, a, "mix", random_state=5),
                         surrogate.sample_local(small_table, np.degrees(a1), speed, "mix", random_state=6)))
    finally:
        numba.set_num_threads(before)
    hits, local = runs[0]
    for hits2, local2 in runs[1:]:
        for x, y in zip(tuple(hits) + tuple(local), tuple(hits2) + tuple(local2)):
            np.testing.assert_array_equal(x, y)

    def uniforms(seed):
        states = chunk_states(np.random.default_rng(seed), m)
        assert states.shape == (3, 4)
        return np.concatenate([table_rebound_uniforms(state.copy(), min(CHUNK_ROWS, m - j * CHUNK_ROWS))
                               for j, state in enumerate(states)])

    cdf = surrogate.mix_cdf(small_table, "mix")
    V3, W3, s3 = np.empty((m, 3)), np.empty((m, 3)), np.empty(m, dtype=np.int8)
    table_rebound_many(small_table.kernel_data, cdf, V, n, a, uniforms(5), V3, W3, s3)
    np.testing.assert_array_equal(hits.V, V3)
    np.testing.assert_array_equal(hits.Omega, W3)
    np.testing.assert_array_equal(hits.status, s3)
    for wrong in (chunk_states(np.random.default_rng(5), m - CHUNK_ROWS), np.ones((3, 3), np.uint64)):
        with pytest.raises(ValueError, match="one xoshiro256\\+ state"):
            table_rebound_parallel_rng(small_table.kernel_data, cdf, V, n, a, wrong, V3, W3, s3)
    U = uniforms(6)
    for i in (0, CHUNK_ROWS, m - 1):
        expected = draw_local(small_table.kernel_data, cdf, np.degrees(a1[i]), speed[i], U[i])
        got = (local.status[i], local.alpha2[i], local.beta2[i], local.speed_ratio[i], *local.omega[i])
        np.testing.assert_array_equal(got, expected)
    out, status = np.empty((m, 6)), np.empty(m, dtype=np.int8)
    draw_local_parallel(small_table.kernel_data, cdf, np.degrees(a1), speed, U, out, status)
    np.testing.assert_array_equal(status, local.status)
    np.testing.assert_array_equal(out, np.column_stack([local.alpha2, local.beta2, local.speed_ratio, local.omega]))
    # wrong shapes in C-contiguous arrays, the layout of the call above: no compilation for another layout
    for args, message in (((speed[:-1], U, out, status), f"'speed' has shape \\({m - 1},\\); needed \\({m},\\)"),
                          ((speed, U[:, :-1].copy(), out, status),
                           f"'u' has shape \\({m}, 12\\); needed \\({m}, 13\\)"),
                          ((speed, U, np.empty((m, 5)), status), f"'out' has shape \\({m}, 5\\); needed \\({m}, 6\\)")):
        with pytest.raises(ValueError, match=message):
            draw_local_parallel(small_table.kernel_data, cdf, np.degrees(a1), *args)
    with pytest.raises(ValueError, match=f"'status' has shape \\({m - 1},\\); needed \\({m},\\): one row per "
                       "particle, as many as alpha1 has"):
        draw_local_parallel_rng(small_table.kernel_data, cdf, np.degrees(a1), speed, chunk_states(rng, m), out,
                             status[:-1])


@numba.njit
def _solver_loop(data, cdf, V, n, a, seed):
    """What a user's numba particle loop does: its own RNG, its own scratch, our kernel."""
    np.random.seed(seed)
    V_out = np.empty_like(V)
    Omega_out = np.empty_like(V)
    status = np.empty(V.shape[0], dtype=np.int8)
    u = np.empty(U_PER_DRAW)
    U = np.empty((V.shape[0], U_PER_DRAW))
    for i in range(V.shape[0]):
        for k in range(U_PER_DRAW):
            u[k] = np.random.random()
        U[i] = u
        hit = table_rebound(data, cdf, V[i], n[i], a[i], u)
        status[i], V_new, W_new = hit.status, hit.V, hit.Omega
        for k in range(3):
            V_out[i, k], Omega_out[i, k] = V_new[k], W_new[k]
    return V_out, Omega_out, status, U


def test_callable_from_a_numba_loop(small_table):
    m = 300
    rng = np.random.default_rng(2)
    V = np.column_stack([rng.uniform(20, 100, m), -rng.uniform(60, 200, m), rng.uniform(-50, 50, m)])
    n = np.tile([0.0, 1.0, 0.0], (m, 1))
    a = np.full(m, 1e-4)
    cdf = surrogate.mix_cdf(small_table, [0.25] * 4)
    V1, W1, s1, U = _solver_loop(small_table.kernel_data, cdf, V, n, a, 42)
    V2, W2, s2 = np.empty((m, 3)), np.empty((m, 3)), np.empty(m, dtype=np.int8)
    table_rebound_parallel(small_table.kernel_data, cdf, V, n, a, U, V2, W2, s2)
    np.testing.assert_array_equal(s1, s2)
    np.testing.assert_array_equal(V1, V2)
    np.testing.assert_array_equal(W1, W2)
    assert np.all(s1 == STATUS_REBOUNDED)


@numba.njit
def _tuple_loop(data, cdf, V, n, a, U, V_out, Omega_out, status):
    """A solver loop on scalars: table_rebound on 3-tuples built from the rows (no array views)."""
    for i in range(V.shape[0]):
        hit = table_rebound(data, cdf, (V[i, 0], V[i, 1], V[i, 2]),
                            (n[i, 0], n[i, 1], n[i, 2]), a[i], U[i])
        status[i], V_new, W_new = hit.status, hit.V, hit.Omega
        for k in range(3):
            V_out[i, k], Omega_out[i, k] = V_new[k], W_new[k]


def test_block_and_tuple_kernels_give_the_row_by_row_results(small_table):
    """table_rebound_many (table reads of a block of particles issued together) and table_rebound in a numba
    loop (inputs as tuples) = table_rebound called row by row on (3,) arrays, bit for bit.

    1001 rows (not a multiple of the block), normal impacts (trapped draws
    occur there), rows that leave the wall or are NaN (reported invalid).
    """
    m = 1001
    rng = np.random.default_rng(3)
    speed = rng.uniform(50, 250, m)
    a1 = np.radians(rng.uniform(30, 90, m))
    a1[::7] = np.pi / 2
    V = np.column_stack([speed * np.cos(a1), -speed * np.sin(a1), np.zeros(m)])
    V[5], V[600] = [10.0, 5.0, 0.0], [np.nan, -100.0, 0.0]
    n = np.tile([0.0, 1.0, 0.0], (m, 1))
    a = np.full(m, 1e-4)
    U = rng.random((m, U_PER_DRAW))
    cdf = surrogate.mix_cdf(small_table, "mix")
    data = small_table.kernel_data
    V1, W1, s1 = np.empty((m, 3)), np.empty((m, 3)), np.empty(m, dtype=np.int8)
    for i in range(m):
        hit = table_rebound(data, cdf, V[i], n[i], a[i], U[i])
        s1[i], V1[i], W1[i] = hit.status, hit.V, hit.Omega
    V2, W2, s2 = np.empty((m, 3)), np.empty((m, 3)), np.empty(m, dtype=np.int8)
    table_rebound_many(data, cdf, V, n, a, U, V2, W2, s2)
    V3, W3, s3 = np.empty((m, 3)), np.empty((m, 3)), np.empty(m, dtype=np.int8)
    _tuple_loop(data, cdf, V, n, a, U, V3, W3, s3)
    for s, V_, W_ in ((s2, V2, W2), (s3, V3, W3)):
        np.testing.assert_array_equal(s1, s)
        np.testing.assert_array_equal(V1, V_)
        np.testing.assert_array_equal(W1, W_)
    assert s1[5] == s1[600] == STATUS_INVALID and np.any(s1 == STATUS_TRAPPED)


def test_block_kernel_drawing_its_uniforms_equals_the_one_given_them(small_table):
    """table_rebound_many_rng(state) = table_rebound_uniforms(state) then table_rebound_many, bit for bit, and leaves the
    state where table_rebound_uniforms leaves it (rows: two pipelines' worth of blocks and a partial one, an
    invalid row); a state of the wrong size is rejected."""
    m = 7 * BLOCK + 5
    rng = np.random.default_rng(8)
    speed, a1 = rng.uniform(50, 250, m), np.radians(rng.uniform(30, 90, m))
    V = np.column_stack([speed * np.cos(a1), -speed * np.sin(a1), np.zeros(m)])
    V[3] = [10.0, 5.0, 0.0]
    n, a = np.tile([0.0, 1.0, 0.0], (m, 1)), np.full(m, 1e-4)
    data, cdf = small_table.kernel_data, surrogate.mix_cdf(small_table, "mix")
    state_given, state_drawn = seed_state(9), seed_state(9)
    U = table_rebound_uniforms(state_given, m)
    given = np.empty((m, 3)), np.empty((m, 3)), np.empty(m, dtype=np.int8)
    table_rebound_many(data, cdf, V, n, a, U, *given)
    drawn = np.empty((m, 3)), np.empty((m, 3)), np.empty(m, dtype=np.int8)
    table_rebound_many_rng(data, cdf, V, n, a, state_drawn, *drawn)
    for x, y in zip(given, drawn):
        np.testing.assert_array_equal(x, y)
    np.testing.assert_array_equal(state_given, state_drawn)
    assert drawn[2][3] == STATUS_INVALID and np.all(drawn[2][np.arange(m) != 3] != STATUS_INVALID)
    with pytest.raises(ValueError, match="one xoshiro256\\+ state"):
        table_rebound_many_rng(data, cdf, V, n, a, np.ones(3, np.uint64), *drawn)


def test_block_kernel_takes_strided_rows_and_rejects_short_arrays(small_table):
    """V and n as column slices of wider arrays give the results of their contiguous copies; an array with
    another number of rows, or u with another width, is a ValueError naming it and its shape."""
    m = 2 * BLOCK + 3
    rng = np.random.default_rng(10)
    speed, a1 = rng.uniform(50, 250, m), np.radians(rng.uniform(30, 90, m))
    wide_V = np.column_stack([speed * np.cos(a1), -speed * np.sin(a1), np.zeros(m), np.ones(m)])
    wide_n = np.column_stack([np.ones(m), np.zeros(m), np.ones(m), np.zeros(m)])
    V, n, a = wide_V[:, :3], wide_n[:, 1:], np.full(m, 1e-4)
    assert not V.flags.c_contiguous and not n.flags.c_contiguous
    data, cdf = small_table.kernel_data, surrogate.mix_cdf(small_table, "mix")
    strided = np.empty((m, 3)), np.empty((m, 3)), np.empty(m, dtype=np.int8)
    table_rebound_many_rng(data, cdf, V, n, a, seed_state(3), *strided)
    copied = np.empty((m, 3)), np.empty((m, 3)), np.empty(m, dtype=np.int8)
    table_rebound_many_rng(data, cdf, V.copy(), n.copy(), a, seed_state(3), *copied)
    for x, y in zip(strided, copied):
        np.testing.assert_array_equal(x, y)
    assert np.all(strided[2] != STATUS_INVALID)
    with pytest.raises(ValueError, match="'n' has shape \\(66, 3\\); needed \\(67, 3\\)"):
        table_rebound_many_rng(data, cdf, V, n[:-1], a, seed_state(3), *copied)
    with pytest.raises(ValueError, match="'status' has shape \\(66,\\); needed \\(67,\\)"):
        table_rebound_many_rng(data, cdf, V, n, a, seed_state(3), *copied[:2], copied[2][:-1])
    with pytest.raises(ValueError, match="'u' has shape \\(67, 12\\); needed \\(67, 13\\)"):
        table_rebound_many(data, cdf, V, n, a, np.zeros((m, U_PER_DRAW - 1)), *copied)
    # the parallel kernels check before their loop (contiguous V and n: the layout the other tests compile)
    with pytest.raises(ValueError, match="'Omega_out' has shape \\(65, 3\\); needed \\(67, 3\\)"):
        table_rebound_parallel_rng(data, cdf, V.copy(), n.copy(), a, chunk_states(np.random.default_rng(3), m),
                                   copied[0], copied[1][:-2], copied[2])


def test_numba_kernel_flags_a_particle_leaving_the_wall(small_table):
    cdf = surrogate.mix_cdf(small_table, "mix")
    hit = table_rebound(small_table.kernel_data, cdf, np.array([10.0, 5.0, 0.0]),
                        np.array([0.0, 1.0, 0.0]), 1e-4, np.full(U_PER_DRAW, 0.5))
    status, V_out, Omega_out = hit.status, hit.V, hit.Omega
    assert status == STATUS_INVALID and np.all(np.isnan(V_out)) and np.all(np.isnan(Omega_out))
    np.testing.assert_allclose(cdf, [0.25, 0.5, 0.75, 1.0])


def test_speed_move_never_lifts_the_rebound_speed_above_the_incident_one():
    """Regime 0 scales V⁺ − V⁻ by (1 + a(V))/(1 + a(V_iv)) > 1 when the incident speed restitutes more than the grid
    speed: an elastic specular draw at α1 = 83° would come out with s = |V⁺|/|V⁻| ≈ 1.2. It is folded back to
    2 − s, direction kept (so it still leaves the wall), as the chain's s is."""
    from surrogate.kernels.arithmetic import to_speed
    alpha1 = math.radians(83.0)
    c, s = math.cos(alpha1), math.sin(alpha1)
    f_target, f_grid = 0.95, 0.6
    a_target, a_grid = 1.0 - (1.0 - f_target) * s, 1.0 - (1.0 - f_grid) * s
    f = (1.0 + a_target) / (1.0 + a_grid)
    unfolded = np.array([c, abs(f * (s + s) - s), 0.0])       # the move alone, from V⁺ = (cos α1, sin α1, 0)
    assert np.linalg.norm(unfolded) > 1.1
    moved = np.array(to_speed(0.0, f_target, f_grid, c, s, c, s, 0.0, 0.0, 0.0, 0.3)[:3])
    assert np.linalg.norm(moved) == pytest.approx(2.0 - np.linalg.norm(unfolded), rel=1e-14)
    assert np.allclose(moved / np.linalg.norm(moved), unfolded / np.linalg.norm(unfolded), rtol=0, atol=1e-15)
    kept = np.array(to_speed(0.0, 0.6, 0.6, c, s, 0.5 * c, 0.5 * s, 0.0, 0.0, 0.0, 0.3)[:3])   # f = 1, s = 0.5
    assert np.linalg.norm(kept) == pytest.approx(0.5, rel=1e-15)
