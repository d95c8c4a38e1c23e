"""surrogate.rng: xoshiro256+ against an independent plain-Python implementation, uniformity, seeding."""

import numba
import numpy as np
import pytest
from scipy import stats

from surrogate.rng import fill_uniforms, next_uniform, seed_state

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


def test_stream_states_one_per_chunk_and_reproducible():
    from surrogate.rng import ROWS_PER_STREAM, stream_states
    for rows, streams in ((0, 0), (1, 1), (ROWS_PER_STREAM, 1), (ROWS_PER_STREAM + 1, 2)):
        states = stream_states(np.random.default_rng(3), rows)
        assert states.shape == (streams, 4) and states.dtype == np.uint64
    a = stream_states(np.random.default_rng(3), 10 * ROWS_PER_STREAM)
    np.testing.assert_array_equal(a, stream_states(np.random.default_rng(3), 10 * ROWS_PER_STREAM))
    assert len({tuple(row) for row in a}) == 10 and not np.any(np.all(a == 0, axis=1))
