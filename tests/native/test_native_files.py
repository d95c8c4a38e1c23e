"""rbs_table_open refuses what data_schema refuses, with the right error code and a message naming the file:
a missing file, a truncated one, bytes that are not HDF5, another file type (a samples file, an unrelated
HDF5 file), another major version, a group, dataset or attribute missing, a dataset of the wrong shape,
values that derive non-finite kernel arrays, a dataset that fails its checksum. Another minor version
loads. The same files run through the sanitizer build in test_native_programs.py (bad_tables)."""

from __future__ import annotations

import pytest

import _python_side as py
from _bad_files import bad_tables
from _native import OK


@pytest.fixture(scope="module")
def bad_files(small_table_path, tmp_path_factory):
    return bad_tables(small_table_path, tmp_path_factory.mktemp("bad_tables"))


def test_bad_files_give_the_right_code_and_name_the_file(native, bad_files):
    for path, expected, _, names in bad_files:
        code, table, message = native.open(path)
        assert code == expected, (path.name, code, message)
        if expected == OK:
            assert table is not None
            continue
        assert table is None
        assert message.startswith(str(path)), message
        assert names in message, (names, message)


def test_surrogate_refuses_the_same_files(bad_files):
    for path, expected, surrogate_refuses, _ in bad_files:
        if expected == OK:
            py.load(path)
        elif surrogate_refuses:
            with pytest.raises((OSError, ValueError)):
                py.load(path)


def test_good_table_reopens_and_closes(native, small_table_path):
    for _ in range(3):
        code, table, message = native.open(small_table_path)
        assert code == OK, message
        assert table.info().format_major == 3
        table.close()
