"""Environments that force numpy, OpenBLAS and numba onto other SIMD code paths, for subprocesses.

numpy and OpenBLAS pick their kernels per CPU when they load (AVX-512, AVX2, baseline SSE), and numba
compiles for the host CPU; an AVX-512 kernel may sum or round in another order than an AVX2 one. A
test runs the same work under :func:`environment` for each of :data:`CASES` and compares the bits,
which proves on one machine what would otherwise need an AVX2 and an AVX-512 machine side by side.
The subprocesses of the two tests that do so run here (:func:`child_runs`, :func:`forced_rebuilds`),
started by tests/conftest.py when the session starts (tests.helpers.background).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys

import numpy as np

from tests.helpers import REPO, background
from tests.helpers.states import incident_states, uniforms

CASES = ("default", "no AVX-512", "baseline")
REBUILD_CASES = CASES[1:]     # the table build again under these (tests/tabulation/test_build_dispatch.py)

# printed by a subprocess: the code paths it runs (numpy's dispatch targets in use, OpenBLAS's core, numba's CPU)
_PATHS = """
import json, numba
try:
    from numpy._core._multiarray_umath import __cpu_dispatch__, __cpu_features__
except ImportError:      # numpy 1.x
    from numpy.core._multiarray_umath import __cpu_dispatch__, __cpu_features__
import numpy.linalg      # loads OpenBLAS
from threadpoolctl import threadpool_info
blas = sorted({i.get("architecture") for i in threadpool_info() if i.get("internal_api") == "openblas"})
print(json.dumps({"numpy": [f for f in __cpu_dispatch__ if __cpu_features__.get(f)], "openblas": blas,
                  "numba": numba.config.CPU_NAME or "host"}))
"""


def _dispatched_targets(avx512_only: bool) -> list:
    """numpy's dispatch targets that this CPU has (those NPY_DISABLE_CPU_FEATURES may switch off)."""
    try:
        from numpy._core._multiarray_umath import __cpu_dispatch__, __cpu_features__
    except ImportError:      # numpy 1.x
        from numpy.core._multiarray_umath import __cpu_dispatch__, __cpu_features__
    have = [f for f in __cpu_dispatch__ if __cpu_features__.get(f)]
    return [f for f in have if "512" in f or f == "X86_V4"] if avx512_only else have


def environment(case: str, generic_numba: bool = True) -> dict:
    """The process environment of ``case``: "default" (as inherited), "no AVX-512" (numpy without its
    AVX-512 targets, OpenBLAS's Haswell kernels) or "baseline" (numpy without any dispatch target,
    OpenBLAS's Prescott kernels and, with ``generic_numba``, numba compiling for a generic x86-64: no FMA,
    AVX or AVX-512 instruction)."""
    env = dict(os.environ)
    env.pop("LD_PRELOAD", None)
    env.pop("NPY_DISABLE_CPU_FEATURES", None)
    if case == "no AVX-512":
        env["NPY_DISABLE_CPU_FEATURES"] = " ".join(_dispatched_targets(avx512_only=True))
        env["OPENBLAS_CORETYPE"] = "Haswell"
    elif case == "baseline":
        env["NPY_DISABLE_CPU_FEATURES"] = " ".join(_dispatched_targets(avx512_only=False))
        env["OPENBLAS_CORETYPE"] = "Prescott"
        if generic_numba:
            env["NUMBA_CPU_NAME"] = "generic"
    elif case != "default":
        raise ValueError(f"unknown case {case!r}; one of {CASES}")
    return env


def code_paths(env: dict) -> dict:
    """The code paths a process started with ``env`` runs: {"numpy": [...], "openblas": [...], "numba": ...}."""
    done = subprocess.run([sys.executable, "-c", _PATHS], env=env, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    return json.loads(done.stdout)


CHILD_STATES = 20_000


def child_runs(table_path, folder) -> tuple:
    """tests/native/test_native_dispatch.py's runs: (the input, {case: output}) of tests/helpers/dispatch_child.py on
    ``table_path`` for each of :data:`CASES`, on CHILD_STATES random incident states and their uniforms; each
    output also holds the case's code paths under "paths"."""
    rng = np.random.default_rng(2024)
    V, n, a = incident_states(rng, CHILD_STATES, (0.0, 90.0), (10.0, 375.0))
    given = {"V": V, "n": n, "a": a, "u": uniforms(rng, CHILD_STATES)}
    np.savez(folder / "input.npz", **given)
    runs = {}
    # baseline first: its kernels are compiled for another CPU anyway, and by the time the other two run, the
    # test process has put their host kernels in numba's cache
    for case in reversed(CASES):
        output = folder / f"{case.replace(' ', '_')}.npz"
        child = [sys.executable, "-m", "tests.helpers.dispatch_child", str(table_path), str(folder / "input.npz"),
                 str(output)]
        done = background.run(child, cwd=REPO, env=environment(case), timeout=900)
        assert done.returncode == 0, f"{case}: {done.stderr[-3000:]}"
        with np.load(output) as saved:
            runs[case] = {k: saved[k] for k in saved.files}
        runs[case]["paths"] = code_paths(environment(case))
    return given, runs


def forced_rebuilds(config_text, folder) -> dict:
    """tests/tabulation/test_build_dispatch.py's runs: ``tablegen build`` of ``config_text`` under each forced
    case of REBUILD_CASES (numba keeps the host CPU); per case (its code paths, the default ones, the finished
    process or None where the case runs this CPU's default kernels, the table's path)."""
    default = code_paths(environment("default"))
    config = folder / "table.toml"
    config.write_text(config_text)
    runs = {}
    for case in REBUILD_CASES:
        env = environment(case, generic_numba=False)
        paths, rebuilt = code_paths(env), folder / f"rebuilt {case}.h5"
        done = None if paths == default else background.run(
            [sys.executable, "-m", "tablegen.cli", "build", "--config", str(config), "-o", str(rebuilt)], env=env,
            timeout=1200)
        runs[case] = paths, default, done, rebuilt
    return runs
