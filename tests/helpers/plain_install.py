"""tests/test_install.py's run: the packages copied from this checkout, ``pip install .`` into a fresh virtual
environment (no extra), and a draw there from a table; started by tests/conftest.py with the session
(tests.helpers.background)."""

from __future__ import annotations

import shutil
import sys
import tomllib

from tests.helpers import REPO, background

PYPROJECT = tomllib.loads((REPO / "pyproject.toml").read_text())
RUNTIME_ONLY = ("scipy", "sklearn", "threadpoolctl", "tqdm", "matplotlib", "dask")     # modules it must not bring

# the runtime's two halves, each run: the table's draws and the direct model's on spinning particles (not
# sample_global, which compiles both halves into one kernel and, without spin, runs the table's alone)
DRAW = """
import importlib.util, json, sys
import numpy as np
import surrogate
table = surrogate.load(sys.argv[1])
local = surrogate.sample_local(table, np.full(200, 33.7), np.full(200, 144.6), "mix", random_state=7)
hits = surrogate.sample_direct(table, np.tile([120.0, -80.0, 10.0], (50, 1)), [0.0, 1.0, 0.0],
                               5e-5, "prism", random_state=7, omega=[0.0, 0.0, 2e5])
V_out, Omega_out, status = hits.V, hits.Omega, hits.status
missing = [m for m in sys.argv[2:] if importlib.util.find_spec(m) is None]
try:
    import tablegen
    refused = ""
except ImportError as error:
    refused = str(error)
print(json.dumps({"local": np.column_stack([local.alpha2, local.beta2, local.speed_ratio, local.omega,
                                           local.status]).tolist(),
                  "V": V_out.tolist(), "Omega": Omega_out.tolist(), "status": status.tolist(), "missing": missing,
                  "refused": refused, "where": surrogate.__file__}))
"""


def install_and_draw(table_path, folder) -> tuple:
    """(pip's finished process, DRAW's finished process or None if pip failed, the environment's folder)."""
    source = folder / "checkout"
    ignore = shutil.ignore_patterns("__pycache__", "*.nbi", "*.nbc", "*.egg-info")
    for package in (pattern.rstrip("*") for pattern in PYPROJECT["tool"]["setuptools"]["packages"]["find"]["include"]):
        shutil.copytree(REPO / package, source / package, ignore=ignore)
    for name in ("pyproject.toml", "README.md"):
        shutil.copy(REPO / name, source / name)
    env = folder / "venv"
    made = background.run([sys.executable, "-m", "venv", str(env)])
    if made.returncode != 0:
        return made, None, env
    python = env / "bin" / "python"
    install = background.run([python, "-m", "pip", "install", "--quiet", str(source)])
    if install.returncode != 0:
        return install, None, env
    return install, background.run([python, "-c", DRAW, str(table_path), *RUNTIME_ONLY], cwd=folder), env
