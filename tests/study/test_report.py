"""tablegen report: derived quantities, modes, indicatrices, data sources, output folder, CLI."""

import re
import sys

import numpy as np
import pytest

from tests.helpers.cli import user_error
from data_schema.output import FOLDER_MARKER
from data_schema.samples import STATUS_FAILED, STATUS_REBOUNDED, STATUS_TRAPPED
from tablegen.cli import main as tablegen_main
from direct_model.shapes import AspectRatioLaw, second_moment_factor
from direct_model.simulate import simulate
from tablegen.study.figures import FIGURES
from tablegen.study.report import WORK_SPEEDS, direct_data, isotropic_inertia, pool
from tablegen.study.wall_work import bitter_deformation, finnie, scaled_to_meet
from tablegen.study.statistics import (
    PointSamples, collision_classes, derived, histogram_mode, indicatrix_2d, indicatrix_3d, lab_velocity,
    nearest_alpha1, point_statistics,
)

EXPECTED_FILES = {f[0] for f in FIGURES} | {"wall_work.png", "index.md", FOLDER_MARKER}


def _synthetic(m=1000, seed=0, status=(0, 0, 0), collisions=(0,) * 6) -> PointSamples:
    rng = np.random.default_rng(seed)
    return PointSamples(alpha2=rng.uniform(0, np.pi, m), beta2=rng.uniform(-1.2, 1.2, m),
                        speed_ratio=rng.uniform(0.1, 1.0, m), omega=rng.normal(size=(m, 3)),
                        e_rot_ratio=rng.uniform(0, 0.3, m), status_counts=np.array(status),
                        collision_counts=np.array(collisions))


def test_lab_velocity_is_the_specular_direction_for_a_mirror_bounce():
    alpha1 = np.radians([10.0, 45.0, 80.0])
    v = lab_velocity(alpha1, np.zeros(3), np.ones(3))
    np.testing.assert_allclose(v, np.column_stack([np.cos(alpha1), np.sin(alpha1), np.zeros(3)]), atol=1e-15)


def test_derived_quantities_against_closed_forms():
    p = _synthetic()
    q = derived(p)
    V = lab_velocity(p.alpha2, p.beta2, p.speed_ratio)
    # the lab-frame vector gives back the state it was built from (docs/model.md §2)
    np.testing.assert_allclose(np.linalg.norm(V, axis=1), p.speed_ratio, rtol=1e-14)
    np.testing.assert_allclose(np.arctan2(V[:, 1], V[:, 0]), p.alpha2, rtol=1e-13)
    np.testing.assert_allclose(np.arcsin(V[:, 2] / p.speed_ratio), p.beta2, rtol=1e-12)
    np.testing.assert_allclose(q["u"], p.speed_ratio * np.cos(p.beta2) * np.cos(p.alpha2), rtol=1e-14)
    np.testing.assert_allclose(q["v"], p.speed_ratio * np.cos(p.beta2) * np.sin(p.alpha2), rtol=1e-14)
    np.testing.assert_array_equal(q["omega_z"], p.omega[:, 2])
    np.testing.assert_allclose(q["e_trans"], p.speed_ratio ** 2, rtol=1e-15)
    np.testing.assert_array_equal(q["e_rot"], p.e_rot_ratio)


def test_histogram_mode_of_known_histograms():
    assert histogram_mode([0.21, 0.22, 0.55, 0.56, 0.57, -0.25], 0.1) == pytest.approx(0.55)
    assert histogram_mode([-0.25, -0.26, -0.27, 0.1, 0.15], 0.1) == pytest.approx(-0.25)
    assert histogram_mode([0.31, 0.32, 0.71, 0.72], 0.1) == pytest.approx(0.35)    # tie: the lower bin
    assert histogram_mode(np.full(7, 0.4999), 0.5) == pytest.approx(0.25)
    assert np.isnan(histogram_mode([], 0.1))
    # a Gaussian's mode within a bin of its peak
    x = np.random.default_rng(1).normal(0.3, 0.1, 200_000)
    assert abs(histogram_mode(x, 0.01) - 0.3) <= 0.01


def test_collision_classes_and_point_statistics():
    np.testing.assert_array_equal(collision_classes([1, 1, 2, 5, 6, 7, 12, -1]), [2, 1, 0, 0, 1, 3])
    p = _synthetic(status=(90, 8, 2), collisions=(45, 20, 10, 5, 5, 5))
    st = point_statistics(p)
    assert st["trapped_percent"] == pytest.approx(8.0) and st["failed_percent"] == pytest.approx(2.0)
    np.testing.assert_allclose(st["collision_percent"], [50, 20 / 0.9, 10 / 0.9, 5 / 0.9, 5 / 0.9, 5 / 0.9])
    assert st["mean"]["e_trans"] == pytest.approx(np.mean(p.speed_ratio ** 2))
    assert st["mode"]["omega_z"] == histogram_mode(p.omega[:, 2], 0.02)


def test_indicatrices_integrate_to_one():
    p = _synthetic(m=5000)
    edges, density = indicatrix_2d(p.alpha2)
    assert np.degrees(edges[1] - edges[0]) == pytest.approx(2.5)
    assert np.sum(density * np.diff(edges)) == pytest.approx(1.0)
    a_edges, b_edges, density = indicatrix_3d(p.alpha2, p.beta2)
    assert density.shape == (36, 36)
    assert np.sum(density * np.outer(np.diff(a_edges), np.diff(b_edges))) == pytest.approx(1.0)


def test_nearest_alpha1():
    assert nearest_alpha1([30, 60, 90], [15, 30, 45, 60, 75, 90]) == (30.0, 60.0, 90.0)
    assert nearest_alpha1([5, 10, 85], [90]) == (85.0,)


def test_isotropic_inertia_against_closed_forms():
    """tr J/(3 m a²): 2/3 for the cube, 2/5 for the sphere; the aspect-ratio mean by Monte Carlo."""
    near_one = AspectRatioLaw(mean=1.0, sd=0.2, low=1.0 - 1e-9, high=1.0)
    assert isotropic_inertia("prism", 0.3, near_one) == pytest.approx(2.0 / 3.0, rel=1e-8)
    assert isotropic_inertia("ellipsoid", 0.3, near_one) == pytest.approx(0.4, rel=1e-8)
    law = AspectRatioLaw()
    r = law.sample(np.random.default_rng(2), 400_000)
    mc = 2.0 / 3.0 * second_moment_factor("tetrahedron") * np.mean(1 + r[:, 0] ** 2 + (r[:, 0] * r[:, 1]) ** 2)
    assert isotropic_inertia("tetrahedron", 0.3, law) == pytest.approx(mc, rel=2e-3)


def test_pool_is_the_union_with_summed_counts():
    a, b = _synthetic(10, 1, (9, 1, 0), (5, 4, 0, 0, 0, 0)), _synthetic(20, 2, (20, 0, 0), (1, 1, 1, 1, 1, 15))
    m = pool([a, b])
    np.testing.assert_array_equal(m.alpha2, np.r_[a.alpha2, b.alpha2])
    np.testing.assert_array_equal(m.omega, np.vstack([a.omega, b.omega]))
    np.testing.assert_array_equal(m.status_counts, [29, 1, 0])
    np.testing.assert_array_equal(m.collision_counts, [6, 5, 1, 1, 1, 15])


def test_direct_data_holds_the_rebounds_of_the_direct_model():
    data = direct_data(["prism", "mix"], (90.0, 45.0), n=200, seed=5)
    assert data.alpha1 == (45.0, 90.0) and data.shapes == ("prism", "mix") and data.speed == 200.0
    s = simulate("prism", 45.0, 200.0, 200, seed=5)
    p = data.points["prism", 45.0]
    ok = s.rebounded
    np.testing.assert_array_equal(p.speed_ratio, s.speed_ratio[ok])
    np.testing.assert_array_equal(p.e_rot_ratio, s.extra["e_rot_ratio"][ok])      # exact, not approximated
    np.testing.assert_array_equal(p.status_counts, [np.sum(s.status == c) for c in
                                                    (STATUS_REBOUNDED, STATUS_TRAPPED, STATUS_FAILED)])
    mix = data.points["mix", 90.0]
    assert mix.status_counts.sum() == 4 * 200                                     # four shapes, 200 each
    assert mix.alpha2.size == mix.status_counts[STATUS_REBOUNDED]
    assert mix.collision_counts.sum() == mix.status_counts[STATUS_REBOUNDED]


def test_the_work_on_the_wall_is_the_direct_model_s_at_both_speeds():
    """The report's work: every hit that rebounded or was trapped, W/(½|V⁻|²), at each speed of WORK_SPEEDS; the mix
    pools the shapes'."""
    data = direct_data(["prism", "mix"], (45.0,), n=200, seed=5)
    assert data.work_speeds == WORK_SPEEDS == (100.0, 200.0)
    for speed in WORK_SPEEDS:
        s = simulate("prism", 45.0, speed, 200, seed=5)
        kept = (s.status == STATUS_REBOUNDED) | (s.status == STATUS_TRAPPED)
        w = data.work["prism", 45.0, speed]
        np.testing.assert_array_equal(w.normal, s.extra["wall_work_normal"][kept] / (0.5 * speed ** 2))
        np.testing.assert_array_equal(w.tangential, s.extra["wall_work_tangential"][kept] / (0.5 * speed ** 2))
        assert data.work["mix", 45.0, speed].normal.size == sum(
            np.count_nonzero(simulate(shape, 45.0, speed, 200, seed=5).status != STATUS_FAILED)
            for shape in ("ellipsoid", "prism", "cut_prism", "tetrahedron"))


def test_the_erosion_laws_drawn_beside_the_work():
    """Finnie's cutting function is continuous where its regimes meet (tan α = 1/3: both 0.3) and peaks where
    tan 2α = 2/3 (16.85°); Bitter's deformation wear is sin²α; a law scaled to meet a curve equals it at its peak."""
    meet = np.degrees(np.arctan(1.0 / 3.0))
    assert finnie(meet) == pytest.approx(0.3, abs=1e-12) and finnie(meet + 1e-9) == pytest.approx(0.3, abs=1e-8)
    fine = np.linspace(0.1, 90.0, 89_901)
    assert fine[np.argmax(finnie(fine))] == pytest.approx(np.degrees(np.arctan(2.0 / 3.0)) / 2.0, abs=1e-3)
    assert finnie(90.0) == pytest.approx(0.0, abs=1e-15) and bitter_deformation([30.0, 90.0]) == pytest.approx([0.25, 1])
    at, c = scaled_to_meet(bitter_deformation, [30.0, 60.0, 90.0], np.array([0.1, 0.5, 0.4]))
    assert at == 60.0 and c * bitter_deformation(60.0) == pytest.approx(0.5, rel=1e-14)


def _figure_links(index: str) -> set:
    return set(re.findall(r"!\[[^\]]*\]\(([^)]+)\)", index))


def test_cli_direct_writes_every_figure_and_refuses_an_existing_folder(tmp_path, capsys):
    out = tmp_path / "report"
    argv = ["report", "--direct", "-o", str(out), "--shapes", "cut_prism", "-n", "300", "--seed", "3",
            "--alpha1", "30,90", "--no-progress"]
    assert tablegen_main(argv) == 0
    assert {p.name for p in out.iterdir()} == EXPECTED_FILES
    assert all((out / f).read_bytes().startswith(b"\x89PNG") for f in EXPECTED_FILES - {"index.md", FOLDER_MARKER})
    index = (out / "index.md").read_text(encoding="utf-8")
    assert _figure_links(index) == EXPECTED_FILES - {"index.md", FOLDER_MARKER}
    assert "## Collisions per rebound at α1 = 90°" in index and "| cut_prism |" in index
    assert "**E_Ω⁺/E_V⁻** is exact" in index
    assert "## Work on the wall" in index and "| α1 (deg) | W_n/E⁻ 100 m/s | W_t/E⁻ 100 m/s |" in index
    # the numbers table: one row per α1, with the statistics of the same run
    data = direct_data(["cut_prism"], (30.0, 90.0), n=300, seed=3)
    st = point_statistics(data.points["cut_prism", 30.0])
    assert f"| 30 | {st['rebounds']} | " in index and f"{st['mean']['u']:.4f}" in index
    assert [p.name for p in tmp_path.iterdir()] == ["report"]                      # no temporary folder left
    # an existing folder is refused and left intact without --overwrite, replaced with it
    before = (out / "index.md").read_bytes()
    user_error(tablegen_main, argv, capsys, "--overwrite")
    assert (out / "index.md").read_bytes() == before
    (out / "stale.txt").write_text("old")
    assert tablegen_main(argv + ["--overwrite"]) == 0
    assert {p.name for p in out.iterdir()} == EXPECTED_FILES
    assert [p.name for p in tmp_path.iterdir()] == ["report"]


def test_cli_direct_reports_the_grains_of_a_config(tmp_path, capsys):
    """--direct --config runs the configuration's grid shapes (user grains too) with its model, as its table's cells
    would be; the mix pools them; a name outside the grid, or --config with --table, is one line naming it."""
    from tablegen.tabulation.config import load_config
    from tests.helpers.tables import write_grain_config
    config_path = write_grain_config(tmp_path)
    out = tmp_path / "report"
    argv = ["report", "--direct", "--config", str(config_path), "-o", str(out), "--shapes", "sand_b", "mix", "-n",
            "200", "--seed", "3", "--alpha1", "90", "--no-progress"]
    assert tablegen_main(argv) == 0
    index = (out / "index.md").read_text(encoding="utf-8")
    assert "| sand_b |" in index and "| mix |" in index and "grid shapes sand_a, sand_b" in index
    config = load_config(config_path)
    data = direct_data(["sand_b", "mix"], (90.0,), n=200, seed=3, config=config)
    grain = simulate(config.grain("sand_b"), 90.0, 200.0, 200, seed=3, kappa=config.kappa, aspect=config.aspect,
                     n_max=config.n_max, wall=config.wall)
    assert np.array_equal(data.points["sand_b", 90.0].alpha2, grain.alpha2[grain.rebounded])
    assert data.mix_of == ("sand_a", "sand_b")
    assert data.points["mix", 90.0].alpha2.size > data.points["sand_b", 90.0].alpha2.size
    user_error(tablegen_main, argv[:4] + ["-o", str(tmp_path / "r2"), "--shapes", "prism"], capsys,
               "--shapes", "'prism'", "sand_a, sand_b, mix")
    user_error(tablegen_main, ["report", "--table", "t.h5", "--config", str(config_path), "-o", str(tmp_path / "r3")],
               capsys, "--config", "--direct")


@pytest.mark.parametrize("extra, word", [
    (["--direct", "--alpha1", "0"], "--alpha1"), (["--direct", "--alpha1", "30,abc"], "--alpha1"),
    (["--direct", "--alpha1", "95"], "--alpha1"), (["--direct", "-n", "0"], "-n"),
    (["--direct", "--shapes", "sphere"], "--shapes"), (["--direct", "--seed", "-1"], "seed"),
    ([], "--table"), (["--direct", "--table", "t.h5"], "--table"),
    (["--table", "missing.h5"], "missing.h5"),
])
def test_cli_bad_arguments_exit_2_naming_the_argument(extra, word, tmp_path, capsys):
    out = tmp_path / "r"
    user_error(tablegen_main, ["report", "-o", str(out)] + extra, capsys, word)
    assert not out.exists()


def test_cli_tells_what_to_install_without_matplotlib(tmp_path, monkeypatch, capsys):
    for name in [m for m in sys.modules if m == "matplotlib" or m.startswith("matplotlib.")]:
        monkeypatch.delitem(sys.modules, name)
    monkeypatch.setitem(sys.modules, "matplotlib", None)          # import matplotlib raises ImportError
    out = tmp_path / "r"
    user_error(tablegen_main, ["report", "--direct", "-o", str(out), "-n", "10"], capsys,
               'pip install "rebound-scatter[plots]"')
    assert not out.exists()


def test_cli_from_a_table(small_table_path, tmp_path, capsys):
    from data_schema.table import read_table

    out = tmp_path / "report"
    assert tablegen_main(["report", "--table", str(small_table_path), "-o", str(out), "--shapes", "prism",
                          "mix", "-n", "400", "--seed", "1"]) == 0
    assert {p.name for p in out.iterdir()} == EXPECTED_FILES
    index = (out / "index.md").read_text(encoding="utf-8")
    assert _figure_links(index) == EXPECTED_FILES - {"index.md", FOLDER_MARKER}
    # grid α1, the grid speed nearest 200 m/s (150 and 250 tie: the lower), the approximate rotational energy
    assert "| α1 (deg) | 30, 60, 90 |" in index and "150 m/s (the table's grid speed nearest 200 m/s)" in index
    assert "**E_Ω⁺/E_V⁻** is approximate" in index
    # the work on the wall at the grid speeds nearest 100 and 200 m/s (50 and 150)
    assert "| α1 (deg) | W_n/E⁻ 50 m/s | W_t/E⁻ 50 m/s | W_n/E⁻ 150 m/s | W_t/E⁻ 150 m/s |" in index
    # collision percentages at 90° are the table's own cell counts
    table = read_table(small_table_path)
    cell = table.cells["collision_counts"][table.shapes.index("prism"), 2, 1]
    one = 100.0 * cell[0] / cell.sum()
    assert re.search(rf"\| prism \| {one:.1f} % \|", index)
    # α1 off the table's grid: exit 2 naming alpha1 and the grid
    user_error(tablegen_main, ["report", "--table", str(small_table_path), "-o", str(tmp_path / "r2"),
                               "--alpha1", "45"], capsys, "alpha1")


def test_cli_from_a_table_on_rough_walls(small_table_path, tmp_path, capsys):
    """--roughness-deg adds the mix's law on those walls: a figure and one row per (Δγ, α1); the smooth wall's rows
    never hit again, and the rough wall widens β2 at every α1 (400 hits a row: sd of an sd about 4 %)."""
    out = tmp_path / "report"
    assert tablegen_main(["report", "--table", str(small_table_path), "-o", str(out), "--shapes", "mix",
                          "-n", "400", "--seed", "1", "--alpha1", "30,60", "--roughness-deg", "0,20"]) == 0
    index = (out / "index.md").read_text(encoding="utf-8")
    assert (out / "rough_wall.png").stat().st_size > 10_000 and "![Rough walls](rough_wall.png)" in index
    section = index.split("## Rough walls")[1].split("\n## ")[0]
    cells = [line.strip("| ").split(" | ") for line in section.splitlines() if line[2:3].isdigit()]
    rows = {(float(c[0]), float(c[1])): [float(x) for x in c[2:]] for c in cells}
    assert set(rows) == {(0.0, 30.0), (0.0, 60.0), (20.0, 30.0), (20.0, 60.0)}
    for a1 in (30.0, 60.0):
        assert rows[0.0, a1][4] == 0.0 and rows[20.0, a1][3] > 1.2 * rows[0.0, a1][3]
    user_error(tablegen_main, ["report", "--direct", "-o", str(tmp_path / "r3"), "--roughness-deg", "5"], capsys,
               "--roughness-deg goes with --table")
    user_error(tablegen_main, ["report", "--table", str(small_table_path), "-o", str(tmp_path / "r4"),
                               "--roughness-deg", "5,50"], capsys, "[0, 45]", "5,50")
