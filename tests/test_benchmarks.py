"""benchmarks/bench_sampler.py and bench_direct.py run end to end and report every figure the issues ask for
(bench_grains.py, which times C too: tests/native/test_native_bench.py).

A smoke test, so the benchmark cannot silently break when the kernels' data or signatures change; the
figures themselves are machine-dependent and are not asserted (speed is reported, never tested). And the
hopperRebound hits sample bench_direct.py reads (benchmarks/data/hopper_hits.csv) holds what its header says.
"""

import json
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
bench_sampler = pytest.importorskip("bench_sampler")


def test_bench_sampler_reports_every_figure(small_table_path, tmp_path, capsys):
    out = tmp_path / "figures.json"
    assert bench_sampler.main(["--table", str(small_table_path), "-n", "3000", "--repeats", "1",
                               "--min-time", "0.01", "--json", str(out)]) == 0
    figures = json.loads(out.read_text())
    results = figures["results"]
    for key in ("a_all", "a_1", "a_kernel_1", "b", "b_rebound", "b_views", "b_predrawn", "b_block", "b_rng", "c", "d",
                "e_table", "e_auto", "e_spin", "e_mix", "e_rough5", "e_rough10", "e_rough20"):
        assert results[key]["ns_per_state"] > 0, key
    assert figures["ratios"]["mix_over_table"] == pytest.approx(results["e_mix"]["ns_per_state"]
                                                                / results["e_table"]["ns_per_state"])
    assert results["e_spin"]["note"].startswith("1.000 of the hits") and results["e_mix"]["note"].startswith("0.500")
    assert figures["ratios"]["rough10_over_table"] == pytest.approx(results["e_rough10"]["ns_per_state"]
                                                                    / results["e_table"]["ns_per_state"])
    assert float(results["e_rough20"]["note"].split()[0]) > 0       # some hits on a rough wall hit again
    b, c, d = (results[k]["ns_per_state"] for k in ("b", "c", "d"))
    assert figures["ratios"]["direct_over_kernel"] == pytest.approx(c / b)
    assert figures["ratios"]["kernel_over_bounce"] == pytest.approx(b / d)
    assert figures["ratios"]["rebound_over_kernel"] == pytest.approx(results["b_rebound"]["ns_per_state"] / b)
    # (a) and (b) draw the same 3000 states from one table with other uniforms: their fractions of hits not rebounded
    # estimate one p, so they differ by less than 5 standard deviations of a difference of two binomial means
    trapped_a, trapped_b = figures["trapped_fraction"]["a"], figures["trapped_fraction"]["b"]
    p = (trapped_a + trapped_b) / 2.0
    assert abs(trapped_a - trapped_b) <= 5.0 * (2.0 * p * (1.0 - p) / 3000) ** 0.5 + 1.0 / 3000, (trapped_a, trapped_b)
    assert figures["memory_latency"]["table_bytes"] > 0
    printed = capsys.readouterr().out
    assert "(c)/(b)" in printed and "(b)/(d)" in printed and "target" in printed


bench_direct = pytest.importorskip("bench_direct")


def test_bench_direct_reports_the_runtime_kernel(tmp_path, capsys):
    out = tmp_path / "direct.json"
    assert bench_direct.main(["--runtime", "--quick", "--states", "40", "--no-native", "--json", str(out)]) == 0
    rows = json.loads(out.read_text())["runtime"]
    assert [(r["shape"], r["states"]) for r in rows] == [(s, name) for s in bench_direct.SHAPES
                                                         for name in bench_direct.STATE_SETS]
    for row in rows:
        assert row["us_per_rebound"] > 0 and row["us_model_frame"] > 0 and row["collisions_per_rebound"] >= 1
        for piece in ("us_flight_setup", "us_orientation", "us_lowest_points", "us_collision"):
            assert row[piece] > 0, piece
    printed = capsys.readouterr().out
    assert "numba us" in printed and "Targets, C" in printed and "not measured" in printed and "orient %" in printed


def test_the_stored_hits_sample():
    """benchmarks/data/hopper_hits.csv holds what its header says: 2767 hits of a hopperRebound run, half of them
    spinning; they move into their walls through unit normals, and spin_ratio is |Ω⁻|a/|V⁻| of each row."""
    sample = bench_direct.read_hits_sample()
    header = bench_direct.HITS_SAMPLE.read_text().splitlines()[1]
    assert "method auto" in header and "2767 rows" in header and "49.2% spinning" in header
    assert len(sample["a"]) == 2767 and f"{np.mean(sample['spin_ratio'] > 0):.1%}" == "49.2%"
    assert np.all(np.einsum("ij,ij->i", sample["V"], sample["n"]) < 0)
    np.testing.assert_allclose(np.linalg.norm(sample["n"], axis=1), 1.0, rtol=0, atol=1e-12)
    ratio = np.linalg.norm(sample["omega"], axis=1) * sample["a"] / np.linalg.norm(sample["V"], axis=1)
    np.testing.assert_allclose(ratio, sample["spin_ratio"], rtol=1e-15, atol=0)


def test_a_hits_sample_without_omega_in_is_refused(tmp_path):
    """A sample written before Ω⁻ was recorded (no Wx, Wy, Wz) is refused in one line naming the columns."""
    path = tmp_path / "old.csv"
    path.write_text("# old\nVx,Vy,Vz,nx,ny,nz,a,spin_ratio\n3,-4,0,0,1,0,1e-4,0\n")
    with pytest.raises(ValueError, match=r"no column Wx,Wy,Wz; the columns are 'Vx,Vy,Vz,nx,ny,nz,a,spin_ratio'"):
        bench_direct.read_hits_sample(path)
    path.write_text("# new\nVx,Vy,Vz,nx,ny,nz,a,Wx,Wy,Wz,spin_ratio\n3,-4,0,0,1,0,1e-4,0,0,1e4,0.2\n")
    sample = bench_direct.read_hits_sample(path)
    assert sample["omega"].tolist() == [[0.0, 0.0, 1e4]] and sample["n"].tolist() == [[0.0, 1.0, 0.0]]

