"""examples/rough_wall.py runs on any table of the four families and reports every case (docs/model.md §12)."""

from tests.helpers.examples import EXAMPLES, example_module


def test_the_rough_wall_example_reports_every_case(small_table_path, tmp_path, capsys):
    module = example_module(EXAMPLES / "rough_wall.py")
    figure = tmp_path / "rough.png"
    assert module.main(["--table", str(small_table_path), "--n", "200", "--figure", str(figure)]) == 0
    rows = [line.split() for line in capsys.readouterr().out.splitlines() if line[:6].strip().isdigit()]
    assert [(float(r[0]), float(r[1])) for r in rows] == [(a, g) for a in module.ALPHA1_DEG
                                                          for g in module.ROUGHNESS_DEG]
    assert all(float(r[6]) == 0.0 for r in rows if float(r[1]) == 0.0)      # a smooth wall never hits again
    assert figure.stat().st_size > 10_000
