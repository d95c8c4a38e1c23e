"""`tablegen` command line and table build against hostile input: every case ends in one line and exit 2 (or
128 + the signal), before the expensive work where it can be, and nothing of the user's is replaced or left
half-written."""

import functools
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import h5py
import numba
import numpy as np
import pytest

import surrogate
import surrogate.cli
from data_schema.common import DataFormatError
from data_schema.output import FOLDER_MARKER, OutputError, kind_of, remove_stale_temporaries, write_output
from data_schema.table import TABLE_FILE_TYPE
from tablegen.tabulation import driver
from tablegen.tabulation.cells import compute_cell
from tablegen.tabulation.driver import Checkpoint, CheckpointError, build_table, model_sha256, worker_count
from tablegen.tabulation.config import parse_config
from tablegen.cli import main

from tests.helpers.cli import run_cli, user_error

TINY = """
[grid]
alpha1_deg = [30.0, 80.0]
speed_m_s = [100.0]
shapes = ["prism"]
[simulation]
particles_per_cell = 256
seed = 5
"""
# about 2 s a cell on one core: long enough to be interrupted between checkpoints
SLOW = TINY.replace("particles_per_cell = 256", "particles_per_cell = 200000").replace(
    "alpha1_deg = [30.0, 80.0]", "alpha1_deg = [30.0, 40.0, 50.0, 60.0, 70.0, 80.0]")


_run = functools.partial(run_cli, main)               # (exit status, stderr lines, stdout)
_user_error = functools.partial(user_error, main)     # one line on stderr, exit 2: (line, stdout)


@pytest.fixture
def tiny_config(tmp_path):
    path = tmp_path / "tiny.toml"
    path.write_text(TINY)
    return path


def _build_command(config, out, *extra):
    return [sys.executable, "-m", "tablegen.cli", "build", "--config", str(config), "-o", str(out), "--no-progress",
            *extra]


# -- outputs that are not ours ---------------------------------------------------

def test_report_overwrite_never_deletes_a_folder_that_is_not_a_report(small_table_path, tmp_path, capsys):
    project = tmp_path / "myproject"
    project.mkdir()
    (project / "thesis.tex").write_text("four years of work")
    _user_error(["report", "--table", str(small_table_path), "-o", str(project), "--overwrite", "-n", "100"],
                capsys, str(project), "not an output of rebound-scatter")
    assert (project / "thesis.tex").read_text() == "four years of work"


def test_report_overwrite_replaces_a_report_folder_atomically(small_table_path, tmp_path, capsys):
    out = tmp_path / "study"
    argv = ["report", "--table", str(small_table_path), "-o", str(out), "-n", "200", "--shapes", "prism",
            "--alpha1", "30", "--seed", "1"]
    assert _run(argv, capsys)[0] == 0
    assert kind_of(out) == "study_report" and (out / FOLDER_MARKER).is_file()
    _user_error(argv, capsys, "exists", "--overwrite")
    assert _run(argv + ["--overwrite"], capsys)[0] == 0
    assert (out / "index.md").is_file()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["study"]      # no temporary folder left beside


def test_build_overwrite_replaces_only_a_table(tiny_config, small_table_path, tmp_path, capsys):
    notes = tmp_path / "notes.txt"
    notes.write_text("my notes")
    _user_error(["build", "--config", str(tiny_config), "-o", str(notes), "--overwrite"], capsys,
                "not an output of rebound-scatter", TABLE_FILE_TYPE)
    assert notes.read_text() == "my notes"
    samples = tmp_path / "s.h5"
    assert surrogate.cli.main(["sample", "--table", str(small_table_path), "--alpha1", "45", "--speed", "150",
                               "-n", "5", "--out", str(samples)]) == 0
    capsys.readouterr()
    _user_error(["build", "--config", str(tiny_config), "-o", str(samples), "--overwrite"], capsys,
                "a rebound_samples output")
    assert kind_of(samples) == "rebound_samples"
    assert not (tmp_path / "s.h5.partial").exists() and not (tmp_path / "notes.txt.partial").exists()


# -- configurations and sizes -------------------------------------------------------

def test_a_grid_step_that_gives_too_many_points_is_refused_before_allocating(tmp_path, capsys):
    config = tmp_path / "c.toml"
    config.write_text("[grid]\nalpha1_deg = {start = 10, stop = 90, step = 1e-12}\n")
    _user_error(["build", "--config", str(config), "--print-config"], capsys, "grid.alpha1_deg", "8e+13",
                "at most 1000")


def test_print_config_needs_no_output(capsys):
    code, err, out = _run(["build", "--print-config"], capsys)
    assert code == 0 and err == [] and out.startswith("[grid]")
    _user_error(["build"], capsys, "-o/--out is required")


def test_a_config_that_is_not_utf8(tmp_path, capsys):
    config = tmp_path / "c.toml"
    config.write_bytes(b"\xff\xfe[grid]\n")
    _user_error(["build", "--config", str(config), "-o", str(tmp_path / "t.h5")], capsys, "not UTF-8")


@pytest.mark.parametrize("argv, words", [
    (["simulate", "--shape", "prism", "--alpha1", "45", "--speed", "100", "-n", "1e12"], ["-n = 1000000000000", "GiB"]),
    (["simulate", "--shape", "prism", "--alpha1", "45", "--speed", "100", "-n", "10", "--seed", "1e27"], ["--seed"]),
    (["simulate", "--shape", "prism", "--alpha1", "45", "--speed", "100", "-n", "10",
      "--seed", "1000000000000000000000000000"], ["--seed", "[0, 2**63)"]),
    (["simulate", "--shape", "prism", "--alpha1", "95", "--speed", "100", "-n", "10"], ["(0, 90]", "95.0"]),
])
def test_sizes_and_seeds_outside_their_range(tmp_path, capsys, argv, words):
    _user_error(argv + ["--out", str(tmp_path / "x.h5")], capsys, *words)
    assert list(tmp_path.iterdir()) == []


# -- paths -------------------------------------------------------------------------

@pytest.mark.parametrize("where, words", [("missing/t.h5", ["does not exist"]), ("", ["empty"]),
                                          (".", ["is a folder"])])
def test_build_output_paths_are_checked_before_building(tiny_config, tmp_path, capsys, where, words):
    out = str(tmp_path / where) if where else ""
    _user_error(["build", "--config", str(tiny_config), "-o", out, "--overwrite"], capsys, *words)
    assert not any(p.name.endswith(".partial") for p in tmp_path.rglob("*"))


def test_simulate_checks_its_output_before_simulating(tmp_path, capsys):
    _, out = _user_error(["simulate", "--shape", "prism", "--alpha1", "45", "--speed", "100", "-n", "10",
                          "--out", str(tmp_path / "missing" / "x.h5")], capsys, "does not exist")
    assert out == ""        # no summary: nothing was simulated


def test_info_on_a_folder(tmp_path, capsys):
    _user_error(["info", str(tmp_path)], capsys, "is a folder")


def test_an_unreachable_scheduler_is_one_line_and_leaves_nothing(tiny_config, tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(driver, "SCHEDULER_TIMEOUT_S", 1)     # the same error, without waiting 10 s for it
    out = tmp_path / "t.h5"
    _user_error(["build", "--config", str(tiny_config), "-o", str(out), "--scheduler", "tcp://127.0.0.1:9"],
                capsys, "--scheduler tcp://127.0.0.1:9", "cannot reach")
    assert list(tmp_path.iterdir()) == [tiny_config]


@pytest.fixture
def tiny_disk(tmp_path):
    """A 64 KiB file system (tmpfs) for full-disk cases; needs root."""
    mount = tmp_path / "disk"
    mount.mkdir()
    if subprocess.run(["mount", "-t", "tmpfs", "-o", "size=64k", "tmpfs", str(mount)],
                      capture_output=True).returncode != 0:
        pytest.skip("cannot mount a small tmpfs here (needs root)")
    yield mount
    subprocess.run(["umount", str(mount)], check=True)


def test_a_full_disk_fails_cleanly_and_leaves_no_temporary(tiny_disk, tiny_config, small_table_path, capsys):
    with pytest.raises(OSError) as info:
        write_output(tiny_disk / "big.h5", b"x" * 100_000, "rebound_table")
    assert info.value.errno == 28 and list(tiny_disk.iterdir()) == []
    # a build checks the space its checkpoints and table need before computing
    _user_error(["build", "--config", str(tiny_config), "-o", str(tiny_disk / "t.h5")], capsys, "GiB free")
    assert list(tiny_disk.iterdir()) == []
    # a samples file larger than the disk: the write fails as one line, nothing is left
    code, err, _ = run_cli(surrogate.cli.main, ["sample", "--table", str(small_table_path), "--alpha1", "45",
                                                "--speed", "150", "-n", "20000", "--out", str(tiny_disk / "s.h5")],
                           capsys)
    assert code == 2 and len(err) == 1 and "No space left on device; nothing was written" in err[0], err
    assert list(tiny_disk.iterdir()) == []


def test_an_immutable_table_is_refused_before_building(tiny_config, small_table_path, tmp_path, capsys):
    out = Path(shutil.copy(small_table_path, tmp_path / "t.h5"))
    if subprocess.run(["chattr", "+i", str(out)], capture_output=True).returncode != 0:
        pytest.skip("this file system has no immutable attribute (chattr +i)")
    try:
        _user_error(["build", "--config", str(tiny_config), "-o", str(out), "--overwrite"], capsys,
                    "cannot be replaced")
    finally:
        subprocess.run(["chattr", "-i", str(out)], check=True)
    assert not (tmp_path / "t.h5.partial").exists()


# -- interrupted and concurrent builds -------------------------------------------

def _start(command):
    # SIGINT restored to its default in the child: a shell starts background jobs with it ignored
    return subprocess.Popen(command, start_new_session=True, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                            text=True, preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))


def _wait_for_cells(partial, count, proc, timeout=180):
    deadline = time.time() + timeout
    while time.time() < deadline and len(list(partial.glob("*.npz"))) < count and proc.poll() is None:
        time.sleep(0.05)


def _children(pid):
    found = subprocess.run(["pgrep", "-P", str(pid)], capture_output=True, text=True).stdout.split()
    return [int(p) for p in found]


def _alive(pid):
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    with open(f"/proc/{pid}/stat") as f:
        return f.read().split(")")[-1].split()[0] != "Z"


@pytest.mark.parametrize("signal_number", [signal.SIGTERM, signal.SIGINT])
def test_a_signal_stops_the_workers_and_keeps_the_checkpoints(tmp_path, signal_number):
    config = tmp_path / "slow.toml"
    config.write_text(SLOW)
    out = tmp_path / "t.h5"
    proc = _start(_build_command(config, out, "--workers", "2"))
    partial = tmp_path / "t.h5.partial"
    _wait_for_cells(partial, 1, proc)
    workers = _children(proc.pid)
    assert proc.poll() is None and workers, "the build ended before it could be interrupted"
    if signal_number == signal.SIGINT:
        os.killpg(proc.pid, signal_number)      # Ctrl-C: the whole foreground process group
    else:
        proc.send_signal(signal_number)         # a batch scheduler: the main process only
    err = proc.communicate(timeout=60)[1].splitlines()
    assert proc.returncode == 128 + signal_number
    assert len(err) == 2 and err[1].startswith(f"tablegen build: interrupted by {signal_number.name}"), err
    assert "finished cells kept in" in err[1] and "Traceback" not in "".join(err)
    time.sleep(0.5)
    assert not any(_alive(pid) for pid in workers if pid != proc.pid)
    assert len(list(partial.glob("*.npz"))) >= 1 and not out.exists()


def test_a_local_worker_saves_its_cell_and_sends_back_nothing(tmp_path, monkeypatch):
    # a cell sent back could be cut off by terminating its worker, and the pool's reader would wait forever
    config = parse_config(TINY)
    path = tmp_path / "cell.npz"
    monkeypatch.setattr(driver, "_WORKER_CONFIG", config)       # what _worker_init gives each worker
    assert driver._compute_and_save(path, "prism", 1, 0) is None
    with np.load(path) as saved:
        expected = compute_cell(config, "prism", 1, 0).arrays()
        assert sorted(saved.files) == sorted(expected)
        for name, array in expected.items():
            assert saved[name].dtype == array.dtype and saved[name].tobytes() == array.tobytes(), name


def test_a_second_build_of_the_same_output_stops_at_once(tmp_path, capsys):
    config = tmp_path / "slow.toml"
    config.write_text(SLOW)
    out = tmp_path / "t.h5"
    proc = _start(_build_command(config, out, "--workers", "1"))
    try:
        _wait_for_cells(tmp_path / "t.h5.partial", 1, proc)
        assert proc.poll() is None
        _user_error(["build", "--config", str(config), "-o", str(out)], capsys, "another build")
    finally:
        proc.terminate()
        proc.communicate(timeout=60)


def test_workers_are_capped_by_the_cells_left_and_the_cpus():
    cpus = os.cpu_count()
    assert worker_count(1000, 3) == min(3, cpus)
    assert worker_count(None, 1000) == cpus
    assert worker_count(1, 1000) == 1


def test_a_temporary_file_of_a_killed_run_is_removed_by_the_next_run(tiny_config, tmp_path, capsys):
    out = tmp_path / "t.h5"
    stale = tmp_path / ".t.h5.rebound-scatter-999999999-0badcafe.tmp"    # no process has this id
    stale.write_bytes(b"half a table")
    mine = tmp_path / f".t.h5.rebound-scatter-{os.getpid()}-0badcafe.tmp"   # a running writer's: kept
    mine.write_bytes(b"being written")
    assert remove_stale_temporaries(tmp_path, "t.h5") == [stale]
    stale.write_bytes(b"half a table")
    assert _run(["build", "--config", str(tiny_config), "-o", str(out), "--workers", "1"], capsys)[0] == 0
    assert not stale.exists() and mine.exists()
    mine.unlink()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["t.h5", "tiny.toml"]


# -- provenance and integrity ------------------------------------------------------

def test_a_resume_with_another_model_is_refused(tmp_path):
    config = parse_config(TINY)
    out = tmp_path / "t.h5"
    with Checkpoint(out, config) as checkpoint:
        marker = checkpoint.path / "config.toml"
    marker.write_text(marker.read_text().replace(model_sha256(), "0" * 64))
    with pytest.raises(CheckpointError, match=r"another model source hash \(checked: table format, package "
                                              r"version, model source hash, configuration\)"):
        build_table(config, out, workers=1)
    assert not out.exists()


def test_a_table_records_the_model_that_made_it(tiny_config, tmp_path, capsys):
    out = tmp_path / "t.h5"
    assert _run(["build", "--config", str(tiny_config), "-o", str(out), "--workers", "1"], capsys)[0] == 0
    with h5py.File(out, "r") as f:
        assert f.attrs["model_sha256"] == model_sha256()
        assert all(f["cells"][name].fletcher32 for name in f["cells"])


def test_non_finite_derived_arrays_fail_to_load(small_table_path, tmp_path):
    """A table whose stored numbers are wrong but checksummed (written so) still cannot give a non-finite
    rebound: the loader's table contract refuses the value, naming the dataset, before any array is derived."""
    bad = Path(shutil.copy(small_table_path, tmp_path / "t.h5"))
    with h5py.File(bad, "a") as f:
        mean = f["cells/mean"][()]
        mean[0, 1, 1, 2] = np.nan
        f["cells/mean"][...] = mean
    with pytest.raises(DataFormatError, match=r"dataset 'cells/mean' holds nan at element 26; its values must be "
                                              r"in \[-1e\+06, 1e\+06\]"):
        surrogate.load(bad)


def test_output_error_is_a_value_error_naming_the_path(tmp_path):
    with pytest.raises(OutputError, match=str(tmp_path / "missing")):
        write_output(tmp_path / "missing" / "x.h5", b"", "rebound_table")
