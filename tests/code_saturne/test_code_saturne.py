"""The code_saturne integration (integrations/code_saturne) on a real Lagrangian case.

Builds the C runtime (integrations/code_saturne/build.sh, on the outputs of install-deps.sh), runs the
case channelRebound with Debian's code_saturne 6.0 serially and on 2 MPI ranks (its Allrun compiles the
case's user sources and the adapter with `code_saturne compile`), and checks: the hit records are
well-formed and agree with the solver's log; every rebound leaves the wall; the paths follow the rule of
method auto; the solver's rebounds follow surrogate's law at the same incident states, path by path (the
solver-neutral comparison tablegen.study.solver_comparison, called through compare_saturne_rebounds.py); each
rank draws its own stream; each particle hits as one grain (grain kept) and the grains follow the mix's
weights; trapped particles are deposited or removed; each boundary zone does what its [zone] section says
(its own wall's table, a rough wall, or a stock behaviour) and is counted apart; a bad setup stops the solver
with one clear message; the work of the hits on the walls, the adapter's boundary statistics in the run's
postprocessing against the hit records and the summary, a table of format 4.0 (no work) counted apart; and the
CPU time against the solver's own rebound (CS_LAGR_REBOUND).

These tests need code_saturne: they fail (they are not skipped) when it is missing, with a message naming
integrations/code_saturne/install-deps.sh.

Copyright (C) 2026 the rebound-scatter authors. License: GPL-2.0-or-later
(see integrations/code_saturne/LICENSE): these tests import the integration's scripts.
"""

from __future__ import annotations

import math
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from tests.helpers import background

REPO = Path(__file__).resolve().parents[2]
CS_DIR = REPO / "integrations" / "code_saturne"
CASE = CS_DIR / "cases" / "channelRebound"

sys.path.insert(0, str(CS_DIR))

import compare_saturne_rebounds  # noqa: E402
import make_channel_table  # noqa: E402
from read_hits import (BOUNDARY_STATISTICS, HITS_TITLE, boundary_statistics, read_cpu_seconds,  # noqa: E402
                       read_hits, read_summary, zone_settings, zone_summary)
from saturne_api import (PATH_DIRECT, PATH_TABLE, STATUS_INVALID, STATUS_REBOUNDED,  # noqa: E402
                         build_table_from_text, grain_mismatches, load, table_without_work)

INSTALL_HINT = ("run `bash integrations/code_saturne/install-deps.sh` (as root on Debian bookworm: it installs "
                "Debian's code_saturne 6.0 with its headers and Open MPI) and then "
                "`bash integrations/code_saturne/build.sh`")
INJECTED = 2500          # the case's 50 particles per step over 50 steps (cs_user_lagr_boundary_conditions.c)


def _cache() -> Path:
    return Path(os.environ.get("RBS_CS_CACHE", CS_DIR / ".build"))


def _run(cmd, cwd, env=None, timeout=900) -> subprocess.CompletedProcess:
    proc = subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True, timeout=timeout)
    return background.succeeded(proc)


@pytest.fixture(scope="session")
def cs_build(saturne_build_job):
    """install-deps.sh's outputs checked, then the C runtime built (build.sh, started with the session)."""
    missing = [tool for tool in ("code_saturne", "mpirun", "gfortran") if shutil.which(tool) is None]
    if missing:
        pytest.fail(f"code_saturne is missing ({', '.join(missing)} not on PATH): {INSTALL_HINT}")
    background.succeeded(saturne_build_job.result())
    lib = _cache() / "native-install" / "lib" / "librebound_scatter.so"
    assert lib.is_file()
    return lib


# The case's table with 1000 particles per cell instead of make_channel_table.py's 10 000 (a tenth of the
# build). The comparison's power does not come from the table: the solver and surrogate draw from this one
# table, so its particle count sets the law both sides follow, not how finely the two are compared. That is
# set by the hits: about 6000 rebounds per path (n = m), where the bounds of one law are KS ≤ 2.25·√(2/n)
# ≈ 0.041 and a classifier accuracy ≤ ½ + 3.29·√(0.25/n_test) ≈ 0.521 (family α 1e-3 over the 2 paths and
# 6 variables, solver_comparison.agreement), as they would be with 10 000. 1000 particles (40 clusters a
# cell) keep the law's shape: a cell needs 256 (tablegen's minimum).
CASE_TABLE_PARTICLES = 1000


@pytest.fixture(scope="session")
def case_table(tmp_path_factory):
    """The case's table (make_channel_table.py's grid), built once."""
    path = tmp_path_factory.mktemp("cs_table") / "rebound_table.h5"
    build_table_from_text(make_channel_table.case_table_config(CASE_TABLE_PARTICLES), path)
    return path


def _copy_case(tmp_path_factory, name) -> Path:
    case = tmp_path_factory.mktemp(name) / "channelRebound"
    shutil.copytree(CASE, case, ignore=shutil.ignore_patterns("RESU", "log.*", "rebound_table.h5"))
    return case


def _set(case: Path, key: str, value: str | None) -> None:
    """Set ``key = value`` in the case's settings file (None: remove the key)."""
    conf = case / "rebound_scatter.conf"
    lines = [line for line in conf.read_text().splitlines() if not line.startswith(f"{key} =")]
    if value is not None:
        lines.append(f"{key} = {value}")
    conf.write_text("\n".join(lines) + "\n")


def _allrun(case: Path, table: Path, np_: int = 1, walls: str = "rebound-scatter", check: bool = True):
    env = dict(os.environ, RBS_CS_DIR=str(CS_DIR), RBS_TABLE=str(table), RBS_PYTHON=sys.executable)
    cmd = ["bash", "./Allrun", "-np", str(np_), "-walls", walls]
    if check:
        return _run(cmd, cwd=case, env=env)
    return subprocess.run(cmd, cwd=case, env=env, capture_output=True, text=True, timeout=900)


def _run_case(tmp_path_factory, name, table, np_=1, walls="rebound-scatter", edit=None) -> Path:
    case = _copy_case(tmp_path_factory, name)
    if edit:
        edit(case)
    _allrun(case, table, np_, walls)
    return case


@pytest.fixture(scope="session")
def serial_case(cs_build, case_table, tmp_path_factory):
    return _run_case(tmp_path_factory, "cs_serial", case_table)


@pytest.fixture(scope="session")
def parallel_case(cs_build, case_table, tmp_path_factory):
    return _run_case(tmp_path_factory, "cs_parallel", case_table, np_=2)


def _lagrangian_log(case: Path) -> np.ndarray:
    """RESU/lagrangian.log's table: one row per time step (columns as its header lists them, from 1)."""
    rows = [line.split() for line in (case / "RESU" / "lagrangian.log").read_text().splitlines()
            if line.strip() and not line.startswith("#")]
    return np.array(rows, dtype=float)


# ----------------------------------------------------------------------------- sources and build

def test_sources_carry_the_gpl_notice():
    sources = sorted((CS_DIR / "stochastic_rebound").glob("*.[ch]")) + sorted((CASE / "SRC").glob("*"))
    assert len(sources) >= 8
    for f in sources + sorted(CS_DIR.glob("*.py")) + sorted(CS_DIR.glob("*.sh")):
        text = f.read_text()
        assert "GNU General Public License" in text or "GPL-2.0-or-later" in text, f
        assert "version 3" not in text.lower(), f
    licence = (CS_DIR / "LICENSE").read_text()[:200]
    assert "GNU GENERAL PUBLIC LICENSE" in licence and "Version 2" in licence


def test_solver_links_the_c_runtime(serial_case):
    solvers = sorted(_cache().glob("solver-*/cs_solver"), key=lambda p: p.stat().st_mtime)
    assert solvers
    linked = subprocess.run(["ldd", str(solvers[-1])], capture_output=True, text=True).stdout
    assert "librebound_scatter" in linked and "not found" not in linked, linked
    symbols = subprocess.run(["nm", str(solvers[-1])], capture_output=True, text=True).stdout
    assert " T cs_lagr_user_boundary_interaction" in symbols


# ----------------------------------------------------------------------------- the case

def _check_run(case: Path, n_ranks: int) -> tuple[dict, dict, list]:
    """The counts of the log, the hit records and the solver's own particle counts, checked against each
    other; every rebound physical. Returns (counts, hits, headers)."""
    info = read_summary((case / "RESU" / "run_solver.log").read_text())
    hits, headers = read_hits(case / "RESU")
    assert len(headers) == n_ranks and [h["stream"] for h in headers] == list(range(n_ranks))
    assert all(h["method"] == "auto" and h["shape"] == {"prism": 0.7, "tetrahedron": 0.3} for h in headers)
    assert info["hits"] == len(hits["status"]) == info["rebounded"] + info["trapped"] + info["failed"] \
        + info["invalid"]
    assert info["hits"] == info["table"] + info["direct"] + info["invalid"]
    assert (np.sum(hits["path"] == PATH_TABLE), np.sum(hits["path"] == PATH_DIRECT)) == (info["table"],
                                                                                        info["direct"])
    assert set(np.unique(hits["patch"])) == {"walls", "target"}
    assert set(np.unique(hits["rank"])) == set(range(n_ranks))
    # 2500 grains at 50-300 m/s in a 0.1 m channel: several wall hits each
    assert 5000 < info["hits"] < 40000, info
    # every grain moves into the wall it hits, with a unit normal into the gas, and carries no spin (6.0)
    assert info["invalid"] == 0
    np.testing.assert_allclose(np.linalg.norm(hits["n"], axis=1), 1.0, atol=1e-12)
    assert np.all(np.einsum("ij,ij->i", hits["V"], hits["n"]) < 0)
    assert np.all(hits["Win"] == 0) and np.all(hits["Uw"] == 0) and np.all(hits["spin_ratio"] == 0)
    np.testing.assert_allclose(hits["a"], 0.5 * hits["d"], rtol=1e-8)
    assert np.all((hits["d"] >= 1e-4 * (1 - 1e-8)) & (hits["d"] <= 3e-4 * (1 + 1e-8)))
    # every rebound leaves the wall, no faster than it came (Ω⁻ = 0: no energy to gain); a trapped or failed
    # hit has no rebound
    reb = hits["status"] == STATUS_REBOUNDED
    assert np.all(np.einsum("ij,ij->i", hits["Vout"][reb], hits["n"][reb]) > 0)
    assert np.all(np.linalg.norm(hits["Vout"][reb], axis=1) <= np.linalg.norm(hits["V"][reb], axis=1) * (1 + 1e-12))
    assert np.all(np.isfinite(hits["Wout"][reb])) and np.all(np.isnan(hits["Vout"][~reb]))
    # Ω⁻ = 0: under auto the direct model answers exactly the hits outside the table's grid
    assert info["direct"] == info["outside"] > 0 and info["table"] > 0.3 * info["hits"], info
    # the solver's own count of particles: all injected, none lost by the tracking (a rebound that put a
    # particle's next segment in the wrong place would lose it), none left the domain but through the inlet
    lagr = _lagrangian_log(case)
    assert lagr[:, 4].sum() == INJECTED
    assert lagr[:, 10].sum() == 0
    assert lagr[-1, 2] == INJECTED - lagr[:, 6].sum()
    return info, hits, headers


def _check_comparison(case: Path, info: dict) -> dict:
    """compare_saturne_rebounds.compare of a run (tablegen.study.solver_comparison), checked: the paths, the hits per
    path and, per path, the solver's rebounds against surrogate's on the same incident states."""
    res = compare_saturne_rebounds.compare(case / "RESU")
    print(compare_saturne_rebounds.report(res))
    paths, comparison = res["paths"], res["comparison"]
    # the path is a pure function of the state: with Ω⁻ = 0 (6.0) no hit spins, the direct model answers the
    # hits outside the table's grid and the table every other one (path_rule's margin leaves out a hit at
    # the grid's very edge, hence the adapter's count within 2)
    assert paths["spinning"] == 0 and paths["outside"] == pytest.approx(info["outside"], abs=2), paths
    assert paths["outside_not_direct"] == paths["still_inside_not_table"] == 0, paths
    assert comparison.hits_per_path == {"table": info["table"], "direct": info["direct"], "invalid": 0}
    # each path's rebounds follow surrogate's law at the same incident states: the KS statistics, the
    # classifier's accuracy and the fractions not rebounded within the bounds of one law at these sample sizes,
    # shared over the run's two paths (family α 1e-3: a false alarm once in a thousand runs)
    assert set(comparison.agreement) == {"table", "direct"}
    for name, a in comparison.agreement.items():
        assert a.n_solver > 1000 and a.classifier_n_test > 1000, (name, a)
        assert a.ks_ok and a.classifier_ok and a.not_rebounded_ok, (name, a)
    assert comparison.family_alpha == 1e-3 and comparison.ok and res["checks_passed"]
    return res


def test_serial_run_hits_and_rebounds_against_the_sampler(serial_case):
    info = _check_run(serial_case, 1)[0]
    _check_comparison(serial_case, info)


def test_two_rank_run_hits_and_rebounds(parallel_case, serial_case):
    info, hits, _ = _check_run(parallel_case, 2)
    serial = read_summary((serial_case / "RESU" / "run_solver.log").read_text())
    # the same case: the hit count moves with the draws only (a few per cent)
    assert abs(info["hits"] - serial["hits"]) < 0.1 * serial["hits"], (info, serial)
    assert min(np.sum(hits["rank"] == r) for r in (0, 1)) > 1000, "both ranks see wall hits"
    _check_comparison(parallel_case, info)


def test_comparison_script_command_line(serial_case, tmp_path, capsys):
    # main() in this process: a new interpreter would load the kernels again for the same check
    main = compare_saturne_rebounds.main
    assert main([str(serial_case / "RESU"), "--check", "--no-classifier", "--json", str(tmp_path / "c.json")]) == 0
    assert "hits per path: table" in capsys.readouterr().out and (tmp_path / "c.json").stat().st_size > 0
    # a run folder without hit records, or a --json file already there: one line on stderr, status 2
    for args in ([str(tmp_path)], [str(serial_case / "RESU"), "--json", str(tmp_path / "c.json")]):
        assert main(args) == 2
        assert len(capsys.readouterr().err.strip().splitlines()) == 1


def test_each_rank_draws_its_own_stream(parallel_case, serial_case):
    hits, headers = read_hits(parallel_case / "RESU")
    assert len({h["seed"] for h in headers}) == 1
    u0 = {r: hits["u0"][hits["rank"] == r] for r in (0, 1)}
    # the first uniform of every draw: a repeated stream would repeat them, rank against rank
    assert len(np.intersect1d(u0[0], u0[1])) == 0
    assert len(np.unique(hits["u0"])) == len(hits["u0"])
    # rank 0 draws stream 0 of the seed, as a serial run does: the first draw is the same
    serial, _ = read_hits(serial_case / "RESU")
    assert serial["u0"][0] == u0[0][0] != u0[1][0]


# ----------------------------------------------------------------------------- the work on the walls

DENSITY = 2650.0   # the case's sand (cs_user_lagr_boundary_conditions.c): a grain's mass is ρπd³/6 (cs_user_lagr_in)
# the summary writes the mean work with 6 significant digits (a relative rounding of at most 5e-6) and the
# postprocessing the statistics in float32 (6e-8 each): the bound on their products' and sums' relative difference
PRINTED_RTOL = 6e-6


def _check_work(case: Path, with_work=None) -> dict:
    """The adapter's boundary statistics of a run (its EnSight output), checked per zone against the hit records
    and the summary. In a zone that draws, over the hits ``with_work(hits)`` (default: every record of the zone
    but the invalid ones; the case's statistical weight is 1): the statistic of the hits counts them, that of
    the mass sums their ρπd³/6, the zone's counts add up (hits = with work + without + invalid), the two works
    are the summary's means times that mass and at most the translational kinetic energy the grains lost (V⁺ = 0
    where none rebounded: the rest went into their spin); every value is finite and >= 0, and every other
    zone's faces (the inlet, a stock zone) hold none. The first block's total work is the statistics' sum.
    Returns per drawing zone its means (J/kg), total works (J) and the work's share of the translational
    energy lost."""
    run = case / "RESU"
    stats, log = boundary_statistics(run), (run / "run_solver.log").read_text()
    rows, info = zone_summary(log), read_summary(log)
    hits, _ = read_hits(run)
    for name in BOUNDARY_STATISTICS:
        assert np.all(np.isfinite(stats[name]) & (stats[name] >= 0)), name
    out = {}
    drawn = [zone for zone, row in rows.items() if row["interaction"].startswith("rebound-scatter")]
    for zone in drawn:
        row, on = rows[zone], stats["zone"] == zone
        rec = (hits["patch"] == zone) & (with_work(hits) if with_work else hits["status"] != STATUS_INVALID)
        mass = DENSITY * np.pi * hits["d"][rec] ** 3 / 6
        assert stats["rbs_wall_hits"][on].sum() == np.sum(rec) == row["hits"] - row["no_work"] - row["invalid"] > 0
        np.testing.assert_allclose(stats["rbs_wall_hit_mass"][on].sum(), mass.sum(), rtol=1e-6)
        work = {}
        for key in ("normal", "tangential"):
            work[key] = stats[f"rbs_wall_work_{key}"][on].sum()
            np.testing.assert_allclose(work[key], row[f"work_{key}"] * mass.sum(), rtol=PRINTED_RTOL)
        v_in, v_out = hits["V"][rec], np.nan_to_num(hits["Vout"][rec])
        lost = np.sum(mass * 0.5 * (np.einsum("ij,ij->i", v_in, v_in) - np.einsum("ij,ij->i", v_out, v_out)))
        share = (work["normal"] + work["tangential"]) / lost
        assert 0 < share <= 1 + 1e-6, (zone, share)
        out[zone] = {"Wn": row["work_normal"], "Wt": row["work_tangential"], "Wn_J": work["normal"],
                     "Wt_J": work["tangential"], "share": share}
    others = ~np.isin(stats["zone"], drawn)
    assert others.any() and all(np.all(stats[name][others] == 0) for name in BOUNDARY_STATISTICS)
    for key in ("normal", "tangential"):
        np.testing.assert_allclose(info[f"work_{key}_J"], stats[f"rbs_wall_work_{key}"].sum(), rtol=PRINTED_RTOL)
    assert info["no_work"] == sum(rows[zone]["no_work"] for zone in drawn)
    return out


def test_work_on_the_walls(serial_case, parallel_case, capsys):
    """The work of the hits on the walls (rbs_result.wall_work_normal, wall_work_tangential; docs/model.md §4.7):
    the boundary statistics of the serial and the 2-rank run (summed over the ranks by the postprocessing) against
    their hit records and summaries (_check_work); the table of format 4.1 gives every hit its work."""
    lines = []
    for name, case in (("serial", serial_case), ("2 ranks", parallel_case)):
        work = _check_work(case)
        assert set(work) == {"target", "walls"} and read_summary(
            (case / "RESU" / "run_solver.log").read_text())["no_work"] == 0
        lines += [f"  {name:8s}{zone:7s} W_n {w['Wn']:.6g} J/kg, W_t {w['Wt']:.6g} J/kg; {w['Wn_J']:.4g} J, "
                  f"{w['Wt_J']:.4g} J; {w['share']:.3f} of the translational energy lost" for zone, w in work.items()]
    with capsys.disabled():
        print("\nchannelRebound, the work on the walls (mean per unit mass; sum; share of the energy lost):\n"
              + "\n".join(lines))


def test_work_with_a_table_of_format_4_0(cs_build, case_table, serial_case, tmp_path_factory):
    """A table of format 4.0 holds no work: its hits (the table path's) are counted without work (no-work) and
    left out of the statistics and the means, which hold the direct model's hits alone; the rebounds are the
    serial run's (the same table without its work datasets), bit for bit."""
    table = table_without_work(case_table, tmp_path_factory.mktemp("cs_table_4_0") / "rebound_table_4_0.h5")
    case = _run_case(tmp_path_factory, "cs_format_4_0", table)
    log = (case / "RESU" / "run_solver.log").read_text()
    rows, info = zone_summary(log), read_summary(log)
    assert info["no_work"] == info["table"] > 0
    for zone in ("target", "walls"):
        assert rows[zone]["no_work"] == rows[zone]["table"] > 0 and rows[zone]["direct"] > 0, rows[zone]
    _check_work(case, with_work=lambda hits: hits["path"] == PATH_DIRECT)
    hits, _ = read_hits(case / "RESU")
    serial, _ = read_hits(serial_case / "RESU")
    for key in ("V", "n", "d", "status", "path", "Vout", "Wout", "u0", "key"):
        np.testing.assert_array_equal(hits[key], serial[key], err_msg=key)


@pytest.fixture(scope="session")
def specular_case(cs_build, case_table, tmp_path_factory):
    """The case with the solver's own rebound (CS_LAGR_REBOUND: specular) on the walls."""
    return _run_case(tmp_path_factory, "cs_specular", case_table, walls="specular")


def test_cpu_time_against_the_solvers_rebound(serial_case, specular_case, capsys):
    """The solver's CPU time with rebound-scatter's walls and with its own specular rebound. The two runs do
    not do the same work: specular grains keep their speed and leave the channel within about 1.5 ms,
    scattered ones slow down and stay, so the tracking has more particle steps to do; the adapter's own
    CPU time (its clock around every hit) is the cost of the rebounds themselves."""
    log = (specular_case / "RESU" / "run_solver.log").read_text()
    assert "rebound-scatter" not in log and not (specular_case / "RESU" / "hits").exists()
    ours, stock = read_cpu_seconds(serial_case / "RESU"), read_cpu_seconds(specular_case / "RESU")
    steps = {k: int(_lagrangian_log(c)[:, 2].sum()) for k, c in (("ours", serial_case), ("stock", specular_case))}
    info = read_summary((serial_case / "RESU" / "run_solver.log").read_text())
    with capsys.disabled():
        print(f"\nchannelRebound, serial, one run each on a machine others may share; CPU s (user + system), "
              f"wall s, particle displacement wall s, particle steps:\n"
              f"  rebound-scatter  {ours['cpu']:.2f}, {ours['wall']:.2f}, {ours['displacement_wall']:.3f}, "
              f"{steps['ours']}; {info['hits']} wall hits, {info['direct']} by the direct model "
              f"({info['direct_us']:.1f} us each, wall); CPU in the hits {info['hits_cpu_s']:.3f} s "
              f"({1e6 * info['hits_cpu_s'] / info['hits']:.1f} us per hit)\n"
              f"  CS_LAGR_REBOUND  {stock['cpu']:.2f}, {stock['wall']:.2f}, {stock['displacement_wall']:.3f}, "
              f"{steps['stock']}\n"
              f"  CPU ratio {ours['cpu'] / stock['cpu']:.2f}; the hits' share of rebound-scatter's CPU "
              f"{info['hits_cpu_s'] / ours['cpu']:.3f}")
    assert min(ours.values()) > 0 and min(stock.values()) > 0
    # the scattered grains lose speed (s < 1) and stay longer: more particle steps than the specular run's
    assert steps["ours"] > steps["stock"]
    assert 0 < info["hits_cpu_s"] < ours["cpu"]


# ----------------------------------------------------------------------------- trapped particles

# The case's grid with n_max = 2: a particle that would touch the wall a third time counts as trapped, so a
# good part of the hits are trapped. A coarse grid and 1000 particles per cell are enough: both sides of the
# comparison draw from this table (CASE_TABLE_PARTICLES).
TRAPPING_TABLE_CONFIG = """\
[grid]
alpha1_deg = [1.0, 7.5, 30.0, 60.0, 90.0]
speed_m_s = [50.0, 300.0]
shapes = ["prism", "tetrahedron"]
[simulation]
particles_per_cell = 1000
seed = 20261126
n_max = 2
"""


@pytest.fixture(scope="session")
def trapping_table(tmp_path_factory):
    path = tmp_path_factory.mktemp("cs_trapping_table") / "rebound_table_nmax2.h5"
    build_table_from_text(TRAPPING_TABLE_CONFIG, path)
    return path


@pytest.mark.parametrize("policy", ["deposit", "remove"])
def test_trapped_particles_are_deposited_or_removed(policy, cs_build, trapping_table, tmp_path_factory):
    """Trapped particles are deposited or removed; the deposit run keeps each particle's grain (the default),
    the remove run draws a new grain per hit (grain = perHit: no key, no shape recorded), and both trap as
    surrogate does."""
    grain = "kept" if policy == "deposit" else "perHit"

    def edit(case):
        _set(case, "trapped", policy)
        _set(case, "grain", grain)

    case = _run_case(tmp_path_factory, f"cs_trapped_{policy}", trapping_table, edit=edit)
    hits, headers = read_hits(case / "RESU")
    assert [h["grain"] for h in headers] == [grain]
    if grain == "perHit":
        assert (hits["key"] == -1).all() and set(hits["shape"].tolist()) == {""} and np.isnan(hits["ratio_ba"]).all()
    else:
        assert (hits["key"] >= 0).all() and set(hits["shape"].tolist()) <= {"prism", "tetrahedron"}
    info = read_summary((case / "RESU" / "run_solver.log").read_text())
    assert info["trapped"] > 200, info
    lagr = _lagrangian_log(case)
    # the solver counts them as deposited; removed ones leave the domain (column 7), deposited ones stay in
    # it, at rest
    assert lagr[:, 8].sum() == info["trapped"] + info["failed"]
    assert lagr[:, 10].sum() == 0
    if policy == "remove":
        assert lagr[:, 6].sum() >= info["trapped"] and lagr[-1, 2] == INJECTED - lagr[:, 6].sum()
    else:
        assert lagr[-1, 2] >= info["trapped"] and lagr[-1, 2] == INJECTED - lagr[:, 6].sum()
    # the solver traps as often as surrogate does at the same incident states, on both paths (the direct
    # model with the table's n_max = 2 traps too): KS and the fractions not rebounded (no classifier: the
    # fractions are what this run is for)
    res = compare_saturne_rebounds.compare(case / "RESU", classifier=False)
    print(compare_saturne_rebounds.report(res))
    comparison = res["comparison"]
    assert comparison.hits_per_path["table"] + comparison.hits_per_path["direct"] == info["hits"]
    assert comparison.ok and res["checks_passed"], comparison.lines()
    assert min(a.not_rebounded[0] for a in comparison.agreement.values()) > 0, comparison.lines()


def _grains(case: Path, table: Path) -> dict:
    """The hits of a grain-kept run by grain key (6.0's particles carry no id: the key, from the particle's
    random value, stands for the particle), checked: every hit carries its key's grain in the run's mix
    (surrogate.grain_of: the shape, and on the direct path b/a, c/b and the hand to the bit; NaN on the table
    path)."""
    hits, headers = read_hits(case / "RESU")
    assert {(h["grain"], h["grain_seed"]) for h in headers} == {("kept", headers[0]["seed"])}
    mismatches = grain_mismatches(hits, headers[0], load(table))
    assert mismatches == {"key": 0, "shape": 0, "direct": 0, "table": 0}, mismatches
    assert np.sum(hits["path"] == PATH_DIRECT) > 1000
    rows: dict = {}
    for i, key in enumerate(hits["key"].tolist()):
        rows.setdefault(key, []).append(i)
    return {key: np.array(i) for key, i in rows.items()}


def test_each_particle_hits_as_one_grain_of_the_mix(serial_case, parallel_case, case_table):
    """grain kept (the default): a particle's key comes from its random value (drawn at injection, carried
    from rank to rank), so on 2 ranks particles that hit walls on both ranks keep one key; and over the
    particles the shapes follow the weights 0.7/0.3: about 2500 keys (one per particle, at most the injected
    number), the prisms' fraction within 3.29 standard deviations, sqrt(0.21/n), of 0.7 (two-sided 1e-3)."""
    for case in (serial_case, parallel_case):
        rows = _grains(case, case_table)
        hits, _ = read_hits(case / "RESU")
        assert 0.8 * INJECTED < len(rows) <= INJECTED, len(rows)
        shapes = np.array([hits["shape"][i[0]] for i in rows.values()], dtype=object)
        assert set(shapes.tolist()) == {"prism", "tetrahedron"}
        n = len(shapes)
        assert abs(np.mean(shapes == "prism") - 0.7) < 3.29 * np.sqrt(0.21 / n), np.mean(shapes == "prism")
    on_both = [key for key, i in rows.items() if len(set(hits["rank"][i].tolist())) == 2]
    assert len(on_both) > 50, len(on_both)


# ----------------------------------------------------------------------------- bad setup

@pytest.mark.parametrize("edits, words", [
    ({"table": "missing_table.h5"}, ["cannot open the table", "missing_table.h5"]),
    ({"weights": None, "shape": "sphere"}, ["bad shape \"sphere\""]),
    ({"seed": "-3"}, ["seed must be an integer in [0, 9223372036854775807], not \"-3\""]),
    ({"seed": "12abc"}, ["seed must be an integer", "\"12abc\""]),
    ({"method": "tabel"}, ["method must be auto, table or direct, not \"tabel\""]),
    ({"interpolaton": "scaled"}, ["unknown key \"interpolaton\""]),
    ({"grain": "once"}, ["grain must be kept or perHit, not \"once\""]),
    ({"hits_every": "0"}, ["hits_every must be an integer in [1, 9223372036854775807], not \"0\""]),
], ids=["missing table", "unknown shape", "negative seed", "seed not a number", "unknown method",
        "misspelled key", "unknown grain mode", "zero hits_every"])
def test_bad_setup_is_one_clear_error_from_the_solver(cs_build, case_table, tmp_path_factory, edits, words):
    case = _copy_case(tmp_path_factory, "cs_bad_setup")
    for key, value in edits.items():
        _set(case, key, value)
    proc = _allrun(case, case_table, check=False)
    assert proc.returncode != 0
    error = (case / "RESU" / "error").read_text()
    assert "rebound-scatter settings rebound_scatter.conf" in error, error
    for word in words:
        assert word in error, error
    # stopped before the first particle moved: no hit recorded
    assert not list((case / "RESU").glob("hits/hits_*.csv"))


def test_hit_records_never_overwrite_another_file(cs_build, case_table, tmp_path_factory):
    case = _copy_case(tmp_path_factory, "cs_foreign_hits")
    (case / "results").mkdir()
    (case / "results" / "hits_0.csv").write_text("someone else's data\n")
    _set(case, "hits", "../results")
    proc = _allrun(case, case_table, check=False)
    assert proc.returncode != 0
    assert "results/hits_0.csv exists and is not a rebound-scatter hits file" in \
        (case / "RESU" / "error").read_text()
    assert (case / "results" / "hits_0.csv").read_text() == "someone else's data\n"


def test_settings_without_a_table_are_one_clear_error(cs_build, case_table, tmp_path_factory):
    case = _copy_case(tmp_path_factory, "cs_no_table")
    (case / "rebound_scatter.conf").write_text("seed = 1\n")
    proc = _allrun(case, case_table, check=False)
    assert proc.returncode != 0
    assert "no table (table = path of a table written by tablegen build)" in (case / "RESU" / "error").read_text()


# ----------------------------------------------------------------------------- a wall per zone

# Two walls for one grain, on a coarse grid (α1 from 10°, |V⁻| 50-150 m/s) that the case's hits fall below,
# inside and above, and below in α1: an elastic wall (small k: little of the normal speed lost) and a lossy one
# (large k) that traps (n_max = 2); the lossy wall's name holds a comma, which the hits files write as ';'
WALL_TABLE_CONFIG = """\
[grid]
alpha1_deg = [10.0, 45.0, 90.0]
speed_m_s = [50.0, 150.0]
shapes = ["prism"]
[simulation]
particles_per_cell = 1000
seed = 20261127
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
GRID = {"alpha1_lo": 10.0, "speed_lo": 50.0, "speed_hi": 150.0}

# the side walls as two zones: walls (y = 0 and 0.02 m) and sides (z = 0 and 0.02 m)
SPLIT_ZONES = ('  cs_boundary_zone_define("walls", "3", 0);\n',
               '  cs_boundary_zone_define("walls", "y < 0.001 or y > 0.019", 0);\n'
               '  cs_boundary_zone_define("sides", "z < 0.001 or z > 0.019", 0);\n')


@pytest.fixture(scope="session")
def wall_tables(tmp_path_factory):
    """The two walls' tables (6 cells each), by name."""
    folder = tmp_path_factory.mktemp("cs_wall_tables")
    paths = {wall: folder / f"wall_{wall}.h5" for wall in WALLS}
    for wall, law in WALLS.items():
        # one worker: starting a pool takes longer than these 6 cells
        build_table_from_text(WALL_TABLE_CONFIG.format(**law), paths[wall], workers=1)
    return paths


def _zones_case(tmp_path_factory, name, wall_tables, sections: str, split: bool = True) -> Path:
    """The case on the elastic wall's table (the global settings, shape prism), with ``sections`` appended
    to its settings and, if ``split``, the side walls as the zones walls and sides. Not run."""
    case = _copy_case(tmp_path_factory, name)
    if split:
        zones = case / "SRC" / "cs_user_zones.c"
        zones.write_text(zones.read_text().replace(*SPLIT_ZONES))
    _set(case, "table", str(wall_tables["elastic"]))
    _set(case, "weights", None)
    _set(case, "shape", "prism")
    with (case / "rebound_scatter.conf").open("a") as conf:
        conf.write(sections)
    return case


@pytest.fixture(scope="session")
def zones_case(cs_build, wall_tables, tmp_path_factory):
    """walls on the global settings (the elastic wall, method auto, trapped deposit), target on the lossy
    wall's table with method table and trapped remove, sides with the solver's rebound."""
    case = _zones_case(tmp_path_factory, "cs_zones", wall_tables,
                       f"\n[zone target]\ntable = {wall_tables['lossy']}\nmethod = table\ntrapped = remove\n"
                       "\n[zone sides]\ntype = rebound\n")
    _allrun(case, wall_tables["elastic"])
    return case


def _outside_by_cause(hits: dict, on) -> dict:
    """The hits ``on`` outside the walls' grid, by cause, from their records."""
    V, n = hits["V"][on], hits["n"][on]
    speed = np.linalg.norm(V, axis=1)
    alpha1 = np.degrees(np.arcsin(np.clip(-np.einsum("ij,ij->i", V, n) / speed, -1, 1)))
    return {"speed_below": np.sum(speed < GRID["speed_lo"]), "speed_above": np.sum(speed > GRID["speed_hi"]),
            "alpha1_outside": np.sum(alpha1 < GRID["alpha1_lo"])}


def test_each_zone_does_what_its_section_says(zones_case):
    """The per-zone summary: each hit has one fate; walls draws from the elastic wall's table by both paths and
    deposits what it traps, target from the lossy wall's by the table alone and removes what it traps, sides
    rebounds as the solver's CS_LAGR_REBOUND (V⁺ = V⁻ − 2 (V⁻·n) n, no draw); the hits outside each table's
    grid by cause equal those of the records; each record names its zone's interaction and wall; the tables
    are opened once each; the solver counts the removed particles as deposited and loses none."""
    log = (zones_case / "RESU" / "run_solver.log").read_text()
    rows, info = zone_summary(log), read_summary(log)
    print("\n" + log[log.rindex("  rebound-scatter ("):log.rindex("Destroying")].rstrip())
    assert log.count("rebound-scatter: opened the table") == 2
    assert {z: r["interaction"] for z, r in rows.items()} == {
        "target": "rebound-scatter, wall lossy, soft", "walls": "rebound-scatter, wall elastic (hard steel)",
        "sides": "rebound"}
    walls, target, sides = rows["walls"], rows["target"], rows["sides"]
    for zone, r in rows.items():
        assert r["hits"] == r["rebounded"] + r["stuck"] + r["removed"] + r["escaped"] + r["invalid"] > 1000, zone
        assert r["escaped"] == r["invalid"] == 0, zone
    assert walls["table"] > 0 and walls["direct"] > 0 and walls["table"] + walls["direct"] == walls["hits"]
    assert walls["stuck"] == walls["trapped"] + walls["failed"] and walls["removed"] == 0
    assert target["table"] == target["hits"] and target["direct"] == target["failed"] == 0
    assert target["removed"] == target["trapped"] > 200 and target["stuck"] == 0
    assert sides["rebounded"] == sides["hits"] and sum(sides[k] for k in (
        "table", "direct", "trapped", "speed_below", "speed_above", "alpha1_outside")) == 0
    # the tables' walls are smooth: one wall hit per hit
    assert walls["roughness"] == target["roughness"] == 0 and sides["roughness"] is None
    # the drawn hits' work on the wall, the trapped ones' too (up to the trap); none on the solver's rebound
    assert sides["work_normal"] is None and sides["no_work"] == walls["no_work"] == target["no_work"] == 0
    _check_work(zones_case)
    assert walls["hit_again"] == walls["at_cap"] == target["hit_again"] == target["at_cap"] == 0
    # the first block: the hits a table or the direct model answered, both drawing zones'
    assert info["hits"] == walls["hits"] + target["hits"] and info["direct"] == walls["direct"]
    assert info["trapped"] == walls["trapped"] + target["trapped"]

    hits, headers = read_hits(zones_case / "RESU")
    assert headers[0]["table"].endswith("wall_elastic.h5") and headers[0]["shape"] == "prism"
    for zone, interaction, wall in (("walls", HITS_TITLE, "elastic (hard steel)"),
                                    ("target", HITS_TITLE, "lossy; soft"), ("sides", "rebound", "")):
        on = hits["patch"] == zone
        assert np.sum(on) == rows[zone]["hits"], zone
        assert set(hits["interaction"][on]) == {interaction} and set(hits["wall"][on]) == {wall}, zone
    for zone in ("walls", "target"):
        counted = _outside_by_cause(hits, hits["patch"] == zone)
        for cause, count in counted.items():
            # a hit at the grid's edge itself may fall either side by a rounding of the record
            assert rows[zone][cause] == pytest.approx(count, abs=2) and count > 0, (zone, cause)
    # the hits outside the speeds the zone's wall law holds over: the elastic wall's 60-200 m/s; the lossy wall
    # states none
    on = hits["patch"] == "walls"
    speed = np.linalg.norm(hits["V"][on], axis=1)
    outside = int(np.sum((speed < 60.0) | (speed > 200.0)))
    assert rows["walls"]["outside_law"] == pytest.approx(outside, abs=2) and outside > 0
    assert rows["target"]["outside_law"] == rows["sides"]["outside_law"] == 0
    on = hits["patch"] == "sides"
    V, n = hits["V"][on], hits["n"][on]
    np.testing.assert_allclose(hits["Vout"][on], V - 2 * np.einsum("ij,ij->i", V, n)[:, None] * n,
                               rtol=0, atol=1e-12 * 300)
    assert (hits["status"][on] == STATUS_REBOUNDED).all() and (hits["path"][on] == -1).all()
    assert np.isnan(hits["u0"][on]).all() and (hits["key"][on] == -1).all() and (hits["Wout"][on] == 0).all()

    lagr = _lagrangian_log(zones_case)
    assert lagr[:, 4].sum() == INJECTED and lagr[:, 10].sum() == 0
    assert lagr[:, 8].sum() == target["removed"] + walls["stuck"]
    assert lagr[-1, 2] == INJECTED - lagr[:, 6].sum()


def test_each_zone_draws_from_its_own_table(zones_case, wall_tables):
    """walls' hits follow the elastic wall's law, target's the lossy wall's (surrogate at the same incident
    states with the zone's table, mix, method and interpolation); the elastic law at target's hits is not
    theirs (faster, and never trapped); the hits of two tables are not compared together."""
    for zone, wall in (("walls", "elastic"), ("target", "lossy")):
        res = compare_saturne_rebounds.compare(zones_case / "RESU", classifier=False, zones=[zone])
        assert res["table"] == str(wall_tables[wall]) and res["zones"] == [zone]
        assert res["checks_passed"], (zone, compare_saturne_rebounds.report(res))
    res = compare_saturne_rebounds.compare(zones_case / "RESU", wall_tables["elastic"], classifier=False,
                                           zones=["target"])
    other = res["comparison"].agreement["table"]
    assert not other.ks_ok and not other.not_rebounded_ok, other
    assert other.mean_speed_ratio[0] < other.mean_speed_ratio[1] - 0.1, other
    with pytest.raises(ValueError, match="the zones target, walls draw with 2 tables or settings"):
        compare_saturne_rebounds.compare(zones_case / "RESU", classifier=False)


# the roughness (deg) of the walls zone in test_deposit_and_outlet_zones
ROUGHNESS_DEG = 10


def test_deposit_and_outlet_zones(cs_build, wall_tables, tmp_path_factory):
    """A deposit zone keeps every particle that hits it, at rest (the solver counts them as deposited), an
    outlet zone lets every one leave; neither is recorded, both are counted. The records are thinned
    (hits_every = 3): the 1st, 4th, 7th, ... of the walls' hits, as the file's second line says. walls, a
    section of its own with roughness_deg = 10 (a rough wall on the elastic wall's smooth table), says so in the
    log and the hits files, and some of its hits hit the wall again; compare_saturne_rebounds.py refuses it."""
    # hits_every before the sections: a global key
    case = _zones_case(tmp_path_factory, "cs_stock_zones", wall_tables,
                       f"hits_every = 3\n\n[zone walls]\nroughness_deg = {ROUGHNESS_DEG}\n"
                       "[zone sides]\ntype = deposit\n[zone target]\ntype = outlet\n")
    _allrun(case, wall_tables["elastic"])
    log = (case / "RESU" / "run_solver.log").read_text()
    rows = zone_summary(log)
    assert {z: r["interaction"] for z, r in rows.items()} == {
        "target": "outlet", "walls": "rebound-scatter, wall elastic (hard steel)", "sides": "deposit"}
    assert rows["sides"]["stuck"] == rows["sides"]["hits"] > 100
    assert rows["target"]["escaped"] == rows["target"]["hits"] > 100
    walls = rows["walls"]
    assert f"rebound-scatter: zone walls = rebound-scatter, table {wall_tables['elastic']}" in log
    assert f", roughness {ROUGHNESS_DEG} deg, wall elastic (hard steel)\n" in log
    assert walls["roughness"] == ROUGHNESS_DEG and rows["sides"]["roughness"] is None
    # some hits hit the wall again (docs/model.md §12: 2-5 % at Δγ = 10°); one path counted each
    assert 0 < walls["hit_again"] < 0.2 * walls["hits"] and walls["at_cap"] <= walls["hit_again"], walls
    assert walls["hits"] == walls["table"] + walls["direct"] + walls["invalid"], walls
    assert zone_settings(case / "RESU")["walls"]["roughness"] == ROUGHNESS_DEG
    with pytest.raises(ValueError, match=rf"the zones walls \(roughness_deg {ROUGHNESS_DEG}\) are rough"):
        compare_saturne_rebounds.compare(case / "RESU", classifier=False)
    hits, _ = read_hits(case / "RESU")
    assert set(hits["patch"].tolist()) == {"walls"}
    # one rank: its walls hits are all the hits it would record, of which every 3rd is written
    assert len(hits["status"]) == math.ceil(rows["walls"]["hits"] / 3), rows["walls"]
    with (case / "RESU" / "hits" / "hits_0.csv").open() as f:
        f.readline()
        assert f.readline().startswith("# Every 3rd hit (hits_every 3): the 1st, 4th, 7th, ... of the hits this "
                                       "rank would record. V: incident velocity")
    lagr = _lagrangian_log(case)
    assert lagr[:, 8].sum() == rows["sides"]["stuck"] + rows["walls"]["stuck"]
    assert lagr[:, 6].sum() >= rows["target"]["escaped"] and lagr[:, 10].sum() == 0
    assert lagr[-1, 2] == INJECTED - lagr[:, 6].sum() >= rows["sides"]["stuck"]


@pytest.mark.parametrize("sections, words", [
    ("[zone target]\ntype = bounce\n",
     ['[zone target]: type must be rebound-scatter, rebound, deposit or outlet, not "bounce"']),
    ("[zone wals]\ntype = rebound\n",
     ["[zone wals]: no boundary zone is named wals; the zones are inlet, target, walls"]),
    ("[zone inlet]\ntype = outlet\n",
     ["[zone inlet]: the zone's Lagrangian type is CS_LAGR_INLET, not CS_LAGR_BC_USER: give it CS_LAGR_BC_USER "
      "in cs_user_lagr_boundary_conditions before calling rbs_cs_initialize()"]),
    ("[zone target]\ntype = rebound\ntable = hard.h5\n",
     ['[zone target]: a zone of type rebound takes no key but type, not "table"']),
    ("[zone target]\nseed = 3\n",
     ['global key "seed" in [zone target]; the keys of a section are type, table, shape, weights, method, '
      "interpolation, trapped, roughness_deg"]),
    ("[zone target]\nroughness_deg = 50\n",
     ['[zone target]: roughness_deg must be in [0, 45] (degrees), not "50"']),
], ids=["unknown type", "unknown zone", "zone not CS_LAGR_BC_USER", "key of another type", "global key",
        "roughness out of range"])
def test_bad_zone_section_is_one_clear_error(cs_build, wall_tables, tmp_path_factory, sections, words):
    case = _zones_case(tmp_path_factory, "cs_bad_zone", wall_tables, "\n" + sections, split=False)
    proc = _allrun(case, wall_tables["elastic"], check=False)
    assert proc.returncode != 0
    error = (case / "RESU" / "error").read_text()
    assert "rebound-scatter settings rebound_scatter.conf" in error, error
    for word in words:
        assert word in error, error
    assert not list((case / "RESU").glob("hits/hits_*.csv"))
