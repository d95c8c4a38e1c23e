"""The map between the C library and its Python twins stays true: every Python module, file and name that
native/'s sources and docs/native.md cite exists, and each twin pair of docs/native.md's table is named alike."""

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
    """Whether ``dotted`` is a module, or a module followed by attributes."""
    parts = dotted.split(".")
    for cut in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:cut]))
        except ImportError:
            continue
        for name in parts[cut:]:
            if not hasattr(obj, name):
                return False
            obj = getattr(obj, name)
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
