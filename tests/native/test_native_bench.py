"""benchmarks/bench_native.py and bench_direct.py --runtime run end to end (--quick) on the session's table,
and bench_grains.py on a few states, and report every figure.

Smoke tests: the figures are machine-dependent and are not asserted; the bits of the C calls against
numba's on the bench states are.
"""

import json
import sys

import pytest

from tests.helpers import REPO

sys.path.insert(0, str(REPO / "benchmarks"))


def test_bench_native_quick(native_build, small_table_path, tmp_path, capsys):
    import bench_native
    out = tmp_path / "native.json"
    assert bench_native.main(["--quick", "--table", str(small_table_path), "-n", "20000", "--build-dir",
                              str(native_build), "--json", str(out)]) == 0
    figures = json.loads(out.read_text())
    for key in ("c_per_particle", "c_many", "c_many_given", "c_rng", "numba_per_particle", "numba_block",
                "c_grant_tabakoff", "numba_grant_tabakoff", "c_spin_still"):
        assert figures["ns_per_state"][key] > 0, key
    # the spinning hits (|Omega-| a/|V-| = 0.3, far above the spin tolerance) all went to the direct model
    spin = figures["spin"]
    assert spin["spinning"] == 20000 and spin["spinning_direct"] == spin["spinning"] and spin["spinning_us_per_hit"] > 0
    assert figures["same_bits"] is True
    printed = capsys.readouterr().out
    assert "(C-many)/(C-GT)" in printed and "target" in printed


def test_bench_direct_runtime_quick(native_build, small_table_path, tmp_path, capsys):
    """bench_direct.py --runtime times the C direct model next to numba's, and its outputs are numba's bits."""
    import bench_direct
    out = tmp_path / "direct.json"
    assert bench_direct.main(["--runtime", "--quick", "--states", "40", "--table", str(small_table_path),
                              "--build-dir", str(native_build), "--json", str(out)]) == 0
    rows = json.loads(out.read_text())["runtime"]
    assert len(rows) == 4 * len(bench_direct.STATE_SETS)
    for row in rows:
        assert row["us_c"] > 0 and row["c_same_bits"] is True, row
        for piece in ("c_us_model_frame", "c_us_flight_setup", "c_us_orientation", "c_us_lowest_points",
                      "c_us_collision"):
            assert row[piece] > 0, piece
    printed = capsys.readouterr().out
    assert "C outputs equal numba's bits on every row: yes" in printed and "Where C's time goes" in printed
    assert "at the 'spinning' states:" in printed and "averaged over hopperRebound's hits, per shape: ellipsoid" in printed


def test_bench_grains_reports_the_cost_against_hull_size(native_build, tmp_path, capsys):
    """bench_grains.py times numba and C on every hull size, C's outputs numba's bits, and reports the targets."""
    import bench_grains
    out = tmp_path / "grains.json"
    assert bench_grains.main(["--states", "40", "--repeats", "1", "--build-dir", str(native_build), "--json",
                              str(out)]) == 0
    rows = json.loads(out.read_text())["rows"]
    one_set = [("prism", 8)] + [(f"grain_{n}", n) for n in bench_grains.SIZES]
    scanned = [(r["shape"], r["vertices"]) for r in rows[len(one_set):len(one_set) + len(bench_grains.SCANNED)]]
    assert all(name == f"scanned_{n}" and n > 1000 for name, n in scanned)
    assert [(r["shape"], r["vertices"]) for r in rows] == (one_set + scanned) * 2
    for row in rows:
        assert row["us_per_rebound"] > 0 and row["c_us_per_rebound"] > 0 and row["collisions_per_rebound"] >= 1
        assert row["c_equals_numba"] is True
        assert row["over_prism"] == pytest.approx(row["us_per_rebound"] / next(
            r["us_per_rebound"] for r in rows if r["shape"] == "prism" and r["states"] == row["states"]))
    printed = capsys.readouterr().out
    for size, ratio in bench_grains.TARGETS.items():
        for runtime in ("numba", "C"):
            assert f"Target: a {size}-vertex grain within {ratio:g}x the prism's cost per rebound, {runtime}:" in \
                printed
