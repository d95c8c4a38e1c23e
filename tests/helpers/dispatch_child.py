"""Run in a subprocess by test_native_dispatch.py, under one setting of numpy's, OpenBLAS's and numba's
CPU dispatch: load a table, derive its kernel arrays and draw, and save everything to an .npz file.

    python -m tests.helpers.dispatch_child TABLE.h5 INPUT.npz OUTPUT.npz      (from the repository's root)

INPUT holds V, n, a (incident states) and u (uniforms); OUTPUT the derived arrays (``array_<name>``),
the mix CDFs, table_rebound_many's draws for both interpolations, sample_global's and sample_local's draws for
a fixed seed (the latter also as the velocities `surrogate sample` writes).
"""

from __future__ import annotations

import sys

import numpy as np

from tests.helpers import python_side as py

KERNEL_ARRAYS = ("alpha1_axis", "speed_axis", "cells", "clusters", "dictionary", "speed_restitution",
                 "restitution_pieces", "work_rows", "work_dictionary", "work_cells")
WEIGHTS = {"ellipsoid": 0.1, "prism": 0.2, "cut_prism": 0.3, "tetrahedron": 0.4}


def main(table_path: str, input_path: str, output_path: str) -> None:
    table = py.load(table_path)
    data = table.kernel_data
    given = np.load(input_path)
    V, n, a, u = given["V"], given["n"], given["a"], given["u"]
    out = {f"array_{name}": np.asarray(getattr(data, name)) for name in KERNEL_ARRAYS}
    out["cdf_mix"], out["cdf_weighted"] = py.mix_cdf(table, "mix"), py.mix_cdf(table, WEIGHTS)
    for label, scaled in (("scaled", True), ("stochastic", False)):
        V_out, W_out, status = np.empty_like(V), np.empty_like(V), np.empty(len(V), dtype=np.int8)
        py.table_rebound_many(data, out["cdf_weighted"], V, n, a, u, V_out, W_out, status, scaled)
        out[f"many_{label}"] = np.column_stack([V_out, W_out, status])
    # the rows sample_global takes: valid, not the tiny (~1e-13 m/s) or huge speeds it refuses (thresholds far from
    # every speed drawn, so that no process's rounding moves a row across it)
    speed = np.linalg.norm(V, axis=1)
    valid = (status != py.STATUS_INVALID) & (speed > 1e-6) & (speed < 1e6)
    hits = py.surrogate.sample_global(table, V[valid], n[valid], a[valid], shape=WEIGHTS,
                                      random_state=5, clamp=True, method="table")
    V_g, W_g, status_g = hits.V, hits.Omega, hits.status
    out["global"] = np.column_stack([V_g, W_g, status_g])
    local = py.surrogate.sample_local(table, np.full(5000, 45.0), np.linspace(60.0, 240.0, 5000), "mix",
                                      random_state=6)
    velocity = py.angles_to_velocity(local.alpha2, local.beta2, 120.0 * local.speed_ratio)   # surrogate sample's
    out["local"] = np.column_stack([local.alpha2, local.beta2, local.speed_ratio, local.omega, local.status, velocity])
    np.savez(output_path, **out)


if __name__ == "__main__":
    main(*sys.argv[1:4])
