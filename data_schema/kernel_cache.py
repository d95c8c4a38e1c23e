"""numba's on-disk cache of compiled kernels, keyed by every source of this project that a kernel depends on.

numba keys a cached kernel by its own file alone: a kernel whose callee in another file changed would load its
stale machine code (the callee is compiled into it). Here a kernel is keyed instead by the contents of its own
file and of every module of the project's packages (:data:`PACKAGES`) that the file imports, directly or through
others (:func:`source_closure`): any edit to a kernel's source, or to a function or constant of the project that
it reaches, gives freshly compiled code at the next import, in a clone, an editable install or a plain one alike
(docs/design/kernel_cache.md). That holds for the project's own kernels and for a user's ``@njit(cache=True)``
code that calls them (a solver's loop over ``surrogate.kernels``): an upgrade of this package recompiles it.
A kernel whose file imports none of the project's modules keeps numba's own keying.

Importing this module installs the keying for every ``cache=True`` kernel decorated afterwards; it lives in
``data_schema`` because every package imports that first (:mod:`direct_model.options` imports it before any
kernel is decorated). Setting numba's ``NUMBA_CACHE_LOCATOR_CLASSES`` replaces this keying with the locators
named there.
"""

from __future__ import annotations

import functools
import hashlib
import re
from pathlib import Path

from numba.core import caching

PACKAGES = ("data_schema", "direct_model", "surrogate", "tablegen")
ROOT = Path(__file__).resolve().parents[1]       # the folder that holds the packages


def _module_file(name: str) -> Path | None:
    """The source file of project module ``name`` (a package's ``__init__.py``), or None if it is not one."""
    if name.split(".")[0] not in PACKAGES:
        return None
    base = ROOT.joinpath(*name.split("."))
    for candidate in (base.with_suffix(".py"), base / "__init__.py"):
        if candidate.is_file():
            return candidate
    return None


def _module_name(path: Path) -> str | None:
    """The dotted name of a project module's file; None for a file outside the project's packages."""
    if not is_project_source(path):
        return None
    parts = path.relative_to(ROOT).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


# import statements at any indentation (a function's imports too); ``from P import (a, b)`` over several lines
_IMPORT = re.compile(r"^[ \t]*import[ \t]+([^\n#;]+)", re.M)
_FROM = re.compile(r"^[ \t]*from[ \t]+(\.*)([\w.]*)[ \t]+import[ \t]+(\([^)]*\)|[^\n#;]*)", re.M)


@functools.lru_cache(maxsize=None)
def _imports(path: Path) -> tuple:
    """The project modules that ``path`` imports: for ``from P import N``, the submodule P.N where there is one,
    else P itself (N is defined in P or brought there). A line of a docstring that reads like an import only adds a
    module: the closure may be larger than needed, never smaller."""
    module = _module_name(path)       # a relative import outside the project is the user's own module
    package = None if module is None else module if path.name == "__init__.py" else module.rpartition(".")[0]
    text = path.read_text(encoding="utf-8")
    found = [name.split()[0] for names in _IMPORT.findall(text) for name in names.split(",") if name.strip()]
    for dots, base, names in _FROM.findall(text):
        if dots and package is None:
            continue
        if dots:
            anchor = package.split(".")[:len(package.split(".")) - len(dots) + 1]
            base = ".".join(anchor + ([base] if base else []))
        for name in names.strip("()").replace("\\", " ").split(","):
            name = name.split()[0] if name.split() else ""
            found.append(f"{base}.{name}" if name and _module_file(f"{base}.{name}") else base)
    return tuple(sorted({f for f in map(_module_file, found) if f is not None}))


def source_closure(path: Path) -> list:
    """The project source files that a kernel defined in ``path`` may depend on: ``path`` and every project module
    it imports, transitively, sorted."""
    seen, todo = set(), [Path(path).resolve()]
    while todo:
        current = todo.pop()
        if current not in seen:
            seen.add(current)
            todo.extend(_imports(current))
    return sorted(seen)


@functools.lru_cache(maxsize=None)
def _file_digest(path: Path) -> bytes:
    return hashlib.sha256(path.read_bytes()).digest()


@functools.lru_cache(maxsize=None)
def source_stamp(path: Path) -> str:
    """SHA-256 over the module names and contents of :func:`source_closure` (where the project's tree lies does not
    enter)."""
    digest = hashlib.sha256()
    for source in source_closure(path):
        digest.update((_module_name(source) or "").encode() + b"\0" + _file_digest(source))
    return digest.hexdigest()


def is_project_source(py_file) -> bool:
    """Whether ``py_file`` is a module of one of the project's packages."""
    try:
        relative = Path(py_file).resolve().relative_to(ROOT)
    except (OSError, ValueError):
        return False
    return len(relative.parts) > 1 and relative.parts[0] in PACKAGES and relative.suffix == ".py"


def reaches_project(py_file) -> bool:
    """Whether a kernel in ``py_file`` may depend on the project's sources: the file is one of its modules or imports
    one (False for a file that cannot be read: numba's own keying then serves it)."""
    path = Path(py_file)
    try:
        return is_project_source(path) or bool(_imports(path.resolve()))
    except (OSError, UnicodeDecodeError, ValueError):
        return False


class _KeyedBySources:
    """A numba cache locator's stamp replaced by :func:`source_stamp`, for the files that reach the project."""

    def get_source_stamp(self):
        return source_stamp(Path(self._py_file).resolve())

    @classmethod
    def from_function(cls, py_func, py_file):
        return super().from_function(py_func, py_file) if reaches_project(py_file) else None


def _numba(name: str):
    """A class of numba's caching module (before numba 0.61 its name began with an underscore)."""
    return getattr(caching, name, None) or getattr(caching, "_" + name)


class KeyedUserProvidedLocator(_KeyedBySources, _numba("UserProvidedCacheLocator")):
    """In ``NUMBA_CACHE_DIR``, where it is set."""


class KeyedInTreeLocator(_KeyedBySources, _numba("InTreeCacheLocator")):
    """In ``__pycache__`` beside the source."""


class KeyedUserWideLocator(_KeyedBySources, _numba("UserWideCacheLocator")):
    """In the user's cache folder, where ``__pycache__`` is not writable (a system-wide install)."""


_LOCATORS = _numba("CacheImpl")._locator_classes
if KeyedUserProvidedLocator.__name__ not in {c.__name__ for c in _LOCATORS}:    # once, if this module is reloaded
    _LOCATORS[:0] = [KeyedUserProvidedLocator, KeyedInTreeLocator, KeyedUserWideLocator]     # numba's own order
