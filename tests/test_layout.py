"""The source tree's layout: no folder that a contributor's ignore file would hide, and no circles: no Python module of
the project's packages imports itself through others (function-level imports too), no C source of native/src calls
itself through others and no header includes itself."""

import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

# folder names that GitHub's Python, C, C++ and CMake .gitignore templates ignore wherever they stand
IGNORED_FOLDERS = {"build", "develop-eggs", "dist", "downloads", "eggs", ".eggs", "lib", "lib64", "parts", "sdist",
                   "var", "wheels", "htmlcov", ".tox", ".nox", "cover", "instance", "target", ".ipynb_checkpoints",
                   "profile_default", "__pypackages__", ".venv", "env", "venv", "ENV", "env.bak", "venv.bak",
                   ".mypy_cache", ".pyre", ".pytype", ".ruff_cache", "cython_debug", "CMakeFiles", "CMakeScripts",
                   "Testing", "_deps", ".tmp_versions"}


def _tracked_files():
    try:
        listing = subprocess.run(["git", "ls-files"], cwd=ROOT, capture_output=True, text=True, check=True)
    except (OSError, subprocess.CalledProcessError):
        pytest.skip("not a git checkout")
    return listing.stdout.splitlines()


def test_no_tracked_folder_is_named_like_build_output():
    hidden = sorted({"/".join(Path(f).parts[:i + 1]) for f in _tracked_files()
                     for i, part in enumerate(Path(f).parts[:-1]) if part in IGNORED_FOLDERS})
    assert not hidden, f"folders a standard .gitignore would hide from commits: {hidden}"


# ------------------------------------------------------------------------- no import circles

PACKAGES = ("direct_model", "surrogate", "data_schema", "tablegen")
NATIVE_SRC = ROOT / "native" / "src"
NATIVE_INCLUDE = ROOT / "native" / "include"


def _circles(graph: dict) -> list:
    """The strongly connected components of more than one node of ``graph`` (node: the nodes it depends on),
    each sorted (Tarjan's algorithm, iterative)."""
    index, low, stack, on_stack, circles, counter = {}, {}, [], set(), [], 0
    for root in sorted(graph):
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = counter
        counter += 1
        stack.append(root)
        on_stack.add(root)
        while work:
            node, edges = work[-1]
            child = next(edges, None)
            if child is not None:
                if child not in index:
                    index[child] = low[child] = counter
                    counter += 1
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(graph[child]))))
                elif child in on_stack:
                    low[node] = min(low[node], index[child])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                component = []
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    component.append(member)
                    if member == node:
                        break
                if len(component) > 1:
                    circles.append(sorted(component))
    return circles


def _python_modules(root: Path = ROOT) -> dict:
    """Module name: (whether it is a package's ``__init__``, its source), for every module of PACKAGES."""
    modules = {}
    for package in PACKAGES:
        for path in (root / package).rglob("*.py"):
            parts = path.relative_to(root).with_suffix("").parts
            name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
            modules[name] = (parts[-1] == "__init__", path.read_text())
    return modules


def python_import_graph(modules: dict) -> dict:
    """Module: the modules of ``modules`` (_python_modules) it imports, anywhere in it (inside a function too).
    ``from p import x`` imports p.x if that is a module, else p; the packages that a dotted name passes through
    are not counted (a package's ``__init__`` may import its own modules)."""
    import ast

    def known(name):
        while name and name not in modules:
            name = name.rpartition(".")[0]
        return name

    graph = {}
    for module, (is_package, source) in modules.items():
        package = module if is_package else module.rpartition(".")[0]
        targets = set()
        for node in ast.walk(ast.parse(source, module)):
            if isinstance(node, ast.Import):
                targets.update(known(alias.name) for alias in node.names)
            elif isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:
                    anchor = package.split(".")[:len(package.split(".")) - node.level + 1]
                    base = ".".join(anchor + ([base] if base else []))
                for alias in node.names:
                    full = f"{base}.{alias.name}"
                    targets.add(full if full in modules else known(base))
        graph[module] = targets - {"", module}
    return graph


def test_the_circle_check_sees_imports_in_functions():
    modules = {"p": (True, "from p.a import run\n"), "p.a": (False, "from . import b\n\ndef run():\n    pass\n"),
               "p.b": (False, "def late():\n    from p.a import run\n    return run\n")}
    graph = python_import_graph(modules)
    assert graph == {"p": {"p.a"}, "p.a": {"p.b"}, "p.b": {"p.a"}}
    assert _circles(graph) == [["p.a", "p.b"]]


def test_python_packages_import_each_other_without_circles():
    graph = python_import_graph(_python_modules())
    config = graph["tablegen.tabulation.config"]
    assert {"tablegen.tabulation.shape_config", "tablegen.tabulation.config_error"} <= config
    assert not _circles(graph), f"modules importing each other (directly or through others): {_circles(graph)}"


def _c_text(path: Path) -> str:
    """A C file without its comments and string literals."""
    import re
    return re.sub(r'/\*.*?\*/|//[^\n]*|"(?:\\.|[^"\\\n])*"', " ", path.read_text(), flags=re.S)


def c_include_graph(folders=(NATIVE_SRC, NATIVE_INCLUDE)) -> dict:
    """Header or source of ``folders``: the headers of ``folders`` it includes ("...")."""
    import re
    files = {p.name: p for folder in folders for p in folder.iterdir() if p.suffix in (".c", ".h")}
    return {name: set(re.findall(r'^\s*#\s*include\s+"([^"]+)"', path.read_text(), flags=re.M)) & set(files) - {name}
            for name, path in files.items()}


def c_call_graph(folder: Path = NATIVE_SRC) -> dict:
    """Source of ``folder``: the other sources whose functions it calls (a function defined at file scope, not
    static, is its file's)."""
    import re
    definition = re.compile(r"^([A-Za-z_][\w \t*]*?)\b([A-Za-z_]\w*)\s*\([^;{}]*\)\s*\{", flags=re.M)
    sources = {p.name: _c_text(p) for p in folder.glob("*.c")}
    owner = {}
    for name, text in sources.items():
        for prefix, function in definition.findall(text):
            if not re.search(r"\b(static|RBS_INLINE)\b", prefix):
                owner[function] = name
    return {name: {owner[f] for f in re.findall(r"\b([A-Za-z_]\w*)\s*\(", text) if f in owner} - {name}
            for name, text in sources.items()}


def test_c_sources_include_and_call_each_other_without_circles():
    includes, calls = c_include_graph(), c_call_graph()
    assert "shape_records.c" in calls["loader.c"] and "hdf5_read.c" in calls["shape_records.c"]
    assert not _circles(includes), f"headers including each other: {_circles(includes)}"
    assert not _circles(calls), f"sources calling each other (directly or through others): {_circles(calls)}"
