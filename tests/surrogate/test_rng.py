"""surrogate.kernels.rng: xoshiro256+ against an independent plain-Python implementation, uniformity, seeding."""

import numba
import numpy as np
import pytest
from scipy import stats

from surrogate.kernels import BLOCK, U_PER_DRAW, table_rebound_uniforms
from surrogate.kernels.rng import fill_lanes, fill_uniforms, next_uniform, seed_lanes, seed_state

MASK = (1 << 64) - 1


def _reference_xoshiro256plus(state, n):
    """The published algorithm (Blackman & Vigna), on Python integers."""
    s = [int(w) for w in state]
    out = []
    for _ in range(n):
        result = (s[0] + s[3]) & MASK
        t = (s[1] << 17) & MASK
        s[2] ^= s[0]
        s[3] ^= s[1]
        s[1] ^= s[2]
        s[0] ^= s[3]
        s[2] ^= t
        s[3] = ((s[3] << 45) | (s[3] >> 19)) & MASK
        out.append((result >> 11) * 2.0 ** -53)
    return out, s


def _reference_splitmix64(x):
    """splitmix64's output for the counter value x (Steele, Lea & Flood 2014), on Python integers."""
    z = x & MASK
    z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & MASK
    z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & MASK
    return z ^ (z >> 31)


def _reference_raw(state):
    """The next 64-bit xoshiro256+ output and the state after it, on Python integers."""
    s = [int(w) for w in state]
    result = (s[0] + s[3]) & MASK
    _, after = _reference_xoshiro256plus(state, 1)
    return result, after


@numba.njit
def _fill_lanes_32_13(lanes, u):
    fill_lanes(lanes, u, 32, 13)


@numba.njit
def _seed_lanes(state, lanes):
    seed_lanes(state, lanes)


@numba.njit
def _draw(state, n):
    out = np.empty(n)
    for i in range(n):
        out[i] = next_uniform(state)
    return out


def test_matches_the_reference_algorithm():
    state = seed_state(7)
    expected, final = _reference_xoshiro256plus(state, 1000)
    got = _draw(state, 1000)
    assert got.tolist() == expected
    assert [int(w) for w in state] == final


def test_fill_uniforms_continues_the_stream():
    a, b = seed_state(3), seed_state(3)
    u = np.empty(13)
    fill_uniforms(a, u)
    np.testing.assert_array_equal(u, _draw(b, 13))
    np.testing.assert_array_equal(a, b)      # the state moved on by exactly 13 steps
    fill_uniforms(a, u)
    np.testing.assert_array_equal(u, _draw(b, 13))


def test_uniform_on_the_unit_interval():
    """KS against U(0, 1) on 10⁵ draws: with a fixed seed, p < 1e-3 would flag a defect."""
    x = _draw(seed_state(11), 100_000)
    assert x.min() >= 0.0 and x.max() < 1.0
    assert stats.kstest(x, "uniform").pvalue > 1e-3


def test_streams_are_distinct_and_reproducible():
    states = seed_state(5, n_streams=4)
    assert states.shape == (4, 4) and states.dtype == np.uint64
    assert len({tuple(row) for row in states}) == 4
    np.testing.assert_array_equal(states, seed_state(5, n_streams=4))
    np.testing.assert_array_equal(seed_state(5), seed_state(5, n_streams=1)[0])


@pytest.mark.parametrize("kwargs, message", [({"seed": -1}, "seed"), ({"seed": 1.5}, "seed"),
                                             ({"seed": 1, "n_streams": 0}, "n_streams")])
def test_bad_seeds_are_rejected(kwargs, message):
    with pytest.raises(ValueError, match=message):
        seed_state(**kwargs)


def test_chunk_states_one_per_chunk_and_reproducible():
    from surrogate.kernels.rng import CHUNK_ROWS, chunk_states
    for rows, streams in ((0, 0), (1, 1), (CHUNK_ROWS, 1), (CHUNK_ROWS + 1, 2)):
        states = chunk_states(np.random.default_rng(3), rows)
        assert states.shape == (streams, 4) and states.dtype == np.uint64
    a = chunk_states(np.random.default_rng(3), 10 * CHUNK_ROWS)
    np.testing.assert_array_equal(a, chunk_states(np.random.default_rng(3), 10 * CHUNK_ROWS))
    assert len({tuple(row) for row in a}) == 10 and not np.any(np.all(a == 0, axis=1))


def test_seed_lanes_is_splitmix64_of_the_next_output():
    """Word j of the lanes is splitmix64(x + (j + 1)·γ), x the state's next output; the state moves one step."""
    state = seed_state(21)
    x, after = _reference_raw(state)
    lanes = np.zeros(4 * 32, dtype=np.uint64)
    _seed_lanes(state, lanes)
    assert [int(w) for w in state] == after
    gamma = 0x9E3779B97F4A7C15
    assert [int(w) for w in lanes] == [_reference_splitmix64(x + (j + 1) * gamma) for j in range(4 * 32)]


def test_fill_lanes_runs_each_lane_as_xoshiro256plus():
    """u[q·L + l] is output q of lane l's own xoshiro256+ stream, and each lane's state moves on by the count."""
    lanes = np.zeros(4 * 32, dtype=np.uint64)
    _seed_lanes(seed_state(22), lanes)
    before = lanes.copy()
    u = np.empty(32 * 13)
    _fill_lanes_32_13(lanes, u)
    for lane in range(32):
        words = [before[w * 32 + lane] for w in range(4)]
        expected, final = _reference_xoshiro256plus(words, 13)
        assert u[lane::32].tolist() == expected
        assert [int(lanes[w * 32 + lane]) for w in range(4)] == final


def test_rebound_uniforms_gives_row_b_of_each_block_from_lane_b():
    """Row i of table_rebound_uniforms: uniforms 13·(i // BLOCK) … of lane i % BLOCK, seeded by seed_lanes."""
    rows = 3 * BLOCK + 7
    state, copy = seed_state(23), seed_state(23)
    U = table_rebound_uniforms(state, rows)
    lanes = np.zeros(4 * BLOCK, dtype=np.uint64)
    _seed_lanes(copy, lanes)
    np.testing.assert_array_equal(state, copy)
    for lane in (0, 5, BLOCK - 1):
        stream, _ = _reference_xoshiro256plus([lanes[w * BLOCK + lane] for w in range(4)], 4 * U_PER_DRAW)
        for block in range(4):
            i = block * BLOCK + lane
            if i < rows:
                assert U[i].tolist() == stream[block * U_PER_DRAW:(block + 1) * U_PER_DRAW]


def test_rebound_uniforms_are_uniform_and_lanes_uncorrelated():
    """KS against U(0, 1) on 10⁴ rows (1.3·10⁵ uniforms): p < 1e-3 would flag a defect. Neighbouring lanes
    (rows i, i + 1 of a block) and consecutive uniforms of a row: the correlation of n independent pairs has
    standard deviation 1/√n (n = 10⁴ rows), so |r| < 5/√n fails by chance with probability below 1e-6."""
    U = table_rebound_uniforms(seed_state(24), 10_000)
    assert U.min() >= 0.0 and U.max() < 1.0
    assert stats.kstest(U.ravel(), "uniform").pvalue > 1e-3
    limit = 5.0 / np.sqrt(len(U))
    assert abs(np.corrcoef(U[:-1, 4], U[1:, 4])[0, 1]) < limit
    assert abs(np.corrcoef(U[:, 5], U[:, 6])[0, 1]) < limit
