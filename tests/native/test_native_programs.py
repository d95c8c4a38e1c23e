"""The C test programs under AddressSanitizer and UndefinedBehaviorSanitizer (good and bad tables, draws,
threads, the free flight's invariants), the C, C++ and Fortran examples, and the installed CMake package."""

from __future__ import annotations

import os
import shutil

import pytest

from tests.helpers.bad_files import bad_tables, parameter_row_cases, tabulated_wall_cases
from tests.helpers.native_library import INSTALL_HINT, NATIVE, run

SANITIZER_ENV = {"ASAN_OPTIONS": "detect_leaks=1:abort_on_error=0:halt_on_error=1",
                 "UBSAN_OPTIONS": "halt_on_error=1:print_stacktrace=1"}
SANITIZER_REPORTS = ("ERROR: AddressSanitizer", "ERROR: LeakSanitizer", "runtime error:", "SUMMARY: ")


def _sanitized_run(command, timeout=300):
    env = dict(os.environ, **SANITIZER_ENV)
    env.pop("LD_PRELOAD", None)
    done = run([str(c) for c in command], env=env, timeout=timeout)
    output = done.stdout + done.stderr
    reports = [r for r in SANITIZER_REPORTS if r in output]
    assert done.returncode == 0 and not reports, f"exit {done.returncode}, sanitizer reports {reports}:\n{output[-6000:]}"
    return done.stdout


def test_tables_program_under_sanitizers(native_sanitized, small_table_path, tabulated_table_path, tmp_path):
    """Open the good table twice (every draw function, good and bad mixes), then every bad file: the
    expected code, a message naming the file, no sanitizer report, no leak; tables of 1 and 64 shapes (a mix
    sized by the table, the shapes' records, the direct path's answer for a user's grain) and a table of a
    tabulated wall law (its arrays in rbs_table_wall, and its bad files) drawn from alike."""
    from tests.helpers.python_side import many_shape_table
    one, many = tmp_path / "one_shape.h5", tmp_path / "many_shapes.h5"
    many_shape_table(small_table_path, one, 1)
    many_shape_table(small_table_path, many, 64)
    arguments = [one, 0, many, 0, tabulated_table_path, 0]
    for path, code, _ in bad_tables(small_table_path, tmp_path / "bad") + parameter_row_cases(small_table_path,
                                                                                               tmp_path / "rows"):
        arguments += [path, code]
    for path, code, _ in tabulated_wall_cases(tabulated_table_path, tmp_path / "tabulated"):
        arguments += [path, code]
    out = _sanitized_run([native_sanitized / "rbs_test_tables", small_table_path, *arguments])
    assert "0 failure(s)" in out
    print(f"\nsanitizers (address, undefined, leaks): no report over {len(arguments) // 2} bad files and the good one")


def test_direct_model_program_under_sanitizers(native_sanitized, small_table_path, tmp_path):
    """The direct model's invariants as C tests (a collision never adds energy and keeps the angular momentum
    about the contact point, a free flight keeps energy and L to 1e-9, a rebound never adds energy), its
    hostile calls on the small table (every table of format 4 records the direct model's parameters), a grain of
    512 vertices whose work space is on the heap (rbs_rebound_model_frame's equals rbs_body_rebound's), four
    threads on one table against one: no failure, no sanitizer report."""
    out = _sanitized_run([native_sanitized / "rbs_test_direct", small_table_path])
    assert "0 failure(s)" in out
    print("\n" + out)


def test_threads_draw_as_one_thread(native_sanitized, small_table_path):
    """Four threads drawing from one table at once give the bits of one thread, stream by stream."""
    out = _sanitized_run([native_sanitized / "rbs_test_threads", small_table_path, 4, 4000])
    assert "0 stream(s) differ" in out


def test_rotation_invariants_under_sanitizers(native_sanitized):
    """rotation.c over 9 x 300 flights of every mode: lab angular momentum and kinetic energy kept to 1e-9,
    R orthonormal to 1e-12, R(0) = R0; hostile arguments return; no sanitizer report."""
    out = _sanitized_run([native_sanitized / "rbs_test_rotation", 300])
    assert "0 failure(s)" in out and "near separatrix: 300 flights" in out
    print("\n" + out)


def test_c_example(native_build, small_table_path):
    done = run([str(native_build / "rbs_example_rebound"), str(small_table_path), "20"])
    assert done.returncode == 0, done.stderr
    assert "of 20 rebounded" in done.stdout


def test_fortran_example(native_build, small_table_path):
    done = run([str(native_build / "rbs_example_fortran"), str(small_table_path)])
    assert done.returncode == 0, done.stdout + done.stderr
    assert "direct: status 0" in done.stdout and "many: 1000 particles" in done.stdout
    assert done.stdout.strip().endswith("ok")


def test_cxx_compiles_against_the_header(native_build, small_table_path, tmp_path):
    compiler = shutil.which("g++") or shutil.which("c++")
    assert compiler, f"no C++ compiler: {INSTALL_HINT}"
    program = tmp_path / "cxx_example"
    done = run([compiler, "-std=c++17", "-Wall", "-Wextra", "-Werror", "-pedantic", f"-I{NATIVE / 'include'}",
                str(NATIVE / "examples" / "cxx_example.cpp"), f"-L{native_build}", "-lrebound_scatter",
                f"-Wl,-rpath,{native_build}", "-o", str(program)])
    assert done.returncode == 0, done.stderr
    done = run([str(program), str(small_table_path)])
    assert done.returncode == 0, done.stderr
    assert "C++:" in done.stdout


def test_installed_package_config(native_build, tmp_path):
    """cmake --install (the test-only library is not installed), then a consumer project finds it with
    find_package(ReboundScatter CONFIG); the library it links says the header's version."""
    prefix = tmp_path / "prefix"
    done = run(["cmake", "--install", str(native_build), "--prefix", str(prefix)])
    assert done.returncode == 0, done.stdout + done.stderr
    assert (prefix / "include" / "rebound_scatter.h").is_file()
    assert not [p for p in prefix.rglob("*") if "testing" in p.name], "the test-only library was installed"
    consumer = tmp_path / "consumer"
    consumer.mkdir()
    (consumer / "CMakeLists.txt").write_text(
        "cmake_minimum_required(VERSION 3.18)\nproject(consumer LANGUAGES C)\n"
        "find_package(ReboundScatter 1.0 CONFIG REQUIRED)\n"
        "add_executable(consumer main.c)\ntarget_link_libraries(consumer PRIVATE ReboundScatter::rebound_scatter)\n"
        "add_executable(consumer_static main.c)\n"
        "target_link_libraries(consumer_static PRIVATE ReboundScatter::rebound_scatter_static)\n")
    (consumer / "main.c").write_text(
        '#include <stdio.h>\n#include "rebound_scatter.h"\n'
        'int main(void) { rbs_rng r; rbs_rng_seed(&r, 1); printf("%s %d %d %.17g\\n", rbs_version(), '
        'rbs_version_number(), RBS_VERSION_NUMBER, rbs_rng_uniform(&r)); return 0; }\n')
    build = tmp_path / "consumer_build"
    done = run(["cmake", "-S", str(consumer), "-B", str(build), f"-DCMAKE_PREFIX_PATH={prefix}"])
    assert done.returncode == 0, done.stdout + done.stderr
    done = run(["cmake", "--build", str(build)])
    assert done.returncode == 0, done.stdout + done.stderr
    outputs = {run([str(build / name)]).stdout for name in ("consumer", "consumer_static")}
    assert len(outputs) == 1 and outputs.pop().startswith("1.4.1 1004001 1004001 ")


@pytest.mark.parametrize("script", ["install-deps.sh"])
def test_install_deps_script_is_idempotent_when_all_is_there(script):
    """With every tool present the script installs nothing and exits 0 (it only checks)."""
    done = run(["bash", str(NATIVE / script), "--check"])
    assert done.returncode == 0, done.stdout + done.stderr
    assert "all present" in done.stdout
