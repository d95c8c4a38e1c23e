"""A table built from a seed has the same bits whichever SIMD kernels numpy, OpenBLAS and numba use.

The session's tabulated table (four cells of the prism with a tabulated wall law, built in this process with the
kernels numpy, OpenBLAS and numba pick for this CPU) is built again by ``tablegen build`` in a subprocess under
each forced case of tests/helpers/cpu_dispatch.py
(tests.helpers.cpu_dispatch.forced_rebuilds, started with the session):
numpy without its AVX-512 targets and OpenBLAS's Haswell kernels, then numpy without any dispatch target and
OpenBLAS's Prescott kernels. Every dataset of the files must be equal byte for byte. numba keeps the host CPU
for the whole build (a generic-CPU compile of the direct model takes minutes; tests/native/test_native_dispatch.py
covers the direct model's kernels on a generic CPU); the representation's own kernels (the k-means, the fits)
are run on a generic x86-64 CPU by the last test.
"""

from __future__ import annotations

import hashlib
import subprocess
import sys

import h5py
import numpy as np
import pytest

from data_schema.table import TableResolution, table_fingerprint
from tests.helpers.cpu_dispatch import REBUILD_CASES, code_paths, environment

# hashes the arrays of tablegen.tabulation.tabulate.represent for the states saved in argv[1]
_REPRESENT = """
import hashlib, sys
import numpy as np
from data_schema.table import TableResolution
from tablegen.tabulation.tabulate import represent
saved = np.load(sys.argv[1])
cell = represent(saved["folded"], saved["regime"], TableResolution(200, 16, 24), 20261121, saved["work"])
print(hashlib.sha256(b"".join(np.ascontiguousarray(cell[k]).tobytes() for k in sorted(cell))).hexdigest())
"""


def _datasets(path) -> dict:
    found = {}
    with h5py.File(path, "r") as f:
        f.visititems(lambda name, node: found.__setitem__(name, node[()]) if isinstance(node, h5py.Dataset) else None)
    return found


def _bytes(values) -> bytes:
    values = np.asarray(values)
    return repr(values.tolist()).encode() if values.dtype.kind in "OSU" else np.ascontiguousarray(values).tobytes()


@pytest.mark.parametrize("case", REBUILD_CASES)
def test_table_bits_do_not_depend_on_numpy_or_openblas_kernels(case, tabulated_table_path, forced_rebuilds):
    paths, default, done, rebuilt = forced_rebuilds.result()[case]      # started with the session
    if case == "baseline":
        assert paths["numpy"] == [] and paths["openblas"] != default["openblas"], (paths, default)
    elif done is None:      # a CPU without AVX-512 runs this case on its default kernels: nothing to compare
        pytest.skip(f"the {case} kernels are this CPU's default ones ({paths})")
    assert done.returncode == 0, done.stderr[-3000:]
    expected, got = _datasets(tabulated_table_path), _datasets(rebuilt)
    assert sorted(got) == sorted(expected)
    differ = [name for name in expected if _bytes(got[name]) != _bytes(expected[name])]
    assert differ == [], f"datasets that differ with {case} kernels ({paths}): {differ}"
    assert table_fingerprint(rebuilt) == table_fingerprint(tabulated_table_path)


def test_representation_bits_do_not_depend_on_numbas_target(tmp_path):
    """represent (k-means, quantiles, least squares) of one cell's worth of states, in this process and in a
    subprocess with numba compiling for a generic x86-64 (no AVX, no FMA), numpy's baseline kernels and
    OpenBLAS's Prescott ones: the same bytes."""
    from tablegen.tabulation.tabulate import represent

    rng = np.random.default_rng(5)
    folded = np.abs(rng.standard_normal((20_000, 6))) * np.array([1.0, 0.5, 0.3, 2.0, 2.0, 2.0])
    regime = (rng.random(20_000) < 0.2).astype(np.uint8)
    work = np.column_stack([0.1 * folded[:, 2] ** 2 * rng.random(20_000), rng.random(20_000)])   # r, φ
    states = tmp_path / "states.npz"
    np.savez(states, folded=folded, regime=regime, work=work)
    cell = represent(folded, regime, TableResolution(200, 16, 24), 20261121, work)
    here = hashlib.sha256(b"".join(np.ascontiguousarray(cell[k]).tobytes() for k in sorted(cell))).hexdigest()
    env = environment("baseline", generic_numba=True)
    assert code_paths(env)["numba"] == "generic"
    done = subprocess.run([sys.executable, "-c", _REPRESENT, str(states)], env=env, capture_output=True, text=True,
                          timeout=3600)
    assert done.returncode == 0, done.stderr[-3000:]
    assert done.stdout.strip() == here
