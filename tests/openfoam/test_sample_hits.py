"""integrations/openfoam/sample_hits.py: every k-th hit of a hits file with its Ω⁻ (the columns Winx, Winy, Winz),
checked against the run's own spin_ratio column, read back by benchmarks/bench_direct.py. Needs no OpenFOAM:
the hits files are written here, with the adapter's columns (HIT_COLUMNS).

Copyright (C) 2026 the rebound-scatter authors. License: GPL-3.0-or-later
(see integrations/openfoam/LICENSE).
"""

import math
import sys
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "integrations" / "openfoam"))
sys.path.insert(0, str(REPO / "benchmarks"))

import sample_hits  # noqa: E402
from rbs_api import HIT_COLUMNS  # noqa: E402
from bench_direct import read_hits_sample  # noqa: E402

HEADER = ("# stochasticRebound hits: seed 7, stream 0, table /x/t.h5, mix prism, halfSizeFactor 1, "
          "interpolation scaled, method auto, spin tolerance 1e-06\n# columns\n"
          + ",".join(HIT_COLUMNS) + "\n")
A = 1e-4   # m


def _case(tmp_path, hits):
    """A case folder whose hits file holds ``hits``: (V, Win, spin_ratio), a = A, n = +y, one parcel each."""
    folder = tmp_path / "postProcessing" / "lagrangian" / "cloud" / "stochasticRebound"
    folder.mkdir(parents=True)
    lines = [HEADER]
    for i, (V, W, ratio) in enumerate(hits):
        row = dict.fromkeys(HIT_COLUMNS, "0")
        row.update(time=repr(0.1 * (i + 1)), patch="walls", origId=str(i), d=repr(2 * A), a=repr(A), ny="1",
                   Voutx="1", Vouty="1", Wx="5e3", spin_ratio=repr(ratio), u0="0.5")
        row.update({f"V{c}": repr(v) for c, v in zip("xyz", V)})
        row.update({f"Win{c}": repr(w) for c, w in zip("xyz", W)})
        lines.append(",".join(row[c] for c in HIT_COLUMNS) + "\n")
    (folder / "hits_0.csv").write_text("".join(lines))
    return tmp_path


def test_the_sample_takes_every_kth_hit_with_its_omega_in(tmp_path):
    V = (3.0, -4.0, 0.0)                                    # |V⁻| = 5 m/s
    spins = [(0.0, 0.0, 0.0), (1e4, 0.0, 0.0), (0.0, -2e4, 2e4), (3e3, 4e3, 0.0), (0.0, 0.0, -7e3)]
    hits = [(V, W, math.sqrt(sum(w * w for w in W)) * A / 5) for W in spins]
    out = tmp_path / "sample.csv"
    summary = sample_hits.extract(_case(tmp_path, hits), out, 2)     # 5 hits, at most 2 rows: every 3rd
    assert (summary["hits"], summary["stride"], summary["rows"]) == (5, 3, 2)
    assert summary["worst_spin_ratio_difference"] < 1e-15
    sample = read_hits_sample(out)
    np.testing.assert_array_equal(sample["omega"], [spins[0], spins[3]])   # Winx..z, not the Ω⁺ column Wx..z
    np.testing.assert_array_equal(sample["V"], [V, V])
    np.testing.assert_array_equal(sample["n"], [(0, 1, 0), (0, 1, 0)])
    np.testing.assert_array_equal(sample["a"], [A, A])
    np.testing.assert_array_equal(sample["spin_ratio"], [0.0, 5e3 * A / 5])
    assert "method auto" in out.read_text().splitlines()[1]


def test_a_file_whose_spin_ratio_does_not_match_its_omega_in_is_refused(tmp_path):
    V = (3.0, -4.0, 0.0)
    ratio = 1e4 * A / 5
    hits = [(V, (1e4, 0.0, 0.0), ratio * (1 + 3 * sample_hits.SPIN_RATIO_TOLERANCE))]
    with pytest.raises(SystemExit, match="does not match the run's spin_ratio"):
        sample_hits.extract(_case(tmp_path, hits), tmp_path / "sample.csv", 10)
    hits = [(V, (1e4, 0.0, 0.0), ratio * (1 + 0.5 * sample_hits.SPIN_RATIO_TOLERANCE))]   # within: accepted
    assert sample_hits.extract(_case(tmp_path / "ok", hits), tmp_path / "sample.csv", 10)["rows"] == 1


def test_command_line_refuses_max_below_one(tmp_path, capsys):
    assert sample_hits.main([str(tmp_path), "--max", "0"]) == 2
    err = capsys.readouterr().err.strip()
    assert err == "sample_hits.py: --max must be >= 1; got 0"
