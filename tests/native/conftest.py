"""Fixtures of the native tests: the library built once per session with CMake (the builds start with the
session, tests/conftest.py), and a table.

The builds never skip: a missing tool (cmake, a C, C++ or Fortran compiler, HDF5's development files)
fails every test that needs it, with a message saying to run native/install-deps.sh.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.helpers.native_library import INSTALL_HINT, BuildError, Native, missing_tools


def _require_tools(fortran=True, cxx=True):
    missing = missing_tools(fortran=fortran, cxx=cxx)
    if missing:
        pytest.fail(f"the native tests need {', '.join(missing)}: {INSTALL_HINT}", pytrace=False)


def _built(job) -> Path:
    """The folder of a build started with the session (tests/conftest.py), or the test fails with its output."""
    try:
        return job.result()
    except BuildError as exc:
        pytest.fail(str(exc), pytrace=False)


@pytest.fixture(scope="session")
def native_build(native_build_job):
    """native/ configured and built (Release, -Werror): shared and static libraries, the test-only library of the
    internal functions, the C and Fortran examples, the C test programs, the bench program."""
    _require_tools()
    return _built(native_build_job)


@pytest.fixture(scope="session")
def native_sanitized(native_sanitized_job):
    """native/ built with -fsanitize=address,undefined: the static library and the C test programs."""
    _require_tools(fortran=False, cxx=False)
    return _built(native_sanitized_job)


@pytest.fixture(scope="session")
def native_baseline(native_baseline_job):
    """The shared library built for the x86-64 baseline only (no multi-versioning: fma() from the C library)."""
    _require_tools(fortran=False, cxx=False)
    return Native(_built(native_baseline_job))


@pytest.fixture(scope="session")
def native(native_build):
    """The public shared library through ctypes (its ``internal``: the test-only library of the same build)."""
    return Native(native_build)


@pytest.fixture(scope="session")
def table_pair(native, small_table_path):
    """(surrogate's table, the native table) of the session's small table."""
    from tests.helpers import python_side as py
    return py.load(small_table_path), native.table(small_table_path)
