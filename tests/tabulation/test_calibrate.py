"""`tablegen calibrate` (tablegen.tabulation.calibration): the fit recovers the wall law that made the data, with
standard errors that cover the truth; data that cannot determine the fit, bad CSV and outputs that are not ours are
refused in one line with exit 2 and nothing written; the [wall] section written reads back through the
configuration reader."""

import functools
import subprocess
import sys

import numpy as np
import pytest

from direct_model.wall import TabulatedWall, WallMaterial
from tablegen.cli import main
from tablegen.tabulation import calibration as cal
from tablegen.tabulation.config import load_config, parse_config
from tests.helpers import REPO, cpu_dispatch
from tests.helpers.cli import run_cli, user_error

_run = functools.partial(run_cli, main)
_user_error = functools.partial(user_error, main)

PARTICLES = 500         # per row in the fits: a mean's model standard error ~0.007 (0.003 for e_n beyond 30°)


def _data(law, alpha1, speed, *, mix, seed, particles, n_exp, noise_seed, names=cal.COEFFICIENTS, with_sd=True):
    """Measurements made by the direct model with ``law``: the means of ``particles`` per row drawn from ``seed``
    (:func:`cal.particle_seeds`, as the fit draws its own), plus gaussian noise of sd/√n_exp on each mean, as the
    mean of n_exp measured particles would carry (sd: the model's own scatter among particles)."""
    alpha1, speed = np.asarray(alpha1, float), np.asarray(speed, float)
    counts = [max(1, round(particles * w)) for w in mix.values()]
    means, variances = cal.model_means(law, alpha1, speed, list(mix), list(mix.values()), counts,
                                       cal.particle_seeds(seed, len(alpha1), len(mix)), {})
    means, variances = cal.in_form(names, alpha1, means), cal.in_form(names, alpha1, variances, True)
    sd = np.sqrt(variances * particles)
    noisy = means + np.random.default_rng(noise_seed).standard_normal(means.shape) * sd / np.sqrt(n_exp)
    return cal.measurements(alpha1, speed, names, noisy, sd if with_sd else None, np.full(len(alpha1), n_exp),
                            source="synthetic")


def _assert_recovered(fit, truth, max_relative_se):
    """Each free parameter within 3 standard errors of the truth (a law, or its fit values by name), in its fit
    coordinate (log k, log p, q; logit a_nc): the noise is gaussian with the stated sd/√n, so a parameter misses
    with probability 0.3 % if the linearised covariance holds; and the standard errors are small enough
    (``max_relative_se``, in those coordinates) for the check to mean something."""
    true = truth.parameters() if hasattr(truth, "parameters") else truth
    transforms = cal.fit_form(fit.family, fit.data.speed).transforms
    for name in fit.free:
        transform = transforms[name]
        se = fit.standard_error[name] / transform.slope(transform.forward(fit.values[name]))
        miss = transform.forward(fit.values[name]) - transform.forward(true[name])
        assert abs(miss) < 3.0 * se, (name, fit.values[name], true[name], se)
        assert se < max_relative_se[name], (name, se)


TWO_SPEEDS = dict(alpha1=[20.0, 45.0, 70.0] * 2, speed=[60.0] * 3 + [300.0] * 3)
THREE_SPEEDS = dict(alpha1=[25.0, 50.0, 75.0] * 3, speed=[80.0] * 3 + [150.0] * 3 + [300.0] * 3)
LAW_A = WallMaterial(0.15, 0.55, 0.7, name="a")
LAW_B = WallMaterial(0.05, 0.75, 1.3, name="b")
MIX_B = {"ellipsoid": 0.3, "cut_prism": 0.7}


@pytest.fixture(scope="module")
def fit_two_speeds():
    """LAW_A at 2 speeds, e_n and e_t with their sd, the four families. Common random numbers made honest: the data
    come from other seeds than the fit's (and 4x the particles, so their own Monte Carlo error is a small part of
    the stated sd/√n); the fit's model noise enters its weights, so its standard errors cover the bias its fixed
    particles leave."""
    data = _data(LAW_A, **TWO_SPEEDS, mix=cal.DEFAULT_MIX, seed=101, particles=4 * PARTICLES, n_exp=2000,
                 noise_seed=3)
    return cal.calibrate(data, particles=PARTICLES, seed=7)


def test_recovers_a_law_at_two_speeds(fit_two_speeds):
    _assert_recovered(fit_two_speeds, LAW_A, {"k": 0.6, "p": 0.15, "q": 0.1})
    # residual variance per mean sd²(1/n_exp + 1/(4 PARTICLES) + 1/PARTICLES), weights 1/(sd²(1/n_exp + 1/PARTICLES)):
    # chi2/dof about 1.2 over 12 − 3 = 9 degrees of freedom; above 2.5 with probability about 3 %
    assert not fit_two_speeds.scaled and fit_two_speeds.chi2_dof < 2.5
    assert abs(fit_two_speeds.correlation[0, 1]) > 0.9       # k and p trade off even across 60-300 m/s


def test_recovers_another_law_at_three_speeds_without_sd():
    """LAW_B at 3 speeds as u⁺/|V⁻|, v⁺/|V⁻| without sd (estimated from the residuals), a weighted mix."""
    data = _data(LAW_B, **THREE_SPEEDS, mix=MIX_B, seed=3, particles=PARTICLES, n_exp=1000, noise_seed=2,
                 names=cal.RATIOS, with_sd=False)
    fit = cal.calibrate(data, mix=MIX_B, particles=PARTICLES, seed=3)
    _assert_recovered(fit, LAW_B, {"k": 0.6, "p": 0.15, "q": 0.1})
    assert fit.scaled and np.all(np.isfinite(fit.sd_estimate)) and fit.chi2_dof == pytest.approx(1.0, abs=0.2)


def test_recovers_a_tabulated_law_at_two_speeds():
    """The tabulated family: a_nc at normal contact at each speed of the data (linear in the contact sine from 1
    at sine 0), recovered from data the direct model made with such a law at 2 speeds (q held at the truth: the
    exponential fits above recover q, the same friction law); its [wall] section reads back as the fitted law."""
    truth = TabulatedWall((60.0, 300.0), (0.0, 1.0), ((1.0, 0.72), (1.0, 0.45)), 0.9, name="truth")
    data = _data(truth, **TWO_SPEEDS, mix=MIX_B, seed=7, particles=PARTICLES, n_exp=2000, noise_seed=4)
    fit = cal.calibrate(data, "tabulated", {"q": 0.9}, mix=MIX_B, particles=PARTICLES, seed=7)
    assert fit.free == ("a_nc_60", "a_nc_300") and fit.wall.contact_speed_m_s == (60.0, 300.0)
    _assert_recovered(fit, {"a_nc_60": 0.72, "a_nc_300": 0.45}, {"a_nc_60": 0.3, "a_nc_300": 0.3})
    wall = parse_config(cal.wall_toml(fit, "calibrated_tabulated")).wall
    assert wall.family == "tabulated" and wall.restitution == fit.wall.restitution and wall.q == 0.9
    with pytest.raises(ValueError, match=r"cannot fix 'k': the tabulated wall law's fit values are a_nc_60, "
                                         r"a_nc_300, q"):
        cal.calibrate(data, "tabulated", {"k": 0.1})
    with pytest.raises(ValueError, match=r"cannot fix 'a_nc_60' at 1.0: the tabulated wall law's 'a_nc_60' must be "
                                         r"in \(0, 1\)"):
        cal.calibrate(data, "tabulated", {"a_nc_60": 1.0})


def test_the_written_wall_section_reads_back_as_the_fit(fit_two_speeds):
    text = cal.wall_toml(fit_two_speeds, "calibrated_synthetic")
    assert text.startswith(f"# rebound-scatter {cal.WALL_FILE_KIND}:") and "60 to 300 m/s" in text
    assert f"chi2/dof = {fit_two_speeds.chi2_dof:.3g}" in text
    assert parse_config(text).wall.parameters() == fit_two_speeds.values


# ------------------------------------------------------------------------------------------------ command line

HEADER = "alpha1_deg,speed_m_s,e_n,e_t,e_n_sd,e_t_sd,n\n"
GOOD_ROWS = ["30,100,0.55,0.58,0.2,0.2,50\n", "50,150,0.25,0.52,0.1,0.25,50\n", "70,200,0.12,0.47,0.05,0.4,50\n"]


def _csv(tmp_path, text, name="m.csv"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_command_line_fit_writes_a_wall_section_the_build_reads(tmp_path, capsys):
    """One fit (q alone, the prism, few particles: fast), an unknown column warned once, the file read back, and
    the outputs never replaced without --overwrite nor when not ours."""
    data = _csv(tmp_path, "alpha1_deg,speed_m_s,operator,e_n,e_t,n\n30,100,ann,0.55,0.58,50\n"
                          "50,150,ann,0.25,0.52,50\n70,200,bob,0.12,0.47,50\n")
    out, figure = tmp_path / "wall.toml", tmp_path / "wall.png"
    argv = ["calibrate", "--data", str(data), "-o", str(out), "--fix", "k=0.1,p=0.61", "--shapes", "prism",
            "--particles", "200", "--figure", str(figure)]
    code, err, printed = _run(argv, capsys)
    assert code == 0 and err == [f"{data}: warning: columns ignored: operator (the columns read: alpha1_deg, "
                                 f"speed_m_s, e_n, e_t, e_n_sd, e_t_sd, n)"], err
    q = float(next(line.split()[1] for line in printed.splitlines() if line.startswith("q ")))
    wall = load_config(out).wall
    assert (wall.k, wall.p, wall.name) == (0.1, 0.61, "calibrated_m") and wall.q == pytest.approx(q, rel=1e-5)
    assert "sd of e_n: not given" in printed and figure.read_bytes().startswith(b"\x89PNG")
    before = out.read_text()
    _user_error(argv, capsys, str(out), "exists", "--overwrite")
    assert out.read_text() == before
    foreign = tmp_path / "mine.toml"
    foreign.write_text("[wall]\nk = 1.0\n")
    _user_error(argv[:4] + [str(foreign)] + argv[5:] + ["--overwrite"], capsys, str(foreign), "not an output")
    assert foreign.read_text() == "[wall]\nk = 1.0\n"
    assert _run(argv + ["--overwrite"], capsys)[0] == 0 and load_config(out).wall.q == wall.q


def test_a_fit_gives_the_same_bits_on_other_simd_code_paths(tmp_path):
    """tablegen calibrate with numpy and OpenBLAS forced onto their baseline kernels (tests.helpers.cpu_dispatch)
    writes the very file of the default ones: the fit's sums and solves do not go through them."""
    data = _csv(tmp_path, HEADER + "".join(GOOD_ROWS) + "40,60,0.45,0.55,0.15,0.2,50\n")
    written = {}
    for case in ("default", "baseline"):
        env = cpu_dispatch.environment(case, generic_numba=False)
        out = tmp_path / f"{case}.toml"
        done = subprocess.run([sys.executable, "-m", "tablegen.cli", "calibrate", "--data", str(data), "-o", str(out),
                               "--fix", "q=1", "--shapes", "prism", "--particles", "200", "--no-progress"],
                              env=env, capture_output=True, text=True, timeout=600, cwd=REPO)
        assert done.returncode == 0, done.stderr[-2000:]
        written[case] = out.read_bytes()
        if case == "baseline":
            assert cpu_dispatch.code_paths(env) != cpu_dispatch.code_paths(cpu_dispatch.environment("default"))
    assert written["baseline"] == written["default"]


@pytest.mark.parametrize("rows, words", [
    ([GOOD_ROWS[0], "50,150,nan,0.52,0.1,0.25,50\n"], ["line 3 (data row 2)", "column 'e_n'", "finite and > 0", "nan"]),
    ([GOOD_ROWS[0], "50,150,,0.52,0.1,0.25,50\n"], ["line 3 (data row 2)", "column 'e_n'", "empty"]),
    (["0,100,0.55,0.58,0.2,0.2,50\n"], ["line 2 (data row 1)", "column 'alpha1_deg'", "(0, 90]"]),
    ([GOOD_ROWS[0], "95,100,0.55,0.58,0.2,0.2,50\n"], ["line 3 (data row 2)", "column 'alpha1_deg'", "(0, 90]"]),
    ([GOOD_ROWS[0], "90,150,0.2,0.5,0.1,0.2,50\n"], ["line 3 (data row 2)", "column 'alpha1_deg'", "u_ratio, v_ratio"]),
    ([GOOD_ROWS[0], "50,-150,0.25,0.52,0.1,0.25,50\n"], ["line 3 (data row 2)", "column 'speed_m_s'", "> 0 m/s"]),
    ([GOOD_ROWS[0], "50,150,0,0.52,0.1,0.25,50\n"], ["line 3 (data row 2)", "column 'e_n'", "> 0"]),
    ([GOOD_ROWS[0], "50,150,0.25,0.52,0,0.25,50\n"], ["line 3 (data row 2)", "column 'e_n_sd'", "> 0"]),
    ([GOOD_ROWS[0], "50,150,0.25,0.52,0.1,0.25,2.5\n"], ["line 3 (data row 2)", "column 'n'", "integer >= 1"]),
    (GOOD_ROWS + [GOOD_ROWS[1]], ["line 5 (data row 4)", "'alpha1_deg', 'speed_m_s'", "repeats line 3 (data row 2)",
                                  "one row per (alpha1, speed)"]),
])
def test_bad_csv_is_refused_naming_row_and_column(tmp_path, capsys, rows, words):
    out = tmp_path / "wall.toml"
    _user_error(["calibrate", "--data", str(_csv(tmp_path, HEADER + "".join(rows))), "-o", str(out)], capsys, *words)
    assert not out.exists()


def test_a_missing_column_is_refused(tmp_path, capsys):
    out = tmp_path / "wall.toml"
    data = _csv(tmp_path, "alpha1_deg,speed_m_s,e_n\n30,100,0.5\n")
    _user_error(["calibrate", "--data", str(data), "-o", str(out)], capsys, "line 1", "column 'e_t' is missing")
    assert not out.exists()


@pytest.mark.parametrize("rows, extra, words", [
    ([r.replace(",150,", ",100,").replace(",200,", ",100,") for r in GOOD_ROWS], [],
     ["column 'speed_m_s'", "k and p trade off at one speed; fix one, e.g. --fix p=0.61"]),
    (GOOD_ROWS[:2], [], ["2 data rows and 3 free parameters (k, p, q)", "at least as many rows"]),
    (GOOD_ROWS, ["--fix", "r=1"], ["cannot fix 'r'", "fit values are k, p, q"]),
    (GOOD_ROWS, ["--fix", "p=-1"], ["cannot fix 'p'", "finite and > 0"]),
    (GOOD_ROWS, ["--shapes", "sphere"], ["'sphere'", "ellipsoid, prism, cut_prism, tetrahedron"]),
])
def test_data_that_cannot_determine_the_fit_is_refused(tmp_path, capsys, rows, extra, words):
    out = tmp_path / "wall.toml"
    data = _csv(tmp_path, HEADER + "".join(rows))
    _user_error(["calibrate", "--data", str(data), "-o", str(out), *extra], capsys, *words)
    assert not out.exists()
