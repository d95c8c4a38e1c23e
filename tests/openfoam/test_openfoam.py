"""The OpenFOAM adapter (integrations/openfoam) on a real Lagrangian case.

Builds the C runtime and the stochasticRebound patch interaction model
against Debian's OpenFOAM v1912 (integrations/openfoam/build.sh, on the
outputs of install-deps.sh), runs the case hopperRebound serially and on 2
MPI ranks with method auto (these runs and the others of tests/openfoam/cases.py are made beside the tests,
from the session's start), and checks the hit counts per path, the
rebounds the table answered and those the direct model answered against
surrogate on the same incident states (the BSD statistics of
tablegen.study.solver_comparison, called through compare_rebounds), the random streams per rank, the grain
each parcel keeps from hit to hit (grain kept), a moving wall, OpenFOAM's erosion model beside ours, the work of
the hits on the walls (the fields per face against the hit records, on one and two ranks, over a restart, from a
table without it), a wall per patch (two tables, OpenFOAM's rebound, an open patch; the per-patch summary), a
rough patch beside a smooth one and the refused patch entries, and times the runs against
standardWallInteraction.

These tests need OpenFOAM: they fail (they are not skipped) when it is
missing, with a message naming integrations/openfoam/install-deps.sh.

Copyright (C) 2026 the rebound-scatter authors. License: GPL-3.0-or-later
(see integrations/openfoam/LICENSE): these tests import the integration's scripts.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy import stats

from tests.helpers import background

REPO = Path(__file__).resolve().parents[2]
OPENFOAM_DIR = REPO / "integrations" / "openfoam"
SOLVER = "icoUncoupledKinematicParcelFoam"
HITS = Path("postProcessing/lagrangian/kinematicCloud/stochasticRebound")

sys.path.insert(0, str(OPENFOAM_DIR))

import compare_rebounds  # noqa: E402
from rbs_api import (PATH_TABLE, agreement, grain_key, grain_mismatches, incident_states, load,  # noqa: E402
                     solver_hits, summary_counts, surrogate_answers)

from tests.openfoam import cases  # noqa: E402

INSTALL_HINT = ("run `bash integrations/openfoam/install-deps.sh` (as root on Debian bookworm: it installs "
                "Debian's OpenFOAM v1912 and Open MPI, unpacks the v1912 headers from the source package "
                "and builds wmake)")


def _cache() -> Path:
    """The folder of install-deps.sh's and build.sh's outputs, as openfoam-env.sh finds it."""
    return Path(cases.openfoam_env("RBS_OPENFOAM_CACHE"))


def _run(cmd, cwd, env=None, timeout=600) -> subprocess.CompletedProcess:
    proc = subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True, timeout=timeout)
    return background.succeeded(proc)


def _timings(case: Path) -> dict:
    return {k: float(v) for k, v in (line.split() for line in (case / "log.timings").read_text().splitlines())}


def _cloud_info(log: str, cloud: str | None = None) -> dict:
    """The stochasticRebound counts of the last time step in a solver log (of ``cloud``'s block, where a solver has
    several clouds), the work on the walls (J, normal and tangential) and the hits without it, the incoming spin's
    mean and max, and the spin memory's: the hits with a remembered spin, the parcels holding one and the hits that
    missed it (None where the summary has no such line)."""
    start = log.rindex(f"Cloud: {cloud}\n") if cloud else log.rindex("Stochastic rebound")
    block = log[log.index("Stochastic rebound", start):]
    block = block[:block.index("Per patch (")]
    spin = re.search(r"incoming spin \|Omega\|a/\|V\|\s*= mean\s*([-0-9.eE+]+), max\s*([-0-9.eE+]+)", block)
    memory = re.search(r"hits with a remembered spin = (\d+) \(held for (\d+) parcels; (\d+) missed it", block)
    work = re.search(r"work on the walls \(normal, tangential\) = ([-0-9.eE+]+), ([-0-9.eE+]+) J \((\d+) hits "
                     r"without it", block)
    return dict(summary_counts(block), spin_mean=float(spin.group(1)) if spin else None,
                work_normal=float(work.group(1)), work_tangential=float(work.group(2)), no_work=int(work.group(3)),
                spin_max=float(spin.group(2)) if spin else None,
                remembered=int(memory.group(1)) if memory else None, held=int(memory.group(2)) if memory else None,
                missed=int(memory.group(3)) if memory else None)


def _cloud_parcels(log: str) -> dict:
    """Parcels in the system, added and escaped (through open patches) at the last time step."""
    block = log[log.rindex("Current number of parcels"):]
    def number(label):
        return int(float(re.search(re.escape(label) + r"\s*=\s*([-0-9.eE+]+)", block).group(1)))
    return {"current": number("Current number of parcels"), "added": number("- parcels added"),
            "escaped": number("- escape")}


def _cpu_seconds(case: Path) -> float:
    """The solver's ExecutionTime (CPU seconds of rank 0) at its last time step."""
    return float(re.findall(r"ExecutionTime = ([0-9.eE+-]+) s", (case / f"log.{SOLVER}").read_text())[-1])


@pytest.fixture(scope="session")
def openfoam_build(openfoam_build_job):
    """install-deps.sh's outputs checked, then the C runtime and the adapter built (build.sh, started with the
    session)."""
    missing = [tool for tool in (SOLVER, "blockMesh", "decomposePar", "mpirun") if shutil.which(tool) is None]
    tree = _cache() / "OpenFOAM-v1912"
    if missing:
        pytest.fail(f"OpenFOAM is missing ({', '.join(missing)} not on PATH): {INSTALL_HINT}")
    if not (tree / "src" / "lagrangian" / "intermediate" / "lnInclude").is_dir():
        pytest.fail(f"the OpenFOAM v1912 headers are missing ({tree}): {INSTALL_HINT}")
    proc = background.succeeded(openfoam_build_job.result())
    lib = _cache() / "lib" / "libstochasticRebound.so"
    assert lib.is_file(), proc.stdout
    return {"lib": lib, "log": proc.stdout}


@pytest.fixture(scope="session")
def runs_folder(openfoam_build, openfoam_runs):
    """The folder of tests/openfoam/cases.py's tables and runs, made beside the tests (tests/conftest.py's
    openfoam_runs, after the adapter's build)."""
    done, folder = openfoam_runs.result()
    background.succeeded(done)
    return folder


def _case(folder: Path, name: str) -> Path:
    """The case ``name`` of cases.CASES as its run left it (a run that failed fails the test, with its output)."""
    case, done = cases.read_runs(folder)[name]
    background.succeeded(done)
    return case


@pytest.fixture(scope="session")
def case_table(runs_folder):
    """The case's table (make_case_table.py's configuration)."""
    return runs_folder / cases.TABLES["case"]


@pytest.fixture(scope="session")
def serial_case(runs_folder):
    return _case(runs_folder, "serial")


@pytest.fixture(scope="session")
def parallel_case(runs_folder):
    return _case(runs_folder, "parallel")


# ----------------------------------------------------------------------------- build

# the outermost parcel type of each cloud family's kinematic cloud type (coal clouds are reacting-multiphase ones)
FAMILY_PARCELS = {"kinematic": "KinematicParcel", "colliding": "CollidingParcel", "MPPIC": "MPPICParcel",
                  "thermo": "ThermoParcel", "reacting": "ReactingParcel",
                  "reactingMultiphase": "ReactingMultiphaseParcel", "heterogeneous": "ReactingHeterogeneousParcel",
                  "spray": "SprayParcel"}


def test_adapter_registers_the_model_for_every_cloud_family(openfoam_build):
    symbols = subprocess.run(["nm", "-DC", str(openfoam_build["lib"])], capture_output=True, text=True,
                             check=True).stdout
    names = [line for line in symbols.splitlines() if "StochasticRebound<" in line and "::typeName" in line]
    registered = {family for family, parcel in FAMILY_PARCELS.items()
                  if any(f"StochasticRebound<Foam::KinematicCloud<Foam::Cloud<Foam::{parcel}<" in line
                         for line in names)}
    assert registered == set(FAMILY_PARCELS), names
    # one translation unit per family, each built
    objects = {p.name for p in (_cache() / "adapter" / "stochasticRebound" / "Make").glob("*/*.o")}
    assert objects >= {f"makeStochasticRebound{f[0].upper() + f[1:]}.o" for f in FAMILY_PARCELS}, objects
    linked = subprocess.run(["ldd", str(openfoam_build["lib"])], capture_output=True, text=True).stdout
    assert "librebound_scatter" in linked and "not found" not in linked, linked


def test_adapter_sources_carry_the_gpl_notice():
    sources = sorted((OPENFOAM_DIR / "stochasticRebound").glob("*.[CH]"))
    assert sources
    for f in sources:
        assert "GNU General Public License" in f.read_text(), f
    assert "GNU GENERAL PUBLIC LICENSE" in (OPENFOAM_DIR / "LICENSE").read_text()[:200]
    assert "Version 3" in (OPENFOAM_DIR / "LICENSE").read_text()[:200]


# ----------------------------------------------------------------------------- the case

def _check_counts(case: Path, n_ranks: int) -> dict:
    info = _cloud_info((case / f"log.{SOLVER}").read_text())
    hits, headers = compare_rebounds.read_hits(case)
    post = compare_rebounds.read_patch_post(case)
    assert len(headers) == n_ranks
    assert info["hits"] == info["rebounded"] + info["trapped"] + info["failed"] + info["invalid"]
    # every hit took one path (method auto), and the hits file says the same
    assert info["hits"] == info["table"] + info["direct"] + info["invalid"]
    assert (np.sum(hits["path"] == compare_rebounds.PATH_TABLE), np.sum(hits["path"] == compare_rebounds.PATH_DIRECT)) \
        == (info["table"], info["direct"])
    assert all(h["method"] == "auto" for h in headers)
    assert info["hits"] == len(hits["status"]), "the adapter's log and its hit records disagree"
    assert info["hits"] == sum(len(r["time"]) for r in post.values()), \
        "the adapter's hits and patchPostProcessing's wall hits disagree"
    # 8000 sand parcels at 150 m/s: about 14 000 wall hits in 5 ms, some on every wall patch
    assert 8000 < info["hits"] < 30000, info
    assert set(post) == {"walls", "frontAndBack"} and min(len(r["time"]) for r in post.values()) > 1000
    # every parcel moves into the wall when it hits it: nothing is left to the stock behaviour
    assert info["invalid"] == 0
    # colliding parcels: Ω⁺ set as angular momentum, so later hits arrive spinning: a good part of the hits
    # goes to the direct model (about half in this case), the first hit of every parcel to the table
    assert 0.05 < info["spin_mean"] < info["spin_max"], info
    assert info["direct"] > 0.3 * info["hits"] and info["table"] > 0.3 * info["hits"], info
    assert info["direct_us"] > 0
    # the paths follow the rule: spinning hits (above the tolerance) and hits outside the grid went to the
    # direct model, non-spinning hits inside the grid to the table
    paths = compare_rebounds.compare_paths(case)
    assert paths["spinning"] > 1000 and paths["still_inside"] > 1000, paths
    assert paths["spinning_not_direct"] == paths["outside_not_direct"] == paths["still_inside_not_table"] == 0, paths
    return info


def test_serial_run_hit_counts_and_rebounds_against_the_sampler(serial_case, tmp_path):
    info = _check_counts(serial_case, 1)
    res = compare_rebounds.compare(serial_case)
    res["records"] = compare_rebounds.check_records(*[compare_rebounds.read_hits(serial_case)[0],
                                                      compare_rebounds.read_patch_post(serial_case)])
    print(compare_rebounds.report(res))
    r = res["records"]
    assert r["hits_per_patch_adapter"] == r["hits_per_patch_patchPostProcessing"]
    assert r["parcels_mismatched"] == 0 and r["max_relative_difference_of_incident_velocity"] < 1e-5
    comparison = res["comparison"]
    # the hits the table answered follow the table's law, and the hits the direct model answered (spinning,
    # or off the grid) the direct model's, against surrogate run again on the same incident states (Ω⁻
    # included): KS, classifier and the fractions not rebounded within the bounds of one law at these
    # sample sizes (solver_comparison.agreement)
    s, d = comparison.agreement["table"], comparison.agreement["direct"]
    assert s.ok, s
    assert d.n_solver > 1000 and d.ok, d
    assert comparison.ok and res["checks_passed"]
    # ... and the table alone (the adapter before it passed Ω⁻) was measurably off for the spinning ones
    far = res["spinning_vs_table_only"]
    assert far.classifier_accuracy > far.classifier_bound, far
    assert max(far.ks.values()) > far.ks_bound, far
    # far from the stock specular bounce
    sp = res["table_vs_specular"]
    assert sp.ks["speed_ratio"] > 0.5 and sp.ks["beta2"] > 0.3, sp
    assert res["incidence"]["fraction_outside_speed_range"] < 0.2
    # the adapter's count of hits drawn at the grid's edge (rounding may move a hit at the edge itself)
    assert info["outside"] == pytest.approx(res["paths"]["outside"], abs=2)
    png = tmp_path / "rebounds.png"
    compare_rebounds.plot(res, png)
    assert png.stat().st_size > 10_000


def test_comparison_script_command_line(serial_case, tmp_path):
    out = subprocess.run([sys.executable, str(OPENFOAM_DIR / "compare_rebounds.py"), str(serial_case),
                          "--check", "--no-classifier", "--json", str(tmp_path / "c.json"),
                          "--work-png", str(tmp_path / "work.png")],
                         capture_output=True, text=True, cwd=REPO,
                         env=dict(os.environ, PYTHONPATH=str(REPO)))
    assert out.returncode == 0, out.stdout + out.stderr
    assert "bound" in out.stdout and (tmp_path / "c.json").stat().st_size > 0
    assert "wall work (walls):" in out.stdout and (tmp_path / "work.png").stat().st_size > 10_000


def test_two_rank_run_hit_counts_and_rebounds(parallel_case, serial_case):
    info = _check_counts(parallel_case, 2)
    serial = _cloud_info((serial_case / f"log.{SOLVER}").read_text())
    # the same case: the hit count moves only with the draws (about 1 %)
    assert abs(info["hits"] - serial["hits"]) < 0.05 * serial["hits"], (info, serial)
    hits, _ = compare_rebounds.read_hits(parallel_case)
    assert min(np.sum(hits["rank"] == r) for r in (0, 1)) > 1000, "both ranks see wall hits"
    res = compare_rebounds.compare(parallel_case)
    print(compare_rebounds.report(res))
    assert res["comparison"].ok and set(res["comparison"].agreement) == {"table", "direct"}, res


def test_each_rank_draws_its_own_stream(parallel_case, serial_case):
    _, headers = compare_rebounds.read_hits(parallel_case)
    assert [h["stream"] for h in headers] == [0, 1]
    assert len({h["seed"] for h in headers}) == 1
    hits, _ = compare_rebounds.read_hits(parallel_case)
    u0 = {r: hits["u0"][hits["rank"] == r] for r in (0, 1)}
    # the first uniform of every draw: a repeated stream would repeat them, rank against rank
    assert len(np.intersect1d(u0[0], u0[1])) == 0
    assert len(np.unique(hits["u0"])) == len(hits["u0"])
    # rank 0 draws stream 0 of the seed, as a serial run does: the first draw is the same
    serial, serial_headers = compare_rebounds.read_hits(serial_case)
    assert serial_headers[0]["stream"] == 0
    assert serial["u0"][0] == u0[0][0] and serial["u0"][0] != u0[1][0]


def _parcels(hits: dict) -> dict:
    """Row indices of the hits per parcel, keyed by its birth ids (origProc, origId)."""
    rows: dict = {}
    for i, parcel in enumerate(zip(hits["origProc"].tolist(), hits["origId"].tolist())):
        rows.setdefault(parcel, []).append(i)
    return {parcel: np.array(i) for parcel, i in rows.items()}


def _check_grains(case: Path, table: Path) -> dict:
    """Every hit of a grain-kept run carries its parcel's key, rbs_grain_key(grainSeed, origProc, origId) equal
    to surrogate.grain_key's, and the grain of that key: the shape surrogate.grain_of gives it on every hit, and
    on the direct path its b/a, c/b and hand to the bit (NaN on the table path). Returns the parcels' rows."""
    hits, headers = compare_rebounds.read_hits(case)
    assert {(h["grain"], h["grain_seed"]) for h in headers} == {("kept", headers[0]["grain_seed"])}
    keys = grain_key(headers[0]["grain_seed"], hits["origProc"], hits["origId"])
    np.testing.assert_array_equal(hits["key"], keys)
    mismatches = grain_mismatches(hits, headers[0], load(table))
    assert mismatches == {"key": 0, "shape": 0, "direct": 0, "table": 0}, mismatches
    direct = hits["path"] == compare_rebounds.PATH_DIRECT
    assert direct.sum() > 1000
    rows = _parcels(hits)
    # ... so each parcel hits as one grain: one key, one shape, and one b/a, c/b on the direct path
    for parcel, i in rows.items():
        assert len(set(hits["key"][i].tolist())) == 1 and len(set(hits["shape"][i].tolist())) == 1, parcel
        on_direct = i[direct[i]]
        proportions = np.column_stack([hits["ratio_ba"][on_direct], hits["ratio_cb"][on_direct]])
        # NaN equal to NaN: a shape of fixed proportions records none
        np.testing.assert_array_equal(proportions, proportions[:1].repeat(len(on_direct), axis=0), err_msg=str(parcel))
    return rows


def test_each_parcel_hits_as_one_grain_on_one_and_two_ranks(serial_case, parallel_case, case_table):
    """grain kept (the default): a parcel's key is a function of its birth ids only, so it keeps its grain from
    hit to hit, and from rank to rank: on 2 ranks some 600 parcels hit walls on both ranks, with one key. The
    serial and the 2-rank run number their parcels on the rank that injects them (rank 0 serially, rank 1 on 2
    ranks, where the injection point lies), so one injected parcel has other ids, and another key, in the two
    runs: a function of the ids, the same on both (_check_grains), not of the decomposition."""
    serial_rows = _check_grains(serial_case, case_table)
    rows = _check_grains(parallel_case, case_table)
    hits, headers = compare_rebounds.read_hits(parallel_case)
    assert headers[0]["grain_seed"] == headers[0]["seed"], "grainSeed defaults to seed"
    on_both = [parcel for parcel, i in rows.items() if len(set(hits["rank"][i].tolist())) == 2]
    assert len(on_both) > 100, len(on_both)
    assert {p[0] for p in serial_rows} == {0} and {p[0] for p in rows} == {1}


def _check_every_kth_hit(thinned: Path, full: Path, k: int, said: str, end: float) -> None:
    """The hits file of ``thinned`` (serial, hitsEvery k, run to ``end``) holds every k-th row of ``full``'s up to
    ``end``, from its first: the same draws, bit for bit; its first header line is full's (the case's folder
    aside), its second says ``said`` ahead of full's text."""
    rows = {case: (case / HITS / "hits_0.csv").read_text().splitlines() for case in (thinned, full)}
    lines = [line.replace(str(full), str(thinned)) for line in rows[full][:3]]
    assert rows[thinned][0] == lines[0] and rows[thinned][2] == lines[2]
    assert rows[thinned][1] == f"# {said} " + lines[1][2:]
    until_end = [row for row in rows[full][3:] if float(row.split(",", 1)[0]) <= end]
    assert len(until_end) > 1000 and rows[thinned][3:] == until_end[::k]


def test_a_parcel_keeps_its_grain_over_a_restart(runs_folder, serial_case, case_table):
    """The case run to 2.5 ms (cases.CASES["restart"]), then restarted from its written time to 5 ms with another
    seed (new streams) and grainSeed the first run's: the parcels (their ids are written with the cloud and read
    back) hit after the restart as the grains they were before it. The first run draws as the serial run does
    and wrote every 3rd hit (hitsEvery 3): its rows are every 3rd of the serial run's to 2.5 ms, whose hits stand
    for its own. The work fields it wrote at 2.5 ms are the sums of those hits; the restart reads them back and
    adds its own hits' (its draws are not the serial run's: another seed)."""
    case = _case(runs_folder, "restart")
    _check_every_kth_hit(case, serial_case, cases.RESTART_HITS_EVERY, "Every 3rd hit (hitsEvery 3): the 1st, 4th, "
                         "7th, ... of the hits this rank would record.", 0.0025)
    _, before_headers = compare_rebounds.read_hits(case)
    serial, _ = compare_rebounds.read_hits(serial_case)
    before = {name: column[serial["time"] <= 0.0025] for name, column in serial.items()}
    half = _work_fields(case, "0.0025")
    _check_fields(half, _record_sums(compare_rebounds.read_wall_work(serial_case, serial), serial["time"] <= 0.0025,
                                     half))
    control = case / "system" / "controlDict"
    text = re.sub(r"\nendTime\s+[^;]+;", "\nendTime         0.005;", control.read_text())
    control.write_text(re.sub(r"\nstartFrom\s+[^;]+;", "\nstartFrom       latestTime;", text))
    seed = before_headers[0]["seed"]
    cases.set_coeff(case, "seed", str(seed + 1))
    cases.insert_coeff(case, f"grainSeed {seed};")
    # every hit again: the grain checks below need them all
    cases.set_coeff(case, "hitsEvery", "1")
    script = f". {OPENFOAM_DIR / 'openfoam-env.sh'} && {SOLVER} > log.restart 2>&1"
    _run(["bash", "-c", script], cwd=case)
    log = (case / "log.restart").read_text()
    assert "Starting time loop" in log
    assert (f"stochasticRebound: read the work on the walls ({CLOUD}:stochasticReboundWorkNormal, {CLOUD}:"
            f"stochasticReboundWorkTangential, {CLOUD}:stochasticReboundHits) at time 0.0025") in log
    after, after_headers = compare_rebounds.read_hits(case)
    end = _work_fields(case, END)
    added = _record_sums(compare_rebounds.read_wall_work(case, after), np.ones(len(after["time"]), bool), end)
    _check_fields(end, {patch: {key: half[patch][key] + added[patch][key] for key in added[patch]}
                        for patch in end})
    info = _cloud_info(log)
    assert (info["work_normal"], info["work_tangential"]) == pytest.approx(_field_totals(end), rel=1e-6)
    assert (after_headers[0]["seed"], after_headers[0]["grain_seed"]) == (seed + 1, seed)
    assert after["time"].min() > 0.0025 and before["time"].max() <= 0.0025
    _check_grains(case, case_table)
    # the same parcels on both sides of the restart, each with its key and shape
    key_before = dict(zip(zip(before["origProc"].tolist(), before["origId"].tolist()), before["key"].tolist()))
    both = [(p, k) for p, k in zip(zip(after["origProc"].tolist(), after["origId"].tolist()), after["key"].tolist())
            if p in key_before]
    assert len({p for p, _ in both}) > 1000
    assert all(key_before[p] == k for p, k in both)
    # new streams: no first uniform of the restart repeats one of the first run
    assert len(np.intersect1d(before["u0"], after["u0"])) == 0


def test_moving_wall_velocity_is_taken_out_of_the_incident_velocity(runs_folder):
    """The side and funnel walls slide along z at 20 m/s (cases.CASES["moving"])."""
    case = _case(runs_folder, "moving")
    hits, _ = compare_rebounds.read_hits(case)
    on_walls = hits["patch"] == "walls"
    assert on_walls.sum() > 1000
    np.testing.assert_allclose(hits["Uw"][on_walls], np.tile([0.0, 0.0, 20.0], (on_walls.sum(), 1)), atol=1e-9)
    np.testing.assert_allclose(hits["Uw"][~on_walls], 0.0, atol=1e-9)
    # V⁻ is relative to the wall: patchPostProcessing's absolute U = V⁻ + Uw, per parcel and hit
    r = compare_rebounds.check_records(hits, compare_rebounds.read_patch_post(case))
    assert r["parcels_mismatched"] == 0 and r["max_relative_difference_of_incident_velocity"] < 1e-5, r
    res = compare_rebounds.compare(case, classifier=False)
    assert res["comparison"].ok, res
    # the prisms' own halfSizeFactor (weights { prism { weight 1; halfSizeFactor 1.4; } }): a = 1.4 d/2
    _, headers = compare_rebounds.read_hits(case)
    assert headers[0]["shape"] == {"prism": 1.0} and headers[0]["half_size_factor"] == 1.0
    np.testing.assert_allclose(hits["a"], cases.PRISM_HALF_SIZE_FACTOR * hits["d"] / 2, rtol=1e-8)


@pytest.fixture(scope="session")
def many_shapes(runs_folder):
    """The case's table with 63 user grains beside its prism (the grains share the prism's cells:
    tests.helpers.python_side.many_shape_table) as format 4.0 wrote it (no work on the wall), and the case run on
    it with shape mix (equal weights)."""
    return runs_folder / cases.TABLES["many_shapes"], _case(runs_folder, "many_shapes")


def test_a_table_of_64_shapes_draws_in_the_adapter(many_shapes):
    """The adapter loads the table of 64 shapes, its mix sized by the table takes them with equal weights
    (shape mix), and every hit takes a path: the table, or the direct model, which answers the prism's hits and
    the grains' alike, so that no hit is invalid."""
    _, case = many_shapes
    log = (case / f"log.{SOLVER}").read_text()
    assert "Stochastic rebound (mix)" in log
    info = _cloud_info(log)
    assert info["hits"] == info["table"] + info["direct"] and info["table"] > 1000, info
    assert info["direct"] > 0 and info["invalid"] == 0, info


def test_the_parcels_grains_follow_the_mix_weights(many_shapes):
    """Each parcel hits as one grain of the 64-shape mix, and over the parcels the shapes follow the mix's equal
    weights: about 7000 parcels, some 110 per shape; Pearson's chi-square of the counts against n/64 each, with
    63 degrees of freedom, has mean 63 and sd 11 and stays below its 0.999 quantile (103.4) but for one run in a
    thousand (the run is fixed by its seeds: this one passes or fails for good)."""
    table, case = many_shapes
    rows = _check_grains(case, table)
    hits, _ = compare_rebounds.read_hits(case)
    shapes = np.array([hits["shape"][i[0]] for i in rows.values()], dtype=object)
    names = load(table).shapes
    assert len(names) == 64 and len(shapes) > 5000
    counts = np.array([np.sum(shapes == name) for name in names])
    expected = len(shapes) / len(names)
    chi2 = float(np.sum((counts - expected) ** 2 / expected))
    assert chi2 < stats.chi2.ppf(0.999, len(names) - 1), (chi2, counts)


def test_a_table_without_work_leaves_its_hits_out_of_the_work_fields(many_shapes):
    """On the table of format 4.0 (cases.as_format_4_0) the hits its law answered give no work (NaN): each is
    counted (the summary's no-work, per patch and in all) and left out of the fields, which hold the work of the
    hits the direct model answered, and no NaN."""
    _, case = many_shapes
    log = (case / f"log.{SOLVER}").read_text()
    info, rows = _cloud_info(log), compare_rebounds.patch_summary(log)
    hits, _ = compare_rebounds.read_hits(case)
    work = compare_rebounds.read_wall_work(case, hits)
    on_table = hits["path"] == compare_rebounds.PATH_TABLE
    assert np.array_equal(np.isnan(work["Wn"]), on_table) and np.array_equal(np.isnan(work["Wt"]), on_table)
    assert info["no_work"] == info["table"] == on_table.sum() > 1000, info
    for patch in ("walls", "frontAndBack"):
        direct = (work["patch"] == patch) & ~on_table
        assert rows[patch]["no_work"] == rows[patch]["table"], rows[patch]
        assert rows[patch]["work_normal_mean"] == pytest.approx(work["Wn"][direct].mean(), rel=1e-5)
    fields = _work_fields(case, END)
    _check_fields(fields, _record_sums(work, np.ones(len(work["face"]), bool), fields))
    assert sum(int(v["hits"].sum()) for v in fields.values()) == info["direct"]
    assert (info["work_normal"], info["work_tangential"]) == pytest.approx(_field_totals(fields), rel=1e-6)


@pytest.fixture(scope="session")
def standard_cases(runs_folder):
    """The case with OpenFOAM's specular bounce (standardWallInteraction), serially and on 2 ranks."""
    return {np_: _case(runs_folder, f"standard{np_}") for np_ in (1, 2)}


def test_run_times_against_standard_wall_interaction(serial_case, parallel_case, standard_cases, capsys):
    standard_hits = {}
    for np_, case in standard_cases.items():
        log = (case / f"log.{SOLVER}").read_text()
        assert "Stochastic rebound" not in log and not (case / HITS).exists()
        post = compare_rebounds.read_patch_post(case)
        standard_hits[np_] = sum(len(r["time"]) for r in post.values())
        assert standard_hits[np_] > 5000
    ours = {1: serial_case, 2: parallel_case}
    infos = {np_: _cloud_info((case / f"log.{SOLVER}").read_text()) for np_, case in ours.items()}
    with capsys.disabled():
        print("\nhopperRebound solver time (s, CPU (ExecutionTime, rank 0) and wall; one run each, on a machine "
              "others may share; the specular bounce keeps the parcels fast, so they cross more cells and hit the "
              "walls more often):")
        for np_ in (1, 2):
            cpu = (_cpu_seconds(ours[np_]), _cpu_seconds(standard_cases[np_]))
            wall = (_timings(ours[np_])[SOLVER], _timings(standard_cases[np_])[SOLVER])
            info = infos[np_]
            print(f"  {np_} rank(s): stochasticRebound auto CPU {cpu[0]:.2f}, wall {wall[0]:.2f} ({info['hits']} wall "
                  f"hits, {info['direct']} by the direct model at {info['direct_us']:.1f} us each); "
                  f"standardWallInteraction CPU {cpu[1]:.2f}, wall {wall[1]:.2f} ({standard_hits[np_]} wall hits); "
                  f"CPU ratio {cpu[0] / cpu[1]:.2f}")
            assert min(cpu + wall) > 0


def test_erosion_beside_the_rebound_models(serial_case, standard_cases, tmp_path, capsys):
    """OpenFOAM's particleErosion runs beside stochasticRebound and beside the stock bounce; the specular
    bounce keeps every parcel at full speed into its next hits (erosion grows as |V⁻|²), ours takes 40 % of
    it away on average (s ≈ 0.6): the specular run erodes more."""
    ours, specular = (compare_rebounds.erosion_summary(c) for c in (serial_case, standard_cases[1]))
    with capsys.disabled():
        print(f"\nerosion of the hopper's walls: stochasticRebound auto {ours['faces_eroded']} of {ours['faces']} "
              f"faces, {ours['total_m3']:.3e} m3; standardWallInteraction {specular['faces_eroded']} faces, "
              f"{specular['total_m3']:.3e} m3")
    for e in (ours, specular):
        assert e["faces"] == 512 and 100 < e["faces_eroded"] < 512 and 0 < e["total_m3"] < 1e-8, e
    assert specular["total_m3"] > 1.5 * ours["total_m3"], (ours, specular)
    png = tmp_path / "erosion.png"
    compare_rebounds.plot_erosion({"specular": standard_cases[1], "ours": serial_case}, png)
    assert png.stat().st_size > 10_000


# ----------------------------------------------------------------------------- the work on the walls

CLOUD = "kinematicCloud"
END = "0.005"   # the runs' last (written) time


def _patches_of(root: Path) -> list:
    """The patches of the mesh of ``root`` (a case or a processor folder) that are not processor patches."""
    boundary = (root / "constant" / "polyMesh" / "boundary").read_text()
    return [name for name, kind in re.findall(r"\n\s*(\w+)\s*\{\s*type\s+(\w+);", boundary) if kind != "processor"]


def _work_fields(root: Path, time: str) -> dict:
    """The work fields of ``root``'s mesh at ``time``: patch -> {normal, tangential, hits: values per face}; each
    field zero inside (checked)."""
    for name in compare_rebounds.WORK_FIELDS.values():
        text = (root / time / f"{CLOUD}:{name}").read_text()
        assert "\ninternalField   uniform 0;\n" in text, name
    return {patch: {key: compare_rebounds.read_patch_field(root, f"{CLOUD}:{name}", patch, time)
                    for key, name in compare_rebounds.WORK_FIELDS.items()} for patch in _patches_of(root)}


def _record_sums(work: dict, rows, fields: dict) -> dict:
    """The sums per face of the wall work records at ``rows`` (a boolean mask) with work, in the layout of
    :func:`_work_fields`'s ``fields``: mass × W_n, mass × W_t (J) and the number of hits."""
    rows = rows & np.isfinite(work["Wn"]) & np.isfinite(work["Wt"])
    sums = {}
    for patch, values in fields.items():
        n = len(values["hits"])
        sums[patch] = {key: compare_rebounds.face_sums(work["patch"][rows], work["face"][rows], weights, patch, n)
                       for key, weights in (("normal", (work["mass"] * work["Wn"])[rows]),
                                            ("tangential", (work["mass"] * work["Wt"])[rows]),
                                            ("hits", np.ones(rows.sum())))}
    return sums


def _check_fields(fields: dict, expected: dict) -> None:
    """Each field's values on each patch are ≥ 0, the hits those of ``expected`` exactly, the work its sums to
    the 8 digits the fields are written with, and zero on every face no hit with work reached."""
    for patch, values in fields.items():
        assert np.array_equal(values["hits"], expected[patch]["hits"]), patch
        for key in ("normal", "tangential"):
            assert np.all(values[key] >= 0) and np.all(values[key][expected[patch]["hits"] == 0] == 0), (patch, key)
            np.testing.assert_allclose(values[key], expected[patch][key], rtol=6e-8, atol=0, err_msg=f"{patch} {key}")


def _field_totals(fields: dict) -> tuple:
    return tuple(sum(float(v[key].sum()) for v in fields.values()) for key in ("normal", "tangential"))


def test_the_work_on_the_walls_sums_the_hits_face_by_face(serial_case):
    """The work fields of the serial run at its end, <cloud>:stochasticReboundWorkNormal, ...WorkTangential (J)
    and ...Hits, against its wall work records (wallWork_0.csv, a row per row of the hits file): per face of every
    patch, the sums of mass × W_n and mass × W_t and the number of hits, zero where no hit was; the log's totals
    are the fields' and the per-patch summary's means per hit the records'; every hit of a table of format 4.1
    gives work, ≥ 0, and on the parcels' first hits (Ω⁻ = 0) no more than the translational kinetic energy they
    lose."""
    hits, _ = compare_rebounds.read_hits(serial_case)
    work = compare_rebounds.read_wall_work(serial_case, hits)
    assert np.all(np.isfinite(work["Wn"])) and np.all(np.isfinite(work["Wt"]))
    assert np.all(work["Wn"] >= 0) and np.all(work["Wt"] >= 0) and np.all(work["mass"] > 0)
    fields = _work_fields(serial_case, END)
    assert set(fields) == {"walls", "frontAndBack", "inlet", "outlet"}
    _check_fields(fields, _record_sums(work, np.ones(len(work["face"]), bool), fields))
    assert min(int(np.sum(fields[p]["hits"] > 0)) for p in ("walls", "frontAndBack")) > 200
    log = (serial_case / f"log.{SOLVER}").read_text()
    info = _cloud_info(log)
    assert info["no_work"] == 0
    assert (info["work_normal"], info["work_tangential"]) == pytest.approx(_field_totals(fields), rel=1e-6)
    for patch, row in compare_rebounds.patch_summary(log).items():
        on = work["patch"] == patch
        if row["roughness"] is None:
            assert row["work_normal_mean"] is row["work_tangential_mean"] is None and not on.any(), patch
            continue
        assert row["no_work"] == 0 and row["hits"] == on.sum()
        assert (row["work_normal_mean"], row["work_tangential_mean"]) == pytest.approx(
            (work["Wn"][on].mean(), work["Wt"][on].mean()), rel=1e-5), patch
    # W_n + W_t = E⁻ − E⁺: from rest (Ω⁻ = 0), E⁻ = |V⁻|²/2 and E⁺ ≥ |V⁺|²/2
    still = ~hits["Win"].any(axis=1)
    drop = 0.5 * (np.sum(hits["V"] ** 2, axis=1) - np.sum(hits["Vout"] ** 2, axis=1))
    energy = 0.5 * np.sum(hits["V"] ** 2, axis=1)
    assert still.sum() > 5000
    assert np.all((work["Wn"] + work["Wt"])[still] <= drop[still] + 1e-9 * energy[still])


def test_each_rank_adds_the_work_of_its_own_faces(parallel_case):
    """On 2 ranks each rank's fields (processor<r>/0.005, its own faces) hold the work of its own hits; the log's
    totals are both ranks'."""
    hits, _ = compare_rebounds.read_hits(parallel_case)
    work = compare_rebounds.read_wall_work(parallel_case, hits)
    totals = np.zeros(2)
    for rank in (0, 1):
        root = parallel_case / f"processor{rank}"
        fields = _work_fields(root, END)
        expected = _record_sums(work, hits["rank"] == rank, fields)
        _check_fields(fields, expected)
        assert sum(int(v["hits"].sum()) for v in fields.values()) > 1000, rank
        totals += _field_totals(fields)
    info = _cloud_info((parallel_case / f"log.{SOLVER}").read_text())
    assert (info["work_normal"], info["work_tangential"]) == pytest.approx(tuple(totals), rel=1e-6)


def test_the_work_on_the_walls_beside_the_erosion_model(serial_case, tmp_path, capsys):
    """compare_rebounds' summary and figure of the work on the walls beside particleErosion's Q of the same run:
    the totals are the log's; the cutting work W_t ranks the faces as Finnie's cutting erosion does (Spearman's
    rank correlation over the faces hit 0.91 on the side and funnel walls, 0.97 on the front and back planes,
    where the grains graze)."""
    summary = compare_rebounds.wall_work_summary(serial_case)
    with capsys.disabled():
        print("\n" + compare_rebounds.wall_work_report(summary))
    info = _cloud_info((serial_case / f"log.{SOLVER}").read_text())
    every = summary["all"]
    assert (every["normal"]["total"], every["tangential"]["total"]) == pytest.approx(
        (info["work_normal"], info["work_tangential"]), rel=1e-6)
    assert every["hits"] == info["hits"]
    for patch in ("walls", "frontAndBack"):
        s = summary[patch]
        assert s["spearman_tangential_Q"] > 0.8 and s["spearman_normal_Q"] > 0.5, (patch, s)
        assert 0 < s["faces_hit"] < s["faces"]
    png = tmp_path / "wall_work.png"
    compare_rebounds.plot_wall_work(serial_case, png)
    assert png.stat().st_size > 10_000


@pytest.fixture(scope="session")
def trapping_table(runs_folder):
    """The case's grid with n_max = 2 (cases.TRAPPING_TABLE_CONFIG)."""
    return runs_folder / cases.TABLES["trapping"]


@pytest.mark.parametrize("policy", ["stick", "remove"])
def test_trapped_parcels_stick_or_are_removed(policy, runs_folder, trapping_table):
    """Trapped parcels stick or are removed; the stick run keeps each parcel's grain (the default), the remove
    run draws a new grain per hit (grain perHit: no key, no shape recorded), and both trap as the sampler does."""
    grain = "kept" if policy == "stick" else "perHit"
    case = _case(runs_folder, f"trapped_{policy}")
    hits, headers = compare_rebounds.read_hits(case)
    assert [h["grain"] for h in headers] == [grain]
    if grain == "perHit":
        assert (hits["key"] == -1).all() and set(hits["shape"].tolist()) == {""} and np.isnan(hits["ratio_ba"]).all()
    else:
        assert (hits["key"] >= 0).all() and set(hits["shape"].tolist()) == {"prism"}
    log = (case / f"log.{SOLVER}").read_text()
    info, parcels = _cloud_info(log), _cloud_parcels(log)
    assert info["trapped"] > 200, info
    assert f"trapped, {'stuck' if policy == 'stick' else 'removed'}" in log
    # a stuck parcel stays in the cloud, a removed one leaves it (escapes count the open patches only)
    removed = info["trapped"] if policy == "remove" else 0
    assert parcels["current"] == parcels["added"] - parcels["escaped"] - removed, (parcels, info)
    if policy == "stick":
        # ... inactive and at rest on the wall
        last = max((p for p in case.iterdir() if re.fullmatch(r"[0-9.e-]+", p.name) and p.name != "0"),
                   key=lambda p: float(p.name))
        cloud = last / "lagrangian" / "kinematicCloud"
        active = np.array(re.findall(r"^\s*([01])\s*$", (cloud / "active").read_text().split("(", 1)[1],
                                     re.M), dtype=int)
        assert np.sum(active == 0) == info["trapped"]
    # the solver traps as often as the sampler does at the same incident states
    res = compare_rebounds.compare(case, classifier=False)
    print(compare_rebounds.report(res))
    assert res["trapped"] == info["trapped"] and res["failed"] == info["failed"]
    assert info["outside"] == pytest.approx(res["paths"]["outside"], abs=2)
    # KS and the fractions not rebounded on both paths: the direct model with the table's n_max = 2 traps
    # too, as often as surrogate's direct model does
    table, direct = res["comparison"].agreement["table"], res["comparison"].agreement["direct"]
    assert table.ok and direct.ok, res["comparison"]
    assert direct.not_rebounded[0] > 0, direct


def test_mppic_cloud_selects_and_runs_the_model(openfoam_build, case_table, tmp_path):
    """MPPICFoam's cloud (basicKinematicMPPICCloud): the stock v1912 tutorial MPPICFoam/column with the
    parcels thrown down at 60 m/s onto its bottom wall for 1 ms."""
    tutorial = cases.tutorials() / "lagrangian" / "MPPICFoam" / "column"
    case = tmp_path / "column"
    shutil.copytree(tutorial, case)
    props = case / "constant" / "kinematicCloudProperties"
    text = props.read_text().replace("U0              (0 0 0);", "U0              (0 0 -60);")
    text, n = re.subn(r"\n    patchInteractionModel localInteraction;\n",
                      "\n    patchInteractionModel stochasticRebound;\n    stochasticReboundCoeffs\n    {\n"
                      f"        table \"{case_table}\";\n        shape prism;\n        seed 5;\n    }}\n", text)
    assert n == 1 and "(0 0 -60)" in text
    props.write_text(text)
    control = case / "system" / "controlDict"
    text = re.sub(r"\nendTime\s+[^;]+;", "\nendTime         0.001;", control.read_text())
    control.write_text(text.replace("\napplication", '\nlibs ("libstochasticRebound.so");\n\napplication', 1))
    env = dict(os.environ, RBS_OPENFOAM_DIR=str(OPENFOAM_DIR))
    script = (f". {OPENFOAM_DIR / 'openfoam-env.sh'} && blockMesh > log.blockMesh 2>&1 && "
              "MPPICFoam > log.MPPICFoam 2>&1")
    _run(["bash", "-c", script], cwd=case, env=env)
    log = (case / "log.MPPICFoam").read_text()
    assert "MPPIC" in log and "End" in log
    info_block = log[log.rindex("Stochastic rebound"):]
    info = _cloud_info(log)
    assert info["hits"] > 200 and info["rebounded"] + info["invalid"] <= info["hits"] and info["invalid"] == 0, \
        info_block[:600]
    # MPPIC parcels carry no spin: the spin memory (spinRelaxation auto, the default) gives a parcel's later hits
    # the spin of its last rebound, so under auto the direct model answers the hits outside the table's grid and
    # hits that arrive with a remembered spin
    assert "spin memory (spinRelaxation) = auto" in info_block
    assert info["outside"] <= info["direct"] <= info["outside"] + info["remembered"], info


@pytest.fixture(scope="session")
def patches_case(runs_folder):
    """The case with a wall per patch (cases.CASES["patches"]): frontAndBack split into front and back; walls on
    the elastic wall's table, front on the lossy wall's (method table, trapped remove), back OpenFOAM's stock
    rebound, inlet the elastic table again, outlet named by no entry."""
    return _case(runs_folder, "patches")


def test_each_patch_does_what_its_entry_says(patches_case, capsys):
    """The per-patch summary: every patch with its interaction, every hit with one fate, the tables' hits by path
    and outside the grid by cause (as the hits file's incident states give them); the stock rebound exact; each
    table opened once."""
    log = (patches_case / f"log.{SOLVER}").read_text()
    with capsys.disabled():
        print("\n" + log[log.rindex("    Stochastic rebound ("):log.rindex("    Rotational kinetic energy")])
    rows = compare_rebounds.patch_summary(log)
    elastic, lossy = cases.WALLS["elastic"]["name"], cases.WALLS["lossy"]["name"]
    assert {name: r["interaction"] for name, r in rows.items()} == {
        "walls": f"stochasticRebound, wall {elastic}", "front": f"stochasticRebound, wall {lossy}",
        "back": "rebound, e 0.5, mu 0.2", "inlet": f"stochasticRebound, wall {elastic}",
        "outlet": "escape (open patch no entry names: OpenFOAM's default)"}
    for name, r in rows.items():
        assert r["hits"] == r["rebounded"] + r["stuck"] + r["removed"] + r["escaped"] + r["invalid"], (name, r)
    drawn = {name: rows[name] for name in ("walls", "front", "inlet")}
    for name, r in drawn.items():
        assert r["hits"] == r["table"] + r["direct"] + r["invalid"] and r["escaped"] == 0, (name, r)
        assert r["trapped"] + r["failed"] == r["stuck"] + r["removed"], (name, r)
        # the tables' walls are smooth: one wall hit per hit
        assert r["roughness"] == 0 and r["hit_again"] == r["at_cap"] == 0, (name, r)
    assert rows["back"]["roughness"] is None and rows["outlet"]["roughness"] is None
    walls, front, back, outlet = rows["walls"], rows["front"], rows["back"], rows["outlet"]
    # walls: method auto, the spinning hits to the direct model; front: method table, the trapped removed
    assert walls["direct"] > 500 and walls["table"] > 1000 and walls["stuck"] == walls["trapped"] == 0, walls
    assert front["direct"] == 0 and front["stuck"] == 0 and front["removed"] == front["trapped"] > 100, front
    assert back["hits"] == back["rebounded"] > 1000 and outlet["hits"] == outlet["escaped"] > 100, (back, outlet)
    # the totals of the tables' hits are the drawing patches' sums
    info = _cloud_info(log)
    for key in ("hits", "table", "direct", "rebounded", "trapped", "failed", "invalid"):
        assert info[key] == sum(r[key] for r in drawn.values()), key
    # OpenFOAM's own count of parcels leaving: a hit on a patch not a wall (its comment: whatever the interaction
    # does); the parcels left: those added, less the outlet's escapes and the front's removals
    parcels = _cloud_parcels(log)
    assert parcels["escaped"] == outlet["hits"] + rows["inlet"]["hits"]
    assert parcels["current"] == parcels["added"] - outlet["escaped"] - front["removed"], (parcels, rows)
    # the elastic table, the global one, and named by another path for inlet, is opened once
    assert log.count("stochasticRebound: opened the table") == 2

    hits, headers = compare_rebounds.read_hits(patches_case)
    assert headers[0]["table"].endswith("constant/rebound_table.h5")
    # every hit the adapter answered is recorded, with its patch's interaction and wall, and patchPostProcessing
    # saw the same hits (the outlet's escapes are OpenFOAM's, not recorded)
    recorded = {str(p): int(np.sum(hits["patch"] == p)) for p in np.unique(hits["patch"])}
    assert recorded == {name: rows[name]["hits"] for name in ("walls", "front", "back")}
    for name, interaction, wall in (("walls", "stochasticRebound", elastic), ("front", "stochasticRebound",
                                    lossy.replace(",", ";")), ("back", "rebound", "")):
        on = hits["patch"] == name
        assert set(hits["interaction"][on]) == {interaction} and set(hits["wall"][on]) == {wall}, name
    r = compare_rebounds.check_records(hits, compare_rebounds.read_patch_post(patches_case))
    assert r["hits_per_patch_adapter"] == r["hits_per_patch_patchPostProcessing"], r
    assert r["parcels_mismatched"] == 0 and r["max_relative_difference_of_incident_velocity"] < 1e-5, r
    # back: localInteraction's rebound, V⁺ = V⁻ − (1 + e) Vn n − mu V_t (n out of the domain), no draw
    on = hits["patch"] == "back"
    V, n = hits["V"][on], -hits["n"][on]
    Vn = np.einsum("ij,ij->i", V, n)[:, None]
    np.testing.assert_allclose(hits["Vout"][on], V - 1.5 * Vn * n - 0.2 * (V - Vn * n), rtol=0, atol=1e-9 * 150)
    assert (hits["path"][on] == -1).all() and (hits["status"][on] == 0).all() and np.isnan(hits["u0"][on]).all()
    # the hits outside each table's grid by cause (both tables: α1 5-90°, |V⁻| 80-140 m/s); the adapter's count
    # of hits at the grid's edge itself may differ by a rounding
    for name in ("walls", "front"):
        on = hits["patch"] == name
        alpha1, speed, _ = incident_states(hits["V"][on], hits["n"][on], hits["a"][on], hits["Win"][on])
        for key, count in (("speed_below", np.sum(speed < 80)), ("speed_above", np.sum(speed > 140)),
                           ("alpha1_outside", np.sum(alpha1 < 5))):
            assert rows[name][key] == pytest.approx(count, abs=2), (name, key)
        assert rows[name]["speed_below"] > 0, name
    # α1 below the grid: the grazing hits of front; the walls see 0-2 of their 4000 hits there
    assert front["speed_above"] > 0 and front["alpha1_outside"] > 0
    # the hits outside the speeds the wall law holds over: the elastic wall's (walls) 60-200 m/s, the lossy
    # wall (front) states none
    on = hits["patch"] == "walls"
    _, speed, _ = incident_states(hits["V"][on], hits["n"][on], hits["a"][on], hits["Win"][on])
    outside = int(np.sum((speed < 60.0) | (speed > 200.0)))
    assert rows["walls"]["outside_law"] == pytest.approx(outside, abs=2) and outside > 0
    assert front["outside_law"] == 0


def test_each_wall_draws_from_its_own_table(patches_case, runs_folder):
    """The hits of walls follow the elastic wall's law and those of front the lossy wall's (surrogate on the same
    incident states, per patch); the lossy wall's law at the walls' hits is not theirs and slower, as its
    larger k predicts; the hits of two walls are not compared with one table."""
    elastic, lossy = (runs_folder / cases.TABLES[name] for name in ("elastic", "lossy"))
    for patch, table in (("walls", elastic), ("front", lossy)):
        res = compare_rebounds.compare(patches_case, table, classifier=False, patches=[patch])
        assert res["comparison"].ok, (patch, res["comparison"].lines())
    hits, headers = compare_rebounds.read_hits(patches_case)
    record = solver_hits(compare_rebounds.drawn_hits(hits, ["walls"]), headers[0])
    on_table = record.take(record.path == PATH_TABLE)
    other = agreement(on_table, surrogate_answers(load(lossy), on_table, method="table"), classifier=False)
    assert not other.ks_ok and other.mean_speed_ratio[0] > other.mean_speed_ratio[1] + 0.05, other
    with pytest.raises(ValueError, match="of 2 walls"):
        compare_rebounds.compare(patches_case, elastic, classifier=False)


def test_the_work_of_a_wall_per_patch(patches_case):
    """With a wall per patch the fields hold the work of the hits the tables and the direct model answered on
    their patches, the trapped hits' on the lossy wall (trapped remove) included, and nothing of the stock
    rebound's (back: no work recorded, zero fields, no mean in the summary) or of the open patch's."""
    hits, _ = compare_rebounds.read_hits(patches_case)
    work = compare_rebounds.read_wall_work(patches_case, hits)
    drawn = hits["interaction"] == compare_rebounds.HITS_TITLE
    assert np.all(np.isfinite(work["Wn"][drawn]) & np.isfinite(work["Wt"][drawn]))
    assert np.all(np.isnan(work["Wn"][~drawn]) & np.isnan(work["Wt"][~drawn])) and (~drawn).sum() > 1000
    trapped = hits["status"] == compare_rebounds.STATUS_TRAPPED
    assert trapped.sum() > 100 and np.all(work["Wn"][trapped] + work["Wt"][trapped] > 0)
    fields = _work_fields(patches_case, END)
    _check_fields(fields, _record_sums(work, drawn, fields))
    for patch in ("back", "outlet"):
        assert not any(fields[patch][key].any() for key in fields[patch]), patch
    rows = compare_rebounds.patch_summary((patches_case / f"log.{SOLVER}").read_text())
    assert rows["back"]["work_normal_mean"] is rows["outlet"]["work_tangential_mean"] is None
    for patch in ("walls", "front"):
        on = work["patch"] == patch
        assert rows[patch]["work_tangential_mean"] == pytest.approx(work["Wt"][on].mean(), rel=1e-5), patch


def test_a_rough_patch_hits_again_and_a_smooth_one_keeps_its_bits(runs_folder, openfoam_build):
    """cases.CASES["rough"]: walls with roughnessDeg 10, frontAndBack on the same table's smooth wall. The log
    states each patch's roughness; some of the walls' hits hit the wall again, none of frontAndBack's, whose
    paths follow the rule of auto; compare_rebounds refuses the rough patch. Every
    hit takes 13 uniforms of the rank's stream, rough or not, so the run's hits replay through the C library
    (rbs_rebound on the recorded V⁻, n and grain key, with the stream's uniforms): the parcels' first hits
    (Ω⁻ = 0, whose V⁺ does not depend on the recorded a's rounding) give the recorded V⁺ bit for bit,
    frontAndBack's with roughness 0 (the smooth law), the walls' with roughness 10 where the replay
    hit the wall once by the table (a hit that hits again goes on spinning, with a); with roughness 0 none of
    the walls' does."""
    from tests.helpers.native_library import PATH_TABLE as C_PATH_TABLE
    from tests.helpers.native_library import U_PER_DRAW, Native

    case = _case(runs_folder, "rough")
    log = (case / f"log.{SOLVER}").read_text()
    assert re.search(rf"\n        walls: stochasticRebound, .*, roughness {cases.ROUGHNESS_DEG} deg\n", log)
    assert re.search(r"\n        frontAndBack: stochasticRebound, .*, roughness 0 deg \(the table's\)\n", log)
    rows, info = compare_rebounds.patch_summary(log), _cloud_info(log)
    rough, smooth = rows["walls"], rows["frontAndBack"]
    assert rough["roughness"] == cases.ROUGHNESS_DEG and smooth["roughness"] == 0, rows
    # α1 of 10-60° at Δγ 10° hits again 2-5 % of the time (docs/model.md §12)
    assert 0.01 * rough["hits"] < rough["hit_again"] < 0.2 * rough["hits"] and rough["at_cap"] <= rough["hit_again"]
    assert smooth["hit_again"] == smooth["at_cap"] == 0 and smooth["hits"] > 5000, smooth
    # a rough hit is counted by the path of its last wall hit: one path each, as on a smooth wall
    for r in (rough, smooth):
        assert r["hits"] == r["table"] + r["direct"] + r["invalid"] and r["invalid"] == 0, r
    assert info["hits"] == rough["hits"] + smooth["hits"] == info["table"] + info["direct"], info
    # the smooth patch's paths follow the rule of method auto; a rough patch is not compared with surrogate
    paths = compare_rebounds.compare_paths(case, patches=["frontAndBack"])
    assert paths["spinning_not_direct"] == paths["outside_not_direct"] == paths["still_inside_not_table"] == 0
    with pytest.raises(ValueError, match=rf"the patches walls \(roughnessDeg {cases.ROUGHNESS_DEG}\) are rough"):
        compare_rebounds.compare(case, classifier=False)

    hits, headers = compare_rebounds.read_hits(case)
    native = Native(_cache() / "native-install" / "lib")
    table = native.table(case / "constant" / "rebound_table.h5")
    mix = table.mix("prism")
    state = native.seed(headers[0]["seed"], 0)
    replayed = {}
    for i in range(len(hits["time"])):
        u, state = native.fill(state, U_PER_DRAW)
        assert u[0] == hits["u0"][i], i
        if hits["Win"][i].any():
            continue
        patch = str(hits["patch"][i])
        for roughness in (0.0, float(cases.ROUGHNESS_DEG)):
            result, _ = table.hit(mix, hits["V"][i], hits["Win"][i], hits["n"][i], hits["a"][i], u,
                                  key=int(hits["key"][i]), roughness_deg=roughness)
            same = np.array_equal(np.array(result.V[:]), hits["Vout"][i])
            once = result.wall_hits == 1 and result.path == C_PATH_TABLE
            replayed.setdefault((patch, roughness), []).append((same, once))
    smooth_bits, smooth_rough = (np.array(replayed["frontAndBack", r]) for r in (0.0, cases.ROUGHNESS_DEG))
    rough_smooth, rough_bits = (np.array(replayed["walls", r]) for r in (0.0, cases.ROUGHNESS_DEG))
    assert len(smooth_bits) > 3000 and smooth_bits[:, 0].all() and not smooth_rough[:, 0].any()
    once = rough_bits[:, 1]
    assert once.sum() > 0.9 * len(rough_bits) > 1000 and rough_bits[once, 0].all()
    assert not rough_smooth[:, 0].any()


def test_a_rough_wall_widens_the_rebound_angles(runs_folder, serial_case, capsys):
    """rebound_spread.py on the serial run and on cases.CASES["rough"] (the same case, walls rough): the parcels'
    first hits (Ω⁻ = 0) meet the walls in the same incident states in both runs, and on the rough walls their
    rebound angle from the wall spreads wider (sd 15.1° → 16.8°; with seeds 1 and 2, 15.4° → 16.4° and 15.4° →
    16.7°), out of the impact plane too; frontAndBack, smooth in both, keeps its spread."""
    import rebound_spread

    smooth, rough = (rebound_spread.spread(case) for case in (serial_case, _case(runs_folder, "rough")))
    with capsys.disabled():
        for name, run in (("smooth", smooth), ("rough walls", rough)):
            print(f"\nhopperRebound, {name}: " + "; ".join(
                f"{patch} roughness {p['roughness']:g}, {p['hit_again']} of {p['hits']} hits hit again, first hits' "
                f"a2 sd {p['first']['alpha2_sd']:.2f}, b2 sd {p['first']['beta2_sd']:.2f}" for patch, p in run.items()))
    walls = smooth["walls"]["first"], rough["walls"]["first"]
    assert walls[0]["n"] == walls[1]["n"] > 1000
    assert walls[1]["alpha2_sd"] > walls[0]["alpha2_sd"] + 0.8 and walls[1]["beta2_sd"] > walls[0]["beta2_sd"] + 1
    sides = smooth["frontAndBack"]["first"], rough["frontAndBack"]["first"]
    assert sides[0]["n"] == sides[1]["n"] and abs(sides[1]["alpha2_sd"] - sides[0]["alpha2_sd"]) < 0.5
    assert smooth["walls"]["hit_again"] == 0 < rough["walls"]["hit_again"]


def _refused(case_table, folder, edit, solver=SOLVER) -> str:
    """The solver's log of the case edited by ``edit``, which must stop with a FatalIOError before a time step."""
    case = cases.copy_case(folder)
    edit(case)
    proc = cases.run_allrun(case, case_table)
    log = (case / f"log.{solver}").read_text()
    assert proc.returncode != 0 and "FOAM FATAL IO ERROR" in log, log[-3000:]
    assert "stochasticReboundCoeffs" in log and "Time = " not in log.split("FOAM FATAL IO ERROR")[0]
    return log


def _patches(entries: str):
    return lambda case: cases.insert_coeff(case, f"patches ( {entries} );")


@pytest.mark.parametrize("edit, words", [
    (_patches("walls { type stick; }"),
     ["wall patch frontAndBack is named by no entry of patches in stochasticReboundCoeffs: say what each wall does"]),
    (_patches("walls { type bounce; } frontAndBack { type stick; }"),
     ["patches entry walls in stochasticReboundCoeffs: type bounce is unknown; the types are stochasticRebound, "
      "rebound, stick, escape"]),
    (_patches("walls { type stick; } frontAndBack { type rebound; e 1.5; mu 0.1; }"),
     ["patches entry frontAndBack in stochasticReboundCoeffs: e must be in [0, 1], not 1.5"]),
    (_patches('walls { type stochasticRebound; table "constant/steel.h5"; } frontAndBack { type stick; }'),
     ["patches entry walls in stochasticReboundCoeffs: cannot open the rebound table", "constant/steel.h5"]),
    (_patches("wals { type stick; } walls { type stick; } frontAndBack { type stick; }"),
     ["patches entry wals in stochasticReboundCoeffs: no patch or patch group is named wals; the patches are "
      "walls, frontAndBack, inlet, outlet"]),
    (_patches("walls { type stochasticRebound; shape cube; } frontAndBack { type stick; }"),
     ["patches entry walls in stochasticReboundCoeffs: bad shape cube for the table"]),
    (_patches("walls { type stochasticRebound; } frontAndBack { type escape; e 0.5; }"),
     ["unknown entry e in patches entry frontAndBack in stochasticReboundCoeffs; the entries are type"]),
    (_patches("walls { type stochasticRebound; roughnessDeg 50; } frontAndBack { type stick; }"),
     ["patches entry walls in stochasticReboundCoeffs: roughnessDeg must be in [0, 45] (degrees), not 50"]),
])
def test_bad_patches_entries_stop_before_the_first_step(openfoam_build, case_table, tmp_path_factory, edit,
                                                        words):
    """A wall no entry names, an unknown type, e outside [0, 1], a table file missing, a name no patch has, a
    shape the table lacks, an entry the type does not read and a roughness outside [0, 45] degrees: each a
    one-line FatalIOError naming the entry and what is allowed, before any time step."""
    log = _refused(case_table, tmp_path_factory.mktemp("bad_patches"), edit)
    assert log.count("FOAM FATAL IO ERROR") == 1, log[-3000:]
    for word in words:
        assert word in log, log[-3000:]


@pytest.mark.parametrize("edit, words", [
    (lambda c: cases.insert_coeff(c, "interpolaton stochastic;"), ["unknown entry interpolaton", "interpolation"]),
    (lambda c: cases.insert_coeff(c, "weights { prism 1; }"), ["shape and weights are both given"]),
    (lambda c: cases.set_coeff(c, "maxHitRecords", "-1"), ["maxHitRecords must be >= 0, not -1"]),
    (lambda c: cases.insert_coeff(c, "hitsEvery 2.5;"), ["hitsEvery must be an integer >= 1, not 2.5"]),
    (lambda c: cases.insert_coeff(c, "method tabel;"), ["method must be auto, table or direct, not tabel"]),
    (lambda c: cases.insert_coeff(c, "grain once;"), ["grain must be kept or perHit, not once"]),
    (lambda c: cases.insert_coeff(c, "spinRelaxation fast;"),
     ["spinRelaxation must be auto, off or a time in s > 0, not fast"]),
    (lambda c: cases.insert_coeff(c, "spinRelaxation -1;"),
     ["spinRelaxation must be auto, off or a time in s > 0, not -1"]),
    (lambda c: cases.set_weights(c, "prism { weight 1; halfSizeFactor 0; }"),
     ["weights entry prism in stochasticReboundCoeffs: halfSizeFactor must be > 0, not 0"]),
    (lambda c: cases.set_weights(c, "prism { weight 1; size 2; }"),
     ["unknown entry size in weights entry prism in stochasticReboundCoeffs; the entries are weight, halfSizeFactor"]),
    (lambda c: (cases.set_weights(c, "prism { weight 1; halfSizeFactor 1.4; }"),
                cases.insert_coeff(c, "grain perHit;")),
     ["halfSizeFactor per shape in weights needs grain kept, not perHit"]),
])
def test_dictionary_contradictions_and_unknown_entries_are_fatal(openfoam_build, case_table, tmp_path_factory,
                                                                 edit, words):
    """A misspelled entry silently fell back to its default, shape was ignored under weights, and
    maxHitRecords -1 wrote nothing: each is now a FatalIOError naming the entry, before any time step (so is a
    hitsEvery that is no integer >= 1)."""
    log = _refused(case_table, tmp_path_factory.mktemp("bad_dictionary"), edit)
    for word in words:
        assert word in log, log[-3000:]


def test_spin_relaxation_auto_needs_a_gas_viscosity(openfoam_build, case_table, tmp_path_factory):
    """spinRelaxation auto (the default) in a kinematic cloud whose gas has no viscosity: stopped before the first
    step, naming the entry and what to give instead."""
    def no_viscosity(case):
        cases._kinematic(case)
        thermo = case / "constant" / "thermophysicalProperties"
        thermo.write_text(thermo.read_text().replace(f"mu {cases.AIR_MU};", "mu 0;"))
    log = _refused(case_table, tmp_path_factory.mktemp("no_viscosity"), no_viscosity, cases.KINEMATIC_SOLVER)
    assert ("spinRelaxation auto needs the gas viscosity, but the cloud's mu field is not > 0 everywhere (min 0): "
            "give spinRelaxation as a time in s, or off") in log, log[-3000:]


# ----------------------------------------------------------------------------- every cloud family

@pytest.mark.parametrize("name", list(cases.FAMILY_RUNS))
def test_every_cloud_family_selects_the_model_and_draws(runs_folder, name):
    """The stock tutorials of the thermo (coalChemistryFoam's limestone), reacting-multiphase (reactingParcelFoam)
    and coal, heterogeneous reacting and spray clouds (cases.FAMILY_RUNS), aimed at a wall for a few steps: each
    cloud selects stochasticRebound, its parcels hit walls and rebound, and as they carry no spin the spin memory
    (auto: the gas thermo's viscosity) stands in for it."""
    case, done = cases.read_runs(runs_folder)[name]
    background.succeeded(done)
    _, solver, clouds, _, _ = cases.FAMILY_RUNS[name]
    log = (case / f"log.{solver}").read_text()
    assert log.count("Selecting patch interaction model stochasticRebound") == len(clouds) and "\nEnd\n" in log
    for cloud in clouds:
        info = _cloud_info(log, cloud)
        assert info["hits"] > 0, (cloud, info)
        assert info["hits"] == info["rebounded"] + info["trapped"] + info["failed"] + info["invalid"], (cloud, info)
        assert info["hits"] == info["table"] + info["direct"] + info["invalid"], (cloud, info)
        assert info["remembered"] is not None and info["held"] > 0, (cloud, info)


# ----------------------------------------------------------------------------- spin memory

KINEMATIC_LOG = f"log.{cases.KINEMATIC_SOLVER}"
SAND_DENSITY = 2650.0   # the case's rho0


def _parcel_keys(hits: dict) -> np.ndarray:
    return (hits["origProc"].astype(np.int64) << 32) | hits["origId"]


def _next_hits(hits: dict):
    """Each parcel's consecutive hits on one rank's records (a serial run): the rows (i, j), j the next hit after
    i (the records of a rank are in the order of the hits)."""
    keys = _parcel_keys(hits)
    order = np.lexsort((np.arange(len(keys)), keys))
    same = keys[order][1:] == keys[order][:-1]
    return order[:-1][same], order[1:][same]


def _check_relaxation(hits: dict, i, j, tau, delta_t: float, rtol: float = 1e-12, time_slack: float = 1e-12) -> None:
    """Ω⁻ of hit j is Ω⁺ of hit i relaxed over the flight: the same direction (to rtol), |Ω⁻| = |Ω⁺| exp(−Δt/τ)
    with Δt between the hits' time steps' ends ±1 step (a hit's time is its step's end in the records; time_slack
    for times read back from a file)."""
    w_out, w_in = hits["Wout"][i], hits["Win"][j]
    np.testing.assert_allclose(w_in / np.linalg.norm(w_in, axis=1)[:, None],
                               w_out / np.linalg.norm(w_out, axis=1)[:, None], rtol=0, atol=10 * rtol + 1e-14)
    flight = -tau * np.log(np.linalg.norm(w_in, axis=1) / np.linalg.norm(w_out, axis=1))
    steps = hits["time"][j] - hits["time"][i]
    slack = rtol * tau + time_slack
    assert np.all(flight >= steps - delta_t - slack) and np.all(flight <= steps + delta_t + slack), \
        (np.min(flight - steps + delta_t), np.max(flight - steps - delta_t))


@pytest.fixture(scope="session")
def kinematic_runs(runs_folder):
    """The case with the plain kinematic cloud (parcels without spin): spinRelaxation auto (the default), off, and
    auto on 2 ranks (cases.CASES)."""
    return {name: _case(runs_folder, name) for name in ("kinematic", "kinematic_off", "kinematic_parallel")}


def test_spin_memory_gives_spinless_parcels_their_last_spin(kinematic_runs, serial_case, capsys):
    """Parcels that carry no spin: with spinRelaxation auto every hit after a parcel's first drawn rebound arrives
    with that rebound's Ω⁺, relaxed with τ_r = ρ_p (2a)²/(60 μ), and under auto goes to the direct model; with off
    none does, and the direct model answers the hits outside the grid only. The remembered spin is the colliding
    cloud's (serial_case): no fluid torque acts on colliding parcels in v1912 and τ_r (25-100 ms) is long against
    the flights."""
    on, off = (kinematic_runs[name] for name in ("kinematic", "kinematic_off"))
    info = {name: _cloud_info((case / KINEMATIC_LOG).read_text()) for name, case in (("on", on), ("off", off))}
    colliding = _cloud_info((serial_case / f"log.{SOLVER}").read_text())
    hits, _ = compare_rebounds.read_hits(on)
    off_hits, _ = compare_rebounds.read_hits(off)
    with capsys.disabled():
        for name, i in info.items():
            print(f"\nkinematic cloud, spin memory {name}: {i['hits']} hits, {i['direct']} by the direct model "
                  f"({i['direct'] / i['hits']:.3f}), {i['outside']} outside the grid, remembered spin "
                  f"{i['remembered']}, incoming |Omega|a/|V| mean {i['spin_mean']}")
        print(f"colliding cloud: {colliding['hits']} hits, {colliding['direct']} by the direct model "
              f"({colliding['direct'] / colliding['hits']:.3f}), |Omega|a/|V| mean {colliding['spin_mean']:.3f}")
    # off: no memory, no spin, the direct model for the hits outside the grid only
    assert info["off"]["remembered"] is None and info["off"]["spin_mean"] is None
    assert "spin memory (spinRelaxation) = off" in (off / KINEMATIC_LOG).read_text()
    assert info["off"]["direct"] == info["off"]["outside"] and not off_hits["Win"].any()
    # auto: every hit but each parcel's first arrives with a remembered spin, and all of those are answered by
    # the direct model (|Ω⁻|a/|V⁻| far above the tolerance)
    first = np.unique(_parcel_keys(hits), return_index=True)[1]
    later = np.ones(len(hits["time"]), bool)
    later[first] = False
    spinning = np.linalg.norm(hits["Win"], axis=1) > 0
    assert np.array_equal(spinning, later) and info["on"]["remembered"] == later.sum() > 5000, info["on"]
    assert np.all(hits["path"][later] == compare_rebounds.PATH_DIRECT)
    assert info["on"]["direct"] > 0.4 * info["on"]["hits"] > info["off"]["direct"], info
    parcels = _cloud_parcels((on / KINEMATIC_LOG).read_text())
    assert info["on"]["missed"] == 0 and info["on"]["held"] <= parcels["current"], (info["on"], parcels)
    # the spin the colliding cloud carries itself
    assert info["on"]["spin_mean"] == pytest.approx(colliding["spin_mean"], rel=0.1), (info["on"], colliding)
    # τ_r = ρ_p (2a)²/(60 μ) at the later hit, μ the air's
    i, j = _next_hits(hits)
    tau = SAND_DENSITY * (2 * hits["a"][j]) ** 2 / (60 * cases.AIR_MU)
    _check_relaxation(hits, i, j, tau, delta_t=2e-5)
    # the parcels' rebounds follow the direct model's law at their remembered spins
    assert compare_rebounds.compare(on, classifier=False)["comparison"].ok


def test_spin_relaxation_over_the_flight_and_over_a_restart(runs_folder):
    """spinRelaxation 2e-4 s (cases.CASES["kinematic_tau"], run to 2.5 ms): each later hit's Ω⁻ is the last Ω⁺
    relaxed over the flight, exp(−Δt/τ_r); the remembered spins are written with the parcels at the write time
    and read back by a restart, which goes on relaxing them from the rebounds before it."""
    case = _case(runs_folder, "kinematic_tau")
    tau = cases.SPIN_RELAXATION_S
    before, _ = compare_rebounds.read_hits(case)
    i, j = _next_hits(before)
    assert len(i) > 300
    _check_relaxation(before, i, j, tau, delta_t=2e-5)
    # written with the cloud at 2.5 ms: one value per parcel, zero for those that never rebounded
    cloud = case / "0.0025" / "lagrangian" / "kinematicCloud"
    omega = (cloud / "stochasticReboundOmega").read_text()
    n_parcels = int(re.search(r"\n(\d+)\n\(", (cloud / "origId").read_text()).group(1))
    values = re.findall(r"^\(([-0-9.e+ ]+)\)$", omega.split("\n(", 1)[1], re.M)
    assert len(values) == n_parcels and (cloud / "stochasticReboundTime").is_file()
    remembered = sum(any(float(v) for v in value.split()) for value in values)
    assert remembered > 1000
    # the restart: to 5 ms from 2.5 ms
    control = case / "system" / "controlDict"
    text = re.sub(r"\nendTime\s+[^;]+;", "\nendTime         0.005;", control.read_text())
    control.write_text(re.sub(r"\nstartFrom\s+[^;]+;", "\nstartFrom       latestTime;", text))
    _run(["bash", "-c", f". {OPENFOAM_DIR / 'openfoam-env.sh'} && {cases.KINEMATIC_SOLVER} > log.restart 2>&1"],
         cwd=case)
    log = (case / "log.restart").read_text()
    assert f"stochasticRebound: read the remembered spins of {remembered} parcels" in log
    after, _ = compare_rebounds.read_hits(case)
    # each parcel's first hit after the restart against its last rebound before it (written to 8 digits)
    last = {key: row for row, key in enumerate(_parcel_keys(before).tolist())}
    keys_after = _parcel_keys(after).tolist()
    first_after = {}
    for row, key in enumerate(keys_after):
        first_after.setdefault(key, row)
    pairs = [(last[key], row) for key, row in first_after.items() if key in last]
    assert len(pairs) > 1000
    joined = {name: np.concatenate([before[name], after[name]]) for name in ("Win", "Wout", "time")}
    i = np.array([p[0] for p in pairs])
    j = np.array([p[1] for p in pairs]) + len(before["time"])
    _check_relaxation(joined, i, j, tau, delta_t=2e-5, rtol=1e-7, time_slack=1e-9)
    # the counts go on from the ones stored at the write
    assert _cloud_info(log)["remembered"] == int(np.sum(np.linalg.norm(joined["Win"], axis=1) > 0))


def test_spin_follows_a_parcel_to_another_rank(kinematic_runs):
    """On 2 ranks the remembered spins of the parcels that crossed to the other rank in a time step are handed
    over at its end: every hit after a parcel's first used its remembered spin, but for the hits of parcels that
    crossed and hit in the same time step, which the summary counts as missed."""
    case = kinematic_runs["kinematic_parallel"]
    info = _cloud_info((case / KINEMATIC_LOG).read_text())
    hits, _ = compare_rebounds.read_hits(case)
    keys = _parcel_keys(hits)
    spinning = np.linalg.norm(hits["Win"], axis=1) > 0
    first = np.unique(keys, return_index=True)[1]
    assert info["remembered"] == spinning.sum() and info["remembered"] + info["missed"] == len(keys) - len(first)
    assert info["missed"] < 0.01 * info["remembered"], info
    # hits on a rank a parcel came to after hitting on the other: its spin came with it
    crossed = 0
    for key in np.unique(keys):
        rows = np.flatnonzero(keys == key)
        rows = rows[np.argsort(hits["time"][rows], kind="stable")]
        ranks = hits["rank"][rows]
        if len(set(ranks.tolist())) == 2:
            arrival = rows[np.argmax(ranks != ranks[0])]
            crossed += bool(spinning[arrival])
    assert crossed > 100, crossed
