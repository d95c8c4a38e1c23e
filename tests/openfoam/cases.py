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

# Two walls for one grain, on a coarse grid whose |V⁻| range (80-140 m/s) the case's hits fall below, inside and
# above, and its α1 range (from 5°) below: an elastic wall (small k: little of the normal speed lost) and a lossy
# one (large k) that traps (n_max = 2, as TRAPPING_TABLE_CONFIG); the lossy wall's name holds a comma, which the
# hits file writes as ';'
WALL_TABLE_CONFIG = """\
[grid]
alpha1_deg = [5.0, 30.0, 60.0, 90.0]
speed_m_s = [80.0, 140.0]
shapes = ["prism"]
[simulation]
particles_per_cell = 1000
seed = 20261125
n_max = {n_max}
[wall]
k = {k}
p = 0.61
q = {q}
name = "{name}"
{speed_range}
"""
# the elastic wall's law holds over 60-200 m/s (some hits fall outside it); the lossy one states no range
WALLS = {"elastic": {"k": 0.02, "q": 0.5, "n_max": 1000, "name": "elastic (hard steel)",
                     "speed_range": "speed_range_m_s = [60.0, 200.0]"},
         "lossy": {"k": 0.5, "q": 1.5, "n_max": 2, "name": "lossy, soft", "speed_range": ""}}

# the tables of the runs, by name: file name in FOLDER
TABLES = {"case": "rebound_table.h5", "trapping": "rebound_table_nmax2.h5", "many_shapes": "many_shapes.h5",
          "elastic": "wall_elastic.h5", "lossy": "wall_lossy.h5"}


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


# the prisms' own halfSizeFactor in the run "moving" (weights with a shape's own a)
PRISM_HALF_SIZE_FACTOR = 1.4


def set_weights(case: Path, weights: str) -> None:
    """``weights { weights }`` instead of the case's ``shape prism``."""
    props = case / "constant" / "kinematicCloudProperties"
    text, n = re.subn(r"\n        shape\s+prism;", f"\n        weights         {{ {weights} }}", props.read_text())
    assert n == 1
    props.write_text(text)


def _trapped(policy: str):
    """Trapped parcels stick (grain kept, the default) or are removed (grain perHit)."""
    def edit(case: Path) -> None:
        set_coeff(case, "trapped", policy)
        insert_coeff(case, f"grain {'kept' if policy == 'stick' else 'perHit'};")
    return edit


FRONT_AND_BACK = """\
    frontAndBack
    {
        type wall;
        faces
        (
            // front and back walls
            (4 5 0 1)
            (5 6 7 0)
            (15 14 13 8)
            (8 13 12 9)
            (3 4 1 2)
            (12 11 10 9)
        );
    }"""
FRONT_THEN_BACK = """\
    front
    {
        type wall;
        faces
        (
            (4 5 0 1)
            (5 6 7 0)
            (3 4 1 2)
        );
    }

    back
    {
        type wall;
        faces
        (
            (15 14 13 8)
            (8 13 12 9)
            (12 11 10 9)
        );
    }"""


def _per_patch(case: Path) -> None:
    """frontAndBack split into front and back, and a patches list: walls draw from the global table (the
    elastic wall's), front (named by a regex) from the lossy wall's with method table and trapped remove, back
    rebounds as OpenFOAM's stock rebound (e 0.5, mu 0.2), inlet draws from the elastic table named by another
    path (one table for both), outlet is named by no entry (OpenFOAM's escape, counted); the group wall, last,
    names only patches named before it, which keep their entries."""
    def edit(path: Path, old: str, new: str, count: int = 1) -> None:
        text = path.read_text()
        assert text.count(old) == count, (path, old)
        path.write_text(text.replace(old, new))

    edit(case / "system" / "blockMeshDict", FRONT_AND_BACK, FRONT_THEN_BACK)
    edit(case / "0.orig" / "U", "    frontAndBack\n", '    "(front|back)"\n')
    edit(case / "constant" / "kinematicCloudProperties", "(walls frontAndBack);", "(walls front back);", 2)
    folder = case.parents[1]
    insert_coeff(case, f"""patches
        (
            walls   {{ type stochasticRebound; }}
            "fr.*"  {{ type stochasticRebound; table "{folder / TABLES['lossy']}"; method table; trapped remove; }}
            back    {{ type rebound; e 0.5; mu 0.2; }}
            inlet   {{ type stochasticRebound; table "{folder / TABLES['elastic']}"; }}
            wall    {{ type stick; }}
        );""")


AIR = """\
FoamFile
{
    version     2.0;
    format      ascii;
    class       dictionary;
    object      thermophysicalProperties;
}

thermoType
{
    type            hePsiThermo;
    mixture         pureMixture;
    transport       const;
    thermo          hConst;
    equationOfState perfectGas;
    specie          specie;
    energy          sensibleInternalEnergy;
}

mixture
{
    specie          { molWeight 28.9; }
    thermodynamics  { Cp 1007; Hf 0; }
    transport       { mu 1.8e-05; Pr 0.7; }
}
"""

AIR_FIELD = """\
FoamFile
{{
    version     2.0;
    format      ascii;
    class       volScalarField;
    object      {name};
}}

dimensions      {dimensions};

internalField   uniform {value};

boundaryField
{{
    ".*"
    {{
        type            zeroGradient;
    }}
}}
"""

# the gas viscosity of _kinematic's air (mu of AIR), the mu of spinRelaxation auto
AIR_MU = 1.8e-5
KINEMATIC_SOLVER = "uncoupledKinematicParcelFoam"


def _kinematic(case: Path) -> None:
    """uncoupledKinematicParcelFoam: the plain kinematic cloud (basicKinematicCloud), whose parcels carry no spin,
    through air at rest (psiThermo, mu AIR_MU, 1e5 Pa, 300 K); the cloud reads the viscosity as thermo:mu."""
    control = case / "system" / "controlDict"
    control.write_text(re.sub(r"\napplication\s+[^;]+;", f"\napplication     {KINEMATIC_SOLVER};",
                              control.read_text()))
    (case / "constant" / "thermophysicalProperties").write_text(AIR)
    for name, dimensions, value in (("p", "[1 -1 -2 0 0 0 0]", "1e5"), ("T", "[0 0 0 1 0 0 0]", "300")):
        (case / "0.orig" / name).write_text(AIR_FIELD.format(name=name, dimensions=dimensions, value=value))
    props = case / "constant" / "kinematicCloudProperties"
    text, n = re.subn(r"\n        mu              cell;", "\n        thermo:mu       cell;", props.read_text())
    assert n == 1
    props.write_text(text)


def _then(*edits):
    """The edits one after the other."""
    def edit(case: Path) -> None:
        for e in edits:
            e(case)
    return edit


# the run "restart" writes every 3rd hit of its first half, whose draws are the run "serial"'s first 2.5 ms: its
# rows are every 3rd of serial's there
RESTART_HITS_EVERY = 3

# the relaxation time of the run "kinematic_tau": of the order of the flights between hits (0.1-1 ms), so that the
# remembered spin decays measurably
SPIN_RELAXATION_S = 2e-4

# the roughness (deg) of the walls patch in the run "rough"; frontAndBack stays smooth (its table's wall)
ROUGHNESS_DEG = 10


def _rough(case: Path) -> None:
    """A patches list: walls on a rough wall (roughnessDeg ROUGHNESS_DEG), frontAndBack on the smooth wall of the
    same table (no roughnessDeg: the table's, 0)."""
    insert_coeff(case, f"""patches
        (
            walls           {{ type stochasticRebound; roughnessDeg {ROUGHNESS_DEG}; }}
            frontAndBack    {{ type stochasticRebound; }}
        );""")


# name: (table, MPI ranks, patch interaction model, edit of the copied case or None)
CASES = {
    "serial": ("case", 1, "stochasticRebound", None),
    "parallel": ("case", 2, "stochasticRebound", None),
    "standard1": ("case", 1, "standardWallInteraction", None),
    "standard2": ("case", 2, "standardWallInteraction", None),
    "many_shapes": ("many_shapes", 1, "stochasticRebound", lambda case: set_coeff(case, "shape", "mix")),
    "restart": ("case", 1, "stochasticRebound",
                _then(_first_half, lambda case: insert_coeff(case, f"hitsEvery {RESTART_HITS_EVERY};"))),
    "moving": ("case", 1, "stochasticRebound",
               _then(_moving_walls, lambda case: set_weights(
                   case, f"prism {{ weight 1; halfSizeFactor {PRISM_HALF_SIZE_FACTOR}; }}"))),
    "trapped_stick": ("trapping", 1, "stochasticRebound", _trapped("stick")),
    "trapped_remove": ("trapping", 1, "stochasticRebound", _trapped("remove")),
    "patches": ("elastic", 1, "stochasticRebound", _per_patch),
    "rough": ("case", 1, "stochasticRebound", _rough),
    # parcels without spin: spinRelaxation auto (the default), off, a time (run to 2.5 ms, restarted by the test)
    # and auto on 2 ranks
    "kinematic": ("case", 1, "stochasticRebound", _kinematic),
    "kinematic_off": ("case", 1, "stochasticRebound",
                      _then(_kinematic, lambda case: insert_coeff(case, "spinRelaxation off;"))),
    "kinematic_tau": ("case", 1, "stochasticRebound",
                      _then(_kinematic, _first_half,
                            lambda case: insert_coeff(case, f"spinRelaxation {SPIN_RELAXATION_S};"))),
    "kinematic_parallel": ("case", 2, "stochasticRebound", _kinematic),
}


STOCHASTIC_REBOUND = """patchInteractionModel stochasticRebound;

    stochasticReboundCoeffs
    {{
        table           "{table}";
        shape           prism;
    }}"""


def _replace(path: Path, old: str, new: str) -> None:
    text = path.read_text()
    assert text.count(old) == 1, (path, old)
    path.write_text(text.replace(old, new))


def _positions(path: Path, points) -> None:
    """A positions file of manualInjection holding ``points`` instead of its own."""
    text = path.read_text()
    start = text.index("\n(\n")
    end = text.index("\n)\n", start)
    path.write_text(text[:start] + "\n(\n" + "\n".join(f"({x} {y} {z})" for x, y, z in points) + text[end:])


def _tutorial(case: Path, table: Path, end_time: str, injections: dict) -> None:
    """The tutorial with stochasticRebound for the standardWallInteraction of the clouds of ``injections`` (cloud
    -> (old, new) of its properties), run to ``end_time`` with the adapter loaded."""
    for cloud, injection in injections.items():
        props = case / "constant" / f"{cloud}Properties"
        _replace(props, "patchInteractionModel standardWallInteraction;", STOCHASTIC_REBOUND.format(table=table))
        _replace(props, *injection)
    control = case / "system" / "controlDict"
    text = re.sub(r"\nendTime\s+[^;]+;", f"\nendTime         {end_time};", control.read_text())
    control.write_text(text.replace("\napplication", '\nlibs ("libstochasticRebound.so");\n\napplication', 1))


def _chemistry_off(case: Path) -> None:
    _replace(case / "constant" / "chemistryProperties", "chemistry       on;", "chemistry       off;")


def _parcel_in_box(case: Path, table: Path) -> None:
    """Five water droplets thrown at the box's floor at 130 m/s, for 10 ms."""
    _tutorial(case, table, "0.01", {"reactingCloud1": ("U0              (0 0 0);", "U0              (40 30 -120);")})
    _replace(case / "constant" / "reactingCloud1Properties", "massTotal       5.23599e-10;",
             "massTotal       2.617995e-09;")
    _positions(case / "constant" / "reactingCloud1Positions",
               [(0.05, 0.05, 0.005), (0.03, 0.05, 0.005), (0.05, 0.03, 0.005), (0.07, 0.05, 0.005),
                (0.05, 0.07, 0.005)])


def _simplified_siwek(case: Path, table: Path) -> None:
    """Coal and limestone thrown at the floor at 100 m/s from 1 cm above it, for 0.5 ms, chemistry off."""
    _tutorial(case, table, "0.0005", {cloud: (f"U0              {u0};", "U0              (10 -100 0);")
                                      for cloud, u0 in (("coalCloud1", "(0 -10 0)"), ("limestoneCloud1", "(0 0 0)"))})
    for positions in ("coalCloud1Positions", "limestonePositions"):
        _positions(case / "constant" / positions, [(x, 0.01, 0.05) for x in (0.005, 0.015, 0.025, 0.035, 0.045)])
    _chemistry_off(case)


def _aachen_bomb(case: Path, table: Path) -> None:
    """The n-heptane spray injected 5 mm above the floor instead of below the ceiling, on a 4 x 4 x 10 mesh, for
    0.15 ms, chemistry off."""
    _tutorial(case, table, "0.00015",
              {"sprayCloud": ("position        (0 0.0995 0);", "position        (0 0.005 0);")})
    _replace(case / "system" / "blockMeshDict", "(41 41 100)", "(4 4 10)")
    _chemistry_off(case)


def _rectangular_duct(case: Path, table: Path) -> None:
    """The particles injected at 100 m/s towards the duct's floor, on a 10 x 4 x 2 mesh, for 0.1 s."""
    _tutorial(case, table, "0.1", {"reactingCloud1": ("U0              (0.1 0 0);", "U0              (10 -100 0);")})
    _replace(case / "system" / "blockMeshDict", "(100 40 10)", "(10 4 2)")


# The stock v1912 tutorials of the thermo, reacting-multiphase (and coal), heterogeneous reacting and spray clouds,
# made short and aimed at a wall, with stochasticRebound instead of their standardWallInteraction: name -> (the
# tutorial in tutorials/lagrangian, its solver, its clouds, the commands before the solver, the edit); the run's
# log is log.<solver>. The kinematic, colliding and MPPIC clouds run in CASES and test_openfoam.py.
FAMILY_RUNS = {
    "reactingMultiphase": ("reactingParcelFoam/parcelInBox", "reactingParcelFoam", ("reactingCloud1",), (),
                           _parcel_in_box),
    "coal and thermo": ("coalChemistryFoam/simplifiedSiwek", "coalChemistryFoam", ("coalCloud1", "limestoneCloud1"),
                        ("topoSet",), _simplified_siwek),
    "spray": ("sprayFoam/aachenBomb", "sprayFoam", ("sprayCloud",),
              ("chemkinToFoam chemkin/chem.inp chemkin/therm.dat chemkin/transportProperties constant/reactions "
               "constant/thermo",), _aachen_bomb),
    "heterogeneous": ("reactingHeterogenousParcelFoam/rectangularDuct", "reactingHeterogenousParcelFoam",
                      ("reactingCloud1",), (), _rectangular_duct),
}


def openfoam_env(name: str) -> str:
    """The variable ``name`` as openfoam-env.sh sets it (in a new shell: the folder install-deps.sh and build.sh
    recorded, whatever this process's environment)."""
    return subprocess.run(["bash", "-c", f". {OPENFOAM_DIR / 'openfoam-env.sh'} && echo ${name}"],
                          capture_output=True, text=True, check=True).stdout.strip()


def tutorials() -> Path:
    """The stock tutorials install-deps.sh unpacked ($FOAM_TUTORIALS)."""
    return Path(openfoam_env("FOAM_TUTORIALS"))


def run_tutorial(name: str, folder: Path, table: Path):
    """FAMILY_RUNS[name] copied into ``folder`` and run: the case and the finished process."""
    tutorial, solver, _, before, edit = FAMILY_RUNS[name]
    case = folder / Path(tutorial).name
    shutil.copytree(tutorials() / "lagrangian" / tutorial, case)
    edit(case, table)
    steps = " && ".join(f"{{ {command} > log.{command.split()[0]} 2>&1 || {{ tail -n 30 log.{command.split()[0]}; "
                        "false; }; }" for command in ("blockMesh", *before, solver))
    done = subprocess.run(["bash", "-c", f". {OPENFOAM_DIR / 'openfoam-env.sh'} && {steps}"], cwd=case,
                          capture_output=True, text=True, timeout=600)
    return case, done


def run_allrun(case: Path, table: Path, ranks: int = 1, model: str = "stochasticRebound"):
    """The case's Allrun on ``table``: its finished process."""
    env = dict(os.environ, RBS_OPENFOAM_DIR=str(OPENFOAM_DIR), RBS_TABLE=str(table))
    return subprocess.run(["bash", "./Allrun", "-np", str(ranks), "-model", model], cwd=case, env=env,
                          capture_output=True, text=True, timeout=600)


def as_format_4_0(path: Path) -> None:
    """The table at ``path`` as format 4.0 wrote it: without the work datasets (its draws are the same, bit for
    bit; the work on the wall they give is NaN)."""
    import h5py
    import numpy as np
    from data_schema.table import WORK_DATASETS
    with h5py.File(path, "r+") as f:
        for name in WORK_DATASETS:
            del f[f"cells/{name}"]
        f.attrs["format_version"] = np.array([4, 0], dtype=f.attrs["format_version"].dtype)


def make_tables(folder: Path) -> dict:
    """The tables of :data:`TABLES` built into ``folder``: name -> path."""
    from tests.helpers.python_side import many_shape_table
    paths = {name: folder / file for name, file in TABLES.items()}
    build_table_from_text(make_case_table.CASE_TABLE_CONFIG, paths["case"])
    build_table_from_text(TRAPPING_TABLE_CONFIG, paths["trapping"])
    for wall, law in WALLS.items():
        # one worker: starting a pool takes longer than these 8 cells (4 s against 12 s for both)
        build_table_from_text(WALL_TABLE_CONFIG.format(**law), paths[wall], workers=1)
    # the case's table with 63 user grains beside its prism (tests.helpers.python_side), as format 4.0: its
    # table path gives no work on the wall, the direct model's does
    many_shape_table(paths["case"], paths["many_shapes"], 64)
    as_format_4_0(paths["many_shapes"])
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
    for name in FAMILY_RUNS:
        case, done = run_tutorial(name, folder / name.replace(" ", "_"), tables["case"])
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
