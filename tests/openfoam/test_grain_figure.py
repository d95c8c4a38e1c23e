"""integrations/openfoam/grain_figure.py on hits files written here (no solver run): the parcels' hits in time
order across rank files, the fraction still moving after k hits, α1 at the second hit, the mode check.

Copyright (C) 2026 the rebound-scatter authors. License: GPL-3.0-or-later
(see integrations/openfoam/LICENSE): these tests import the integration's scripts.
"""

from __future__ import annotations

import subprocess
import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[2]
OPENFOAM_DIR = REPO / "integrations" / "openfoam"
sys.path.insert(0, str(OPENFOAM_DIR))

import grain_figure  # noqa: E402
from rbs_api import HIT_COLUMNS, STATUS_REBOUNDED, STATUS_TRAPPED  # noqa: E402

HEADER = ("# stochasticRebound hits: seed 1, stream {rank}, table t.h5, mix weights (prism 0.5, tetrahedron 0.5), "
          "halfSizeFactor 1, interpolation scaled, method auto, spin tolerance 0.001, grain {grain}")

# (rank file, time, parcel id, status, alpha1 in deg, shape): parcel 0 rebounds 3 times (its second hit on
# rank 1), parcel 1 is trapped at its first hit, parcel 2 at its second, parcel 3 hits once and leaves
HITS = [(0, 0.3, 0, STATUS_REBOUNDED, 70.0, "prism"), (0, 0.1, 0, STATUS_REBOUNDED, 10.0, "prism"),
        (0, 0.1, 1, STATUS_TRAPPED, 80.0, "tetrahedron"), (0, 0.1, 2, STATUS_REBOUNDED, 20.0, "tetrahedron"),
        (1, 0.2, 0, STATUS_REBOUNDED, 30.0, "prism"), (0, 0.2, 2, STATUS_TRAPPED, 45.0, "tetrahedron"),
        (1, 0.1, 3, STATUS_REBOUNDED, 60.0, "prism")]


def _case(root: Path, grain: str) -> Path:
    folder = root / "postProcessing" / "lagrangian" / "kinematicCloud" / "stochasticRebound"
    folder.mkdir(parents=True)
    mode = "kept (key seed 1)" if grain == "kept" else "perHit"
    for rank in (0, 1):
        lines = [HEADER.format(rank=rank, grain=mode), "# free text", ",".join(HIT_COLUMNS)]
        for r, time, parcel, status, alpha1, shape in HITS:
            if r != rank:
                continue
            row = dict.fromkeys(HIT_COLUMNS, "0")
            a = np.radians(alpha1)
            row.update(time=repr(time), rank=str(rank), patch="walls", origProc="0", origId=str(parcel),
                       status=str(status), Vx=repr(float(100 * np.cos(a))), Vz=repr(float(-100 * np.sin(a))), nz="1",
                       key=str(parcel) if grain == "kept" else "-1", shape=shape if grain == "kept" else "")
            lines.append(",".join(row[c] for c in HIT_COLUMNS))
        (folder / f"hits_{rank}.csv").write_text("\n".join(lines) + "\n")
    return root


def test_survival_and_second_hit_alpha1(tmp_path):
    kept, per_hit = _case(tmp_path / "kept", "kept"), _case(tmp_path / "perhit", "perHit")
    res = grain_figure.summary(kept, per_hit)
    s = res["kept"]["survival"]
    # 4 parcels make a first hit, 1 stopped; 2 a second, 1 stopped; 1 a third: 3/4, then 3/4 * 1/2 twice
    assert (s["at_risk"], s["stopped"]) == ([4, 2, 1, 0, 0], [1, 1, 0, 0, 0])
    np.testing.assert_allclose(s["fraction"][:3], [0.75, 0.375, 0.375])
    assert res["perHit"]["survival"]["fraction"][:3] == s["fraction"][:3]
    by_shape = res["kept"]["survival_by_shape"]
    assert by_shape["prism"]["fraction"][:3] == [1.0, 1.0, 1.0] and by_shape["tetrahedron"]["fraction"][:2] == [0.5, 0]
    # the second hit of parcel 0 is on rank 1 at t = 0.2 (30°), of parcel 2 at 45°: hits ordered by time per parcel
    np.testing.assert_allclose(np.sort(res["kept"]["alpha1_second"]), [30.0, 45.0], atol=1e-9)
    assert res["alpha1_second_ks"]["distance"] == 0
    png = tmp_path / "grain.png"
    grain_figure.plot(res, png)
    assert png.stat().st_size > 10_000


def test_a_run_of_the_other_mode_is_one_line_exit_2(tmp_path):
    kept = _case(tmp_path / "kept", "kept")
    proc = subprocess.run([sys.executable, str(OPENFOAM_DIR / "grain_figure.py"), "plot", str(kept), str(kept)],
                          capture_output=True, text=True, cwd=REPO)
    assert proc.returncode == 2 and proc.stdout == ""
    assert proc.stderr.strip() == f"grain_figure.py: {kept} was run with grain kept, not perHit"


def test_the_figure_table_is_the_case_grid_with_two_shapes_and_n_max_2():
    case, fig = (tomllib.loads(text) for text in (grain_figure.CASE_TABLE_CONFIG, grain_figure.FIGURE_TABLE_CONFIG))
    assert fig["grid"]["shapes"] == ["prism", "tetrahedron"] and fig["simulation"]["n_max"] == 2
    assert "n_max" not in case["simulation"]        # the default, 1000
    assert {k: v for k, v in fig["grid"].items() if k != "shapes"} == {k: v for k, v in case["grid"].items()
                                                                       if k != "shapes"}


@pytest.fixture(autouse=True)
def _repo_on_path(monkeypatch):
    monkeypatch.setenv("PYTHONPATH", str(REPO))
