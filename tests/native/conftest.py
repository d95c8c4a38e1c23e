"""Fixtures of the native tests: the library built once per session with CMake, and a table.

The builds never skip: a missing tool (cmake, a C, C++ or Fortran compiler, HDF5's development files)
fails every test that needs it, with a message saying to run native/install-deps.sh.
"""

from __future__ import annotations

import pytest

from tests.helpers.native_library import INSTALL_HINT, BuildError, Native, build, missing_tools


def _require_tools(fortran=True, cxx=True):
    missing = missing_tools(fortran=fortran, cxx=cxx)
    if missing:
        pytest.fail(f"the native tests need {', '.join(missing)}: {INSTALL_HINT}", pytrace=False)


@pytest.fixture(scope="session")
def native_build(tmp_path_factory):
    """native/ configured and built (Release, -Werror): shared and static libraries, the C and Fortran
    examples, the bench program."""
    _require_tools()
    folder = tmp_path_factory.mktemp("native_build")
    try:
        return build(folder, {"RBS_BUILD_EXAMPLES": "ON", "RBS_BUILD_FORTRAN": "ON", "RBS_BUILD_BENCH": "ON"})
    except BuildError as exc:
        pytest.fail(str(exc), pytrace=False)


@pytest.fixture(scope="session")
def native_sanitized(tmp_path_factory):
    """native/ built with -fsanitize=address,undefined: the static library and the C test programs."""
    _require_tools(fortran=False, cxx=False)
    folder = tmp_path_factory.mktemp("native_sanitized")
    try:
        return build(folder, {"RBS_SANITIZE": "ON", "RBS_BUILD_TESTS": "ON", "RBS_BUILD_SHARED": "OFF",
                              "CMAKE_BUILD_TYPE": "RelWithDebInfo"})
    except BuildError as exc:
        pytest.fail(str(exc), pytrace=False)


@pytest.fixture(scope="session")
def native_baseline(tmp_path_factory):
    """The shared library built for the x86-64 baseline only (no multi-versioning: fma() from the C library)."""
    _require_tools(fortran=False, cxx=False)
    folder = tmp_path_factory.mktemp("native_baseline")
    try:
        return Native(build(folder, {"CMAKE_C_FLAGS": "-DRBS_NO_CLONES", "RBS_BUILD_STATIC": "OFF"}))
    except BuildError as exc:
        pytest.fail(str(exc), pytrace=False)


@pytest.fixture(scope="session")
def native(native_build):
    """The shared library, through ctypes."""
    return Native(native_build)


@pytest.fixture(scope="session")
def table_pair(native, small_table_path):
    """(surrogate's table, the native table) of the session's small table."""
    from tests.helpers import python_side as py
    return py.load(small_table_path), native.table(small_table_path)
