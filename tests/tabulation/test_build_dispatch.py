"""A table built from a seed has the same bits whichever SIMD kernels numpy picks.

The session's small table (built in this process, numpy's default kernels for this CPU) is built
again by ``tablegen build`` in a subprocess with numpy's dispatch targets switched off
(tests.helpers.cpu_dispatch.baseline_rebuild, started with the session): every dataset of the two
files must be equal byte for byte. OpenBLAS keeps its kernels: scikit-learn's k-means computes
distances through it, and its partition still depends on them (docs/format.md, table minor version
3.2). numba keeps the host CPU here (a generic-CPU compile of the direct model would take minutes);
tests/native/test_native_dispatch.py covers numba's kernels on a generic CPU.
"""

from __future__ import annotations

import h5py
import numpy as np


def _datasets(path) -> dict:
    found = {}
    with h5py.File(path, "r") as f:
        f.visititems(lambda name, node: found.__setitem__(name, node[()]) if isinstance(node, h5py.Dataset) else None)
    return found


def _bytes(values) -> bytes:
    values = np.asarray(values)
    return repr(values.tolist()).encode() if values.dtype.kind in "OSU" else np.ascontiguousarray(values).tobytes()


def test_table_bits_do_not_depend_on_numpy_kernels(small_table_path, numpy_baseline_rebuild):
    paths, default, done, rebuilt = numpy_baseline_rebuild.result()     # started with the session
    assert paths["numpy"] == [] and default["numpy"] != [], (paths, default)
    assert done.returncode == 0, done.stderr[-3000:]
    expected, got = _datasets(small_table_path), _datasets(rebuilt)
    assert sorted(got) == sorted(expected)
    differ = [name for name in expected if _bytes(got[name]) != _bytes(expected[name])]
    assert differ == [], f"datasets that differ with numpy's baseline kernels: {differ}"
