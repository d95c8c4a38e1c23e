"""integrations/openfoam/spin_memory_figure.py on the runs with and without spin memory that tests/openfoam/cases.py
makes (``kinematic``, ``kinematic_off``; no run of its own): the numbers it plots, the figure, the mode check.

Copyright (C) 2026 the rebound-scatter authors. License: GPL-3.0-or-later
(see integrations/openfoam/LICENSE): these tests import the integration's scripts.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np

from tests.openfoam.test_openfoam import _case, openfoam_build, runs_folder  # noqa: F401 (fixtures)

REPO = Path(__file__).resolve().parents[2]
OPENFOAM_DIR = REPO / "integrations" / "openfoam"
sys.path.insert(0, str(OPENFOAM_DIR))

import spin_memory_figure  # noqa: E402
from compare_rebounds import read_hits  # noqa: E402
from rbs_api import STATUS_REBOUNDED  # noqa: E402


def test_spin_memory_figure_of_the_kinematic_runs(runs_folder, tmp_path):  # noqa: F811
    on, off = _case(runs_folder, "kinematic"), _case(runs_folder, "kinematic_off")
    res = spin_memory_figure.summary(on, off)
    assert (res["with"]["mode"], res["without"]["mode"]) == ("auto", "off")
    for label, case in (("with", on), ("without", off)):
        hits, _ = read_hits(case)
        r = res[label]
        assert r["hits"] == len(hits["time"]) and r["rebounded"] == int(np.sum(hits["status"] == STATUS_REBOUNDED))
        assert len(r["alpha2"]) == len(r["s"]) == r["rebounded"]
        assert np.all((r["alpha2"] >= 0) & (r["alpha2"] <= 180)) and np.all(r["s"] >= 0)
    # without memory no hit spins; with it, a parcel's later hits do, nearly all above the tolerance
    assert res["without"]["spinning"] == 0 and res["without"]["above_tolerance"] == 0
    assert 0.3 < res["with"]["above_tolerance"] <= res["with"]["spinning"] / res["with"]["hits"] < 0.7
    assert 0.1 < res["with"]["spin_ratio_mean"] < 1
    png = tmp_path / "spin.png"
    spin_memory_figure.plot(res, png)
    assert 10_000 < png.stat().st_size < 300_000


def test_runs_swapped_are_one_line_exit_2(runs_folder):  # noqa: F811
    on, off = _case(runs_folder, "kinematic"), _case(runs_folder, "kinematic_off")
    proc = subprocess.run([sys.executable, str(OPENFOAM_DIR / "spin_memory_figure.py"), "--with", str(off),
                           "--without", str(on)], capture_output=True, text=True, cwd=REPO,
                          env={**os.environ, "PYTHONPATH": str(REPO)})
    assert proc.returncode == 2 and proc.stdout == ""
    assert proc.stderr.strip() == f"spin_memory_figure.py: {off} was run with spinRelaxation off, not with spin memory"
