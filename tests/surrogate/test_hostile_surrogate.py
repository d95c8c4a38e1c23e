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

from cli_helpers import run_cli, user_error

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
