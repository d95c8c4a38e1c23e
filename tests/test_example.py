"""examples/particle_beam.py: its tracker moves and rebounds particles where the geometry says, and it runs.

The example is a user's view of the numba API (the kernel called from an
``@njit`` loop), so it is checked like code: the specular sphere against its
closed form, the tabulated rebounds against the NumPy API on the same
incident states, straight-line motion before and after the hit, and the
whole script on a small table.
"""

import math
from pathlib import Path

import numpy as np
import pytest

import surrogate
from tests.helpers.examples import example_module

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "particle_beam.py"
N = 2000
ANGLE = 30.0                                    # wall beam, degrees from the wall (a grid α1 of the small table)


@pytest.fixture(scope="module")
def beam():
    return example_module(EXAMPLE)


def _wall_run(beam, table, model, e=0.5, seed=3):
    pos, vel = beam.wall_beam(N, ANGLE, np.random.default_rng(seed))
    t_end = 2 * 0.005 / (beam.SPEED_RANGE[0] * math.sin(math.radians(ANGLE)))
    cdf = surrogate.mix_cdf(table, "mix")
    p_end, v_out, outcome = beam.run(pos, vel, t_end, beam.WALL, model, table, cdf, e, seed)
    t_hit = -pos[:, 1] / vel[:, 1]              # the plane y = 0, reached in straight flight
    hit = pos + vel * t_hit[:, None]
    return vel, hit, t_end - t_hit, p_end, v_out, outcome


def test_wall_specular_sphere_is_the_closed_form(beam, small_table):
    e = 0.5
    vel, hit, t_after, p_end, v_out, outcome = _wall_run(beam, small_table, beam.SPECULAR, e)
    assert np.all(outcome == beam.REBOUNDED)
    expected = vel * np.array([1.0, -e, 1.0])   # tangential part kept, normal part reversed and scaled by e
    np.testing.assert_allclose(v_out, expected, rtol=1e-13, atol=1e-12)
    # straight flight from the hit point with V⁺ for the rest of the time; 1 nm covers the rounding of
    # the tracker's ~100 position steps of ≤ 0.2 mm
    np.testing.assert_allclose(p_end, hit + v_out * t_after[:, None], rtol=0, atol=1e-9)


def test_wall_table_rebounds_leave_the_wall_and_follow_the_sampler(beam, small_table):
    vel, hit, t_after, p_end, v_out, outcome = _wall_run(beam, small_table, beam.TABLE)
    assert set(np.unique(outcome)) <= {beam.REBOUNDED, beam.TRAPPED}
    ok = outcome == beam.REBOUNDED
    assert ok.sum() > 0.9 * N
    assert np.all(v_out[ok, 1] > 0.0)
    np.testing.assert_allclose(p_end[ok], hit[ok] + v_out[ok] * t_after[ok, None], rtol=0, atol=1e-9)
    np.testing.assert_allclose(p_end[~ok], hit[~ok], rtol=0, atol=1e-9)     # trapped: stays where it hit
    # The tracker calls the kernel on each hit's V⁻ and normal: its rebounds follow the law that
    # sample_global draws for the same incident states (independent draws). Means of the in-plane angle
    # and of the speed ratio agree within 4 standard errors of their difference (two-sided p ≈ 6e-5
    # under equal laws; a wrong frame, e.g. a flipped normal or tangent, moves them by tens of SE).
    normals = np.tile([0.0, 1.0, 0.0], (N, 1))
    hits = surrogate.sample_global(small_table, vel, normals, np.full(N, beam.HALF_SIZE), shape="mix",
                                    random_state=9)
    V_api, status = hits.V, hits.status   # method "auto", as the tracker's kernel
    api = status == 0
    for f in (lambda v, v0: beam.angles(v)[0], lambda v, v0: np.linalg.norm(v, axis=1) / np.linalg.norm(v0, axis=1)):
        x, y = f(v_out[ok], vel[ok]), f(V_api[api], vel[api])
        se = math.sqrt(x.var() / x.size + y.var() / y.size)
        assert abs(x.mean() - y.mean()) < 4 * se, (x.mean(), y.mean(), se)


def test_cylinder_every_particle_hits_and_rebounds_outside(beam, small_table):
    pos, vel = beam.cylinder_beam(N, np.random.default_rng(4))
    t_end = 5 * beam.RADIUS / np.mean(beam.SPEED_RANGE)
    cdf = surrogate.mix_cdf(small_table, "mix")
    for model in (beam.SPECULAR, beam.TABLE):           # the sphere with e = 1
        p_end, v_out, outcome = beam.run(pos, vel, t_end, beam.CYLINDER, model, small_table, cdf, 1.0, 5)
        assert not np.any(outcome == beam.MISSED)       # the beam covers |y| < R
        ok = outcome == beam.REBOUNDED
        r_end = np.hypot(p_end[ok, 0], p_end[ok, 1])
        assert np.all(r_end >= beam.RADIUS * (1 - 1e-12))
        # the hit point on the front, x = −√(R² − y0²), and its outward normal
        x_hit = -np.sqrt(beam.RADIUS ** 2 - pos[:, 1] ** 2)
        normal = np.column_stack([x_hit, pos[:, 1], np.zeros(N)]) / beam.RADIUS
        vn_out = np.sum(v_out[ok] * normal[ok], axis=1)
        assert np.all(vn_out > 0.0)                     # every rebound leaves the surface
        if model == beam.SPECULAR:                      # e = 1: the normal component reversed, speed kept
            np.testing.assert_allclose(vn_out, -np.sum(vel * normal, axis=1), rtol=1e-9)
            np.testing.assert_allclose(np.linalg.norm(v_out, axis=1), np.linalg.norm(vel, axis=1), rtol=1e-12)


def test_the_script_writes_its_plots(beam, small_table_path, tmp_path, capsys):
    pytest.importorskip("matplotlib")
    assert beam.main(["--table", str(small_table_path), "--n", "300", "--out", str(tmp_path)]) == 0
    for name in ("wall_rebound_directions.png", "cylinder_positions.png"):
        assert (tmp_path / name).stat().st_size > 10_000
    out = capsys.readouterr().out
    assert "1. flat wall" in out and "2. cylinder" in out


def test_the_script_rejects_bad_options(beam, tmp_path, capsys):
    with pytest.raises(SystemExit) as exit_info:
        beam.main(["--angle", "95", "--out", str(tmp_path)])
    assert exit_info.value.code == 2                    # argparse's usage error
    assert "0 < --angle < 90" in capsys.readouterr().err
