"""Runtime sampler: frames, interpolation, mix, trapped draws, numba API, errors."""

import subprocess
import sys

import numba
import numpy as np
import pytest
from scipy import stats
from scipy.spatial.transform import Rotation

import surrogate
from data_schema.samples import STATUS_REBOUNDED, STATUS_TRAPPED, read_samples
from surrogate.kernels import (BLOCK, STATUS_INVALID, U_PER_DRAW, draw_local, draw_local_batch,
                               draw_local_batch_rng, rebound, rebound_batch, rebound_batch_rng, rebound_many,
                               rebound_many_rng, rebound_tuple, rebound_uniforms)
from surrogate.rng import ROWS_PER_STREAM, seed_state, stream_states
from surrogate.table import CELL_MEAN, CELL_SD, CELL_SIZE, ROW_LOC, ROW_SCALE, ROW_SHAPE, ROW_SLOPE, alias_table


def test_runtime_does_not_import_tablegen():
    code = ("import sys, surrogate, surrogate.cli, surrogate.kernels, surrogate.sampling, surrogate.table; "
            "sys.exit(any(m == 'tablegen' or m.startswith('tablegen.') for m in sys.modules))")
    assert subprocess.run([sys.executable, "-c", code]).returncode == 0


def test_loaded_table_is_immutable(small_table):
    with pytest.raises(ValueError):
        small_table.kernel_data.clusters[0] = 1.0
    with pytest.raises(ValueError):
        small_table.kernel_data.rows()[0, 0, 0, 0, 0] = 1.0
    arrays = [a for a in small_table.kernel_data if isinstance(a, np.ndarray)]
    assert len(arrays) == 7 and all(a.flags.c_contiguous and not a.flags.writeable for a in arrays)


def test_kernel_arrays_hold_the_file_s_law(small_table_path, small_table):
    """The kernel layout is the file's cells rearranged: the dictionary level-major (S_k,m(i/L) at
    [..., k, i, m]), each row's residual shape indices m, location, scale and slopes, each cell's trapped
    fraction, means and standard deviations; both large arrays start on a 64-byte cache line."""
    from data_schema.table import read_table
    cells = read_table(small_table_path).cells
    data = small_table.kernel_data
    rows = data.rows()
    np.testing.assert_array_equal(data.shape_dictionary(), np.swapaxes(cells["shape_dictionary"], -1, -2))
    np.testing.assert_array_equal(rows[..., ROW_SHAPE:ROW_SHAPE + 6], cells["cluster_shape"])
    np.testing.assert_array_equal(rows[..., ROW_LOC:ROW_LOC + 6], cells["cluster_loc"])
    np.testing.assert_array_equal(rows[..., ROW_SCALE:ROW_SCALE + 6], cells["cluster_scale"])
    np.testing.assert_array_equal(rows[..., ROW_SLOPE:ROW_SLOPE + 15], cells["cluster_slope"])
    records = data.cells.reshape(data.cell_shape() + (CELL_SIZE,))
    np.testing.assert_array_equal(records[..., CELL_MEAN:CELL_MEAN + 6], cells["mean"])
    np.testing.assert_array_equal(records[..., CELL_SD:CELL_SD + 6], cells["std"])
    counts = cells["status_counts"]
    np.testing.assert_allclose(data.p_trapped() * (counts[..., STATUS_REBOUNDED] + counts[..., STATUS_TRAPPED]),
                               counts[..., STATUS_TRAPPED], rtol=1e-12)
    assert data.dictionary.ctypes.data % 64 == 0 and data.clusters.ctypes.data % 64 == 0


@pytest.mark.parametrize("weights", [[0.25, 0.25, 0.25, 0.25], [0.7, 0.0, 0.2, 0.1, 0.0], [1.0, 0.0, 0.0],
                                     np.random.default_rng(3).dirichlet(np.ones(500))])
def test_alias_table_reproduces_the_weights(weights):
    """Exact probability of each component under the alias draw: (keep[c] + Σ_{alias[d]=c} (1 − keep[d]))/C."""
    keep, alias = alias_table(np.asarray(weights))
    C = len(weights)
    prob = keep.copy()
    np.add.at(prob, alias, 1.0 - keep)
    np.testing.assert_allclose(prob / C, weights, atol=1e-14)
    assert np.all(keep[np.asarray(weights) == 0] == 0)


def _local_velocity(d, speed):
    cb = np.cos(d.beta2)
    return speed * d.speed_ratio[:, None] * np.column_stack(
        [cb * np.cos(d.alpha2), cb * np.sin(d.alpha2), np.sin(d.beta2)])


def test_global_equals_local_in_the_model_frame(small_table):
    """Wall y = 0, normal +Y, V⁻ in the XY plane moving +X: the global API is the local law."""
    n, speed, alpha1 = 500, 150.0, 60.0
    a1 = np.radians(alpha1)
    V = np.tile([speed * np.cos(a1), -speed * np.sin(a1), 0.0], (n, 1))
    V_out, W_out, status = surrogate.sample_global(small_table, V, [0.0, 1.0, 0.0], 2e-4, "prism", random_state=4)
    d = surrogate.sample_local(small_table, np.full(n, alpha1), speed, "prism", random_state=4)
    np.testing.assert_array_equal(status, d.status)
    np.testing.assert_allclose(V_out, _local_velocity(d, speed), rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(W_out, d.omega * speed / 2e-4, rtol=1e-12, atol=1e-6)


def test_global_frame_is_rotation_equivariant(small_table):
    """Rotating the incident velocity and the wall rotates the outcome (same random numbers)."""
    rng = np.random.default_rng(0)
    n = 400
    normal = np.tile([0.0, 1.0, 0.0], (n, 1))
    a1 = np.radians(rng.uniform(30, 90, n))
    phi = rng.uniform(0, 2 * np.pi, n)
    speed = rng.uniform(50, 250, n)
    V = np.column_stack([speed * np.cos(a1) * np.cos(phi), -speed * np.sin(a1), speed * np.cos(a1) * np.sin(phi)])
    Q = Rotation.random(random_state=1).as_matrix()
    out1 = surrogate.sample_global(small_table, V, normal, 1e-3, [0.25] * 4, random_state=7)
    out2 = surrogate.sample_global(small_table, V @ Q.T, normal @ Q.T, 1e-3, [0.25] * 4, random_state=7)
    np.testing.assert_array_equal(out1[2], out2[2])
    np.testing.assert_allclose(out2[0], out1[0] @ Q.T, atol=1e-9 * 250)
    np.testing.assert_allclose(out2[1], out1[1] @ Q.T, atol=1e-9 * 250 / 1e-3)


def test_normal_impact_picks_a_uniform_in_wall_axis(small_table):
    """V⁻ ∥ −n: the impact plane is undefined, the tangential rebound direction is uniform.

    Kolmogorov–Smirnov against the uniform law on (−π, π]: with 4000 draws and
    the seed fixed, a p-value below 1e-3 would mean a preferred direction.
    """
    n = 4000
    normal = np.array([0.0, 0.0, 1.0])
    V_out, _, status = surrogate.sample_global(small_table, np.tile([0.0, 0.0, -200.0], (n, 1)), normal, 1e-3,
                                               "cut_prism", random_state=3)
    ok = status == STATUS_REBOUNDED
    assert np.all(V_out[ok, 2] > 0)
    azimuth = np.arctan2(V_out[ok, 1], V_out[ok, 0])
    assert stats.kstest(azimuth, stats.uniform(loc=-np.pi, scale=2 * np.pi).cdf).pvalue > 1e-3


def test_mirror_sign_and_ranges(small_table):
    """β2, Ω_x, Ω_y are symmetric about 0 (mean within 4 standard errors, fixed seed)."""
    d = surrogate.sample_local(small_table, np.full(20000, 60.0), 150.0, "tetrahedron", random_state=5)
    ok = d.status == STATUS_REBOUNDED
    for x in (d.beta2[ok], d.omega[ok, 0], d.omega[ok, 1]):
        assert abs(x.mean()) < 4 * x.std() / np.sqrt(ok.sum())
    assert np.all((d.alpha2[ok] >= 0) & (d.alpha2[ok] <= np.pi))
    assert np.all((d.speed_ratio[ok] > 0) & (d.speed_ratio[ok] <= 1))


# (table fixture, α1 values, speeds): grid points and points between them, on the coarse 3 × 3 table
# and near grazing on the off-grid table
PHYSICAL_RANGE_POINTS = [("small_table", np.linspace(30.0, 90.0, 9), (50.0, 100.0, 175.0, 250.0)),
                         ("off_grid_table", (1.0, 1.25, 1.5, 3.0, 3.5, 4.0, 40.0, 42.5, 45.0), (150.0, 175.0, 200.0))]


@pytest.mark.parametrize("fixture, alpha1s, speeds", PHYSICAL_RANGE_POINTS)
def test_every_rebound_leaves_the_wall_without_gaining_energy(request, fixture, alpha1s, speeds):
    """Every rebounded draw has 0 < s ≤ 1, 0 < α2 < π and |β2| < π/2: it leaves the wall (V⁺·n > 0) and
    gains no kinetic energy (tables are built with Ω⁻ = 0 and the direct model never gains energy).

    The chain's linear shifts step outside these ranges at the tails; before the fold
    (surrogate.draw._folded) reflected them, the 3 × 3 table gave s = 0 exactly (V⁺ = 0) in up to
    4e-3 of the draws between grid points, and the default table s up to 1.01 near grazing.
    2·10⁴ draws per point and shape (at that rate, ~80 per point would fail), 2.9·10⁶ and 2.2·10⁶ in all.
    """
    table = request.getfixturevalue(fixture)
    n = 20_000
    for shape in table.shapes:
        for k, alpha1 in enumerate(alpha1s):
            for speed in speeds:
                d = surrogate.sample_local(table, np.full(n, alpha1), speed, shape, random_state=k)
                ok = d.status == STATUS_REBOUNDED
                where = f"{shape} at {alpha1:g} deg, {speed:g} m/s"
                assert np.all((d.speed_ratio[ok] > 0) & (d.speed_ratio[ok] <= 1)), where
                assert np.all((d.alpha2[ok] > 0) & (d.alpha2[ok] < np.pi)), where
                assert np.all(np.abs(d.beta2[ok]) < np.pi / 2), where
        # the same through the global frame: wall y = 0, V⁻ in the XY plane at the α1 values
        a = np.radians(np.repeat(alpha1s, n // 10))
        speed = np.resize(speeds, a.size)
        V = speed[:, None] * np.column_stack([np.cos(a), -np.sin(a), np.zeros(a.size)])
        normals = np.tile([0.0, 1.0, 0.0], (a.size, 1))
        V_out, _, status = surrogate.sample_global(table, V, normals, np.full(a.size, 1e-4), shape=shape,
                                                   random_state=1, clamp=True)
        ok = status == STATUS_REBOUNDED
        assert np.all(V_out[ok, 1] > 0.0)
        assert np.all(np.linalg.norm(V_out[ok], axis=1) <= speed[ok] * (1 + 1e-12))


@pytest.mark.parametrize("interpolation", ["stochastic", "scaled"])
def test_interpolation_mean_is_the_weighted_mean_of_the_neighbours(small_table, interpolation):
    """Between grid points the mean of α2 is the weighted mean of the neighbouring cells' means.

    Both modes: the stochastic mixture by construction, the scaled one because
    it moves each draw to the interpolated mean. At α1 = 40° (w = 1/3 towards
    60°), with 40 000 draws the tolerance is 4 standard errors of the
    difference. At a grid point the neighbour is never used.
    """
    n = 40000
    m30, m40, m60 = (surrogate.sample_local(small_table, np.full(n, a), 150.0, "prism", random_state=k,
                                            interpolation=interpolation).alpha2
                     for k, a in ((1, 30.0), (2, 40.0), (3, 60.0)))
    expected = (2 * m30.mean() + m60.mean()) / 3
    se = np.sqrt((2 / 3) ** 2 * m30.var() / n + (1 / 3) ** 2 * m60.var() / n + m40.var() / n)
    assert abs(m40.mean() - expected) < 4 * se
    assert abs(m30.mean() - m60.mean()) > 20 * se          # the test has power
    at_grid = surrogate.sample_local(small_table, np.full(n, 60.0), 150.0, "prism", random_state=3,
                                     interpolation=interpolation).alpha2
    np.testing.assert_array_equal(at_grid, m60)


def _sd_and_se(x):
    """Sample standard deviation and its standard error √((μ4 − σ⁴)/n)/(2σ) (any law with a 4th moment)."""
    sd = x.std()
    return sd, np.sqrt(np.mean((x - x.mean()) ** 4) - sd ** 4) / (2 * sd * np.sqrt(len(x)))


def test_scaled_interpolation_has_the_interpolated_spread(small_table):
    """Off grid in α1 (at a grid speed), the scaled draws have the linear interpolation of the neighbours' sds.

    At 40° the weight is 1/3 towards 60° (speed 150 m/s on the grid; between
    grid speeds the sampler moves draws by the restitution law instead, which
    test_validation checks against the direct model). Tolerance: 4 standard
    errors of the difference (each sd's SE from its own sample's fourth
    moment, 40 000 draws each). The stochastic mixture of the same neighbours
    has a larger spread (it adds the spread between the cell means), which the
    test also checks so that it can tell the two apart.
    """
    n = 40000
    corners = {a: surrogate.sample_local(small_table, np.full(n, a), 150.0, "prism", random_state=10 + k).speed_ratio
               for k, a in enumerate([30.0, 60.0])}
    weight = {30.0: 2 / 3, 60.0: 1 / 3}
    sds = {key: _sd_and_se(x[np.isfinite(x)]) for key, x in corners.items()}
    expected = sum(weight[key] * sds[key][0] for key in corners)
    se_expected = np.sqrt(sum((weight[key] * sds[key][1]) ** 2 for key in corners))
    results = {}
    for mode in ("scaled", "stochastic"):
        x = surrogate.sample_local(small_table, np.full(n, 40.0), 150.0, "prism", random_state=20,
                                   interpolation=mode).speed_ratio
        results[mode] = _sd_and_se(x[np.isfinite(x)])
    sd, se = results["scaled"]
    assert abs(sd - expected) < 4 * np.hypot(se, se_expected)
    sd_mix, se_mix = results["stochastic"]
    assert sd_mix - expected > 4 * np.hypot(se_mix, se_expected)


def test_trapped_fraction_matches_the_table(small_table):
    """Ellipsoids at normal impact and 250 m/s get trapped; the drawn fraction matches the table (4σ binomial)."""
    s = small_table.shapes.index("ellipsoid")
    p = small_table.kernel_data.p_trapped()[s, 2, 2]
    assert p > 0.005
    n = 40000
    d = surrogate.sample_local(small_table, np.full(n, 90.0), 250.0, "ellipsoid", random_state=8)
    trapped = d.status == STATUS_TRAPPED
    assert abs(trapped.mean() - p) < 4 * np.sqrt(p * (1 - p) / n)
    assert np.all(np.isnan(d.alpha2[trapped])) and not np.any(np.isnan(d.alpha2[~trapped]))


def test_a_pure_mix_is_the_single_shape(small_table):
    a = surrogate.sample_local(small_table, np.full(1000, 45.0), 150.0, "prism", random_state=9)
    b = surrogate.sample_local(small_table, np.full(1000, 45.0), 150.0, {"prism": 1.0}, random_state=9)
    np.testing.assert_array_equal(a.alpha2, b.alpha2)


def test_reproducible_and_generator_accepted(small_table):
    a = surrogate.sample_local(small_table, np.full(100, 45.0), 150.0, "prism", random_state=1)
    b = surrogate.sample_local(small_table, np.full(100, 45.0), 150.0, "prism",
                               random_state=np.random.default_rng(1))
    np.testing.assert_array_equal(a.alpha2, b.alpha2)


def test_api_draws_do_not_depend_on_the_thread_count(small_table):
    """sample_global and sample_local draw the rows of chunk j from the xoshiro256+ state j of
    stream_states: the same bits on one and on two threads, and the same as rebound_many and draw_local
    on the uniforms those states give row after row (2 full chunks and a partial one)."""
    m = 2 * ROWS_PER_STREAM + 77
    rng = np.random.default_rng(4)
    speed, a1 = rng.uniform(50, 250, m), np.radians(rng.uniform(30, 90, m))
    V = np.column_stack([speed * np.cos(a1), -speed * np.sin(a1), np.zeros(m)])
    n, a = np.tile([0.0, 1.0, 0.0], (m, 1)), np.full(m, 1e-4)
    before = numba.get_num_threads()
    runs = []
    try:
        for threads in sorted({1, min(2, numba.config.NUMBA_NUM_THREADS)}):
            numba.set_num_threads(threads)
            runs.append((surrogate.sample_global(small_table, V, n, a, "mix", random_state=5),
                         surrogate.sample_local(small_table, np.degrees(a1), speed, "mix", random_state=6)))
    finally:
        numba.set_num_threads(before)
    (V1, W1, s1), local = runs[0]
    for (V2, W2, s2), local2 in runs[1:]:
        for x, y in zip((V1, W1, s1) + tuple(local), (V2, W2, s2) + tuple(local2)):
            np.testing.assert_array_equal(x, y)

    def uniforms(seed):
        states = stream_states(np.random.default_rng(seed), m)
        assert states.shape == (3, 4)
        return np.concatenate([rebound_uniforms(state.copy(), min(ROWS_PER_STREAM, m - j * ROWS_PER_STREAM))
                               for j, state in enumerate(states)])

    cdf = surrogate.mix_cdf(small_table, "mix")
    V3, W3, s3 = np.empty((m, 3)), np.empty((m, 3)), np.empty(m, dtype=np.int8)
    rebound_many(small_table.kernel_data, cdf, V, n, a, uniforms(5), V3, W3, s3)
    np.testing.assert_array_equal(V1, V3)
    np.testing.assert_array_equal(W1, W3)
    np.testing.assert_array_equal(s1, s3)
    for wrong in (stream_states(np.random.default_rng(5), m - ROWS_PER_STREAM), np.ones((3, 3), np.uint64)):
        with pytest.raises(ValueError, match="one xoshiro256\\+ state"):
            rebound_batch_rng(small_table.kernel_data, cdf, V, n, a, wrong, V3, W3, s3)
    U = uniforms(6)
    for i in (0, ROWS_PER_STREAM, m - 1):
        expected = draw_local(small_table.kernel_data, cdf, np.degrees(a1[i]), speed[i], U[i])
        got = (local.status[i], local.alpha2[i], local.beta2[i], local.speed_ratio[i], *local.omega[i])
        np.testing.assert_array_equal(got, expected)
    out, status = np.empty((m, 6)), np.empty(m, dtype=np.int8)
    draw_local_batch(small_table.kernel_data, cdf, np.degrees(a1), speed, U, out, status)
    np.testing.assert_array_equal(status, local.status)
    np.testing.assert_array_equal(out, np.column_stack([local.alpha2, local.beta2, local.speed_ratio, local.omega]))
    for args, message in (((speed[:-1], U, out, status), f"'speed' has shape \\({m - 1},\\); needed \\({m},\\)"),
                          ((speed, U[:, :-1], out, status), f"'u' has shape \\({m}, 12\\); needed \\({m}, 13\\)"),
                          ((speed, U, out[:, :5], status), f"'out' has shape \\({m}, 5\\); needed \\({m}, 6\\)")):
        with pytest.raises(ValueError, match=message):
            draw_local_batch(small_table.kernel_data, cdf, np.degrees(a1), *args)
    with pytest.raises(ValueError, match=f"'status' has shape \\({m - 1},\\); needed \\({m},\\): one row per "
                       "particle, as many as alpha1 has"):
        draw_local_batch_rng(small_table.kernel_data, cdf, np.degrees(a1), speed, stream_states(rng, m), out,
                             status[:-1])


@numba.njit
def _solver_loop(data, cdf, V, n, a, seed):
    """What a user's numba particle loop does: its own RNG, its own scratch, our kernel."""
    np.random.seed(seed)
    V_out = np.empty_like(V)
    W_out = np.empty_like(V)
    status = np.empty(V.shape[0], dtype=np.int8)
    u = np.empty(U_PER_DRAW)
    U = np.empty((V.shape[0], U_PER_DRAW))
    for i in range(V.shape[0]):
        for k in range(U_PER_DRAW):
            u[k] = np.random.random()
        U[i] = u
        status[i] = rebound(data, cdf, V[i], n[i], a[i], u, V_out[i], W_out[i])
    return V_out, W_out, status, U


def test_callable_from_a_numba_loop(small_table):
    m = 300
    rng = np.random.default_rng(2)
    V = np.column_stack([rng.uniform(20, 100, m), -rng.uniform(60, 200, m), rng.uniform(-50, 50, m)])
    n = np.tile([0.0, 1.0, 0.0], (m, 1))
    a = np.full(m, 1e-4)
    cdf = surrogate.mix_cdf(small_table, [0.25] * 4)
    V1, W1, s1, U = _solver_loop(small_table.kernel_data, cdf, V, n, a, 42)
    V2, W2, s2 = np.empty((m, 3)), np.empty((m, 3)), np.empty(m, dtype=np.int8)
    rebound_batch(small_table.kernel_data, cdf, V, n, a, U, V2, W2, s2)
    np.testing.assert_array_equal(s1, s2)
    np.testing.assert_array_equal(V1, V2)
    np.testing.assert_array_equal(W1, W2)
    assert np.all(s1 == STATUS_REBOUNDED)


@numba.njit
def _tuple_loop(data, cdf, V, n, a, U, V_out, W_out, status):
    """A solver loop on scalars: rebound_tuple on 3-tuples built from the rows (no array views)."""
    for i in range(V.shape[0]):
        status[i], V_new, W_new = rebound_tuple(data, cdf, (V[i, 0], V[i, 1], V[i, 2]),
                                                (n[i, 0], n[i, 1], n[i, 2]), a[i], U[i])
        for k in range(3):
            V_out[i, k], W_out[i, k] = V_new[k], W_new[k]


def test_block_and_tuple_kernels_give_the_row_by_row_results(small_table):
    """rebound_many (table reads of 16 particles issued together) and rebound_tuple (outputs returned,
    inputs as tuples) = rebound row by row, bit for bit.

    1001 rows (not a multiple of the block), normal impacts (trapped draws
    occur there), rows that leave the wall or are NaN (reported invalid).
    """
    m = 1001
    rng = np.random.default_rng(3)
    speed = rng.uniform(50, 250, m)
    a1 = np.radians(rng.uniform(30, 90, m))
    a1[::7] = np.pi / 2
    V = np.column_stack([speed * np.cos(a1), -speed * np.sin(a1), np.zeros(m)])
    V[5], V[600] = [10.0, 5.0, 0.0], [np.nan, -100.0, 0.0]
    n = np.tile([0.0, 1.0, 0.0], (m, 1))
    a = np.full(m, 1e-4)
    U = rng.random((m, U_PER_DRAW))
    cdf = surrogate.mix_cdf(small_table, "mix")
    data = small_table.kernel_data
    V1, W1, s1 = np.empty((m, 3)), np.empty((m, 3)), np.empty(m, dtype=np.int8)
    for i in range(m):
        s1[i] = rebound(data, cdf, V[i], n[i], a[i], U[i], V1[i], W1[i])
    V2, W2, s2 = np.empty((m, 3)), np.empty((m, 3)), np.empty(m, dtype=np.int8)
    rebound_many(data, cdf, V, n, a, U, V2, W2, s2)
    V3, W3, s3 = np.empty((m, 3)), np.empty((m, 3)), np.empty(m, dtype=np.int8)
    _tuple_loop(data, cdf, V, n, a, U, V3, W3, s3)
    for s, V_, W_ in ((s2, V2, W2), (s3, V3, W3)):
        np.testing.assert_array_equal(s1, s)
        np.testing.assert_array_equal(V1, V_)
        np.testing.assert_array_equal(W1, W_)
    assert s1[5] == s1[600] == STATUS_INVALID and np.any(s1 == STATUS_TRAPPED)
    status, V_new, W_new = rebound_tuple(data, cdf, V[7], n[7], a[7], U[7])     # (3,) arrays work as well
    assert status == s1[7] and V_new == tuple(V1[7]) and W_new == tuple(W1[7])



def test_block_kernel_drawing_its_uniforms_equals_the_one_given_them(small_table):
    """rebound_many_rng(state) = rebound_uniforms(state) then rebound_many, bit for bit, and leaves the
    state where rebound_uniforms leaves it (rows: two pipelines' worth of blocks and a partial one, an
    invalid row); a state of the wrong size is rejected."""
    m = 7 * BLOCK + 5
    rng = np.random.default_rng(8)
    speed, a1 = rng.uniform(50, 250, m), np.radians(rng.uniform(30, 90, m))
    V = np.column_stack([speed * np.cos(a1), -speed * np.sin(a1), np.zeros(m)])
    V[3] = [10.0, 5.0, 0.0]
    n, a = np.tile([0.0, 1.0, 0.0], (m, 1)), np.full(m, 1e-4)
    data, cdf = small_table.kernel_data, surrogate.mix_cdf(small_table, "mix")
    state_given, state_drawn = seed_state(9), seed_state(9)
    U = rebound_uniforms(state_given, m)
    given = np.empty((m, 3)), np.empty((m, 3)), np.empty(m, dtype=np.int8)
    rebound_many(data, cdf, V, n, a, U, *given)
    drawn = np.empty((m, 3)), np.empty((m, 3)), np.empty(m, dtype=np.int8)
    rebound_many_rng(data, cdf, V, n, a, state_drawn, *drawn)
    for x, y in zip(given, drawn):
        np.testing.assert_array_equal(x, y)
    np.testing.assert_array_equal(state_given, state_drawn)
    assert drawn[2][3] == STATUS_INVALID and np.all(drawn[2][np.arange(m) != 3] != STATUS_INVALID)
    with pytest.raises(ValueError, match="one xoshiro256\\+ state"):
        rebound_many_rng(data, cdf, V, n, a, np.ones(3, np.uint64), *drawn)

def test_block_kernel_takes_strided_rows_and_rejects_short_arrays(small_table):
    """V and n as column slices of wider arrays give the results of their contiguous copies; an array with
    another number of rows, or u with another width, is a ValueError naming it and its shape."""
    m = 2 * BLOCK + 3
    rng = np.random.default_rng(10)
    speed, a1 = rng.uniform(50, 250, m), np.radians(rng.uniform(30, 90, m))
    wide_V = np.column_stack([speed * np.cos(a1), -speed * np.sin(a1), np.zeros(m), np.ones(m)])
    wide_n = np.column_stack([np.ones(m), np.zeros(m), np.ones(m), np.zeros(m)])
    V, n, a = wide_V[:, :3], wide_n[:, 1:], np.full(m, 1e-4)
    assert not V.flags.c_contiguous and not n.flags.c_contiguous
    data, cdf = small_table.kernel_data, surrogate.mix_cdf(small_table, "mix")
    strided = np.empty((m, 3)), np.empty((m, 3)), np.empty(m, dtype=np.int8)
    rebound_many_rng(data, cdf, V, n, a, seed_state(3), *strided)
    copied = np.empty((m, 3)), np.empty((m, 3)), np.empty(m, dtype=np.int8)
    rebound_many_rng(data, cdf, V.copy(), n.copy(), a, seed_state(3), *copied)
    for x, y in zip(strided, copied):
        np.testing.assert_array_equal(x, y)
    assert np.all(strided[2] != STATUS_INVALID)
    with pytest.raises(ValueError, match="'n' has shape \\(66, 3\\); needed \\(67, 3\\)"):
        rebound_many_rng(data, cdf, V, n[:-1], a, seed_state(3), *copied)
    with pytest.raises(ValueError, match="'status' has shape \\(66,\\); needed \\(67,\\)"):
        rebound_many_rng(data, cdf, V, n, a, seed_state(3), *copied[:2], copied[2][:-1])
    with pytest.raises(ValueError, match="'u' has shape \\(67, 12\\); needed \\(67, 13\\)"):
        rebound_many(data, cdf, V, n, a, np.zeros((m, U_PER_DRAW - 1)), *copied)
    # the parallel kernels check before their loop
    with pytest.raises(ValueError, match="'W_out' has shape \\(65, 3\\); needed \\(67, 3\\)"):
        rebound_batch_rng(data, cdf, V, n, a, stream_states(np.random.default_rng(3), m), copied[0], copied[1][:-2],
                          copied[2])


BAD_GLOBAL = [
    (dict(velocity=[[10.0, 5.0, 0.0]]), "does not move into the wall"),
    (dict(velocity=[[0.0, 0.0, 0.0]]), "is zero"),
    (dict(velocity=[[np.nan, -100.0, 0.0]]), "not finite"),
    (dict(velocity=[[np.inf, -100.0, 0.0]]), "not finite"),
    (dict(normal=[0.0, 2.0, 0.0]), "unit vectors"),
    (dict(half_size=0.0), "half_size"),
    (dict(velocity=[[10.0, -400.0, 0.0]]), r"'speed' value .* outside the table's range \[50, 250\]"),
    (dict(velocity=[[200.0, -10.0, 0.0]]), r"'alpha1' value .* outside the table's range \[30, 90\]"),
    (dict(shape=[0.5, 0.6, 0.0, -0.1]), "must be finite and >= 0"),
    (dict(shape=[0.5, 0.6, 0.0, 0.0]), "sum to 1"),
    (dict(shape="sphere"), "must name one of"),
    (dict(random_state=-1), "random_state"),
]


@pytest.mark.parametrize("kwargs, message", BAD_GLOBAL)
def test_bad_input_is_rejected_with_the_value(small_table, kwargs, message):
    args = dict(velocity=[[100.0, -100.0, 0.0]], normal=[0.0, 1.0, 0.0], half_size=1e-4, shape="prism",
                random_state=0) | kwargs
    with pytest.raises(ValueError, match=message):
        surrogate.sample_global(small_table, **args)


def test_global_writes_into_given_outputs_or_leaves_them_untouched(small_table):
    """out=(V_out, Omega_out, status): the same bits as new arrays, written into those objects; an out array
    of the wrong dtype, shape or layout, read-only, or overlapping an input is a ValueError naming it, and
    no out array is written when any check (theirs or the inputs') fails."""
    m = 2 * ROWS_PER_STREAM + 5
    rng = np.random.default_rng(12)
    speed, a1 = rng.uniform(50, 250, m), np.radians(rng.uniform(30, 90, m))
    V = np.column_stack([speed * np.cos(a1), -speed * np.sin(a1), np.zeros(m)])
    n, a = np.tile([0.0, 1.0, 0.0], (m, 1)), np.full(m, 1e-4)
    fresh = surrogate.sample_global(small_table, V, n, a, "mix", random_state=8)
    out = np.full((m, 3), 7.0), np.full((m, 3), 7.0), np.full(m, 7, dtype=np.int8)
    got = surrogate.sample_global(small_table, V, n, a, "mix", random_state=8, out=out)
    assert all(x is y for x, y in zip(got, out))
    for x, y in zip(fresh, got):
        np.testing.assert_array_equal(x, y)

    untouched = np.full((m, 3), 7.0), np.full((m, 3), 7.0), np.full(m, 7, dtype=np.int8)
    read_only = np.full((m, 3), 7.0)
    read_only.flags.writeable = False
    bad = [((untouched[0], untouched[1], untouched[2].astype(np.int64)),
            rf"out\[2\] \(status\) must be an array of dtype int8 and shape \({m},\); got dtype int64"),
           ((untouched[0][:-1], untouched[1], untouched[2]),
            rf"out\[0\] \(V_out\) must be an array of dtype float64 and shape \({m}, 3\); got dtype float64, "
            rf"shape \({m - 1}, 3\)"),
           ((untouched[0], np.full((3, m), 7.0).T, untouched[2]), r"out\[1\] \(Omega_out\) must be C-contiguous"),
           ((untouched[0], read_only, untouched[2]), r"out\[1\] \(Omega_out\) must be C-contiguous and writeable"),
           ((V, untouched[1], untouched[2]), r"out\[0\] \(V_out\) shares memory with an input"),
           ((untouched[0], untouched[0], untouched[2]), r"out\[1\] \(Omega_out\) shares memory"),
           (untouched[:2], "tuple of 3 arrays")]
    for arrays, message in bad:
        with pytest.raises(ValueError, match=message):
            surrogate.sample_global(small_table, V, n, a, "mix", random_state=8, out=arrays)
    V_bad = V.copy()
    V_bad[m - 1] = [0.0, 0.0, 0.0]
    with pytest.raises(ValueError, match="is zero"):
        surrogate.sample_global(small_table, V_bad, n, a, "mix", random_state=8, out=untouched)
    assert np.all(untouched[0] == 7.0) and np.all(untouched[1] == 7.0) and np.all(untouched[2] == 7)


def test_the_error_names_the_first_failing_check_and_its_first_row(small_table):
    """Several bad rows over three chunks of the parallel check: the error names the first check, in the
    documented order, that any row fails, and the first row failing it; clamp=True lets the range
    checks pass. Each step fixes the reported fault and expects the next."""
    m = 3000
    a1 = np.radians(60.0)
    V = np.tile([100.0 * np.cos(a1), -100.0 * np.sin(a1), 0.0], (m, 1))
    n = np.tile([0.0, 1.0, 0.0], (m, 1))
    a = np.full(m, 1e-4)
    V[2500], V[2900], V[2950] = [10.0, 5.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]
    V[1500] = [100.0 * np.cos(np.radians(10.0)), -100.0 * np.sin(np.radians(10.0)), 0.0]   # α1 = 10° < 30°
    V[700] = [0.0, -400.0, 0.0]                                                            # 400 m/s > 250
    V[2999] = [np.nan, -100.0, 0.0]
    n[1200] = [0.0, 2.0, 0.0]
    a[2000] = -1.0
    steps = [(r"'velocity' vector at index 2999 is not finite", lambda: V.__setitem__(2999, V[0])),
             (r"'normal' at index 1200 has length 2\.0", lambda: n.__setitem__(1200, n[0])),
             (r"'velocity' at index 2900 is zero", lambda: V.__setitem__(slice(2900, 2951, 50), V[0])),
             (r"'velocity' at index 2500 does not move into the wall", lambda: V.__setitem__(2500, V[0])),
             (r"'half_size' at index 2000 must be finite", lambda: a.__setitem__(2000, 1e-4))]
    for message, fix in steps:
        with pytest.raises(ValueError, match=message):
            surrogate.sample_global(small_table, V, n, a, "prism", random_state=0)
        fix()
    with pytest.raises(ValueError, match=r"'alpha1' value [\d.]+ deg \(index 1500\)"):
        surrogate.sample_global(small_table, V, n, a, "prism", random_state=0)
    V_out, _, status = surrogate.sample_global(small_table, V, n, a, "prism", random_state=0, clamp=True)
    assert np.all(np.isfinite(V_out[status == STATUS_REBOUNDED])) and status[700] in (STATUS_REBOUNDED, STATUS_TRAPPED)
    V[1500] = V[0]
    with pytest.raises(ValueError, match=r"'speed' value 400\.0 m/s \(index 700\)"):
        surrogate.sample_global(small_table, V, n, a, "prism", random_state=0)
    with pytest.raises(ValueError, match=r"'half_size' parameter must be a scalar or have shape \(3000,\)"):
        surrogate.sample_global(small_table, V, n, np.full(7, 1e-4), "prism")


def test_clamp_uses_the_nearest_edge(small_table):
    far = surrogate.sample_local(small_table, np.full(500, 90.0), 400.0, "prism", random_state=1, clamp=True)
    edge = surrogate.sample_local(small_table, np.full(500, 90.0), 250.0, "prism", random_state=1)
    np.testing.assert_array_equal(far.alpha2, edge.alpha2)
    with pytest.raises(ValueError, match="not finite"):
        surrogate.sample_local(small_table, np.nan, 100.0, "prism", clamp=True)


def test_shape_missing_from_the_table(tmp_path):
    from tablegen.build import build_table
    from tablegen.config import parse_config
    path = build_table(parse_config("[grid]\nalpha1_deg=[45.0]\nspeed_m_s=[100.0]\nshapes=[\"prism\"]\n"
                                    "[simulation]\nparticles_per_cell=3000\n"), tmp_path / "p.h5", workers=1)
    table = surrogate.load(path)
    with pytest.raises(ValueError, match="'tetrahedron' is not in the table"):
        surrogate.sample_local(table, 45.0, 100.0, "tetrahedron")


def test_cli_sample_writes_the_raw_layout(small_table_path, tmp_path):
    out = tmp_path / "s.h5"
    subprocess.run([sys.executable, "-m", "surrogate.cli", "sample", "--table", str(small_table_path),
                    "--alpha1", "45", "--speed", "100", "--mix", "0.1,0.2,0.3,0.4", "-n", "2000", "--seed", "5",
                    "--out", str(out)], check=True, capture_output=True)
    s = read_samples(out)
    assert len(s) == 2000 and s.producer == "surrogate sample" and np.all(s.n_collisions == -1)
    ok = s.rebounded
    np.testing.assert_allclose(np.linalg.norm(s.velocity[ok], axis=1) / 100.0, s.speed_ratio[ok])
    bad = subprocess.run([sys.executable, "-m", "surrogate.cli", "sample", "--table", str(small_table_path),
                          "--alpha1", "10", "--speed", "100", "--shape", "prism", "-n", "5"],
                         capture_output=True, text=True)
    assert bad.returncode == 2 and "alpha1" in bad.stderr


def test_numba_kernel_flags_a_particle_leaving_the_wall(small_table):
    V_out, W_out = np.empty(3), np.empty(3)
    cdf = surrogate.mix_cdf(small_table, "mix")
    status = rebound(small_table.kernel_data, cdf, np.array([10.0, 5.0, 0.0]), np.array([0.0, 1.0, 0.0]), 1e-4,
                     np.full(U_PER_DRAW, 0.5), V_out, W_out)
    assert status == STATUS_INVALID and np.all(np.isnan(V_out)) and np.all(np.isnan(W_out))
    np.testing.assert_allclose(cdf, [0.25, 0.5, 0.75, 1.0])


def test_speed_shift_follows_the_restitution_law_of_each_regime(small_table):
    """_to_speed from grid speed V_j to V, a(V) = 1 − (1 − exp(−k V^p)) sin α1 (local frame, units of |V⁻|),
    with exp(−k V^p) from the table (_restitution_factors) checked against the law itself.

    Regime 0: V⁺ − V⁻ and Ω⁺ times (1 + a(V))/(1 + a(V_j)), V⁻ = (cos α1, −sin α1, 0);
    regime 1: v⁺_n times a(V)/a(V_j), the rest kept; at V = V_j nothing moves.
    """
    from surrogate.draw import _restitution_factors, _to_speed
    data = small_table.kernel_data
    k, p = 0.1, 0.61       # the wall law the table was built with (tablegen's default)
    assert (small_table.restitution_k, small_table.restitution_p) == (k, p)
    a1 = np.radians(60.0)
    c, s = np.cos(a1), np.sin(a1)
    v, w = np.array([0.2, 0.3, -0.05]), np.array([0.4, -0.1, 0.7])
    a = lambda speed: 1.0 - (1.0 - np.exp(-k * speed ** p)) * s
    for regime in (0.0, 1.0):
        same = _to_speed(regime, *_restitution_factors(data, 1, 0.0, 1), c, s, *v, *w)
        np.testing.assert_allclose(same, np.concatenate([v, w]), rtol=1e-14)
    speed = 100.0
    grid = small_table.speed_m_s
    jv = int(np.searchsorted(grid, speed) - 1)
    wv = (speed - grid[jv]) / (grid[jv + 1] - grid[jv])
    assert 0.0 < wv < 1.0
    f = (1 + a(speed)) / (1 + a(grid[1]))
    factors = _restitution_factors(data, jv, wv, 1)
    moved = _to_speed(0.0, *factors, c, s, *v, *w)
    incident = np.array([c, -s, 0.0])
    np.testing.assert_allclose(moved, np.concatenate([incident + f * (v - incident), f * w]), rtol=1e-12)
    moved = _to_speed(1.0, *factors, c, s, *v, *w)
    np.testing.assert_allclose(moved, np.concatenate([v * [1.0, a(speed) / a(grid[1]), 1.0], w]),
                               rtol=1e-12)
