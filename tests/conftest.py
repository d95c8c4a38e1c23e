"""Shared fixtures: small tables built once per test session (2e4 particles per cell, all four shapes), and the
long subprocesses that tests only wait for (builds, fresh installs, runs under other CPU settings), started when the
session starts (tests.helpers.background)."""

import os
import sys

import pytest

from tablegen import build_table, load_config, parse_config
from tests.helpers import REPO, background, cpu_dispatch
from tests.helpers.families import octahedron_entered
from tests.helpers.native_library import build as native_build_in
from tests.helpers.plain_install import install_and_draw
from tests.helpers.tables import (NEAR_NORMAL_TABLE_CONFIG, OCTAHEDRON_TABLE_CONFIG, OFF_GRID_TABLE_CONFIG,
                                  SMALL_TABLE_CONFIG, TABULATED_TABLE_CONFIG, WIDE_GRAZING_TABLE_CONFIG,
                                  big_grain_config, write_grain_config)


def _build(tmp_path_factory, name, config_text, workers=None):
    path = tmp_path_factory.mktemp("tables") / f"{name}.h5"
    build_table(parse_config(config_text), path, workers=workers)
    return path


@pytest.fixture(scope="session")
def small_table_path(tmp_path_factory):
    """A table on a 3 × 3 grid. The session's first build: one worker compiles the model once, where two would each
    compile it (on a fresh clone's empty cache) and take the core the session's background builds need."""
    return _build(tmp_path_factory, "small", SMALL_TABLE_CONFIG, workers=1)


@pytest.fixture(scope="session")
def grain_table_path(tmp_path_factory):
    """A table of two user grains, one from a mesh file and one from a config's points (GRAIN_TABLE_CONFIG), built
    from its configuration file; its configuration is grains.toml beside it."""
    folder = tmp_path_factory.mktemp("grain_table")
    path = folder / "grains.h5"
    build_table(load_config(write_grain_config(folder)), path)
    return path


@pytest.fixture(scope="session")
def big_grain_table_path(tmp_path_factory):
    """A table of one user grain of 10 000 hull vertices on one grid point (tests.helpers.tables.big_grain_config)."""
    return _build(tmp_path_factory, "big_grain", big_grain_config())


@pytest.fixture(scope="session")
def octahedron_table_path(tmp_path_factory):
    """A table of the prism and of a family entered by the tests alone (tests/helpers/families.py), built in this
    process with the entry in the registry; the entry is gone after the build."""
    path = tmp_path_factory.mktemp("family_entry") / "octahedron.h5"
    with octahedron_entered():
        build_table(parse_config(OCTAHEDRON_TABLE_CONFIG), path, workers=1)
    return path


@pytest.fixture(scope="session")
def tabulated_table_path(tmp_path_factory):
    """A table of the prism on a 2 × 2 grid with a tabulated wall law (TABULATED_TABLE_CONFIG)."""
    return _build(tmp_path_factory, "tabulated", TABULATED_TABLE_CONFIG)


@pytest.fixture(scope="session")
def small_table(small_table_path):
    import surrogate
    return surrogate.load(small_table_path)


@pytest.fixture(scope="session")
def off_grid_table(tmp_path_factory):
    """A table for comparisons between grid points (see OFF_GRID_TABLE_CONFIG)."""
    import surrogate
    return surrogate.load(_build(tmp_path_factory, "off_grid", OFF_GRID_TABLE_CONFIG))


@pytest.fixture(scope="session")
def wide_grazing_table(tmp_path_factory):
    """A table with 1–2° as one α1 interval (see WIDE_GRAZING_TABLE_CONFIG)."""
    import surrogate
    return surrogate.load(_build(tmp_path_factory, "wide_grazing", WIDE_GRAZING_TABLE_CONFIG))


@pytest.fixture(scope="session")
def near_normal_table(tmp_path_factory):
    """A table for comparisons between grid speeds near normal impact (see NEAR_NORMAL_TABLE_CONFIG)."""
    import surrogate
    return surrogate.load(_build(tmp_path_factory, "near_normal", NEAR_NORMAL_TABLE_CONFIG))


# a rank of the 2-rank solver cases waiting in a collective yields its core instead of polling it away from the tests
# and the background worker beside it (docs/design/test_time.md)
os.environ.setdefault("OMPI_MCA_mpi_yield_when_idle", "1")

# fixtures whose subprocesses run next to the tests from the session's start, in this order: the native builds
# first (they need no table), then the compilation of the runtime's kernels on the session's small table (the test
# process builds it meanwhile), then the solvers' builds, the runs on the small table and the OpenFOAM runs; each is
# started only when a selected test uses it
STARTED_WITH_THE_SESSION = ("native_build_job", "native_sanitized_job", "native_baseline_job", "compiled_kernels",
                            "saturne_build_job", "openfoam_build_job", "dispatch_children", "forced_rebuilds",
                            "openfoam_runs", "plain_install")
# the folders of tests/ whose modules use none of those, in the order the test process takes them: the runtime's
# kernels are called most in the last ones, which come when compiled_kernels has put them in numba's cache ("" is
# tests/ itself)
FOLDER_ORDER = ("data_schema", "direct_model", "tabulation", "openfoam", "code_saturne", "native", "study",
                "surrogate", "")


def pytest_collection_modifyitems(items):
    """The modules that use none of STARTED_WITH_THE_SESSION first, by FOLDER_ORDER; then the others by the last
    of them they use, in the worker's order: the test process does the rest of the suite meanwhile instead of
    waiting (docs/design/test_time.md)."""
    def module(item):
        return item.nodeid.split("::")[0]

    last_used = {}
    for item in items:
        used = [STARTED_WITH_THE_SESSION.index(name) for name in item.fixturenames if name in STARTED_WITH_THE_SESSION]
        last_used[module(item)] = max([last_used.get(module(item), -1), *used])

    def rank(item):
        if last_used[module(item)] >= 0:
            return 1, last_used[module(item)]
        parts = module(item).split("/")
        folder = parts[1] if len(parts) > 2 else ""
        return 0, FOLDER_ORDER.index(folder) if folder in FOLDER_ORDER else len(FOLDER_ORDER)

    items.sort(key=rank)


@pytest.fixture(scope="session", autouse=True)
def _start_subprocesses(request):
    used = {name for item in request.session.items for name in item.fixturenames}
    for name in STARTED_WITH_THE_SESSION:
        if name in used:
            request.getfixturevalue(name)
    yield
    background.stop()


@pytest.fixture(scope="session")
def compiled_kernels(small_table_path):
    """The future of ``surrogate compile`` on the session's small table, twice (tests/surrogate/test_compilation.py):
    the first run puts the runtime's kernels in numba's cache before the tests that call them most; the second, a
    new process, finds each there."""
    command = [sys.executable, "-m", "surrogate.cli", "compile", "--table", str(small_table_path)]
    return background.submit(lambda: tuple(background.run(command, cwd=REPO, timeout=1200) for _ in range(2)))


@pytest.fixture(scope="session")
def dispatch_children(small_table_path, tmp_path_factory):
    """The future of tests/native/test_native_dispatch.py's runs (tests.helpers.cpu_dispatch.child_runs)."""
    return background.submit(cpu_dispatch.child_runs, small_table_path, tmp_path_factory.mktemp("dispatch"))


@pytest.fixture(scope="session")
def forced_rebuilds(tmp_path_factory):
    """The future of tests/tabulation/test_build_dispatch.py's rebuilds of the tabulated table (four cells: the
    representation's numpy and OpenBLAS work on every cell at little cost) under forced numpy and OpenBLAS kernels
    (tests.helpers.cpu_dispatch.forced_rebuilds)."""
    return background.submit(cpu_dispatch.forced_rebuilds, TABULATED_TABLE_CONFIG,
                             tmp_path_factory.mktemp("rebuild"))


@pytest.fixture(scope="session")
def plain_install(small_table_path, tmp_path_factory):
    """The future of tests/test_install.py's fresh install and draw (tests.helpers.plain_install.install_and_draw)."""
    return background.submit(install_and_draw, small_table_path, tmp_path_factory.mktemp("install"))


@pytest.fixture(scope="session")
def openfoam_runs(tmp_path_factory):
    """The future of tests/openfoam/cases.py's runs (a GPL-3 program, run as one): (its finished process, the
    folder of its tables and runs)."""
    folder = tmp_path_factory.mktemp("openfoam_runs")
    command = [sys.executable, "-m", "tests.openfoam.cases", str(folder)]
    return background.submit(lambda: (background.run(command, cwd=REPO, timeout=1800), folder))


def _integration_build(name):
    return background.submit(background.run, ["bash", str(REPO / "integrations" / name / "build.sh")], cwd=REPO,
                             timeout=1200)


@pytest.fixture(scope="session")
def saturne_build_job():
    """The future of integrations/code_saturne/build.sh's finished process (tests/code_saturne's cs_build)."""
    return _integration_build("code_saturne")


@pytest.fixture(scope="session")
def openfoam_build_job():
    """The future of integrations/openfoam/build.sh's finished process (tests/openfoam's openfoam_build)."""
    return _integration_build("openfoam")


@pytest.fixture(scope="session")
def native_build_job(tmp_path_factory):
    """The future of native/'s Release build with the C and Fortran examples, the bench program and the test-only
    library of the internal functions, librebound_scatter_testing.so (tests/native/conftest.py's native_build;
    BuildError on failure)."""
    return background.submit(native_build_in, tmp_path_factory.mktemp("native_build"),
                             {"RBS_BUILD_EXAMPLES": "ON", "RBS_BUILD_FORTRAN": "ON", "RBS_BUILD_BENCH": "ON",
                              "RBS_BUILD_TESTS": "ON"})


@pytest.fixture(scope="session")
def native_sanitized_job(tmp_path_factory):
    """The future of native/ built with -fsanitize=address,undefined: the static library and the C test programs."""
    return background.submit(native_build_in, tmp_path_factory.mktemp("native_sanitized"),
                             {"RBS_SANITIZE": "ON", "RBS_BUILD_TESTS": "ON", "RBS_BUILD_SHARED": "OFF",
                              "CMAKE_BUILD_TYPE": "RelWithDebInfo"})


@pytest.fixture(scope="session")
def native_baseline_job(tmp_path_factory):
    """The future of native/'s shared library built for the x86-64 baseline only (no multi-versioning: fma() from
    the C library)."""
    return background.submit(native_build_in, tmp_path_factory.mktemp("native_baseline"),
                             {"CMAKE_C_FLAGS": "-DRBS_NO_CLONES", "RBS_BUILD_STATIC": "OFF"})
