"""Batch API and CLI of the direct model."""

import subprocess
import sys

import h5py
import numba
import numpy as np
import pytest

from tests.helpers.cli import user_error
from data_schema.samples import STATUS_FAILED, STATUS_REBOUNDED, read_samples
from tablegen.cli import main as tablegen_main
from direct_model.shapes import AspectRatioLaw
from direct_model.simulate import simulate
from tablegen.study.statistics import QUANTITIES, summarize


def _arrays(s):
    return [s.velocity, s.omega, s.n_collisions, s.status] + [s.extra[k] for k in sorted(s.extra)]


def test_bit_identical_whatever_the_thread_count():
    previous = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        one = simulate("mix", 45.0, 200.0, 3000, seed=11)
        numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
        many = simulate("mix", 45.0, 200.0, 3000, seed=11)
    finally:
        numba.set_num_threads(previous)
    for a, b in zip(_arrays(one), _arrays(many)):
        assert a.tobytes() == b.tobytes()


def test_prefix_stable_and_seed_sensitive():
    long = simulate("prism", 30.0, 150.0, 500, seed=3)
    short = simulate("prism", 30.0, 150.0, 200, seed=3)
    other = simulate("prism", 30.0, 150.0, 200, seed=4)
    assert long.velocity[:200].tobytes() == short.velocity.tobytes()
    assert not np.array_equal(short.velocity, other.velocity)


@pytest.mark.parametrize("shape", ["ellipsoid", "prism", "cut_prism", "tetrahedron", "mix"])
def test_mirror_symmetry_in_distribution(shape):
    """β2, Ω_x, Ω_y are symmetric about 0 (docs/model.md §3: a 50/50 hand restores it).

    With n = 6000 rebounds, the sample mean of a symmetric variable is within
    4 standard errors (4 s/√n) of 0 except with probability 6e-5, and the count
    of positive values is within 4·√n/2 of n/2 (binomial); the seed is fixed.
    """
    s = simulate(shape, 45.0, 200.0, 6000, seed=2024)
    ok = s.rebounded
    n = ok.sum()
    for name, x in [("beta2", s.beta2[ok]), ("omega_x", s.omega[ok, 0]), ("omega_y", s.omega[ok, 1])]:
        assert abs(x.mean()) < 4 * x.std() / np.sqrt(n), name
        assert abs(np.sum(x > 0) - n / 2) < 4 * np.sqrt(n) / 2, name


def test_a_single_hand_tetrahedron_breaks_the_symmetry():
    """Control for the test above: each hand alone is not mirror-symmetric.

    A tetrahedron with a ≠ b ≠ c is chiral. The effect is weak for the default
    aspect ratios, so this uses a strongly non-equiaxed one (b/a ≈ c/b ≈ 0.6).
    Mirror images give opposite mean Ω_y; with 20 000 particles the difference
    between the hands is expected near 8 combined standard errors (measured
    4.5 at n = 6000, scaling with √n); requiring 5 fails only if the chirality
    were lost (e.g. both hands built alike).
    """
    law = AspectRatioLaw(mean=0.6, sd=0.02, low=0.55, high=0.65)
    s = simulate("tetrahedron", 45.0, 200.0, 20_000, seed=2024, aspect=law)
    means, errors = [], []
    for hand in (1, -1):
        x = s.omega[s.rebounded & (s.extra["hand"] == hand), 1]
        means.append(x.mean())
        errors.append(x.std() / np.sqrt(x.size))
    assert abs(means[0] - means[1]) > 5 * np.hypot(*errors)


@pytest.mark.parametrize("shape", ["ellipsoid", "prism", "cut_prism", "tetrahedron"])
def test_statuses_and_physical_ranges(shape):
    s = simulate(shape, 90.0, 200.0, 2000, seed=5)
    assert np.sum(s.status == STATUS_FAILED) == 0
    ok = s.rebounded
    assert ok.mean() > 0.97
    assert np.all(s.velocity[ok, 1] > 0)                    # leaves the wall
    assert np.all(s.e_trans_ratio[ok] + s.extra["e_rot_ratio"][ok] <= 1 + 1e-12)
    assert np.all(s.n_collisions[ok] >= 1)
    # the work on the wall (m²/s²), each part ≥ 0, is the kinetic energy lost, trapped particles' up to the trap (to
    # round-off: 1e-13 of E⁻ per collision; the rolling ellipsoids trapped after 1000 collisions reach 1.5e-11)
    work_n, work_t = s.extra["wall_work_normal"], s.extra["wall_work_tangential"]
    assert np.all(work_n > 0.0) and np.all(work_t >= 0.0)
    e_in = 0.5 * 200.0 ** 2
    lost = e_in * (1.0 - s.e_trans_ratio - s.extra["e_rot_ratio"])
    assert np.all(np.abs(work_n + work_t - lost) <= 1e-13 * e_in * s.n_collisions)
    assert np.all((s.alpha2[ok] >= 0) & (s.alpha2[ok] <= np.pi))


def test_summary_statistics():
    """The summary of a run has the report's statistics (one definition of mean and most probable)."""
    stats = summarize(simulate("prism", 45.0, 200.0, 500, seed=1))
    assert sum(stats["counts"].values()) == 500
    assert stats["rebounds"] == stats["counts"]["rebounded"]
    assert sum(stats["collision_percent"]) == pytest.approx(100.0)
    assert set(stats["mean"]) == set(stats["mode"]) == {q.key for q in QUANTITIES}


BAD_ARGUMENTS = [
    (dict(alpha1=0.0), "alpha1", r"\(0, 90\]"),
    (dict(alpha1=90.5), "alpha1", r"\(0, 90\]"),
    (dict(alpha1=float("nan")), "alpha1", r"\(0, 90\]"),
    (dict(speed=0.0), "speed", "> 0"),
    (dict(speed=-5.0), "speed", "> 0"),
    (dict(speed=float("inf")), "speed", "finite"),
    (dict(shape="sphere"), "shape", "ellipsoid, prism"),
    (dict(n=0), "'n'", ">= 1"),
]


@pytest.mark.parametrize("kwargs, name, allowed", BAD_ARGUMENTS)
def test_bad_arguments_raise_value_error(kwargs, name, allowed):
    args = dict(shape="prism", alpha1=45.0, speed=200.0, n=10) | kwargs
    with pytest.raises(ValueError, match=name) as info:
        simulate(args.pop("shape"), args.pop("alpha1"), args.pop("speed"), args.pop("n"))
    assert __import__("re").search(allowed, str(info.value))


@pytest.mark.parametrize("argv, word", [
    (["--alpha1", "0"], "alpha1"), (["--alpha1", "120"], "alpha1"), (["--speed", "0"], "speed"),
    (["--speed", "nan"], "speed"), (["-n", "0"], "-n"), (["--shape", "sphere"], "shape"),
    (["--wall-k", "0"], "--wall-k"), (["--wall-p", "-1"], "--wall-p"), (["--wall-q", "inf"], "--wall-q"),
])
def test_cli_exits_2_naming_the_argument(argv, word, capsys):
    base = {"--shape": "prism", "--alpha1": "45", "--speed": "200", "-n": "10"}
    base.update(dict(zip(argv[::2], argv[1::2])))
    user_error(tablegen_main, ["simulate"] + [x for kv in base.items() for x in kv], capsys, word)


def test_cli_writes_the_documented_layout(tmp_path):
    out = tmp_path / "s.h5"
    result = subprocess.run([sys.executable, "-m", "tablegen.cli", "simulate", "--shape", "cut_prism",
                             "--alpha1", "30", "--speed", "120", "-n", "300", "--seed", "9", "--out", str(out)],
                            capture_output=True, text=True, check=True)
    assert "collisions per rebound" in result.stdout
    back = read_samples(out)
    direct = simulate("cut_prism", 30.0, 120.0, 300, seed=9)
    assert back.velocity.tobytes() == direct.velocity.tobytes()
    assert back.omega.tobytes() == direct.omega.tobytes()
    assert (back.alpha1, back.speed, back.shape, back.seed) == (30.0, 120.0, "cut_prism", 9)
    assert np.array_equal(back.status == STATUS_REBOUNDED, direct.rebounded)
    for name in ("wall_work_normal", "wall_work_tangential"):
        assert back.extra[name].tobytes() == direct.extra[name].tobytes()
    # a file without the wall work (written before it was) still loads
    with h5py.File(out, "a") as f:
        assert f["samples/wall_work_normal"].attrs["units"].startswith("m²/s²")
        del f["samples/wall_work_normal"], f["samples/wall_work_tangential"]
    older = read_samples(out)
    assert "wall_work_normal" not in older.extra and older.velocity.tobytes() == back.velocity.tobytes()
    # an existing file is not replaced without --overwrite, and is left intact
    before = out.read_bytes()
    again = subprocess.run([sys.executable, "-m", "tablegen.cli", "simulate", "--shape", "prism",
                            "--alpha1", "30", "--speed", "120", "-n", "10", "--out", str(out)],
                           capture_output=True, text=True)
    assert again.returncode == 2 and "--overwrite" in again.stderr
    assert out.read_bytes() == before


def test_cli_wall_law(tmp_path):
    """--wall-k/-p/-q default to the library's law; another law is the one simulated and recorded."""
    from direct_model.wall import WallMaterial
    out = tmp_path / "s.h5"
    assert tablegen_main(["simulate", "--shape", "prism", "--alpha1", "45", "--speed", "200", "-n", "200",
                          "--seed", "3", "--wall-k", "0.2", "--wall-q", "0.5", "--out", str(out)]) == 0
    back = read_samples(out)
    law = WallMaterial(k=0.2, q=0.5, name="custom")
    assert back.velocity.tobytes() == simulate("prism", 45.0, 200.0, 200, seed=3, wall=law).velocity.tobytes()
    assert back.provenance["wall_law"] == "custom" and back.provenance["wall_k"] == 0.2


def test_cli_takes_the_model_of_a_config(tmp_path):
    """--config gives simulate the configuration's model (kappa, the b/a and c/b law, n_max, the wall law) instead
    of the defaults, so that its particles are a table cell's; a flag given still replaces its part."""
    from direct_model.wall import WallMaterial
    config = tmp_path / "c.toml"
    config.write_text('[grid]\nalpha1_deg = [45.0]\nspeed_m_s = [200.0]\nshapes = ["cut_prism"]\n'
                      '[simulation]\nkappa = 0.1\nn_max = 3\naspect_ratio = {mean = 0.6, sd = 0.1, low = 0.4, '
                      'high = 0.9}\n[wall]\nk = 0.2\np = 0.5\nq = 0.4\nname = "a_wall"\n')
    aspect = AspectRatioLaw(mean=0.6, sd=0.1, low=0.4, high=0.9)
    argv = ["simulate", "--shape", "cut_prism", "--alpha1", "45", "--speed", "200", "-n", "300", "--seed", "4",
            "--config", str(config), "--no-progress"]
    out, flagged = tmp_path / "s.h5", tmp_path / "f.h5"
    assert tablegen_main(argv + ["--out", str(out)]) == 0
    assert tablegen_main(argv + ["--n-max", "1000", "--wall-q", "1.0", "--out", str(flagged)]) == 0
    wall = WallMaterial(k=0.2, p=0.5, q=0.4, name="a_wall")
    cell = simulate("cut_prism", 45.0, 200.0, 300, seed=4, kappa=0.1, aspect=aspect, n_max=3, wall=wall)
    back = read_samples(out)
    assert back.velocity.tobytes() == cell.velocity.tobytes() and np.array_equal(back.status, cell.status)
    assert back.provenance["wall_law"] == "a_wall" and back.provenance["n_max"] == 3
    # n_max = 3 traps some of these particles; the flags' n_max = 1000 and q = 1.0 are what runs then
    custom = WallMaterial(k=0.2, p=0.5, q=1.0, name="custom")
    again = simulate("cut_prism", 45.0, 200.0, 300, seed=4, kappa=0.1, aspect=aspect, n_max=1000, wall=custom)
    assert read_samples(flagged).velocity.tobytes() == again.velocity.tobytes()
    assert (cell.status != STATUS_REBOUNDED).any() and read_samples(flagged).provenance["wall_law"] == "custom"


def test_failures_are_counted_with_their_reason():
    """A one-step search budget cannot follow a flight: those particles fail, with the reason."""
    from data_schema.samples import FAILURE_SEARCH_BUDGET
    s = simulate("prism", 45.0, 200.0, 300, seed=8, max_steps=1)
    failed = s.status == STATUS_FAILED
    assert failed.sum() > 0
    assert np.all(s.extra["failure_reason"][failed] == FAILURE_SEARCH_BUDGET)
    assert np.all(s.extra["failure_reason"][~failed] == 0)
    stats = summarize(s)
    assert stats["counts"]["failed"] == failed.sum()
    assert stats["failures"] == {"contact search step budget exhausted": failed.sum()}
