"""The map between the C library and its Python twins stays true: every Python module, file and name that
native/'s sources and docs/native.md cite exists, and each twin pair of docs/native.md's table is named alike."""

import dataclasses
import importlib
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
NATIVE_DOC = ROOT / "docs" / "native.md"
C_SOURCES = sorted(p for p in (ROOT / "native").rglob("*")
                   if p.suffix in (".c", ".h", ".cpp", ".f90") or p.name == "CMakeLists.txt")
CITING = C_SOURCES + [NATIVE_DOC]

# every package of the project that C may cite
PACKAGES = "surrogate|direct_model|data_schema|tablegen"
DOTTED = re.compile(rf"\b(?:{PACKAGES})(?:\.[A-Za-z_]\w*)+")
PATH = re.compile(rf"\b(?:{PACKAGES}|benchmarks|tests)/[\w/]+\.py\b")
# "(surrogate.kernels.draw: _chain, _folded)": names listed after a module (not prose after a colon)
LISTED = re.compile(rf"\b((?:{PACKAGES})(?:\.\w+)+): (\w+(?:, \w+)*)\)")


def _text(path: Path) -> str:
    """The file's text with C comment continuations (newline, spaces, '*') joined into single spaces."""
    return re.sub(r"\n\s*(?:\*(?!/)\s?)?", " ", path.read_text())


def _resolves(dotted: str) -> bool:
    """Whether ``dotted`` is a module, or a module followed by attributes (a dataclass's field counts, with or
    without a default)."""
    parts = dotted.split(".")
    for cut in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:cut]))
        except ImportError:
            continue
        for i, name in enumerate(parts[cut:]):
            if hasattr(obj, name):
                obj = getattr(obj, name)
            else:
                fields = {f.name for f in dataclasses.fields(obj)} if dataclasses.is_dataclass(obj) else set()
                return name in fields and cut + i + 1 == len(parts)
        return True
    return False


def _citations():
    for path in CITING:
        text = _text(path)
        where = path.relative_to(ROOT)
        for dotted in DOTTED.findall(text):
            yield where, dotted
        for module, names in LISTED.findall(text):
            for name in filter(None, (n.strip() for n in names.split(","))):
                yield where, f"{module}.{name}"


CITATIONS = sorted(set(_citations()))


def test_the_sources_cite_python():
    assert len(CITATIONS) > 50
    assert any(name == "surrogate.kernels.arithmetic._chain" for _, name in CITATIONS)     # a listed name
    assert any(name.startswith("direct_model.") for _, name in CITATIONS)


@pytest.mark.parametrize("where, name", CITATIONS, ids=[f"{w}:{n}" for w, n in CITATIONS])
def test_cited_python_name_exists(where, name):
    assert _resolves(name), f"{where} cites {name}, which does not exist"


@pytest.mark.parametrize("path", CITING, ids=lambda p: str(p.relative_to(ROOT)))
def test_cited_python_file_exists(path):
    missing = [f for f in PATH.findall(_text(path)) if not (ROOT / f).is_file()]
    assert not missing, f"{path.relative_to(ROOT)} cites files that do not exist: {missing}"


def _twin_table() -> list:
    """(C sources, Python twin or None) per row of docs/native.md's table of sources."""
    rows = re.findall(r"^\| ((?:`[\w.]+\.[ch]`(?:, )?)+) \| (`[\w.]+`|—)", NATIVE_DOC.read_text(), flags=re.M)
    return [(re.findall(r"`([\w.]+)`", files), None if twin == "—" else twin.strip("`")) for files, twin in rows]


def test_every_source_is_in_the_twin_table():
    listed = {name for files, _ in _twin_table() for name in files}
    sources = {p.name for p in (ROOT / "native" / "src").iterdir() if p.suffix in (".c", ".h")}
    assert listed == sources


@pytest.mark.parametrize("files, twin", _twin_table(), ids=lambda x: str(x))
def test_twins_are_named_alike(files, twin):
    if twin is None:
        return
    assert _resolves(twin), f"docs/native.md pairs {files} with {twin}, which does not exist"
    if twin.startswith("surrogate.kernels.") and files != ["internal.h"]:
        stem = twin.rsplit(".", 1)[1]
        assert any(Path(f).stem == stem for f in files), f"{files} is the twin of {twin}: name one {stem}.c or .h"


# Offsets and codes written by hand on both sides of the language boundary: (Python module, the C sources that
# mirror it, the names, a Python name's C spelling). Every such name of the module must have its twin, of equal
# value, so that a slot moved on one side only fails here rather than as wrong bits somewhere else.
MIRRORED = [
    ("direct_model.rotation", ["rotation.c"], re.compile(r"_(I_\w+|MODE_\w+|NLEV_MAX|TH_TERMS)"), lambda n: n[1:]),
    ("direct_model.runtime", ["runtime.h", "shapes.h", "wall.h"], re.compile(r"P_\w+|U_(?!PER)\w+|N_PARAMS"),
     lambda n: n),
    ("direct_model.wall", ["wall.h"], re.compile(r"W_\w+|MAX_CONTACT_\w+|WALL_ARRAY_SIZE|EXPONENTIAL_CODE"),
     lambda n: n),
    ("surrogate.kernels.layout", ["internal.h"], re.compile(r"(ROW|CELL|AXIS)_\w+"), lambda n: n),
    ("direct_model.collision", ["collision.h"], re.compile(r"COLLISION_\w+"), lambda n: n),
    ("direct_model.flight", ["flight.h"], re.compile(r"SEARCH_\w+"), lambda n: n),
]
# "#define NAME value" with the value a number or a parenthesised sum of numbers and names
_DEFINE = re.compile(r"^#define (\w+) +\(?(-?[\w.]+(?: \+ \w+)*)\)?(?=\s|$)", flags=re.M)


def _defines(files) -> dict:
    """The numeric #defines of native/src's ``files``, sums of earlier names evaluated."""
    found = [(name, value.split(" + ")) for f in files
             for name, value in _DEFINE.findall((ROOT / "native" / "src" / f).read_text())]
    values, changed = {}, True
    while changed:
        changed = False
        for name, terms in found:
            if name not in values and all(t in values or re.fullmatch(r"-?[\d.]+", t) for t in terms):
                values[name] = sum(values[t] if t in values else float(t) for t in terms)
                changed = True
    return values


@pytest.mark.parametrize("module, files, names, spelled", MIRRORED, ids=[m[0] for m in MIRRORED])
def test_mirrored_offsets_are_equal(module, files, names, spelled):
    python = {spelled(n): v for n, v in vars(importlib.import_module(module)).items()
              if names.fullmatch(n) and isinstance(v, (int, float))}
    c = _defines(files)
    assert len(python) >= 3
    assert {n: c.get(n) for n in python} == python


def test_every_wall_law_family_has_its_code_in_c():
    """Each family of direct_model.wall.WALL_FAMILIES has its code in wall.h (<NAME>_CODE, what the kernels' wall
    array holds at W_FAMILY), and the C loader's table of families names it."""
    from direct_model.wall import WALL_FAMILIES
    codes = _defines(["wall.h"])
    loader = (ROOT / "native" / "src" / "loader.c").read_text()
    for name, family in WALL_FAMILIES.items():
        assert codes.get(f"{name.upper()}_CODE") == family.code, name
        assert f'{{"{name}", {name.upper()}_CODE,' in loader, name
