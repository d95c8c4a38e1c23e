"""The C library's public interface as native/include/rebound_scatter.h declares it (version 1.4).

- The public shared library exports exactly the header's RBS_API functions (the internal ones only from the
  test-only library), and tests.helpers.native_library types each of them.
- The ctypes records of tests.helpers.native_library have the header's layout (sizeof, offsetof of every field, the
  RBS_*_INIT initialisers byte for byte), the enumerations and constants their values, as a C program compiled
  against the header prints them, and so do the Fortran module's bind(c) types; the header compiles without a warning
  in C11 and C++17 (-Wall -Wextra -pedantic), its initialisers too.
- Records that grow: a record whose size is smaller than its 1.0 size gives RBS_INVALID, for every record of every
  call; an rbs_result whose size covers only up to its status gets only that written; records larger than the
  library's (a program built against a later header) work, their later bytes neither read nor written; a NULL
  rbs_options is RBS_OPTIONS_INIT.
- The version (1.4.1, 1004001) and the one status space: each status a distinct value and a string.
- The many-hit and local draws' refusals (rbs_draw_many, rbs_draw_local).
"""

from __future__ import annotations

import ctypes
import re
import shutil

import numpy as np
import pytest

from tests.helpers import python_side as py
from tests.helpers.native_library import (ENUMS, HEADER, INSTALL_HINT, INTERNAL, INTERPOLATION_STOCHASTIC, INVALID,
                                          LOCAL_SIZE, MAX_ROUGHNESS_DEG, MAX_WALL_HITS, METHOD_AUTO, METHOD_DIRECT,
                                          METHOD_TABLE, NATIVE, NO_KEY, OK, PATH_NONE, PUBLIC, RECORDS,
                                          ROUGHNESS_OF_TABLE, STATUSES, U_PER_DRAW, VERSION_NUMBER, Grain, Hit,
                                          Hits, Options, Result, Results, Rng, ShapeInfo, TableInfo, WallInfo, address,
                                          fields, hit, options, ref, run)
from tests.helpers.states import max_ulp

_API = re.compile(r"^RBS_API\b[^;(]*?\b(rbs_\w+)\s*\(", re.M)
# symbols the linker defines in every shared object (older binutils put them in .dynsym)
_LINKER = {"_init", "_fini", "_edata", "_end", "__bss_start"}
GOOD_HIT = dict(V=(80.0, -60.0, 5.0), Omega=(0.0, 0.0, 0.0), n=(0.0, 1.0, 0.0), a=1e-4)
SPIN_HIT = dict(GOOD_HIT, Omega=(0.0, 0.0, 3e5))


def _header_functions() -> set:
    return set(_API.findall(HEADER.read_text()))


def _exported(path) -> dict:
    """{name: nm type} of the defined dynamic symbols of a shared library (nm -D --defined-only), without
    multi-versioning's local clones and resolvers (names with a dot) and symbol versions."""
    nm = shutil.which("nm")
    assert nm, f"nm (binutils) is needed: {INSTALL_HINT}"
    done = run([nm, "-D", "--defined-only", str(path)])
    assert done.returncode == 0, done.stderr
    symbols = {}
    for line in done.stdout.splitlines():
        parts = line.split()
        if len(parts) < 2:
            continue
        kind, name = parts[-2], parts[-1].split("@")[0]
        if "." not in name:
            symbols[name] = kind
    return symbols


# ---------------------------------------------------------------- what the libraries export


def test_the_public_library_exports_exactly_the_header_s_functions(native):
    declared = _header_functions()
    assert len(declared) >= 29 and "rbs_rebound" in declared, sorted(declared)
    symbols = _exported(native.path)
    exported = set(symbols) - _LINKER
    assert exported == declared, (f"exported, not declared: {sorted(exported - declared)}; "
                                  f"declared, not exported: {sorted(declared - exported)}")
    assert all(symbols[name] in "TWi" for name in declared), {n: symbols[n] for n in declared}
    # the ctypes side types every declared function, and nothing the header does not declare
    assert set(PUBLIC) == declared


def test_the_testing_library_exports_the_internal_functions(native):
    """librebound_scatter_testing.so exports what the tests bind there, and the public names too."""
    exported = set(_exported(native.internal._name))
    assert set(INTERNAL) <= exported, sorted(set(INTERNAL) - exported)
    assert _header_functions() <= exported
    assert not set(INTERNAL) & set(_exported(native.path))


# ---------------------------------------------------------------- the header's records, enumerations and constants

DEFINES = {"RBS_U_PER_DRAW": U_PER_DRAW, "RBS_VERSION_NUMBER": VERSION_NUMBER, "RBS_NO_KEY": NO_KEY,
           "RBS_LOCAL_SIZE": LOCAL_SIZE, "RBS_BLOCK": 32, "RBS_MAX_ROUGHNESS_DEG": MAX_ROUGHNESS_DEG,
           "RBS_ROUGHNESS_OF_TABLE": ROUGHNESS_OF_TABLE, "RBS_MAX_WALL_HITS": MAX_WALL_HITS}


def _layout_program() -> str:
    lines = ["#include <stdio.h>", "#include <stddef.h>", '#include "rebound_scatter.h"',
             "static void bytes(const char *name, const void *p, size_t n) {",
             '    printf("init %s ", name);',
             '    for (size_t i = 0; i < n; i++) printf("%02x", ((const unsigned char *)p)[i]);',
             '    printf("\\n");', "}", "int main(void) {"]
    for name, record in RECORDS.items():
        lines.append(f'    printf("sizeof {name} %zu\\n", sizeof({name}));')
        for field in fields(record):
            lines.append(f'    printf("offsetof {name} {field} %zu\\n", offsetof({name}, {field}));')
        init = f"RBS_{name[4:].upper()}_INIT"
        lines.append(f"    {{ static const {name} x = {init}; bytes(\"{name}\", &x, sizeof x); }}")
    for values in ENUMS.values():
        for constant in values:
            lines.append(f'    printf("enum {constant} %d\\n", (int){constant});')
    for constant in ("RBS_U_PER_DRAW", "RBS_VERSION_NUMBER", "RBS_NO_KEY", "RBS_LOCAL_SIZE", "RBS_BLOCK",
                     "RBS_VERSION_MAJOR", "RBS_VERSION_MINOR", "RBS_VERSION_PATCH", "RBS_TABLE_FORMAT_MAJOR",
                     "RBS_TABLE_MAX_SHAPES", "RBS_SHAPE_NAME_SIZE", "RBS_NORMAL_TOLERANCE", "RBS_SPIN_TOLERANCE",
                     "RBS_MAX_ROUGHNESS_DEG", "RBS_ROUGHNESS_OF_TABLE", "RBS_MAX_WALL_HITS"):
        lines.append(f'    printf("define {constant} %.17g\\n", (double)({constant}));')
    lines += ["    return 0;", "}"]
    return "\n".join(lines) + "\n"


@pytest.fixture(scope="module")
def header_facts(tmp_path_factory):
    """What a C program compiled against the header prints: {("sizeof", record): n, ("offsetof", record, field): n,
    ("init", record): hex bytes, ("enum", name): value, ("define", name): value}."""
    compiler = shutil.which("cc") or shutil.which("gcc")
    assert compiler, f"no C compiler: {INSTALL_HINT}"
    folder = tmp_path_factory.mktemp("layout")
    (folder / "layout.c").write_text(_layout_program())
    done = run([compiler, "-std=c11", "-Wall", "-Werror", f"-I{NATIVE / 'include'}", str(folder / "layout.c"), "-o",
                str(folder / "layout")])
    assert done.returncode == 0, done.stderr
    done = run([str(folder / "layout")])
    assert done.returncode == 0, done.stderr
    facts = {}
    for line in done.stdout.splitlines():
        *key, value = line.split()
        facts[tuple(key)] = value
    return facts


def test_the_ctypes_records_have_the_header_s_layout(header_facts):
    for name, record in RECORDS.items():
        assert int(header_facts[("sizeof", name)]) == ctypes.sizeof(record), name
        for field in fields(record):
            assert int(header_facts[("offsetof", name, field)]) == getattr(record, field).offset, (name, field)
        # the RBS_*_INIT initialiser is the record as tests.helpers.native_library creates it
        assert header_facts[("init", name)] == bytes(record()).hex(), name


def test_a_hit_s_record_has_rbs_result_s_fields_in_every_language(header_facts):
    """surrogate.Hit (one hit, numba) and Rebounds (many, NumPy) have the fields of rbs_result, in its
    order (``size`` aside), the paths the header's values, the vectors its length, the kinds its (integers, floats):
    a new output of a hit is a field of all three."""
    from surrogate.kernels import hit
    names = fields(Result)
    assert names[0] == "size" and hit.Hit._fields == hit.Rebounds._fields == tuple(names[1:])
    assert tuple(hit.REBOUNDS_ARRAYS) == tuple(names[1:])
    c_types = dict(Result._fields_)
    for name, (dtype, tail) in hit.REBOUNDS_ARRAYS.items():
        c_type = c_types[name]
        array = hasattr(c_type, "_length_")
        element = c_type._type_ if array else c_type        # an array's element type
        assert tail == ((c_type._length_,) if array else ()), name
        assert np.dtype(dtype).kind == ("f" if element is ctypes.c_double else "i"), name
    # the record a refused hit gets: NaN floats, as rbs_rebound writes them
    refused = hit.invalid_hit()
    assert np.isnan(refused.wall_work_normal) and np.isnan(refused.wall_work_tangential)
    assert (hit.PATH_NONE, hit.PATH_TABLE, hit.PATH_DIRECT) == tuple(
        int(header_facts[("enum", f"RBS_PATH_{p}")]) for p in ("NONE", "TABLE", "DIRECT"))


def test_the_enumerations_and_constants_are_the_helper_s_and_the_packages(header_facts):
    from data_schema.shape_records import MAX_TABLE_SHAPES
    from surrogate.kernels.frame import NORMAL_TOLERANCE
    for values in ENUMS.values():
        for constant, value in values.items():
            assert int(header_facts[("enum", constant)]) == value, constant
    defines = {key[1]: float(value) for key, value in header_facts.items() if key[0] == "define"}
    for constant, value in DEFINES.items():
        assert defines[constant] == value, constant
    assert (defines["RBS_VERSION_MAJOR"], defines["RBS_VERSION_MINOR"], defines["RBS_VERSION_PATCH"]) == (1, 4, 1)
    assert defines["RBS_U_PER_DRAW"] == py.U_PER_DRAW
    assert defines["RBS_SPIN_TOLERANCE"] == py.SPIN_TOLERANCE
    assert defines["RBS_NORMAL_TOLERANCE"] == NORMAL_TOLERANCE
    assert defines["RBS_TABLE_MAX_SHAPES"] == MAX_TABLE_SHAPES
    assert defines["RBS_MAX_ROUGHNESS_DEG"] == py.MAX_ROUGHNESS_DEG
    assert defines["RBS_MAX_WALL_HITS"] == py.MAX_WALL_HITS
    # the hits' statuses are surrogate's
    assert (OK, STATUSES["RBS_TRAPPED"], STATUSES["RBS_FAILED"], INVALID) == \
        (py.STATUS_REBOUNDED, py.STATUS_TRAPPED, py.STATUS_FAILED, py.STATUS_INVALID)
    assert (METHOD_AUTO, METHOD_TABLE, METHOD_DIRECT) == (py.METHOD_AUTO, py.METHOD_TABLE, py.METHOD_DIRECT)


def test_the_header_s_table_format_is_the_one_read_and_written(header_facts, table_pair):
    defines = {key[1]: float(value) for key, value in header_facts.items() if key[0] == "define"}
    assert defines["RBS_TABLE_FORMAT_MAJOR"] == py.TABLE_VERSION[0] == table_pair[1].info().format_major


def _fortran_layout_program() -> str:
    """A Fortran program printing, for each record of the module (native/fortran/rebound_scatter.f90), its c_sizeof
    and each field's offset (c_loc differences), as _layout_program prints them for C, and the defaults of the
    fields of 1.2 and 1.3."""
    lines = ["program layout", "  use rebound_scatter", "  implicit none"]
    for k, name in enumerate(RECORDS):
        lines.append(f"  type({name}), target :: x{k}")
    lines.append("  print '(a, es24.17, 1x, i0, 1x, es24.17, 2(1x, es24.17))', 'defaults ', x1%roughness_deg, &\n"
                 "    x2%wall_hits, x7%roughness_deg, x2%wall_work_normal, x2%wall_work_tangential")
    for k, (name, record) in enumerate(RECORDS.items()):
        lines.append(f"  print '(a, i0)', 'sizeof {name} ', c_sizeof(x{k})")
        for field in fields(record):
            lines.append(f"  print '(a, i0)', 'offsetof {name} {field} ', &\n"
                         f"    transfer(c_loc(x{k}%{field}), 0_c_intptr_t) - transfer(c_loc(x{k}), 0_c_intptr_t)")
    lines.append("end program layout")
    return "\n".join(lines) + "\n"


def test_the_fortran_records_have_the_header_s_layout(native_build, header_facts, tmp_path):
    """The bind(c) types of the Fortran module: the header's sizeof and offsets, field for field (the fields of 1.2
    and 1.3 too), and the defaults of RBS_OPTIONS_INIT, RBS_RESULT_INIT and RBS_WALL_INFO_INIT for the fields of 1.2
    and 1.3."""
    compiler = shutil.which("gfortran")
    assert compiler, f"no Fortran compiler: {INSTALL_HINT}"
    source = tmp_path / "layout.f90"
    source.write_text(_fortran_layout_program())
    done = run([compiler, f"-I{native_build / 'fortran_modules'}", str(source), "-o", str(tmp_path / "layout")])
    assert done.returncode == 0, done.stderr[-3000:]
    done = run([str(tmp_path / "layout")])
    assert done.returncode == 0, done.stderr
    facts = {}
    for line in done.stdout.splitlines():
        *key, value = line.split()
        facts[tuple(key)] = value
    for key, value in facts.items():
        if key[0] in ("sizeof", "offsetof"):
            assert int(value) == int(header_facts[key]), key
    assert len(facts) == 1 + sum(1 + len(fields(record)) for record in RECORDS.values())
    (roughness, wall_hits, wall_roughness, work_n, work_t), = [line.split()[1:] for line in done.stdout.splitlines()
                                                                if line.startswith("defaults")]
    assert (float(roughness), int(wall_hits), float(wall_roughness)) == (ROUGHNESS_OF_TABLE, 0, 0.0)
    assert (float(work_n), float(work_t)) == (Result().wall_work_normal, Result().wall_work_tangential) == (0.0, 0.0)


@pytest.mark.parametrize("language", ["c11", "c++17"])
def test_the_header_compiles_without_warnings(tmp_path, language):
    """A program using every record's initialiser compiles with -Wall -Wextra -pedantic -Werror."""
    cxx = language.startswith("c++")
    compiler = shutil.which("g++" if cxx else "gcc") or shutil.which("c++" if cxx else "cc")
    assert compiler, f"no compiler for {language}: {INSTALL_HINT}"
    body = "\n".join(f"    {name} v{k} = RBS_{name[4:].upper()}_INIT; (void)v{k};" for k, name in enumerate(RECORDS))
    source = tmp_path / ("main.cpp" if cxx else "main.c")
    source.write_text(f'#include "rebound_scatter.h"\nint main(void) {{\n{body}\n    return 0;\n}}\n')
    done = run([compiler, f"-std={language}", "-Wall", "-Wextra", "-pedantic", "-Werror", f"-I{NATIVE / 'include'}",
                "-c", str(source), "-o", str(tmp_path / "main.o")])
    assert done.returncode == 0, done.stderr[-3000:]


# ---------------------------------------------------------------- version and statuses


def test_version(native):
    version = native.version()
    major, minor, patch = map(int, version.split("."))
    assert (major, minor, patch) == (1, 4, 1)
    assert native.version_number() == VERSION_NUMBER == major * 1_000_000 + minor * 1_000 + patch


def test_every_status_has_its_own_value_and_string(native):
    assert len(set(STATUSES.values())) == len(STATUSES) == 8
    assert STATUSES == {"RBS_OK": 0, "RBS_TRAPPED": 1, "RBS_FAILED": 2, "RBS_INVALID": -1, "RBS_ERR_IO": -2,
                        "RBS_ERR_FORMAT": -3, "RBS_ERR_VERSION": -4, "RBS_ERR_MEMORY": -5}
    strings = {code: native.status_string(code) for code in STATUSES.values()}
    unknown = native.status_string(3)
    assert unknown == "unknown status"
    assert all(s and s != unknown for s in strings.values()), strings
    assert len(set(strings.values())) == len(strings), strings
    for code in (-6, 99, -(2 ** 31), 2 ** 31 - 1):
        assert native.status_string(code) == unknown, code


# ---------------------------------------------------------------- records that grow


@pytest.fixture(scope="module")
def api_case(native, small_table_path):
    """(the small table, an equal mix, good uniforms)."""
    table = native.table(small_table_path)
    mix = table.mix()
    yield table, mix, np.full(U_PER_DRAW, 0.5)
    del mix
    table.close()


def _fill(record, byte=0xAB, start=ctypes.sizeof(ctypes.c_size_t)):
    """Every byte of ``record`` from ``start`` set to ``byte`` (the size field kept)."""
    ctypes.memset(ctypes.addressof(record) + start, byte, ctypes.sizeof(record) - start)


def _tail(record, start) -> bytes:
    return bytes(record)[start:]


def _rebound(c, table, mix, h, opts, result):
    return c.rbs_rebound(table.handle, mix.pointer, ref(h), ref(opts), ref(result))


def _size_1_0(record) -> int:
    """The record's 1.0 size: the end of its last field of 1.0 (Record.LAST_1_0; else its last field: its sizeof but
    for trailing padding)."""
    last = getattr(record, record.LAST_1_0 or fields(record)[-1])
    return last.offset + last.size


def _sizes_below(record) -> list:
    """Sizes smaller than the record's 1.0 size: 0, the size field alone, one word short, one byte short."""
    size = _size_1_0(record)
    return [0, ctypes.sizeof(ctypes.c_size_t), size - 8, size - 1]


def test_a_record_smaller_than_its_1_0_size_is_invalid(native, api_case):
    """Each record of each call, its size below its 1.0 size: RBS_INVALID (RBS_PATH_NONE), NaN outputs where the
    call writes them, and rbs_draw_many's rng not advanced."""
    table, mix, u = api_case
    c = native.c
    h, kept = hit(**GOOD_HIT, u=u)
    result = Result()
    assert _rebound(c, table, mix, h, None, result) == OK
    for size in _sizes_below(Hit):
        small, kept_small = hit(**GOOD_HIT, u=u)
        small.size = size
        result = Result()
        assert _rebound(c, table, mix, small, None, result) == result.status == INVALID, size
        assert np.isnan(result.V[:]).all() and np.isnan(result.Omega[:]).all(), size
        assert c.rbs_rebound_path(table.handle, ref(small), None) == PATH_NONE, size
    for size in _sizes_below(Options):
        opts = Options(size=size)
        result = Result()
        assert _rebound(c, table, mix, h, opts, result) == result.status == INVALID, size
        assert np.isnan(result.V[:]).all(), size
        assert c.rbs_rebound_path(table.handle, ref(h), ref(opts)) == PATH_NONE, size
        out = np.full(LOCAL_SIZE, 7.0)
        assert c.rbs_draw_local(table.handle, mix.pointer, 45.0, 150.0, u.ctypes.data, ref(opts), out.ctypes.data) \
            == INVALID, size
        assert np.isnan(out).all()
        assert _draw_many(c, table, mix, opts=opts)[0] == INVALID, size
    for size in _sizes_below(Result):
        assert _rebound(c, table, mix, h, None, Result(size=size)) == INVALID, size
    for size in _sizes_below(Hits):
        code, *_, after, before, _, _ = _draw_many(c, table, mix, hits_size=size, rng="seeded")
        assert code == INVALID and np.array_equal(after, before), size
    for size in _sizes_below(Results):
        assert _draw_many(c, table, mix, results_size=size)[0] == INVALID, size
    for size in _sizes_below(TableInfo):
        assert c.rbs_table_info_get(table.handle, ref(TableInfo(size=size))) == INVALID, size
    for size in _sizes_below(ShapeInfo):
        assert c.rbs_table_shape_info(table.handle, 0, ref(ShapeInfo(size=size))) == INVALID, size
    for size in _sizes_below(WallInfo):
        assert c.rbs_table_wall(table.handle, ref(WallInfo(size=size))) == INVALID, size
    for size in _sizes_below(Grain):
        grain = Grain(size=size)
        _fill(grain)
        assert c.rbs_grain_info(table.handle, mix.pointer, 5, ref(grain)) == INVALID, size
        assert _tail(grain, 8) == b"\xab" * (ctypes.sizeof(Grain) - 8), size      # nothing written
    del kept, kept_small


def test_a_result_covering_its_status_gets_only_that(native, api_case):
    """An rbs_result whose size ends after `status`: the call is refused (smaller than 1.0's rbs_result) and says
    so in the status, and the bytes after it stay as they were."""
    table, mix, u = api_case
    h, kept = hit(**GOOD_HIT, u=u)
    end = Result.status.offset + Result.status.size
    result = Result()
    _fill(result)
    result.size = end
    assert _rebound(native.c, table, mix, h, None, result) == INVALID
    assert result.status == INVALID
    assert _tail(result, end) == b"\xab" * (ctypes.sizeof(Result) - end)
    del kept


def test_a_result_of_1_2_gets_no_wall_work(native, api_case):
    """The wall work of 1.3: written where the record reaches it (a direct hit's > 0, since 1.4 a table hit's drawn,
    >= 0), left alone in a record of 1.2 (its size ends before rbs_result.wall_work_normal), whose other fields are the
    same."""
    table, mix, u = api_case
    for spec, direct in ((SPIN_HIT, True), (GOOD_HIT, False)):
        h, kept = hit(**spec, u=u)
        full = Result()
        assert _rebound(native.c, table, mix, h, None, full) == OK
        work = (full.wall_work_normal, full.wall_work_tangential)
        assert (work[0] > 0.0 if direct else work[0] >= 0.0) and work[1] >= 0.0, (spec, work)
        old = Result()
        _fill(old)
        old.size = Result.wall_work_normal.offset
        assert _rebound(native.c, table, mix, h, None, old) == OK
        end = Result.wall_hits.offset + Result.wall_hits.size       # padding after it
        assert bytes(old)[8:end] == bytes(full)[8:end] and _tail(old, old.size) == b"\xab" * 16
        del kept


def _draw_many(c, table, mix, count=40, opts=None, hits_size=None, results_size=None, rng=None, u=True,
               hits_record=Hits, results_record=Results, **arrays):
    """rbs_draw_many on ``count`` good rows, uniforms given (``u``) or, with ``rng`` "seeded" or "zero", drawn from
    an rng of that state, ``arrays`` replacing V, n, a, u (None: NULL): (code, status, V⁺, Ω⁺, the rng's state
    after, before, the records)."""
    rows = np.random.default_rng(4).random((count, U_PER_DRAW))
    V = np.tile(GOOD_HIT["V"], (count, 1))
    n, a = np.tile(GOOD_HIT["n"], (count, 1)), np.full(count, GOOD_HIT["a"])
    data = {"V": V, "n": n, "a": a, "u": rows if u and rng is None else None}
    data.update(arrays)
    before = np.array([1, 2, 3, 4] if rng == "seeded" else [0, 0, 0, 0], dtype=np.uint64)
    generator = Rng()
    generator.s[:] = [int(x) for x in before]
    hits = hits_record(count=count, rng=None if rng is None else address(generator),
                       **{k: (None if v is None else v.ctypes.data) for k, v in data.items()})
    if hits_size is not None:
        hits.size = hits_size
    V_out, W_out, status = np.full((count, 3), 7.0), np.full((count, 3), 7.0), np.full(count, 77, dtype=np.int8)
    results = results_record(V=V_out.ctypes.data, Omega=W_out.ctypes.data, status=status.ctypes.data)
    if results_size is not None:
        results.size = results_size
    code = c.rbs_draw_many(table.handle, None if mix is None else mix.pointer, ref(hits), ref(opts), ref(results))
    return code, status, V_out, W_out, np.array(list(generator.s), dtype=np.uint64), before, hits, results


def test_larger_records_of_a_later_header_work(native, api_case):
    """Records declared longer (a program built against 1.x, x > 0): their later bytes, set to garbage, are not
    read, and not written; the answers are those of the 1.0 records."""
    table, mix, u = api_case
    c = native.c
    for spec in (GOOD_HIT, SPIN_HIT):
        expected = Result()
        h, kept = hit(**spec, u=u)
        assert _rebound(c, table, mix, h, None, expected) == OK
        big, kept_big = hit(**spec, u=u, record=Hit.grown())
        _fill(big, 0xFF, ctypes.sizeof(Hit))
        opts = options(record=Options.grown())
        _fill(opts, 0xFF, ctypes.sizeof(Options))
        result = Result.grown()()
        _fill(result, 0xAB, ctypes.sizeof(Result))
        assert _rebound(c, table, mix, big, opts, result) == OK
        assert bytes(result)[8:ctypes.sizeof(Result)] == bytes(expected)[8:]
        assert _tail(result, ctypes.sizeof(Result)) == b"\xab" * (ctypes.sizeof(result) - ctypes.sizeof(Result))
        assert c.rbs_rebound_path(table.handle, ref(big), ref(opts)) == \
            c.rbs_rebound_path(table.handle, ref(h), None) == expected.path
        del kept, kept_big
    small = _draw_many(c, table, mix)
    grown = _draw_many(c, table, mix, opts=options(record=Options.grown()), hits_record=Hits.grown(),
                       results_record=Results.grown())
    assert small[0] == grown[0] == OK
    assert all(np.array_equal(x.view(np.uint8), y.view(np.uint8)) for x, y in zip(small[1:4], grown[1:4]))
    for record, call in ((TableInfo, lambda r: c.rbs_table_info_get(table.handle, ref(r))),
                         (ShapeInfo, lambda r: c.rbs_table_shape_info(table.handle, 1, ref(r))),
                         (WallInfo, lambda r: c.rbs_table_wall(table.handle, ref(r))),
                         (Grain, lambda r: c.rbs_grain_info(table.handle, mix.pointer, 12345, ref(r)))):
        plain, big = record(), record.grown()()
        _fill(big, 0xAB, ctypes.sizeof(record))
        assert call(plain) == call(big) == OK, record.__name__
        assert bytes(big)[8:ctypes.sizeof(record)] == bytes(plain)[8:], record.__name__
        assert _tail(big, ctypes.sizeof(record)) == b"\xab" * (ctypes.sizeof(big) - ctypes.sizeof(record))


def test_null_options_are_the_defaults(native, api_case):
    """NULL rbs_options = RBS_OPTIONS_INIT (auto, scaled) for every call that takes options; the stochastic
    interpolation is another law (some hit differs)."""
    table, mix, _ = api_case
    c = native.c
    rng = np.random.default_rng(5)
    differs = 0
    for k in range(200):
        u = rng.random(U_PER_DRAW)
        spec = SPIN_HIT if k % 4 == 0 else GOOD_HIT
        h, kept = hit(**spec, u=u)
        out = {}
        for label, opts in (("null", None), ("init", Options()), ("stochastic", options(METHOD_AUTO,
                                                                                       INTERPOLATION_STOCHASTIC))):
            result = Result()
            _rebound(c, table, mix, h, opts, result)
            out[label] = bytes(result)
        assert out["null"] == out["init"], k
        differs += out["null"] != out["stochastic"]
        assert c.rbs_rebound_path(table.handle, ref(h), None) == c.rbs_rebound_path(table.handle, ref(h),
                                                                                      ref(Options()))
        local = [np.full(LOCAL_SIZE, 7.0) for _ in range(2)]
        for opts, out_local in zip((None, Options()), local):
            c.rbs_draw_local(table.handle, mix.pointer, 40.0, 150.0, u.ctypes.data, ref(opts), out_local.ctypes.data)
        assert local[0].tobytes() == local[1].tobytes()
        del kept
    assert differs > 0
    first, second = _draw_many(c, table, mix), _draw_many(c, table, mix, opts=Options())
    assert first[0] == second[0] == OK
    assert all(np.array_equal(x.view(np.uint8), y.view(np.uint8)) for x, y in zip(first[1:4], second[1:4]))


# ---------------------------------------------------------------- the many-hit and local draws' refusals


def test_draw_many_refuses_what_the_header_says(native, api_case, small_table_path):
    """RBS_INVALID, every row RBS_INVALID and NaN (in the outputs given) and the rng not advanced, for a NULL table,
    mix, hits or results, an array NULL with count > 0, a mix of another table, RBS_METHOD_DIRECT, an unknown
    method or interpolation, a NULL or all-zero rng; RBS_METHOD_TABLE is RBS_METHOD_AUTO; count 0 draws nothing."""
    table, mix, _ = api_case
    c = native.c
    other = native.table(small_table_path)
    other_mix = other.mix()
    good = _draw_many(c, table, mix, rng="seeded")
    assert good[0] == OK and not np.array_equal(good[4], good[5]) and np.all(good[1] != 77)
    as_table = _draw_many(c, table, mix, rng="seeded", opts=Options(method=METHOD_TABLE))
    assert as_table[0] == OK and all(np.array_equal(x.view(np.uint8), y.view(np.uint8))
                                     for x, y in zip(good[1:5], as_table[1:5]))
    cases = {"mix of another table": dict(mix=other_mix), "NULL mix": dict(mix=None),
             "method direct": dict(opts=Options(method=METHOD_DIRECT)), "method 3": dict(opts=Options(method=3)),
             "interpolation 2": dict(opts=Options(interpolation=2)), "NULL V": dict(V=None), "NULL n": dict(n=None),
             "NULL a": dict(a=None)}
    for label, change in cases.items():
        mix_arg = change.pop("mix", mix)
        code, status, V_out, W_out, after, before, _, _ = _draw_many(c, table, mix_arg, rng="seeded", **change)
        assert code == INVALID and np.all(status == INVALID), label
        assert np.isnan(V_out).all() and np.isnan(W_out).all(), label
        assert np.array_equal(after, before), label
    for label, change in {"neither u nor rng": dict(u=False), "all-zero rng": dict(rng="zero")}.items():
        code, status, V_out, W_out, after, _, _, _ = _draw_many(c, table, mix, **change)
        assert code == INVALID and np.all(status == INVALID) and np.isnan(V_out).all(), label
        assert np.array_equal(after, np.zeros(4, dtype=np.uint64)), label
    empty = _draw_many(c, table, mix, count=0, V=None, n=None, a=None, rng="seeded")     # no rows, NULL arrays
    assert empty[0] == OK
    hits, results = Hits(count=1), Results()
    for args in ((None, mix.pointer, ref(hits), None, ref(results)), (table.handle, mix.pointer, None, None,
                                                                       ref(results)),
                 (table.handle, mix.pointer, ref(hits), None, None)):
        assert c.rbs_draw_many(*args) == INVALID
    del other_mix
    other.close()


def test_draw_local_refuses_what_the_header_says(native, api_case, small_table_path):
    table, mix, u = api_case
    c = native.c
    other = native.table(small_table_path)
    other_mix = other.mix()
    out = np.full(LOCAL_SIZE, 7.0)
    assert c.rbs_draw_local(table.handle, mix.pointer, 40.0, 150.0, u.ctypes.data, None, out.ctypes.data) == OK
    cases = {"NULL table": (None, mix.pointer, u.ctypes.data, None), "NULL mix": (table.handle, None, u.ctypes.data,
                                                                                 None),
             "NULL u": (table.handle, mix.pointer, None, None),
             "mix of another table": (table.handle, other_mix.pointer, u.ctypes.data, None),
             "interpolation 2": (table.handle, mix.pointer, u.ctypes.data, ref(Options(interpolation=2)))}
    for label, (t, m, u_ptr, opts) in cases.items():
        out[:] = 7.0
        assert c.rbs_draw_local(t, m, 40.0, 150.0, u_ptr, opts, out.ctypes.data) == INVALID, label
        assert np.isnan(out).all(), label
    assert c.rbs_draw_local(table.handle, mix.pointer, 40.0, 150.0, u.ctypes.data, None, None) == INVALID
    # the method is not read
    for method in (METHOD_DIRECT, 7):
        again = np.full(LOCAL_SIZE, 7.0)
        out[:] = 7.0
        c.rbs_draw_local(table.handle, mix.pointer, 40.0, 150.0, u.ctypes.data, None, out.ctypes.data)
        assert c.rbs_draw_local(table.handle, mix.pointer, 40.0, 150.0, u.ctypes.data, ref(Options(method=method)),
                                again.ctypes.data) == OK
        assert max_ulp(out, again) == 0
    del other_mix
    other.close()


def test_mix_constructors_refuse_bad_arguments(native, api_case):
    """rbs_mix_new_*: NULL with a message naming what is wrong (an unknown name, a name twice, weights negative,
    not finite or not summing to 1), and NULL for a NULL table."""
    table, _, _ = api_case
    shapes = table.shapes
    bad = {"unknown name": {"sphere": 1.0}, "negative": {shapes[0]: 1.5, shapes[1]: -0.5},
           "not finite": {shapes[0]: float("nan"), shapes[1]: 1.0}, "sum": {shapes[0]: 0.5, shapes[1]: 0.4}}
    for label, weights in bad.items():
        mix, message = table.mix_new(weights=weights)
        assert mix is None and message, label
    names = (ctypes.c_char_p * 2)(shapes[0].encode(), shapes[0].encode())
    values = np.array([0.5, 0.5])
    message = ctypes.create_string_buffer(512)
    assert not native.c.rbs_mix_new_from_weights(table.handle, 2, names, values.ctypes.data, message, len(message))
    assert message.value, "a name twice"
    mix, message = table.mix_new("no_such_shape")
    assert mix is None and "no_such_shape" in message
    assert not native.c.rbs_mix_new_equal(None)
    assert not native.c.rbs_mix_new_from_shape(None, b"mix", None, 0)
    native.c.rbs_mix_free(None)
