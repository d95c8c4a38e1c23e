"""examples/rough_wall.py runs on any table of the four families and reports every case (docs/model.md §12)."""

import importlib.util

from tests.helpers import REPO


def test_the_rough_wall_example_reports_every_case(small_table_path, tmp_path, capsys, monkeypatch):
    monkeypatch.syspath_prepend(str(REPO / "examples"))        # as when run as a script: its helper module beside it
    spec = importlib.util.spec_from_file_location("rough_wall", REPO / "examples" / "rough_wall.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    figure = tmp_path / "rough.png"
    assert module.main(["--table", str(small_table_path), "--n", "200", "--figure", str(figure)]) == 0
    rows = [line.split() for line in capsys.readouterr().out.splitlines() if line[:6].strip().isdigit()]
    assert [(float(r[0]), float(r[1])) for r in rows] == [(a, g) for a in module.ALPHA1_DEG
                                                          for g in module.ROUGHNESS_DEG]
    assert all(float(r[6]) == 0.0 for r in rows if float(r[1]) == 0.0)      # a smooth wall never hits again
    assert figure.stat().st_size > 10_000
