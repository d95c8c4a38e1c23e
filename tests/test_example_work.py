"""examples/wall_work.py runs on any table of the four families with the work and reports every case (docs/model.md
§4.7)."""

from tests.helpers.examples import EXAMPLES, example_module


def test_the_wall_work_example_reports_every_case(small_table_path, tmp_path, capsys):
    module = example_module(EXAMPLES / "wall_work.py")
    figure = tmp_path / "work.png"
    assert module.main(["--table", str(small_table_path), "--n", "300", "--figure", str(figure)]) == 0
    rows = [r for r in (line.split() for line in capsys.readouterr().out.splitlines()) if len(r) == 8 and r[0].isdigit()]
    assert [(float(r[0]), float(r[1])) for r in rows] == [(v, a) for v in module.SPEEDS for a in module.ALPHA1_DEG]
    for r in rows:      # each source's mean W_n and W_t per hit: ≥ 0, together at most the incident energy
        table_n, direct_n, table_t, direct_t = float(r[2]), float(r[3]), float(r[5]), float(r[6])
        assert min(table_n, direct_n, table_t, direct_t) >= 0.0
        assert table_n + table_t <= 1.0 and direct_n + direct_t <= 1.0
    assert figure.stat().st_size > 10_000
