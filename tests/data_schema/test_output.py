"""Outputs and the race between the output check and the final step: without overwrite, a file or
folder that appears at the target while the work runs is kept, and the write fails naming it."""

import pytest

from data_schema import output
from data_schema.output import OutputError, atomic_folder, kind_of, write_output

KIND = "rebound_samples"


def _appearing(monkeypatch, make):
    """check_output as it is, then ``make(path)``: what another process does between the check and the end."""
    check = output.check_output

    def check_then_appear(path, *args, **kwargs):
        checked = check(path, *args, **kwargs)
        make(checked)
        return checked
    monkeypatch.setattr(output, "check_output", check_then_appear)


def test_a_file_that_appears_meanwhile_is_kept(tmp_path, monkeypatch):
    """Reproduced: `surrogate sample --out p.h5` while `echo data > p.h5` ran gave exit 0 and p.h5 replaced."""
    target = tmp_path / "p.h5"
    _appearing(monkeypatch, lambda path: path.write_text("data\n"))
    with pytest.raises(OutputError, match="appeared while this command ran"):
        write_output(target, b"new content", KIND)
    assert target.read_text() == "data\n"
    assert [p.name for p in tmp_path.iterdir()] == ["p.h5"]      # no temporary file left


def test_without_a_race_the_file_is_written_and_overwrite_still_replaces(tmp_path):
    target = tmp_path / "p.h5"
    write_output(target, b"first", KIND)
    assert target.read_bytes() == b"first"
    output.replace_file(target, b"second")      # checkpoints: replaced in place
    assert target.read_bytes() == b"second"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["p.h5"]


def test_a_folder_that_appears_meanwhile_is_kept(tmp_path):
    target = tmp_path / "report"
    with pytest.raises(OutputError, match="appeared while this command ran"):
        with atomic_folder(target, "report") as tmp:
            (tmp / "index.md").write_text("new")
            target.mkdir()              # another process makes the folder (empty: a plain rename would replace it)
            (target / "mine.txt").write_text("mine")
    assert (target / "mine.txt").read_text() == "mine" and kind_of(target) is None
    assert sorted(p.name for p in tmp_path.iterdir()) == ["report"]


def test_a_failed_write_names_the_target_not_the_temporary_file(tmp_path, monkeypatch):
    """An error of the final step (here ENOSPC from fsync) names the user's path, never
    `.p.h5.rebound-scatter-PID-RANDOM.tmp`."""
    import errno
    import os

    def full(fd):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
    monkeypatch.setattr(output.os, "fsync", full)
    with pytest.raises(OSError) as info:
        write_output(tmp_path / "p.h5", b"x", KIND)
    assert info.value.filename == str(tmp_path / "p.h5") and ".tmp" not in str(info.value)
    assert list(tmp_path.iterdir()) == []


def test_a_folder_where_nothing_can_be_made_is_refused_before_the_work():
    """/proc: os.access says writable to root, the write failed after the work naming the temporary file."""
    with pytest.raises(OutputError, match="(cannot write in the folder|the folder) /proc"):
        output.check_output("/proc/x.h5", KIND)
