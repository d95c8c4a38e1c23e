"""One contract, two loaders: every file of the corpus of bad tables (tests/helpers/bad_files.py: each way a table can
break docs/format.md, "What makes a table valid") gets the same verdict from rbs_table_open and
surrogate.load, the C code expected and messages naming the file and what is wrong. Another minor version
loads in both; a table of format 3 is refused by both with how to rebuild it. The same files run through the
sanitizer build in test_native_programs.py."""

from __future__ import annotations

import pytest

from tests.helpers import python_side as py
from tests.helpers.bad_files import bad_tables
from tests.helpers.native_library import OK


@pytest.fixture(scope="module")
def bad_files(small_table_path, tmp_path_factory):
    return bad_tables(small_table_path, tmp_path_factory.mktemp("bad_tables"))


def test_bad_files_give_the_right_code_and_name_the_file(native, bad_files):
    for path, expected, names in bad_files:
        code, table, message = native.open(path)
        assert code == expected, (path.name, code, message)
        if expected == OK:
            assert table is not None
            continue
        assert table is None
        assert message.startswith(str(path)), message
        assert names in message, (names, message)


def test_surrogate_gives_the_same_verdict_on_every_file(bad_files):
    for path, expected, names in bad_files:
        if expected == OK:
            py.load(path)
            continue
        with pytest.raises((OSError, ValueError)) as info:
            py.load(path)
        assert str(path) in str(info.value) and names in str(info.value), (path.name, str(info.value))


def test_good_table_reopens_and_closes(native, small_table_path):
    for _ in range(3):
        code, table, message = native.open(small_table_path)
        assert code == OK, message
        assert table.info().format_major == py.TABLE_VERSION[0]
        table.close()
