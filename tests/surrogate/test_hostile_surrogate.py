"""`surrogate` command line and sampler against hostile input: every case ends in one line and exit 2, and
nothing of the user's is replaced."""

import functools
import shutil
import subprocess

import numpy as np
import pytest

import surrogate
from data_schema.output import kind_of
from data_schema.samples import SAMPLES_FILE_TYPE
from data_schema.table import TABLE_FILE_TYPE
from surrogate.cli import main

from tests.helpers.cli import run_cli, user_error

GOOD = ["--alpha1", "45", "--speed", "150", "-n", "10", "--seed", "1"]


_run = functools.partial(run_cli, main)               # (exit status, stderr lines, stdout)
_user_error = functools.partial(user_error, main)     # one line on stderr, exit 2: (line, stdout)


@pytest.fixture
def table(small_table_path, tmp_path):
    """A copy of the small table that a test may try to damage."""
    return shutil.copy(small_table_path, tmp_path / "t.h5")


def test_overwrite_never_replaces_the_table_being_read(table, capsys):
    _user_error(["sample", "--table", str(table), *GOOD, "--out", str(table), "--overwrite"], capsys,
                "input", str(table))
    assert kind_of(table) == TABLE_FILE_TYPE
    surrogate.load(table)


def test_overwrite_replaces_only_a_samples_file(table, small_table_path, tmp_path, capsys):
    notes = tmp_path / "notes.txt"
    notes.write_text("my notes")
    _user_error(["sample", "--table", str(table), *GOOD, "--out", str(notes), "--overwrite"], capsys,
                "not an output of rebound-scatter", SAMPLES_FILE_TYPE)
    assert notes.read_text() == "my notes"
    other_table = shutil.copy(small_table_path, tmp_path / "other.h5")
    _user_error(["sample", "--table", str(table), *GOOD, "--out", str(other_table), "--overwrite"], capsys,
                f"a {TABLE_FILE_TYPE} output")
    assert kind_of(other_table) == TABLE_FILE_TYPE
    out = tmp_path / "s.h5"
    assert _run(["sample", "--table", str(table), *GOOD, "--out", str(out)], capsys)[0] == 0
    _user_error(["sample", "--table", str(table), *GOOD, "--out", str(out)], capsys, "exists", "--overwrite")
    assert _run(["sample", "--table", str(table), *GOOD, "--out", str(out), "--overwrite"], capsys)[0] == 0
    assert kind_of(out) == SAMPLES_FILE_TYPE
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".")] == []


@pytest.mark.parametrize("alpha1, speed, word", [(45, -100, "'speed' value -100.0"), (-30, 150, "'alpha1' value -30.0"),
                                                 (0, 150, "'alpha1' value 0.0"), (1000, 150, "'alpha1' value 1000.0")])
def test_clamp_never_reaches_beyond_the_physical_range(table, capsys, alpha1, speed, word):
    _user_error(["sample", "--table", str(table), "--alpha1", str(alpha1), "--speed", str(speed), "-n", "10",
                 "--clamp"], capsys, word, "physical range")
    with pytest.raises(ValueError, match="physical range"):
        surrogate.sample_local(surrogate.load(table), alpha1, speed, clamp=True)


def test_clamp_still_extends_the_table_range_up_to_the_physical_one(small_table):
    draws = surrogate.sample_local(small_table, [5.0, 90.0], [10.0, 1000.0], random_state=1, clamp=True)
    ok = draws.status == surrogate.STATUS_REBOUNDED
    assert np.all(np.isfinite(draws.speed_ratio[ok])) and np.all(draws.alpha2[ok] > 0)


def test_messages_print_plain_numbers(small_table):
    with pytest.raises(ValueError) as info:
        surrogate.sample_local(small_table, np.float64(10.0), 150.0)
    assert "10.0 deg" in str(info.value) and "np.float64" not in str(info.value)


@pytest.mark.parametrize("argv, words", [
    (["-n", "1e12"], ["-n = 1000000000000", "GiB", "at most"]),
    (["-n", "0"], ["-n", ">= 1"]),
    (["-n", "2.5"], ["-n", "integer"]),
    (["--seed", "1000000000000000000000000000"], ["--seed", "[0, 2**63)"]),
    (["--seed", "-1"], ["--seed", "[0, 2**63)"]),
])
def test_sizes_and_seeds_outside_their_range(table, capsys, argv, words):
    base = ["sample", "--table", str(table), "--alpha1", "45", "--speed", "150", "-n", "10"]
    _user_error(base + argv + ["--out", str(table.parent / "x.h5")], capsys, *words)
    assert not (table.parent / "x.h5").exists()


def test_output_paths_that_cannot_be_written(table, tmp_path, capsys):
    base = ["sample", "--table", str(table), *GOOD, "--out"]
    _user_error(base + [str(tmp_path / "missing" / "x.h5")], capsys, "does not exist")
    _user_error(base + [""], capsys, "empty")
    _user_error(base + [str(tmp_path), "--overwrite"], capsys, "is a folder")


def test_an_immutable_target_is_refused_before_drawing(table, tmp_path, capsys):
    out = tmp_path / "s.h5"
    assert _run(["sample", "--table", str(table), *GOOD, "--out", str(out)], capsys)[0] == 0
    before = out.read_bytes()
    if subprocess.run(["chattr", "+i", str(out)], capture_output=True).returncode != 0:
        pytest.skip("this file system has no immutable attribute (chattr +i)")
    try:
        _user_error(["sample", "--table", str(table), *GOOD, "--out", str(out), "--overwrite"], capsys,
                    "cannot be replaced")
    finally:
        subprocess.run(["chattr", "-i", str(out)], check=True)
    assert out.read_bytes() == before


def test_info_on_a_folder_a_foreign_file_and_a_missing_file(tmp_path, capsys):
    _user_error(["info", str(tmp_path)], capsys, "is a folder")
    notes = tmp_path / "notes.txt"
    notes.write_text("x")
    _user_error(["info", str(notes)], capsys, "neither")
    _user_error(["info", str(tmp_path / "nothing.h5")], capsys, "no such file")


def test_a_corrupted_table_fails_to_load_naming_the_dataset(table, capsys):
    """20 KB of noise in the middle of the file: the Fletcher-32 checksum of the dataset there fails."""
    data = bytearray(table.read_bytes())
    middle = len(data) // 2
    data[middle:middle + 20_000] = np.random.default_rng(1).integers(0, 256, 20_000, dtype=np.uint8).tobytes()
    table.write_bytes(bytes(data))
    line, _ = _user_error(["sample", "--table", str(table), *GOOD], capsys, str(table), "dataset")
    assert "corrupt" in line


# -- the kernels never return a non-finite or unphysical rebound; the API's one-line errors -------------

def _draw(table, V=(40.0, -0.3, 0.0), n=(0.0, 1.0, 0.0), a=1e-4, u=None):
    """(status, V⁺, Ω⁺) of surrogate.kernels.table_rebound for one particle, seed-1 uniforms unless given."""
    from surrogate.kernels import table_rebound
    if u is None:
        u = np.empty(surrogate.U_PER_DRAW)
        surrogate.fill_uniforms(surrogate.seed_state(1), u)
    cdf = surrogate.mix_cdf(table, "mix")
    hit = table_rebound(table.kernel_data, cdf, V, n, a, np.asarray(u, dtype=np.float64), True)
    return hit.status, hit.V, hit.Omega


@pytest.mark.parametrize("k", range(13))
@pytest.mark.parametrize("value", [-0.5, 1.0, 1e6, -1e300, np.nan, np.inf])
def test_uniforms_outside_the_unit_interval_give_invalid(small_table, k, value):
    """The numba twin of rbs_rebound: a uniform outside [0, 1) or NaN is STATUS_INVALID and NaN, never a
    read outside the cell (u[5] = -0.5 was a heap overflow in C) or |V⁺| of 3e6 m/s from 40 m/s (u[5] = 1e6)."""
    u = np.empty(surrogate.U_PER_DRAW)
    surrogate.fill_uniforms(surrogate.seed_state(1), u)
    assert _draw(small_table, u=u)[0] in (surrogate.STATUS_REBOUNDED, surrogate.STATUS_TRAPPED)
    u[k] = value
    status, V_out, W_out = _draw(small_table, u=u)
    assert status == surrogate.STATUS_INVALID and np.isnan(V_out).all() and np.isnan(W_out).all()


@pytest.mark.parametrize("V, n, a", [
    ((0.8e200, -0.6e200, 0.0), (0.0, 1.0, 0.0), 1e-4),      # |V⁻| = 1e200: V·V overflows (was V⁺ = ±inf)
    ((40.0, -0.3, 0.0), (0.0, 1.0, 0.0), 5e-324),           # Ω⁺ = |V⁻|/a · ... overflows
    ((40.0, -0.3, 0.0), (0.0, 1.0, 0.0), 0.0),
    ((40.0, -0.3, 0.0), (0.0, 1.0, 0.0), -1e-4),
    ((40.0, -0.3, 0.0), (0.0, 1.0, 0.0), np.nan),
    ((40.0, -0.3, 0.0), (0.0, 1e200, 0.0), 1e-4),           # a normal of length 1e200 (was NaN with status 0)
    ((40.0, -0.3, 0.0), (0.0, 2.0, 0.0), 1e-4),
])
def test_extreme_particles_give_invalid(small_table, V, n, a):
    status, V_out, W_out = _draw(small_table, V, n, a)
    assert status == surrogate.STATUS_INVALID and np.isnan(V_out).all() and np.isnan(W_out).all()


@pytest.mark.parametrize("speed", [1e-150, 1e-160, 1e-200, 1e-300, 5e-324, 1e150, 1e154])
def test_whatever_is_rebounded_is_finite_and_leaves_the_wall(small_table, speed):
    """Tiny |V⁻| gave V⁺ = (-0, 0, -0) with status 0: a rebound must leave the wall (V⁺·n > 0) and be finite;
    over 200 seeds."""
    n = np.array([0.0, 1.0, 0.0])
    for seed in range(200):
        u = np.empty(surrogate.U_PER_DRAW)
        surrogate.fill_uniforms(surrogate.seed_state(seed), u)
        status, V_out, W_out = _draw(small_table, (0.8 * speed, -0.6 * speed, 0.0), tuple(n), 1e-4, u)
        if status == surrogate.STATUS_REBOUNDED:
            assert np.isfinite(V_out).all() and np.isfinite(W_out).all() and np.dot(V_out, n) > 0.0
        else:
            assert np.isnan(V_out).all() and np.isnan(W_out).all()


def test_an_all_zero_generator_gives_nan_not_zeros(small_table):
    """xoshiro256+'s fixed point: all-zero words gave u = 0 forever; now NaN, which every draw refuses."""
    from surrogate.kernels.rng import next_uniform
    u = np.zeros(5)
    surrogate.fill_uniforms(np.zeros(4, dtype=np.uint64), u)
    assert np.isnan(u).all() and np.isnan(next_uniform(np.zeros(4, dtype=np.uint64)))
    from surrogate.kernels import table_rebound_many_rng
    with pytest.raises(ValueError, match="not all zero"):
        table_rebound_many_rng(small_table.kernel_data, surrogate.mix_cdf(small_table, "mix"), np.zeros((1, 3)), np.zeros((1, 3)), np.zeros(1), np.zeros(4, dtype=np.uint64),
                         np.zeros((1, 3)), np.zeros((1, 3)), np.zeros(1, dtype=np.int8))


@pytest.mark.parametrize("alpha1, speed", [(np.nan, 150.0), (-5.0, 150.0), (0.0, 150.0), (1e30, 150.0),
                                           (45.0, np.nan), (45.0, -1.0), (45.0, 0.0), (45.0, np.inf)])
def test_local_draws_refuse_what_is_not_physical(small_table, alpha1, speed):
    from surrogate.kernels import draw_local
    u = np.full(surrogate.U_PER_DRAW, 0.5)
    out = draw_local(small_table.kernel_data, surrogate.mix_cdf(small_table, "mix"), alpha1, speed, u, True)
    assert out[0] == surrogate.STATUS_INVALID and np.isnan(out[1:]).all()


def test_a_huge_speed_draws_from_the_edge_cell(table, capsys):
    """|V⁻| = 1e25 m/s with clamp: the cell of the top grid speed (the index's truncation overflowed to an
    interior cell: mean α2 41.9° against 36.6° at the edge); the same bits as a draw at the edge speed."""
    t = surrogate.load(table)
    top, huge = (surrogate.sample_local(t, 45.0, v, "mix", random_state=3, clamp=True)
                 for v in (t.speed_range[1], 1e25))
    for got, expected in zip(huge, top):
        assert np.array_equal(got, expected, equal_nan=True)
    code, err, out = _run(["sample", "--table", str(table), "--alpha1", "45", "--speed", "1e25", "--clamp", "-n",
                           "1000", "--seed", "1", "--method", "table"], capsys)
    assert code == 0 and err == []


@pytest.mark.parametrize("kwargs, words", [
    ({"half_size": 5e-324}, ["'half_size' at index 0", "5e-324", "1e+300"]),
    ({"velocity": [[0.8e200, -0.6e200, 0.0]]}, ["|V-| = 1.0000000000000001e+200", "[1e-150, 1e+150]"]),
    ({"velocity": [[40.0 + 1j, -0.3, 0.0]]}, ["'velocity'", "complex"]),
    ({"half_size": 1e-4 + 0j}, ["'half_size'", "complex"]),
    ({"shape": None}, ["'shape'", "None"]),
    ({"shape": {"prism": "a"}}, ["weights", "'a'"]),
    ({"shape": ["0.25", 0.25, 0.25, 0.25]}, ["weights", "'0.25'"]),
])
def test_sample_global_refuses_with_a_value_error(small_table, kwargs, words):
    """ValueError naming the value and the allowed range, never OverflowError (the message's own arithmetic
    overflowed for |V⁻| > 1e154), TypeError (shape=None, a string weight) or complex silently made real."""
    args = {"velocity": [[40.0, -0.3, 0.0]], "normal": [0.0, 1.0, 0.0], "half_size": 1e-4, "shape": "mix"}
    args.update(kwargs)
    with pytest.raises(ValueError) as info:
        surrogate.sample_global(small_table, args["velocity"], args["normal"], args["half_size"], args["shape"],
                                random_state=1, clamp=True)
    for word in words:
        assert word in str(info.value), str(info.value)


def test_sample_local_refuses_complex_and_unreachable_speeds(small_table):
    with pytest.raises(ValueError, match="complex"):
        surrogate.sample_local(small_table, 45.0 + 0j, 150.0)
    with pytest.raises(ValueError, match="physical range"):
        surrogate.sample_local(small_table, 45.0, 1e200, clamp=True)


def test_a_fifo_or_a_device_as_the_table_is_one_line(tmp_path, capsys):
    """A FIFO or /dev/zero said "no such file" (and a read would block or never end)."""
    import os
    fifo = tmp_path / "fifo.h5"
    os.mkfifo(fifo)
    for path in (fifo, "/dev/zero"):
        _user_error(["sample", "--table", str(path), *GOOD], capsys, str(path), "not a regular file")
        _user_error(["info", str(path)], capsys, str(path), "not a regular file")
