"""The runtime's kernels compiled ahead of the first draw: :func:`compile_kernels` (``surrogate compile``).

numba compiles a kernel at its first call and keeps the machine code in its cache (``__pycache__`` beside the
sources, or ``NUMBA_CACHE_DIR``), for this CPU: the first call of a fresh install waits for the compilation, later
processes load the code. Compiling once after installing (in a container's build, before a solver's first run on
many ranks) means that no run waits for it. The compiled code
depends on the argument types only, not on the table's contents, so any table compiles them all.
"""

from __future__ import annotations

import time

import numpy as np
from numba.core import event

from surrogate import kernels
from surrogate.sampling import sample_direct, sample_global, sample_local
from surrogate.table import SurrogateTable
from surrogate.validation import mix_cdf

ROWS = 4        # particles per call: the calls only need to run
# what compile_kernels calls, in this order: the NumPy API's draws and the numba kernels a solver's code calls
# (for a single-hit kernel, the typed function its own code then links), ...
TABLE_KERNELS = ("sample_global", "sample_local", "table_rebound", "draw_local", "table_rebound_many",
                 "table_rebound_many_rng", "table_rebound_parallel", "table_rebound_parallel_rng",
                 "draw_local_parallel")
# ... and, with a table of a shape the direct model answers, the direct model's and the rough wall's (its re-hits
# take the direct model)
DIRECT_KERNELS = ("sample_direct", "rebound", "direct_rebound", "sample_global_rough", "rebound_rough")


def _calls(table: SurrogateTable) -> list:
    """(name, call) for each of TABLE_KERNELS, then of DIRECT_KERNELS where ``table`` lets the model answer."""
    data, cdf = table.kernel_data, mix_cdf(table, "mix")
    V = np.tile([60.0, -80.0, 0.0], (ROWS, 1))
    n, a = np.tile([0.0, 1.0, 0.0], (ROWS, 1)), np.full(ROWS, 1e-4)
    u = np.full((ROWS, kernels.U_PER_DRAW), 0.5)
    outputs = np.empty((ROWS, 3)), np.empty((ROWS, 3)), np.empty(ROWS, dtype=np.int8)
    local, status = np.empty((ROWS, 6)), np.empty(ROWS, dtype=np.int8)
    alpha1, speed = np.full(ROWS, 45.0), np.full(ROWS, 100.0)
    # the direct model's kernels need a shape it answers
    answerable = [k for k in range(len(table.shapes)) if table.model_shapes[k] >= 0]
    direct = bool(answerable)
    shape = table.shapes[answerable[0]] if direct and len(answerable) < len(table.shapes) else "mix"
    # half the particles spinning: method auto takes both paths
    omega = np.where(np.arange(ROWS)[:, None] < ROWS // 2, 0.0, 1e4) * np.array([0.0, 0.0, 1.0]) if direct else None
    calls = [
        ("sample_global", lambda: sample_global(table, V, n, a, shape, 0, omega=omega)),
        ("sample_local", lambda: sample_local(table, alpha1, speed, "mix", 0)),
        ("table_rebound", lambda: kernels.table_rebound(data, cdf, V[0], n[0], a[0], u[0])),
        ("draw_local", lambda: kernels.draw_local(data, cdf, alpha1[0], speed[0], u[0])),
        ("table_rebound_many", lambda: kernels.table_rebound_many(data, cdf, V, n, a, u, *outputs)),
        ("table_rebound_many_rng",
         lambda: kernels.table_rebound_many_rng(data, cdf, V, n, a, kernels.seed_state(0), *outputs)),
        ("table_rebound_parallel", lambda: kernels.table_rebound_parallel(data, cdf, V, n, a, u, *outputs)),
        ("table_rebound_parallel_rng", lambda: kernels.table_rebound_parallel_rng(
            data, cdf, V, n, a, kernels.chunk_states(np.random.default_rng(0), ROWS), *outputs)),
        ("draw_local_parallel", lambda: kernels.draw_local_parallel(data, cdf, alpha1, speed, u, local, status)),
    ]
    if direct:
        params, shapes = table.direct_parameters, table.shape_arrays
        code = int(table.model_shapes[answerable[0]])
        calls += [
            ("sample_direct", lambda: sample_direct(table, V, n, a, shape, 0, omega=omega)),
            ("rebound", lambda: kernels.rebound(data, params, shapes, table.model_shapes, cdf, V[0], omega[-1], n[0],
                                                a[0], u[0], kernels.METHOD_AUTO)),
            ("direct_rebound", lambda: kernels.direct_rebound(params, shapes, code, V[0], omega[-1], n[0], a[0],
                                                              u[0, :kernels.U_PER_REBOUND])),
            ("sample_global_rough", lambda: sample_global(table, V, n, a, shape, 0, omega=omega, roughness_deg=5.0)),
            ("rebound_rough", lambda: kernels.rebound(data, params, shapes, table.model_shapes, cdf, V[0], omega[-1],
                                                      n[0], a[0], u[0], kernels.METHOD_AUTO, True, None, 5.0)),
        ]
    return calls


class _Counter(event.Listener):
    """Counts numba's compilations (a function loaded from the cache is none)."""

    def __init__(self):
        self.count = 0

    def on_start(self, ev):
        self.count += 1

    def on_end(self, ev):
        pass


def compile_kernels(table: SurrogateTable, report=None) -> list:
    """Call every kernel of the runtime once, on a few particles of ``table`` (:func:`surrogate.load`), so that
    numba compiles each into its cache, or finds it there: :data:`TABLE_KERNELS`, then :data:`DIRECT_KERNELS` if
    the table holds a shape the direct model answers. ``report(name, seconds, compiled)`` is
    called after each. Returns [(name, seconds, compiled)] in the order run, ``compiled`` the number of functions
    numba compiled for that call: 0 where all came from the cache (or had been compiled in this process)."""
    done = []
    for name, call in _calls(table):
        counter = _Counter()
        start = time.perf_counter()
        with event.install_listener("numba:compile", counter):
            call()
        done.append((name, time.perf_counter() - start, counter.count))
        if report is not None:
            report(*done[-1])
    return done
