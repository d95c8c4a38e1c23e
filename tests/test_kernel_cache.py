"""numba's on-disk cache follows the sources (data_schema.kernel_cache): an edit to a kernel's callee in another
file gives freshly compiled code at the next import, for the project's kernels and for a user's cached kernel that
calls them; an unchanged tree loads the cached code; every cached kernel of the project is keyed that way."""

import importlib
import os
import pkgutil
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from numba.core.registry import CPUDispatcher

from data_schema import kernel_cache

ROOT = Path(__file__).resolve().parents[1]

# a user's cached kernel outside the project that calls one of its kernels
USER_KERNEL = """
import numba
from direct_model.collision import collide

@numba.njit(cache=True)
def users_collision(V, W, r, Kinv, wall, dV, dW):
    return collide(V, W, r, Kinv, wall, dV, dW)
"""
# one collision each way (direct_model.collision.collide calls direct_model.wall.restitution, in another file)
CALLER = """
import numpy as np
import direct_model.collision as collision
from direct_model.wall import CORUNDUM_ON_STEEL
from users_solver import users_collision
assert collision.__file__.startswith({root!r}), collision.__file__
args = np.array([120.0, -80.0, 10.0]), np.zeros(3), np.array([0.1, -0.9, 0.2]), np.eye(3) * 5.0
for kernel in (collision.collide, users_collision):
    dV, dW = np.empty(3), np.empty(3)
    kernel(*args, CORUNDUM_ON_STEEL.as_array(), dV, dW)
    print(dV.tobytes().hex(), sum(kernel.stats.cache_hits.values()))
"""


def _run(copy: Path, env: dict) -> list:
    """[(ΔV's bytes, cache hits)] of one collision by the project's kernel and by the user's, in a new interpreter
    that imports the packages from ``copy``."""
    done = subprocess.run([sys.executable, "-c", CALLER.format(root=str(copy))], cwd=copy / "user", env=env,
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    return [(bits, int(hits)) for bits, hits in (line.split() for line in done.stdout.splitlines())]


@pytest.mark.parametrize("where", ["beside the sources", "NUMBA_CACHE_DIR"])
def test_an_edited_callee_is_compiled_again(tmp_path, where):
    copy = tmp_path / "tree"
    for package in ("data_schema", "direct_model"):
        shutil.copytree(ROOT / package, copy / package, ignore=shutil.ignore_patterns("__pycache__"))
    env = {k: v for k, v in os.environ.items() if not k.startswith("NUMBA_")}
    (copy / "user").mkdir()
    (copy / "user" / "users_solver.py").write_text(USER_KERNEL)
    env["PYTHONPATH"] = os.pathsep.join([str(copy), str(copy / "user")])
    if where == "NUMBA_CACHE_DIR":
        env["NUMBA_CACHE_DIR"] = str(tmp_path / "numba_cache")

    first = _run(copy, env)
    assert [hits for _, hits in first] == [0, 0] and first[0][0] == first[1][0]
    again = _run(copy, env)
    assert again == [(bits, 1) for bits, _ in first], "an unchanged tree loads the cached code"

    wall = copy / "direct_model" / "wall.py"
    source = wall.read_text()
    assert source.count("contact_speed ** wall[W_P]") == 1
    wall.write_text(source.replace("contact_speed ** wall[W_P]", "contact_speed ** (1.01 * wall[W_P])"))
    edited = _run(copy, env)
    assert [hits for _, hits in edited] == [0, 0], "both callers compiled again with the edited callee"
    assert edited[0][0] == edited[1][0] != first[0][0]

    wall.write_text(source)
    assert [bits for bits, _ in _run(copy, env)] == [bits for bits, _ in first]


def test_every_cached_kernel_is_keyed_by_its_sources():
    """Every ``cache=True`` kernel of the project's packages, whatever module it stands in."""
    for package in kernel_cache.PACKAGES:
        for info in pkgutil.walk_packages(importlib.import_module(package).__path__, package + "."):
            importlib.import_module(info.name)
    kinds = {}
    for name, module in list(sys.modules.items()):
        if name.split(".")[0] in kernel_cache.PACKAGES:
            for value in vars(module).values():
                if isinstance(value, CPUDispatcher) and value.__module__ == name and value._cache is not None:
                    locator = getattr(getattr(value._cache, "_impl", None), "locator", None)
                    if locator is not None:
                        kinds[f"{name}.{value.__name__}"] = type(locator).__name__
    assert len(kinds) > 100
    assert {k: v for k, v in kinds.items() if not v.startswith("Keyed")} == {}


def test_the_closure_follows_imports_through_modules():
    """The caller's stamp covers the callee's file and the constants' file two imports away; not unrelated ones."""
    closure = {kernel_cache._module_name(p) for p in kernel_cache.source_closure(ROOT / "direct_model" / "body_rebound.py")}
    assert {"direct_model.body_rebound", "direct_model.collision", "direct_model.wall", "direct_model.flight",
            "direct_model.rotation", "data_schema.samples"} <= closure
    assert not any(name.startswith(("surrogate", "tablegen")) for name in closure)
