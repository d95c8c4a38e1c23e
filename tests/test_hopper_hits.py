"""benchmarks/hopper_hits.py: each hit's Ω⁻ is the Ω⁺ of the same parcel's previous hit (0 at its first), checked
against the run's own spin_ratio column; and the stored sample benchmarks/data/hopper_hits.csv holds what its
header says."""

import math
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))
hopper_hits = pytest.importorskip("hopper_hits")

HEADER = ("# stochasticRebound hits: seed 7, stream 0, table /x/t.h5, mix prism, halfSizeFactor 1, interpolation scaled\n"
          "# columns\n"
          "time,rank,patch,origProc,origId,d,a,Vx,Vy,Vz,nx,ny,nz,Uwx,Uwy,Uwz,status,Voutx,Vouty,Voutz,Wx,Wy,Wz,"
          "spin_ratio,u0\n")


def _case(tmp_path, rows):
    """A case folder whose hits file holds ``rows``: (time, origId, V, Wout, spin_ratio), a = 1e-4 m, n = +y."""
    folder = tmp_path / "postProcessing" / "lagrangian" / "cloud" / "stochasticRebound"
    folder.mkdir(parents=True)
    lines = [HEADER]
    for time, parcel, V, W, ratio in rows:
        lines.append(f"{time},0,walls,0,{parcel},2e-4,1e-4,{V[0]!r},{V[1]!r},{V[2]!r},0,1,0,0,0,0,0,1,1,0,"
                     f"{W[0]!r},{W[1]!r},{W[2]!r},{ratio!r},0.5\n")
    (folder / "hits_0.csv").write_text("".join(lines))
    return tmp_path


def test_omega_in_is_the_previous_hit_s_omega_out(tmp_path):
    V = (3.0, -4.0, 0.0)                                    # |V⁻| = 5 m/s
    W1, W2 = (1e4, 0.0, 0.0), (0.0, -2e4, 2e4)
    rows = [(0.1, 1, V, W1, 0.0), (0.1, 2, V, W2, 0.0),     # first hits: Ω⁻ = 0
            (0.2, 1, V, W2, 1e4 * 1e-4 / 5), (0.3, 1, V, W1, math.hypot(2e4, 2e4) * 1e-4 / 5),
            (0.3, 2, V, W1, math.hypot(2e4, 2e4) * 1e-4 / 5)]
    out = tmp_path / "sample.csv"
    summary = hopper_hits.extract(_case(tmp_path, rows), out, 10)
    assert summary["rows"] == 5 and summary["worst_spin_ratio_difference"] < 1e-15
    sample = hopper_hits.read_sample(out)
    np.testing.assert_array_equal(sample["omega"], [(0, 0, 0), (0, 0, 0), W1, W2, W2])
    np.testing.assert_array_equal(sample["V"], [V] * 5)


def test_a_run_whose_spins_do_not_chain_is_refused(tmp_path):
    """A parcel turned between its hits (a collision model, say): its spin_ratio does not match."""
    V = (3.0, -4.0, 0.0)
    rows = [(0.1, 1, V, (1e4, 0.0, 0.0), 0.0), (0.2, 1, V, (0.0, 0.0, 0.0), 0.3)]
    with pytest.raises(SystemExit, match="does not match the run's spin_ratio"):
        hopper_hits.extract(_case(tmp_path, rows), tmp_path / "sample.csv", 10)


def test_the_stored_sample():
    """The hits move into their walls through unit normals, and spin_ratio is |Ω⁻|a/|V⁻| of each row."""
    sample = hopper_hits.read_sample()
    assert len(sample["a"]) == 2782 and 0.45 < np.mean(sample["spin_ratio"] > 0) < 0.55
    assert np.all(np.einsum("ij,ij->i", sample["V"], sample["n"]) < 0)
    np.testing.assert_allclose(np.linalg.norm(sample["n"], axis=1), 1.0, rtol=0, atol=1e-12)
    ratio = np.linalg.norm(sample["omega"], axis=1) * sample["a"] / np.linalg.norm(sample["V"], axis=1)
    np.testing.assert_allclose(ratio, sample["spin_ratio"], rtol=1e-15, atol=0)
