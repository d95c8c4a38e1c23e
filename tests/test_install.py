"""The plain install is the runtime alone: a fresh virtual environment with ``pip install .`` draws from a table,
the same draws as the development install, without the build extra."""

import json
import re
import shutil
import subprocess
import tomllib
import venv
from pathlib import Path

import numpy as np

import surrogate
from tablegen import BUILD_EXTRA

ROOT = Path(__file__).resolve().parents[1]
PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text())
RUNTIME_ONLY = ("scipy", "sklearn", "threadpoolctl", "tqdm", "matplotlib", "dask")     # modules it must not bring

DRAW = """
import importlib.util, json, sys
import numpy as np
import surrogate
table = surrogate.load(sys.argv[1])
V = np.tile([120.0, -80.0, 10.0], (200, 1))
V_out, Omega_out, status = surrogate.sample_global(table, V, [0.0, 1.0, 0.0], 5e-5, shape="mix", random_state=7)
missing = [m for m in sys.argv[2:] if importlib.util.find_spec(m) is None]
try:
    import tablegen
    refused = ""
except ImportError as error:
    refused = str(error)
print(json.dumps({"V": V_out.tolist(), "Omega": Omega_out.tolist(), "status": status.tolist(), "missing": missing,
                  "refused": refused, "where": surrogate.__file__}))
"""


def _requirement_name(requirement: str) -> str:
    return re.split(r"[\[<>=!~; ]", requirement, maxsplit=1)[0]


def test_build_extra_is_what_tablegen_checks():
    assert sorted(BUILD_EXTRA.values()) == sorted(map(_requirement_name, PYPROJECT["project"]["optional-dependencies"]
                                                      ["build"]))


def test_plain_install_draws_from_a_table(tmp_path, small_table_path):
    source = tmp_path / "checkout"
    ignore = shutil.ignore_patterns("__pycache__", "*.nbi", "*.nbc", "*.egg-info")
    for package in (pattern.rstrip("*") for pattern in PYPROJECT["tool"]["setuptools"]["packages"]["find"]["include"]):
        shutil.copytree(ROOT / package, source / package, ignore=ignore)
    for name in ("pyproject.toml", "README.md"):
        shutil.copy(ROOT / name, source / name)
    env = tmp_path / "venv"
    venv.create(env, with_pip=True)
    python = env / "bin" / "python"
    install = subprocess.run([python, "-m", "pip", "install", "--quiet", str(source)], capture_output=True, text=True)
    assert install.returncode == 0, install.stderr
    run = subprocess.run([python, "-c", DRAW, str(small_table_path), *RUNTIME_ONLY], capture_output=True, text=True,
                         cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    fresh = json.loads(run.stdout)
    assert Path(fresh["where"]).is_relative_to(env), "surrogate did not come from the fresh install"
    assert fresh["missing"] == list(RUNTIME_ONLY), "the plain install brought more than the runtime"
    assert 'pip install "rebound-scatter[build]"' in fresh["refused"]
    table = surrogate.load(small_table_path)
    V = np.tile([120.0, -80.0, 10.0], (200, 1))
    V_out, Omega_out, status = surrogate.sample_global(table, V, [0.0, 1.0, 0.0], 5e-5, shape="mix", random_state=7)
    assert (status == 0).sum() > 150
    np.testing.assert_array_equal(np.array(fresh["status"]), status)
    np.testing.assert_array_equal(np.array(fresh["V"], dtype=float), V_out)
    np.testing.assert_array_equal(np.array(fresh["Omega"], dtype=float), Omega_out)
