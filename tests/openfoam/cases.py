"""The OpenFOAM runs that tests/openfoam/test_openfoam.py checks, made by one process beside the tests.

``python -m tests.openfoam.cases FOLDER`` (tests/conftest.py starts it with the session; it runs after the adapter's
build on the same worker) builds the tables of the runs into FOLDER (:data:`TABLES`), runs every case of
:data:`CASES` there with the hopperRebound case's Allrun, and writes FOLDER/runs.json: per case its folder, Allrun's
exit status and the end of its output. A run that fails does not stop the others: the test that reads it fails,
with that output (:func:`read_runs`).

Copyright (C) 2026 the rebound-scatter authors. License: GPL-3.0-or-later
(see integrations/openfoam/LICENSE): it runs the integration's case and imports its scripts.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
OPENFOAM_DIR = REPO / "integrations" / "openfoam"
CASE = OPENFOAM_DIR / "cases" / "hopperRebound"
RUNS_FILE = "runs.json"

sys.path.insert(0, str(OPENFOAM_DIR))

import make_case_table  # noqa: E402
from rbs_api import build_table_from_text  # noqa: E402

# The case's grid with n_max = 2: a particle that would touch the wall a third time counts as trapped,
# so a good part of the near-normal hits are trapped and both trapped policies can be seen at work.
# A coarse grid is enough: both sides of the comparison draw from the same table.
TRAPPING_TABLE_CONFIG = """\
[grid]
alpha1_deg = [1.0, 7.5, 30.0, 60.0, 90.0]
speed_m_s = [50.0, 150.0]
shapes = ["prism"]
[simulation]
particles_per_cell = 5000
seed = 20261124
n_max = 2
"""

# the tables of the runs, by name: file name in FOLDER
TABLES = {"case": "rebound_table.h5", "trapping": "rebound_table_nmax2.h5", "many_shapes": "many_shapes.h5"}


def set_coeff(case: Path, key: str, value: str) -> None:
    """Set ``key`` of stochasticReboundCoeffs to ``value``."""
    props = case / "constant" / "kinematicCloudProperties"
    text, n = re.subn(rf"(\n        {key}\s+)[^;]+;", rf"\g<1>{value};", props.read_text(), count=1)
    assert n == 1, key
    props.write_text(text)


def insert_coeff(case: Path, entry: str) -> None:
    """Add ``entry`` to stochasticReboundCoeffs, after its table."""
    props = case / "constant" / "kinematicCloudProperties"
    text, n = re.subn(r"(\n        table\s+[^;]+;)", rf"\g<1>\n        {entry}", props.read_text(), count=1)
    assert n == 1
    props.write_text(text)


def copy_case(folder: Path) -> Path:
    """hopperRebound copied into ``folder`` (made), without the outputs of an earlier run."""
    case = folder / "hopperRebound"
    shutil.copytree(CASE, case, ignore=shutil.ignore_patterns("log.*", "processor*", "postProcessing",
                                                              "rebound_table.h5"))
    return case


def _first_half(case: Path) -> None:
    """Run to 2.5 ms and write that time (test_a_parcel_keeps_its_grain_over_a_restart goes on from it)."""
    control = case / "system" / "controlDict"
    text = re.sub(r"\nendTime\s+[^;]+;", "\nendTime         0.0025;", control.read_text())
    control.write_text(re.sub(r"\nwriteInterval\s+[^;]+;", "\nwriteInterval   0.0025;", text))


def _moving_walls(case: Path) -> None:
    """The side and funnel walls slide along z (tangential to all of them) at 20 m/s."""
    u = case / "0.orig" / "U"
    text = u.read_text().replace("    walls\n    {\n        type            noSlip;\n    }",
                                 "    walls\n    {\n        type            fixedValue;\n"
                                 "        value           uniform (0 0 20);\n    }")
    assert "uniform (0 0 20)" in text
    u.write_text(text)


def _trapped(policy: str):
    """Trapped parcels stick (grain kept, the default) or are removed (grain perHit)."""
    def edit(case: Path) -> None:
        set_coeff(case, "trapped", policy)
        insert_coeff(case, f"grain {'kept' if policy == 'stick' else 'perHit'};")
    return edit


# name: (table, MPI ranks, patch interaction model, edit of the copied case or None)
CASES = {
    "serial": ("case", 1, "stochasticRebound", None),
    "parallel": ("case", 2, "stochasticRebound", None),
    "standard1": ("case", 1, "standardWallInteraction", None),
    "standard2": ("case", 2, "standardWallInteraction", None),
    "many_shapes": ("many_shapes", 1, "stochasticRebound", lambda case: set_coeff(case, "shape", "mix")),
    "restart": ("case", 1, "stochasticRebound", _first_half),
    "moving": ("case", 1, "stochasticRebound", _moving_walls),
    "trapped_stick": ("trapping", 1, "stochasticRebound", _trapped("stick")),
    "trapped_remove": ("trapping", 1, "stochasticRebound", _trapped("remove")),
}


def run_allrun(case: Path, table: Path, ranks: int = 1, model: str = "stochasticRebound"):
    """The case's Allrun on ``table``: its finished process."""
    env = dict(os.environ, RBS_OPENFOAM_DIR=str(OPENFOAM_DIR), RBS_TABLE=str(table))
    return subprocess.run(["bash", "./Allrun", "-np", str(ranks), "-model", model], cwd=case, env=env,
                          capture_output=True, text=True, timeout=600)


def make_tables(folder: Path) -> dict:
    """The tables of :data:`TABLES` built into ``folder``: name -> path."""
    from tests.helpers.python_side import many_shape_table
    paths = {name: folder / file for name, file in TABLES.items()}
    build_table_from_text(make_case_table.CASE_TABLE_CONFIG, paths["case"])
    build_table_from_text(TRAPPING_TABLE_CONFIG, paths["trapping"])
    # the case's table with 63 user grains beside its prism (format 3.4; tests.helpers.python_side)
    many_shape_table(paths["case"], paths["many_shapes"], 64)
    return paths


def main(folder: Path) -> None:
    tables = make_tables(folder)
    runs = {}
    for name, (table, ranks, model, edit) in CASES.items():
        case = copy_case(folder / name)
        if edit:
            edit(case)
        done = run_allrun(case, tables[table], ranks, model)
        runs[name] = {"case": str(case), "returncode": done.returncode, "args": done.args,
                      "stdout": done.stdout[-4000:], "stderr": done.stderr[-4000:]}
    (folder / RUNS_FILE).write_text(json.dumps(runs, indent=1))


def read_runs(folder: Path) -> dict:
    """FOLDER/runs.json of :func:`main`: case name -> (its folder, Allrun's finished process)."""
    runs = json.loads((folder / RUNS_FILE).read_text())
    return {name: (Path(r["case"]), subprocess.CompletedProcess(r["args"], r["returncode"], r["stdout"], r["stderr"]))
            for name, r in runs.items()}


if __name__ == "__main__":
    main(Path(sys.argv[1]))
