"""Every wall hit answered (surrogate.kernels.wall_hit, sample_global's omega and method, `surrogate sample
--omega --method`): the path each hit takes, the three methods against the table and the direct model, bad Ω⁻,
failed rebounds, threads.

KS tolerances: two samples of n and m draws of one law exceed c·√((n+m)/(nm)) with probability α, c =
√(−ln(α/2)/2); α = 1e-3 per comparison (c = 1.95), a dozen comparisons here (seeds fixed).
"""

import dataclasses
import math
import subprocess
import sys

import numba
import numpy as np
import pytest
from scipy import stats

import surrogate
from data_schema.samples import STATUS_FAILED, STATUS_INVALID, STATUS_REBOUNDED
from direct_model.runtime import P_MAX_STEPS, U_PER_REBOUND
from surrogate.kernels import (CHUNK_ROWS, METHOD_AUTO, METHOD_DIRECT, METHOD_TABLE, PATH_DIRECT, PATH_TABLE,
                               SPIN_TOLERANCE, chunk_states, direct_rebound, direct_rebound_parallel_rng, rebound_path,
                               rebound, rebound_parallel_rng, table_rebound, table_rebound_uniforms)

KS_C = math.sqrt(-math.log(1e-3 / 2) / 2)      # c(α = 1e-3) (module doc)
A = 1e-3                                       # half-size, m
NORMAL = (0.0, 1.0, 0.0)


def ks_bound(n, m):
    return KS_C * math.sqrt((n + m) / (n * m))


def _velocity(alpha1_deg, speed, phi=0.0):
    """V⁻ at α1 (deg) from the wall y = 0 and |V⁻| (m/s), its tangential part at angle phi in the wall."""
    a = math.radians(alpha1_deg)
    return (speed * math.cos(a) * math.cos(phi), -speed * math.sin(a), speed * math.cos(a) * math.sin(phi))


def _in_grid(m, seed, alpha1=(30.0, 90.0), speed=(50.0, 250.0)):
    """m incident velocities with α1 and |V⁻| drawn inside the given ranges, random directions in the wall."""
    rng = np.random.default_rng(seed)
    return np.array([_velocity(x, v, p) for x, v, p in zip(rng.uniform(*alpha1, m), rng.uniform(*speed, m),
                                                             rng.uniform(0, 2 * np.pi, m))])


def _spinning(V, ratio, seed):
    """Ω⁻ (rad/s) of random directions with |Ω⁻| a/|V⁻| = ratio for each row of V."""
    d = np.random.default_rng(seed).normal(size=V.shape)
    d /= np.linalg.norm(d, axis=1)[:, None]
    return d * (ratio * np.linalg.norm(V, axis=1) / A)[:, None]


def test_auto_without_spin_inside_the_grid_is_the_table_bit_for_bit(small_table):
    """Ω⁻ None or zero, every state in the grid: "auto" answers every hit by the table, with "table"'s bits
    (three chunks of rows, so the chunked streams are compared too), the wall work the table draws included."""
    m = 2 * CHUNK_ROWS + 77
    V = _in_grid(m, 1)
    table = surrogate.sample_global(small_table, V, NORMAL, A, "mix", random_state=3, method="table")
    assert np.isfinite(table.wall_work_normal).all() and np.isfinite(table.wall_work_tangential).all()
    for omega in (None, np.zeros(3), np.zeros((m, 3))):
        auto = surrogate.sample_global(small_table, V, NORMAL, A, "mix", random_state=3, omega=omega)
        assert np.all(auto.path == PATH_TABLE)
        for x, y in zip(table, auto):
            np.testing.assert_array_equal(x, y)


def test_table_method_ignores_spin(small_table):
    V = _in_grid(500, 2)
    plain = surrogate.sample_global(small_table, V, NORMAL, A, "prism", random_state=4, method="table")
    spun = surrogate.sample_global(small_table, V, NORMAL, A, "prism", random_state=4, method="table",
                                   omega=_spinning(V, 0.5, 3))
    assert np.all(spun.path == PATH_TABLE)
    for x, y in zip(plain, spun):
        np.testing.assert_array_equal(x, y)


def _chunk_uniforms(seed, m):
    """The U_PER_DRAW uniforms of each of m rows as sample_global draws them (random_state=seed)."""
    states = chunk_states(np.random.default_rng(seed), m)
    return np.vstack([table_rebound_uniforms(states[j].copy(), min(CHUNK_ROWS, m - j * CHUNK_ROWS))
                      for j in range(len(states))])


def test_direct_method_is_the_direct_model_with_the_hit_s_uniforms(small_table):
    """method "direct": each hit is direct_rebound on the model shape drawn from the mix with u[0] and
    the uniforms u[1..7], bit for bit (spinning and not, in and out of the grid), its wall work too."""
    m = CHUNK_ROWS + 40
    V = _in_grid(m, 5, alpha1=(5.0, 90.0), speed=(20.0, 300.0))
    W = _spinning(V, 0.3, 6)
    W[::3] = 0.0
    weights = [0.1, 0.2, 0.3, 0.4]
    hits = surrogate.sample_global(small_table, V, NORMAL, A, weights, random_state=7,
                                   omega=W, method="direct")
    V_out, W_out, status, path = hits.V, hits.Omega, hits.status, hits.path
    assert np.all(path == PATH_DIRECT)
    u = _chunk_uniforms(7, m)
    cdf = surrogate.mix_cdf(small_table, weights)
    for i in range(0, m, 7):
        shape = small_table.model_shapes[np.searchsorted(cdf, u[i, 0], side="right")]
        hit = direct_rebound(small_table.direct_parameters, small_table.shape_arrays, shape, tuple(V[i]),
                             tuple(W[i]), NORMAL, A, u[i, 1:1 + U_PER_REBOUND])
        st, v, w = hit.status, hit.V, hit.Omega
        assert st == status[i]
        np.testing.assert_array_equal(np.array(v), V_out[i])
        np.testing.assert_array_equal(np.array(w), W_out[i])
        assert (hit.wall_work_normal, hit.wall_work_tangential) == (hits.wall_work_normal[i],
                                                                    hits.wall_work_tangential[i])
    assert np.all(hits.wall_work_normal > 0.0) and np.all(hits.wall_work_tangential >= 0.0)


def test_rebound_is_the_table_or_the_direct_kernel_by_path(small_table):
    """Per particle: the table path is table_rebound's bits, the direct path direct_rebound's with
    u[1..7]; a uniform outside [0, 1) is STATUS_INVALID on either path, as a bad method."""
    data, params, shapes = small_table.kernel_data, small_table.direct_parameters, small_table.model_shapes
    arrays = small_table.shape_arrays
    cdf = surrogate.mix_cdf(small_table, "mix")
    rng = np.random.default_rng(8)
    for i in range(60):
        u = rng.random(13)
        V = _velocity(rng.uniform(30, 90), rng.uniform(50, 250), rng.uniform(0, 6))
        W = tuple(rng.normal(size=3) * (1e4 if i % 2 else 0.0))
        got = rebound(data, params, arrays, shapes, cdf, V, W, NORMAL, A, u, METHOD_AUTO, True)
        if i % 2 == 0:
            want = table_rebound(data, cdf, V, NORMAL, A, u, True)
        else:
            shape = shapes[np.searchsorted(cdf, u[0], side="right")]
            want = direct_rebound(params, arrays, shape, V, W, NORMAL, A, u[1:8])
        assert got.status == want.status
        np.testing.assert_array_equal(np.array(got.V + got.Omega), np.array(want.V + want.Omega))
        # the wall work: each path's own
        np.testing.assert_array_equal([got.wall_work_normal, got.wall_work_tangential],
                                      [want.wall_work_normal, want.wall_work_tangential])
        assert np.isfinite(got.wall_work_normal) and np.isfinite(got.wall_work_tangential)
        for method in (METHOD_TABLE, METHOD_DIRECT):
            bad = u.copy()
            bad[12] = 1.0
            hit = rebound(data, params, arrays, shapes, cdf, V, W, NORMAL, A, bad, method, True)
            st, v = hit.status, hit.V
            assert st == STATUS_INVALID and np.all(np.isnan(v))
    hit = rebound(data, params, arrays, shapes, cdf, V, W, NORMAL, A, rng.random(13), 3, True)
    st, v = hit.status, hit.V
    assert st == STATUS_INVALID and np.all(np.isnan(v))


def test_spinning_hits_follow_the_direct_model_s_law(small_table):
    """Spinning prisms (|Ω⁻|a/|V⁻| = 0.6 about the axis across V⁻, inside the grid): "auto" answers them
    with the direct model, whose law is surrogate.sample_direct's at the same states (independent draws;
    KS per component of V⁺ and Ω⁺ within the bound from n), and far from the table's (the reason for it)."""
    n = 4000
    V = np.tile(_velocity(45.0, 150.0), (n, 1))
    W = np.array([0.0, 0.0, -0.6 * 150.0 / A])
    hits = surrogate.sample_global(small_table, V, NORMAL, A, "prism", random_state=11, omega=W)
    V_a, W_a, st_a, path = hits.V, hits.Omega, hits.status, hits.path
    assert np.all(path == PATH_DIRECT)
    hits = surrogate.sample_direct(small_table, V, NORMAL, A, omega=W, shape="prism", random_state=12)
    V_d, W_d, st_d = hits.V, hits.Omega, hits.status
    hits = surrogate.sample_global(small_table, V, NORMAL, A, "prism", random_state=13, method="table")
    V_t, W_t, st_t = hits.V, hits.Omega, hits.status
    x, y, z = (np.column_stack([v, w])[s == STATUS_REBOUNDED] for v, w, s in ((V_a, W_a, st_a), (V_d, W_d, st_d),
                                                                            (V_t, W_t, st_t)))
    bound = ks_bound(len(x), len(y))
    for k in range(6):
        assert stats.ks_2samp(x[:, k], y[:, k]).statistic < bound, k
    assert max(stats.ks_2samp(x[:, k], z[:, k]).statistic for k in range(3)) > 5 * ks_bound(len(x), len(z))


def test_the_path_at_the_tolerance_and_the_grid_s_edges(small_table):
    """auto: the table just below the spin tolerance and at the grid's edges (inclusive), the direct model
    just above it and just outside the grid in α1 and |V⁻| (the small table's grid: α1 30–90°, 50–250 m/s);
    "table" and "direct" whatever the state; STATUS_INVALID for a bad state or method."""
    data = small_table.kernel_data
    V = _velocity(60.0, 150.0, 0.4)
    speed = math.sqrt(sum(v * v for v in V))

    def spin(ratio):
        return (0.0, ratio * speed / A, 0.0)

    cases = [(V, spin(SPIN_TOLERANCE * (1 - 1e-9)), PATH_TABLE), (V, spin(SPIN_TOLERANCE * (1 + 1e-9)), PATH_DIRECT),
             (V, (1e-3, -2e-3, 0.0), PATH_TABLE),
             (_velocity(30.0 + 1e-9, 150.0), (0.0, 0.0, 0.0), PATH_TABLE),
             (_velocity(30.0 - 1e-9, 150.0), (0.0, 0.0, 0.0), PATH_DIRECT),
             (_velocity(90.0, 150.0), (0.0, 0.0, 0.0), PATH_TABLE),
             (_velocity(60.0, 50.0 * (1 + 1e-12)), (0.0, 0.0, 0.0), PATH_TABLE),
             (_velocity(60.0, 50.0 * (1 - 1e-12)), (0.0, 0.0, 0.0), PATH_DIRECT),
             (_velocity(60.0, 250.0 * (1 - 1e-12)), (0.0, 0.0, 0.0), PATH_TABLE),
             (_velocity(60.0, 250.0 * (1 + 1e-12)), (0.0, 0.0, 0.0), PATH_DIRECT)]
    for V_in, W, want in cases:
        assert rebound_path(data, V_in, W, NORMAL, A, METHOD_AUTO) == want, (V_in, W)
        assert rebound_path(data, V_in, W, NORMAL, A, METHOD_TABLE) == PATH_TABLE
        assert rebound_path(data, V_in, W, NORMAL, A, METHOD_DIRECT) == PATH_DIRECT
    # sample_global reports the same paths
    hits = surrogate.sample_global(small_table, [c[0] for c in cases], NORMAL, A, random_state=1,
                                   omega=[c[1] for c in cases])
    path = hits.path
    np.testing.assert_array_equal(path, [c[2] for c in cases])
    for bad in [dict(V_in=(1.0, 1.0, 0.0)), dict(W=(np.nan, 0.0, 0.0)), dict(W=(0.0, np.inf, 0.0)),
                dict(a=0.0), dict(n=(0.0, 2.0, 0.0)), dict(method=3), dict(method=-1)]:
        args = dict(V_in=V, W=(0.0, 0.0, 0.0), n=NORMAL, a=A, method=METHOD_AUTO) | bad
        assert rebound_path(data, args["V_in"], args["W"], args["n"], args["a"], args["method"]) == STATUS_INVALID


def test_the_path_at_both_ends_of_an_alpha1_grid_below_normal_impact(off_grid_table):
    """A table whose α1 grid ends at 45° (1–45°, 150–200 m/s): the direct model just above its last α1 and
    just below its first, the table just inside both."""
    data = off_grid_table.kernel_data
    for alpha1, want in [(45.0 - 1e-9, PATH_TABLE), (45.0 + 1e-9, PATH_DIRECT), (1.0 + 1e-9, PATH_TABLE),
                         (1.0 - 1e-9, PATH_DIRECT)]:
        assert rebound_path(data, _velocity(alpha1, 175.0), (0.0, 0.0, 0.0), NORMAL, A, METHOD_AUTO) == want, alpha1


@pytest.mark.parametrize("omega, message", [
    ([[0.0, 0.0, 0.0], [np.nan, 1.0, 0.0], [0.0, 0.0, 0.0]], r"'omega' vector at index 1 is not finite: \[nan, 1\.0"),
    ([[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, -np.inf, 0.0]], r"'omega' vector at index 2 is not finite: \[0\.0, -inf"),
    ([[0.0, 0.0], [0.0, 0.0], [0.0, 0.0]], r"'omega' parameter must have shape \(3, 3\) or \(3,\) \(rad/s\); got \(3, 2\)"),
    ([[0.0, 0.0, 0.0]] * 2, r"got \(2, 3\)"),
    ([1.0 + 1j, 0.0, 0.0], "complex"),
])
def test_bad_omega_is_a_one_line_value_error(small_table, omega, message):
    with pytest.raises(ValueError, match=message) as info:
        surrogate.sample_global(small_table, _in_grid(3, 1), NORMAL, A, omega=omega, random_state=1)
    assert "\n" not in str(info.value)


def test_bad_method_names_the_allowed_ones(small_table):
    with pytest.raises(ValueError, match=r"'method' parameter must be one of auto, table, direct; got 'tabel'"):
        surrogate.sample_global(small_table, _in_grid(3, 1), NORMAL, A, method="tabel")


def test_the_many_hit_kernel_refuses_a_method_code_outside_the_three(small_table):
    V = np.array(_in_grid(3, 1))
    outputs = surrogate.empty_rebounds(3)
    with pytest.raises(ValueError, match=r"'method' code must be METHOD_AUTO \(0\)"):
        rebound_parallel_rng(small_table.kernel_data, small_table.direct_parameters, small_table.shape_arrays,
                             small_table.model_shapes,
                             surrogate.mix_cdf(small_table, "mix"), np.zeros(0, np.int64), np.zeros(0, np.int64), V,
                             np.zeros((1, 3)),
                             np.tile(NORMAL, (3, 1)), np.full(3, A), chunk_states(np.random.default_rng(1), 3), 3,
                             outputs, True)


@pytest.mark.parametrize("shapes, message", [
    (np.array([0, 1], np.int64), r"'shapes' has shape \(2,\); needed \(3,\) or \(0,\)"),
    (np.array([0, 4, 1], np.int64), r"'shapes' must hold -1 \(drawn from the mix\) or a shape index in \[0, 4\); row 1 "
                                     r"holds 4"),
    (np.array([0, 1, -2], np.int64), r"row 2 holds -2"),
])
def test_the_many_hit_kernel_refuses_shape_indices_outside_the_table(small_table, shapes, message):
    """A per-particle shape index outside the table's shapes would read outside the table: a ValueError before
    the parallel loop."""
    V = np.array(_in_grid(3, 1))
    outputs = surrogate.empty_rebounds(3)
    with pytest.raises(ValueError, match=message):
        rebound_parallel_rng(small_table.kernel_data, small_table.direct_parameters, small_table.shape_arrays,
                             small_table.model_shapes,
                             surrogate.mix_cdf(small_table, "mix"), shapes, np.zeros(0, np.int64), V, np.zeros((1, 3)),
                             np.tile(NORMAL, (3, 1)), np.full(3, A), chunk_states(np.random.default_rng(1), 3), 0,
                             outputs, True)


def test_auto_sends_states_outside_the_grid_to_the_model_and_table_keeps_its_errors(small_table):
    V = np.array([_velocity(10.0, 150.0), _velocity(60.0, 400.0), _velocity(60.0, 20.0)])
    hits = surrogate.sample_global(small_table, V, NORMAL, A, "prism", random_state=2)
    V_out, status, path = hits.V, hits.status, hits.path
    assert np.all(path == PATH_DIRECT) and np.all(np.isfinite(V_out[status == STATUS_REBOUNDED]))
    with pytest.raises(ValueError, match=r"'alpha1' value [\d.]+ deg \(index 0\) is outside the table's range"):
        surrogate.sample_global(small_table, V, NORMAL, A, "prism", method="table")
    hits = surrogate.sample_global(small_table, V, NORMAL, A, "prism", method="table", clamp=True)
    path = hits.path
    assert np.all(path == PATH_TABLE)


def test_failed_rebounds_are_status_2_and_never_dropped(small_table):
    """A direct model allowed one contact-search step per flight fails the spinning hits (their flight in
    needs more): those rows are STATUS_FAILED with NaN vectors, in place, and the table answers the others."""
    params = small_table.direct_parameters.copy()
    params[P_MAX_STEPS] = 1
    starved = dataclasses.replace(small_table, direct_parameters=params)
    V = _in_grid(300, 3)
    W = _spinning(V, 0.5, 4)
    W[::2] = 0.0
    hits = surrogate.sample_global(starved, V, NORMAL, A, "mix", random_state=4, omega=W)
    V_out, W_out, status, path = hits.V, hits.Omega, hits.status, hits.path
    failed = status == STATUS_FAILED
    assert len(status) == 300 and np.sum(path == PATH_DIRECT) == 150 and failed.sum() > 0
    assert np.all(path[failed] == PATH_DIRECT) and np.all(np.isin(status[path == PATH_TABLE], (0, 1)))
    assert np.all(np.isnan(V_out[failed])) and np.all(np.isnan(W_out[failed]))
    assert np.all(np.isfinite(V_out[status == STATUS_REBOUNDED]))


def test_a_writable_copy_of_the_parameters_reaches_the_kernel_read_only(small_table):
    """A table whose parameters a caller replaced by a writable copy: sample_global and sample_direct hand the
    kernels a read-only view, the type they are compiled for (a writable one would compile them again), and
    leave the caller's copy writable."""
    params = small_table.direct_parameters.copy()
    table = dataclasses.replace(small_table, direct_parameters=params)
    V = _in_grid(20, 12)
    W = _spinning(V, 0.3, 13)
    surrogate.sample_global(table, V, NORMAL, A, "mix", random_state=4, omega=W)
    surrogate.sample_direct(table, V, NORMAL, A, "mix", random_state=4, omega=W)
    assert params.flags.writeable
    assert all(not signature[1].mutable for signature in rebound_parallel_rng.signatures)
    assert all(not signature[0].mutable for signature in direct_rebound_parallel_rng.signatures)


def test_the_same_seed_gives_the_same_bits_on_one_or_two_threads(small_table):
    """A spinning, half in-grid mix over three chunks: the same bits with 1 and 2 numba threads."""
    m = 2 * CHUNK_ROWS + 300
    V = _in_grid(m, 10, alpha1=(10.0, 90.0), speed=(30.0, 280.0))
    W = _spinning(V, 0.4, 11)
    W[::2] = 0.0
    runs = []
    before = numba.get_num_threads()
    try:
        for threads in (1, min(2, numba.config.NUMBA_NUM_THREADS)):
            numba.set_num_threads(threads)
            runs.append(surrogate.sample_global(small_table, V, NORMAL, A, "mix", random_state=12, omega=W))
    finally:
        numba.set_num_threads(before)
    assert 0 < np.sum(runs[0][3] == PATH_DIRECT) < m
    for x, y in zip(*runs):
        np.testing.assert_array_equal(x, y)


def _cli(*args):
    return subprocess.run([sys.executable, "-m", "surrogate.cli", "sample", *args], capture_output=True, text=True)


def test_cli_sample_with_omega_and_method(small_table_path):
    """--omega (Ω⁻a/|V⁻|, lab frame) and --method: the output names the path's count and the failures; bad
    values exit 2 with one line on stderr naming the value and what is allowed."""
    base = ["--table", str(small_table_path), "--alpha1", "45", "--speed", "150", "--shape", "prism", "-n", "300",
            "--seed", "3"]
    spun = _cli(*base, "--omega", "0", "0", "-0.6")
    assert spun.returncode == 0, spun.stderr
    assert "answered by the table 0, by the direct model 300 (method auto); failed" in spun.stdout
    plain = _cli(*base)
    assert plain.returncode == 0 and "answered by the table 300, by the direct model 0" in plain.stdout
    table = _cli(*base, "--omega", "0", "0", "-0.6", "--method", "table")
    assert table.returncode == 0 and "answered by the table 300" in table.stdout
    outside = _cli(*base[:4], "--speed", "400", *base[6:])
    assert outside.returncode == 0 and "by the direct model 300" in outside.stdout
    for args, words in [(("--method", "tabel"), ["'tabel'", "auto", "table", "direct"]),
                        (("--omega", "nan", "0", "0"), ["'omega'", "nan", "finite"]),
                        (("--speed", "400", "--method", "table"), ["400", "[50, 250]"])]:
        run = _cli(*base, *args)
        assert run.returncode == 2 and run.stderr.count("\n") == 1, run.stderr
        assert all(w in run.stderr for w in words), run.stderr


@pytest.mark.parametrize("method", [METHOD_TABLE, METHOD_DIRECT])
def test_a_row_given_its_shape_draws_what_that_shape_s_mix_draws(small_table, method):
    """Per-particle shapes (the table's index, or -1 to draw from the mix), on both paths: a row given shape k
    gets the bits the one-shape mix of k gives it, a row given -1 those of the mix, and every row still
    consumes its u[0] (the other rows' bits do not move). 2 chunks and a part, so the chunks' slices are
    taken."""
    m = 2 * CHUNK_ROWS + 50
    V = _in_grid(m, 8)
    W = _spinning(V, 0.3, 9) if method == METHOD_DIRECT else np.zeros((1, 3))
    shapes = np.random.default_rng(10).integers(-1, len(small_table.shapes), m)
    data, params, model_shapes = small_table.kernel_data, small_table.direct_parameters, small_table.model_shapes

    def run(cdf, rows):
        outputs = surrogate.empty_rebounds(m)
        rebound_parallel_rng(data, params, small_table.shape_arrays, model_shapes, cdf, rows, np.zeros(0, np.int64), V,
                             W, np.tile(NORMAL, (m, 1)), np.full(m, A),
                             chunk_states(np.random.default_rng(11), m), method, outputs, True)
        return outputs

    mix = surrogate.mix_cdf(small_table, {"prism": 0.5, "tetrahedron": 0.5})
    given = run(mix, shapes)
    expected = [(shapes == -1, run(mix, np.zeros(0, np.int64)))]
    expected += [(shapes == k, run(surrogate.mix_cdf(small_table, name), np.zeros(0, np.int64)))
                 for k, name in enumerate(small_table.shapes)]
    for rows, want in expected:
        assert rows.any()
        for got, wanted in zip(given, want):
            np.testing.assert_array_equal(got[rows], wanted[rows])
    assert np.mean(given.status == STATUS_REBOUNDED) > 0.5
