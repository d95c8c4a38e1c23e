"""Grain keys from NumPy (surrogate.sample_global, sample_direct with ``grain_key``; surrogate.grain_of, grain_key):
a keyed particle hits as the same grain every time, its draws reproducible whatever the threads; without keys
the bits of a call without them; keys spread over the mix with its weights; a bad key array is one ValueError."""

from __future__ import annotations

import math

import numba
import numpy as np
import pytest

import surrogate
from surrogate import STATUS_REBOUNDED
from surrogate.kernels import CHUNK_ROWS, PATH_DIRECT, PATH_TABLE, rebound, table_rebound_uniforms
from surrogate.kernels.grain import NO_KEY
from surrogate.kernels.rng import chunk_states
from tests.surrogate.test_spin import A, NORMAL, _in_grid, _spinning, ks_bound

M = 2 * CHUNK_ROWS + 37         # three chunks, the last a part
MIX = {"ellipsoid": 0.1, "prism": 0.2, "cut_prism": 0.3, "tetrahedron": 0.4}


def _bits(outputs) -> bytes:
    return b"".join(np.ascontiguousarray(x).tobytes() for x in outputs)


def _keys(m, seed=35):
    return surrogate.grain_key(seed, np.arange(m))


@pytest.mark.parametrize("method", ["auto", "table", "direct"])
def test_no_key_gives_the_bits_of_a_call_without_keys(small_table, method):
    """grain_key=None, and the kernel given keys that are all NO_KEY, draw what the call without the keyword
    draws (spinning hits and not, so both paths answer under auto)."""
    V = _in_grid(M, 1)
    W = np.where(np.arange(M)[:, None] % 2 == 0, 0.0, _spinning(V, 0.3, 2))
    plain = surrogate.sample_global(small_table, V, NORMAL, A, MIX, random_state=3, omega=W, method=method)
    assert _bits(plain) == _bits(surrogate.sample_global(small_table, V, NORMAL, A, MIX, random_state=3, omega=W,
                                                         method=method, grain_key=None))
    from surrogate.kernels import rebound_parallel_rng
    outputs = surrogate.empty_rebounds(M)
    rebound_parallel_rng(small_table.kernel_data, small_table.direct_parameters, small_table.shape_arrays,
                         small_table.model_shapes, surrogate.mix_cdf(small_table, MIX), np.zeros(0, np.int64),
                         np.full(M, NO_KEY), V, W, np.tile(NORMAL, (M, 1)), np.full(M, A),
                         chunk_states(np.random.default_rng(3), M), surrogate.METHODS[method], outputs, True)
    assert _bits(plain) == _bits(outputs)
    if method == "auto":
        assert {PATH_TABLE, PATH_DIRECT} <= set(plain.path)
    direct = surrogate.sample_direct(small_table, V, NORMAL, A, MIX, random_state=4, omega=W)
    assert _bits(direct) == _bits(surrogate.sample_direct(small_table, V, NORMAL, A, MIX, random_state=4, omega=W,
                                                          grain_key=None))


@pytest.mark.parametrize("method", ["auto", "direct"])
def test_keyed_rows_are_the_single_hit_with_the_key(small_table, method):
    """Each row of a keyed sample_global is surrogate.kernels.rebound with its key and its row's uniforms
    (table_rebound_uniforms of its chunk's state), on both paths; some rows keyed, some not (NO_KEY)."""
    from surrogate.kernels import rebound_parallel_rng
    V = _in_grid(M, 5)
    W = np.where(np.arange(M)[:, None] % 3 == 0, 0.0, _spinning(V, 0.3, 6))
    keys = np.where(np.arange(M) % 4 == 1, NO_KEY, _keys(M))
    cdf = surrogate.mix_cdf(small_table, MIX)
    states = chunk_states(np.random.default_rng(7), M)
    outputs = surrogate.empty_rebounds(M)
    rebound_parallel_rng(small_table.kernel_data, small_table.direct_parameters, small_table.shape_arrays,
                         small_table.model_shapes, cdf, np.zeros(0, np.int64), keys, V, W, np.tile(NORMAL, (M, 1)),
                         np.full(M, A), states, surrogate.METHODS[method], outputs, True)
    u = np.concatenate([table_rebound_uniforms(states[j].copy(), min(CHUNK_ROWS, M - j * CHUNK_ROWS))
                        for j in range(len(states))])
    for i in range(M):
        hit = rebound(small_table.kernel_data, small_table.direct_parameters, small_table.shape_arrays,
                      small_table.model_shapes, cdf, tuple(V[i]), tuple(W[i]), NORMAL, A, u[i],
                      surrogate.METHODS[method], True, None if keys[i] == NO_KEY else keys[i])
        st, v, w = hit.status, hit.V, hit.Omega
        assert st == outputs.status[i] and np.array(v).tobytes() == outputs.V[i].tobytes(), i
        assert np.array(w).tobytes() == outputs.Omega[i].tobytes(), i
    assert np.mean(outputs.status == STATUS_REBOUNDED) > 0.5


@pytest.mark.parametrize("method", ["auto", "direct"])
def test_keyed_draws_are_reproducible_and_thread_independent(small_table, method):
    V = _in_grid(M, 8)
    W = np.where(np.arange(M)[:, None] % 2 == 0, 0.0, _spinning(V, 0.3, 9))
    keys = _keys(M, 10)
    threads = numba.get_num_threads()
    try:
        results = []
        for n in (1, 2, 1):
            numba.set_num_threads(min(n, numba.config.NUMBA_NUM_THREADS))
            results.append(_bits(surrogate.sample_global(small_table, V, NORMAL, A, MIX, random_state=11, omega=W,
                                                         method=method, grain_key=keys)))
            results.append(_bits(surrogate.sample_direct(small_table, V, NORMAL, A, MIX, random_state=11, omega=W,
                                                         grain_key=keys)))
    finally:
        numba.set_num_threads(threads)
    assert results[0] == results[2] == results[4] and results[1] == results[3] == results[5]
    unkeyed = surrogate.sample_global(small_table, V, NORMAL, A, MIX, random_state=11, omega=W, method=method)
    assert results[0] != _bits(unkeyed)


def test_a_keyed_particle_keeps_its_grain_hit_after_hit(small_table):
    """One key, many hits: on the table path the rows draw what the grain's one shape draws (the key's shape
    given per particle), on the direct path the rows are the same whatever the stream's shape, proportion and
    hand uniforms (the key's); the orientation still varies from hit to hit (the rebounds differ)."""
    key = surrogate.grain_key(12, 0, 99)
    grain = surrogate.grain_of(small_table, [key], MIX)
    V = np.tile(_in_grid(1, 13), (M, 1))
    keys = np.full(M, key)
    table = surrogate.sample_global(small_table, V, NORMAL, A, MIX, random_state=14, method="table", grain_key=keys)
    one_shape = surrogate.sample_global(small_table, V, NORMAL, A, [grain.shape[0]] * M, random_state=14,
                                        method="table")
    assert _bits(table) == _bits(one_shape)
    W = np.tile(_spinning(V[:1], 0.3, 15), (M, 1))
    direct = surrogate.sample_global(small_table, V, NORMAL, A, MIX, random_state=16, omega=W, grain_key=keys)
    cdf = surrogate.mix_cdf(small_table, MIX)
    rng = np.random.default_rng(17)
    for i in range(0, M, 7):
        u = rng.random(13)
        other = u.copy()
        other[[0, 4, 5, 6]] = rng.random(4)       # the shape, b/a, c/b and hand slots of a direct draw
        hits = [rebound(small_table.kernel_data, small_table.direct_parameters, small_table.shape_arrays,
                        small_table.model_shapes, cdf, tuple(V[i]), tuple(W[i]), NORMAL, A, x, 0, True, key)
                for x in (u, other)]
        assert hits[0].status == hits[1].status and np.array(hits[0].V).tobytes() == np.array(hits[1].V).tobytes()
    for V_out, status in ((table.V, table.status), (direct.V, direct.status)):
        rebounded = V_out[status == STATUS_REBOUNDED]
        alpha2 = np.degrees(np.arctan2(rebounded[:, 1], np.hypot(rebounded[:, 0], rebounded[:, 2])))
        assert len(rebounded) > M // 2 and np.std(alpha2) > 5.0      # one grain over random orientations


def test_keys_spread_over_the_mix_with_its_weights(small_table):
    """Shapes of 20 000 keys (grain_key of a seed and 0..19 999): χ² against the weights, 3 degrees of freedom;
    bound 16.27, the 0.999 quantile of χ²(3) (the keys are fixed: the test fails by chance nowhere)."""
    n = 20_000
    names = surrogate.grain_of(small_table, _keys(n, 18), MIX).shape
    observed = np.array([np.sum(names == name) for name in MIX])
    expected = n * np.array(list(MIX.values()))
    assert np.sum((observed - expected) ** 2 / expected) < 16.27


def test_grain_of_gives_the_proportions_the_direct_path_fixes(small_table, grain_table_path):
    grain_table = surrogate.load(grain_table_path)
    grains = surrogate.grain_of(small_table, _keys(4000, 19), MIX)
    params = small_table.direct_parameters
    for name in MIX:
        rows = grains.shape == name
        assert np.all((grains.ratio_ba[rows] >= params[2]) & (grains.ratio_ba[rows] <= params[3]))
        assert np.all((grains.ratio_cb[rows] >= params[2]) & (grains.ratio_cb[rows] <= params[3]))
        # the tetrahedron alone comes in both hands, each half of the keys (6 binomial sds)
        if name == "tetrahedron":
            assert abs(np.mean(grains.hand[rows] == 1.0) - 0.5) < 6 * 0.5 / math.sqrt(rows.sum())
            assert np.all(np.abs(grains.hand[rows]) == 1.0)
        else:
            assert np.all(np.isnan(grains.hand[rows]))
    # a user grain of fixed proportions: NaN b/a, c/b; the one of random proportions in both hands: numbers
    user = surrogate.grain_of(grain_table, _keys(200, 20), "mix")
    fixed = np.array([r.aspect is None for r in grain_table.records])[[grain_table.shapes.index(s) for s in user.shape]]
    assert fixed.any() and (~fixed).any()
    assert np.all(np.isnan(user.ratio_ba[fixed])) and np.all(np.isfinite(user.ratio_ba[~fixed]))
    # a shape given per key wins over the key's draw from the mix
    assert set(surrogate.grain_of(small_table, [1, 2, 3], ["prism"] * 3).shape) == {"prism"}


@pytest.mark.parametrize("method", ["table", "direct"])
def test_a_population_of_keys_draws_the_law_of_new_grains(small_table, method):
    """Averaged over keys (one hit each) a keyed population draws the law without keys: the keyed uniforms are
    uniform too. Two-sample Kolmogorov–Smirnov on |V⁺|/|V⁻| and on V⁺_y/|V⁻|, n = m = 3000, bound at α = 1e-3
    (test_spin.ks_bound); fixed seeds."""
    n = 3000
    V = np.tile(_in_grid(1, 22, alpha1=(45.0, 45.0), speed=(100.0, 100.0)), (n, 1))
    W = np.zeros((1, 3)) if method == "table" else np.tile(_spinning(V[:1], 0.05, 23), (n, 1))
    keyed = surrogate.sample_global(small_table, V, NORMAL, A, MIX, random_state=24, omega=W, method=method,
                                    grain_key=_keys(n, 25))
    new = surrogate.sample_global(small_table, V, NORMAL, A, MIX, random_state=26, omega=W, method=method)
    speed = np.linalg.norm(V[0])
    for ratio in (lambda x: np.linalg.norm(x, axis=1) / speed, lambda x: x[:, 1] / speed):
        a, b = (np.sort(ratio(out.V[out.status == STATUS_REBOUNDED])) for out in (keyed, new))
        grid = np.concatenate([a, b])
        distance = np.max(np.abs(np.searchsorted(a, grid, "right") / len(a) - np.searchsorted(b, grid, "right") / len(b)))
        assert distance < ks_bound(len(a), len(b)), distance


def _splitmix64(x: int) -> int:
    """splitmix64 in Python integers (Steele, Lea & Flood 2014): the reference for grain_key."""
    z = x % 2 ** 64
    z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) % 2 ** 64
    z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) % 2 ** 64
    return z ^ (z >> 31)


def test_grain_key_is_splitmix64_chained():
    golden = 0x9E3779B97F4A7C15
    for seed, ids in ((0, ()), (1, (0, 42)), (2 ** 64 - 1, (2 ** 64 - 1, 5, 7)), (123, (9,))):
        h = _splitmix64(seed + golden)
        for x in ids:
            h = _splitmix64(h + x + golden)
        assert surrogate.grain_key(seed, *ids) == h & (2 ** 63 - 1)
    keys = surrogate.grain_key(5, 3, np.arange(1000))
    assert keys.dtype == np.int64 and keys.shape == (1000,) and len(np.unique(keys)) == 1000
    assert keys[17] == surrogate.grain_key(5, 3, 17)


@pytest.mark.parametrize("bad, message", [
    (np.arange(3), r"'grain_key' parameter must be one key per particle, shape \(4,\); got \(3,\)"),
    (np.array([0, 1, -5, 2]), r"'grain_key' at index 2 must be in \[0, 2\*\*63\); got -5"),
    (np.array([0, 2 ** 63, 1, 2], dtype=np.uint64), r"'grain_key' at index 1 must be in \[0, 2\*\*63\)"),
    (np.array([0.0, 1.5, 2.0, 3.0]), r"got an array of dtype float64 \(a float, bool or object key is refused"),
    (np.array([0.0, 1.0, 2.0, 3.0]), r"dtype float64"),
    (np.array([True, False, True, True]), r"dtype bool"),
    (np.array([1, 2, 3, None], dtype=object), r"dtype object"),
    (2.0, r"'grain_key' parameter must be integers in \[0, 2\*\*63\), one per particle; got 2.0"),
    (np.zeros((4, 1), dtype=np.int64), r"shape \(4,\); got \(4, 1\)"),
])
def test_a_bad_key_array_is_one_clear_error(small_table, bad, message):
    V = _in_grid(4, 21)
    for call in (surrogate.sample_global, surrogate.sample_direct):
        with pytest.raises(ValueError, match=message):
            call(small_table, V, NORMAL, A, MIX, random_state=1, grain_key=bad)


@pytest.mark.parametrize("bad", [-1, 2 ** 64, 1.0, True, np.array([-3])])
def test_grain_key_refuses_what_is_no_64_bit_unsigned_integer(bad):
    with pytest.raises(ValueError, match=r"grain_key must be integers in \[0, 2\*\*64\)"):
        surrogate.grain_key(1, bad)


def test_cli_draws_one_grain_over_orientations(small_table_path, small_table, tmp_path, capsys):
    """surrogate sample --grain-key: the draws of sample_global with that key for every draw (on the table path its
    shape, on the direct path its proportions and hand too); the grain in the samples' provenance; --mix takes
    name=weight pairs as well as four numbers (the same draws)."""
    from data_schema.samples import read_samples
    from surrogate.cli import main
    from tests.helpers.cli import run_cli
    key = 7
    shape = surrogate.grain_of(small_table, [key], MIX).shape[0]
    common = ["sample", "--table", str(small_table_path), "--alpha1", "45", "--speed", "100", "-n", "500",
              "--seed", "5"]
    named = ",".join(f"{k}={v}" for k, v in MIX.items())
    for method in ("table", "direct"):
        outputs = []
        for mix in (named, ",".join(str(v) for v in MIX.values())):
            out = tmp_path / f"{method}_{len(outputs)}.h5"
            code, err, text = run_cli(main, common + ["--mix", mix, "--grain-key", str(key), "--method", method,
                                                      "--out", str(out)], capsys)
            assert code == 0, err
            assert f"one grain, key {key}: {shape}" in text
            outputs.append(read_samples(out))
        assert outputs[0].velocity.tobytes() == outputs[1].velocity.tobytes()
        samples = outputs[0]
        assert samples.provenance["grain_key"] == key and samples.provenance["grain_shape"] == shape
        a1 = math.radians(45.0)          # as the command line computes V⁻
        V = np.tile([100.0 * math.cos(a1), -100.0 * math.sin(a1), 0.0], (500, 1))
        keyed = surrogate.sample_global(small_table, V, NORMAL, 1.0, MIX, random_state=5, method=method,
                                        grain_key=np.full(500, key))
        assert samples.velocity.tobytes() == keyed.V.tobytes()
        assert np.all(keyed.shape == small_table.shapes.index(shape))
        if method == "table":
            assert "grain_ratio_ba" not in samples.provenance
        else:
            assert samples.provenance["grain_ratio_ba"] == surrogate.grain_of(small_table, [key], MIX).ratio_ba[0]


@pytest.mark.parametrize("argv, words", [
    (["--grain-key", "-3"], ["--grain-key", "[0, 2**63)", "-3"]),
    (["--grain-key", "1.5"], ["--grain-key", "'1.5'"]),
    (["--grain-key", str(2 ** 63)], ["--grain-key", str(2 ** 63)]),
    (["--mix", "prism=x,tetrahedron=0.5"], ["--mix", "'prism'", "'x'"]),
    (["--mix", "prism=0.5,prism=0.5"], ["--mix", "at most once"]),
    (["--mix", "prism=0.5,0.5"], ["--mix", "name=weight"]),
    (["--mix", "prism=0.5,grit=0.5"], ["'grit'"]),
    (["--mix", "prism=0.7,tetrahedron=0.5"], ["sum"]),
])
def test_cli_bad_grain_key_or_mix_is_one_line(small_table_path, capsys, argv, words):
    from surrogate.cli import main
    from tests.helpers.cli import user_error
    user_error(main, ["sample", "--table", str(small_table_path), "--alpha1", "45", "--speed", "100", "-n", "5"]
               + argv, capsys, *words)


def test_cli_draws_one_grain_per_draw_from_a_file_of_keys(small_table_path, small_table, tmp_path, capsys):
    """surrogate sample --grain-keys FILE: draw i is the grain of key i, as sample_global draws it with those keys,
    on the table path and on the direct path; the shapes' counts are printed and kept in the provenance."""
    from data_schema.samples import read_samples
    from surrogate.cli import main
    from tests.helpers.cli import run_cli
    n = 300
    keys = np.arange(n, dtype=np.int64) * 1_000_003 + 11
    path = tmp_path / "keys.txt"
    path.write_text("\n".join(map(str, keys[:150])) + "\n" + " ".join(map(str, keys[150:])))
    names, counts = np.unique(surrogate.grain_of(small_table, keys, MIX).shape, return_counts=True)
    shapes = ", ".join(f"{name} {count}" for name, count in zip(names, counts))
    named = ",".join(f"{k}={v}" for k, v in MIX.items())
    a1 = math.radians(45.0)          # as the command line computes V⁻
    V = np.tile([100.0 * math.cos(a1), -100.0 * math.sin(a1), 0.0], (n, 1))
    for method in ("table", "direct"):
        out = tmp_path / f"{method}.h5"
        code, err, text = run_cli(main, ["sample", "--table", str(small_table_path), "--alpha1", "45", "--speed",
                                         "100", "-n", str(n), "--seed", "5", "--mix", named, "--grain-keys",
                                         str(path), "--method", method, "--out", str(out)], capsys)
        assert code == 0, err
        assert f"{n} grains, one per draw, from {path}: {shapes}" in text
        samples = read_samples(out)
        assert samples.provenance["grain_shapes"] == shapes
        expected = surrogate.sample_global(small_table, V, NORMAL, 1.0, MIX, random_state=5, method=method,
                                           grain_key=keys)
        assert samples.velocity.tobytes() == expected.V.tobytes()


@pytest.mark.parametrize("content, words", [
    ("1 2", ["2 keys", "-n asks for 5"]),
    ("1 2 3 -4 5", ["entry 4", "'-4'", "[0, 2**63)"]),
    ("1 2 3 4.0 5", ["entry 4", "'4.0'"]),
    (f"1 2 3 4 {2 ** 63}", ["entry 5", str(2 ** 63)]),
    (None, ["cannot read"]),
])
def test_cli_bad_file_of_keys_is_one_line(small_table_path, tmp_path, capsys, content, words):
    from surrogate.cli import main
    from tests.helpers.cli import user_error
    path = tmp_path / "keys.txt"
    if content is not None:
        path.write_text(content)
    user_error(main, ["sample", "--table", str(small_table_path), "--alpha1", "45", "--speed", "100", "-n", "5",
                      "--grain-keys", str(path)], capsys, "--grain-keys", *words)
