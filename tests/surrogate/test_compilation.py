"""``surrogate compile``: every kernel of the runtime compiled into numba's cache, so that a later process
compiles none of them (surrogate.compilation)."""

import re

from surrogate.compilation import DIRECT_KERNELS, TABLE_KERNELS
from tests.helpers import background


def test_a_second_process_finds_every_kernel_in_the_cache(compiled_kernels):
    """Two runs of ``surrogate compile`` on the small table (tests/conftest.py, beside the tests): each calls
    every kernel, the direct model's too (the table has its parameters); the second, a new process, loads every
    one from the cache that the first filled."""
    first, second = (background.succeeded(run) for run in compiled_kernels.result())
    line = re.compile(r"^  (\w+): [0-9.]+ s, (\d+ functions compiled|from the cache)$", re.M)
    for run in (first, second):
        assert [m.group(1) for m in line.finditer(run.stdout)] == list(TABLE_KERNELS + DIRECT_KERNELS), run.stdout
    assert {m.group(2) for m in line.finditer(second.stdout)} == {"from the cache"}, second.stdout
    assert second.stdout.splitlines()[-1].startswith(f"done: {len(TABLE_KERNELS + DIRECT_KERNELS)} kernels in ")
    assert " 0 functions compiled;" in second.stdout.splitlines()[-1], second.stdout


def test_a_bad_table_is_one_line_and_exit_2(tmp_path, capsys):
    from surrogate.cli import main
    (tmp_path / "notes.txt").write_text("not a table\n")
    for path in (tmp_path / "missing.h5", tmp_path / "notes.txt", tmp_path):
        assert main(["compile", "--table", str(path)]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and err[0].startswith("surrogate compile: error: ") and str(path) in err[0], err
