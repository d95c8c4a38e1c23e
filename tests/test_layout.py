"""The source tree's layout: no folder that a contributor's ignore file would hide."""

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
