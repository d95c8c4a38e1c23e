"""benchmarks/bench_support.py runs end to end and reports climb and scan for every hull size (figures not asserted)."""

import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
import bench_support  # noqa: E402


def test_bench_support_reports_every_hull_size(tmp_path):
    out = tmp_path / "support.json"
    assert bench_support.main(["--queries", "2000", "--json", str(out)]) == 0
    results = json.loads(out.read_text())["results"]
    assert sorted(map(int, results)) == list(bench_support.SIZES)
    assert all(r["climb_ns"] > 0 and r["scan_ns"] > 0 for r in results.values())
