"""Benchmark of the wall law's calibration (``tablegen calibrate``).

Makes measurements of 15 rows (α1 ∈ {15, 30, 45, 60, 75}° × |V⁻| ∈ {100, 200, 300} m/s, e_n and e_t with their
sd, n = 200 particles a row) from the direct model with a known law (k = 0.15, p = 0.55, q = 0.8; the four
families in equal parts, 4x the fit's particles from other seeds, gaussian noise sd/√n on each mean), writes them
as a CSV and times the 3-parameter fit of ``tablegen calibrate`` on it, from reading the file
(:func:`tablegen.tabulation.calibration.calibrate`, the command's defaults). Prints the wall time, the number of
evaluations of the model, the model's standard errors of a row's means, and the fitted parameters with their
standard errors against the truth.

Run from the repository root::

    python benchmarks/bench_calibrate.py [--particles N] [--json FILE]
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import tempfile
import time
from pathlib import Path

import numba
import numpy as np

from direct_model.simulate import simulate
from direct_model.wall import WallMaterial
from tablegen.tabulation import calibration as cal

ALPHA1 = (15.0, 30.0, 45.0, 60.0, 75.0)
SPEEDS = (100.0, 200.0, 300.0)
TRUE_LAW = WallMaterial(0.15, 0.55, 0.8, name="bench")
N_MEASURED = 200
DATA_SEED = 2024


def measurements_csv(path: Path, particles: int) -> None:
    """The benchmark's 15 rows (module doc) as a CSV of ``tablegen calibrate``."""
    alpha1 = np.tile(ALPHA1, len(SPEEDS))
    speed = np.repeat(SPEEDS, len(ALPHA1))
    mix = cal.DEFAULT_MIX
    counts = [round(4 * particles * w) for w in mix.values()]
    means, variances = cal.model_means(TRUE_LAW, alpha1, speed, list(mix), list(mix.values()), counts,
                                       cal.particle_seeds(DATA_SEED, len(alpha1), len(mix)), {})
    means = cal.in_form(cal.COEFFICIENTS, alpha1, means)
    sd = np.sqrt(cal.in_form(cal.COEFFICIENTS, alpha1, variances, True) * 4 * particles)
    noisy = means + np.random.default_rng(DATA_SEED).standard_normal(means.shape) * sd / np.sqrt(N_MEASURED)
    rows = [f"{a:g},{v:g},{m[0]:.6f},{m[1]:.6f},{s[0]:.6f},{s[1]:.6f},{N_MEASURED}"
            for a, v, m, s in zip(alpha1, speed, noisy, sd)]
    path.write_text("alpha1_deg,speed_m_s,e_n,e_t,e_n_sd,e_t_sd,n\n" + "\n".join(rows) + "\n")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--particles", type=int, default=cal.DEFAULT_PARTICLES,
                        help="model particles per row of the fit (default: tablegen calibrate's, %(default)s)")
    parser.add_argument("--json", metavar="FILE", help="also write the figures as JSON")
    args = parser.parse_args(argv)
    print(f"machine: {platform.platform()}, {os.cpu_count()} cores, numba {numba.__version__} "
          f"({numba.get_num_threads()} threads)")
    start = time.perf_counter()
    simulate("prism", 45.0, 200.0, 10, seed=1)
    print(f"model kernels loaded in {time.perf_counter() - start:.1f} s (from numba's cache, or compiled)")
    with tempfile.TemporaryDirectory() as tmp:
        data = Path(tmp) / "measurements.csv"
        measurements_csv(data, args.particles)
        start = time.perf_counter()
        fit = cal.calibrate(cal.read_measurements(data), particles=args.particles)
        seconds = time.perf_counter() - start
    figures = {"rows": 15, "free_parameters": 3, "particles_per_row": args.particles, "seconds": seconds,
               "evaluations": fit.evaluations, "chi2_dof": fit.chi2_dof,
               "model_se_median": dict(zip(cal.COEFFICIENTS, np.median(fit.fitted_se, axis=0).round(5).tolist())),
               "model_se_max": dict(zip(cal.COEFFICIENTS, fit.fitted_se.max(axis=0).round(5).tolist())),
               "fit": {name: {"value": fit.values[name], "standard_error": fit.standard_error[name],
                              "true": TRUE_LAW.parameters()[name]} for name in fit.free}}
    print(f"tablegen calibrate, 15 rows x 3 parameters, {args.particles} particles per row: {seconds:.1f} s wall, "
          f"{fit.evaluations} evaluations of the model ({seconds / fit.evaluations:.2f} s each); target: <= 120 s")
    print(f"model standard error of a row's mean: median e_n {figures['model_se_median']['e_n']}, "
          f"e_t {figures['model_se_median']['e_t']}; largest e_n {figures['model_se_max']['e_n']}, "
          f"e_t {figures['model_se_max']['e_t']}")
    for name, v in figures["fit"].items():
        print(f"  {name} = {v['value']:.4f} +- {v['standard_error']:.4f} (true {v['true']})")
    print(f"  chi2/dof = {fit.chi2_dof:.3g}")
    if args.json:
        Path(args.json).write_text(json.dumps(figures, indent=2))
        print(f"figures written to {args.json}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
