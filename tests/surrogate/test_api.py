"""The NumPy API and the command line: reproducible seeds, checks before any write, clamping, outputs."""

import subprocess
import sys
import warnings

import numpy as np
import pytest

import surrogate
from data_schema.samples import STATUS_INVALID, STATUS_REBOUNDED, STATUS_TRAPPED, read_samples
from surrogate.kernels import PATH_DIRECT, PATH_NONE, PATH_TABLE, rebound, table_rebound_uniforms
from surrogate.kernels.rng import CHUNK_ROWS, chunk_states

A, NORMAL = 1e-4, np.array([0.0, 1.0, 0.0])


def test_reproducible_and_generator_accepted(small_table):
    a = surrogate.sample_local(small_table, np.full(100, 45.0), 150.0, "prism", random_state=1)
    b = surrogate.sample_local(small_table, np.full(100, 45.0), 150.0, "prism",
                               random_state=np.random.default_rng(1))
    np.testing.assert_array_equal(a.alpha2, b.alpha2)


BAD_GLOBAL = [
    (dict(velocity=[[10.0, 5.0, 0.0]]), "does not move into the wall"),
    (dict(velocity=[[0.0, 0.0, 0.0]]), "is zero"),
    (dict(velocity=[[np.nan, -100.0, 0.0]]), "not finite"),
    (dict(velocity=[[np.inf, -100.0, 0.0]]), "not finite"),
    (dict(normal=[0.0, 2.0, 0.0]), "unit vectors"),
    (dict(half_size=0.0), "half_size"),
    # outside the grid is an error only where the table answers every hit (method "table")
    (dict(velocity=[[10.0, -400.0, 0.0]], method="table"), r"'speed' value .* outside the table's range \[50, 250\]"),
    (dict(velocity=[[200.0, -10.0, 0.0]], method="table"), r"'alpha1' value .* outside the table's range \[30, 90\]"),
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


def _sevens(m):
    """A Rebounds of m rows, every byte of it set (float 7.0, int 7)."""
    out = surrogate.empty_rebounds(m)
    for arr in out:
        arr[...] = 7
    return out


def test_global_writes_into_given_outputs_or_leaves_them_untouched(small_table):
    """out=surrogate.empty_rebounds(m): the same bits as a new record, written into those arrays; a field of the
    wrong dtype, shape or layout, read-only, or overlapping an input or another field is a ValueError naming it,
    and nothing is written when any check (theirs or the inputs') fails."""
    m = 2 * CHUNK_ROWS + 5
    rng = np.random.default_rng(12)
    speed, a1 = rng.uniform(50, 250, m), np.radians(rng.uniform(30, 90, m))
    V = np.column_stack([speed * np.cos(a1), -speed * np.sin(a1), np.zeros(m)])
    n, a = np.tile([0.0, 1.0, 0.0], (m, 1)), np.full(m, 1e-4)
    fresh = surrogate.sample_global(small_table, V, n, a, "mix", random_state=8)
    out = _sevens(m)
    got = surrogate.sample_global(small_table, V, n, a, "mix", random_state=8, out=out)
    assert got is out and all(x is y for x, y in zip(got, out))
    for x, y in zip(fresh, got):
        np.testing.assert_array_equal(x, y)

    untouched = _sevens(m)
    read_only = np.full((m, 3), 7.0)
    read_only.flags.writeable = False
    bad = [(untouched._replace(status=untouched.status.astype(np.int64)),
            rf"out\.status must be an array of dtype int8 and shape \({m},\); got dtype int64"),
           (untouched._replace(V=untouched.V[:-1]),
            rf"out\.V must be an array of dtype float64 and shape \({m}, 3\); got dtype float64, "
            rf"shape \({m - 1}, 3\)"),
           (untouched._replace(Omega=np.full((3, m), 7.0).T), r"out\.Omega must be C-contiguous"),
           (untouched._replace(Omega=read_only), r"out\.Omega must be C-contiguous and writeable"),
           (untouched._replace(V=V), r"out\.V shares memory with an input"),
           (untouched._replace(Omega=untouched.V), r"out\.Omega shares memory"),
           (tuple(untouched), "must be None or a surrogate.Rebounds")]
    for arrays, message in bad:
        with pytest.raises(ValueError, match=message):
            surrogate.sample_global(small_table, V, n, a, "mix", random_state=8, out=arrays)
    V_bad = V.copy()
    V_bad[m - 1] = [0.0, 0.0, 0.0]
    with pytest.raises(ValueError, match="is zero"):
        surrogate.sample_global(small_table, V_bad, n, a, "mix", random_state=8, out=untouched)
    assert all(np.all(arr == 7) for arr in untouched)


def test_a_hit_record_is_the_rows_of_the_many_hits_record(small_table):
    """Every field of sample_global's record, row by row, is that of rebound (surrogate.Hit) with the
    row's uniforms; on the table path ``shape`` is the shape the mix drew (u[0]) and n_collisions −1, on the
    direct path n_collisions ≥ 1; a refused hit is STATUS_INVALID, PATH_NONE, −1, −1."""
    m = 400
    rng = np.random.default_rng(5)
    speed, a1 = rng.uniform(50, 250, m), np.radians(rng.uniform(30, 90, m))
    V = np.column_stack([speed * np.cos(a1), -speed * np.sin(a1), np.zeros(m)])
    W = np.zeros((m, 3))
    W[::3, 2] = 0.4 * speed[::3] / A           # every third hit spins: the direct path
    cdf = surrogate.mix_cdf(small_table, "mix")
    got = surrogate.sample_global(small_table, V, NORMAL, A, "mix", random_state=9, omega=W)
    u = table_rebound_uniforms(chunk_states(surrogate.check_random_state(9), m)[0].copy(), m)
    assert set(got.path) == {PATH_TABLE, PATH_DIRECT}
    for i in range(m):
        hit = rebound(small_table.kernel_data, small_table.direct_parameters, small_table.shape_arrays,
                      small_table.model_shapes, cdf, tuple(V[i]), tuple(W[i]), tuple(NORMAL), A, u[i])
        assert hit.shape == got.shape[i] == min(int(u[i, 0] * 4), 3), i
        assert (hit.status, hit.path, hit.n_collisions) == (got.status[i], got.path[i], got.n_collisions[i]), i
        assert np.array(hit.V + hit.Omega).tobytes() == np.concatenate([got.V[i], got.Omega[i]]).tobytes(), i
        assert (hit.n_collisions == -1) if hit.path == PATH_TABLE else (hit.n_collisions >= 1), i
    refused = rebound(small_table.kernel_data, small_table.direct_parameters, small_table.shape_arrays,
                      small_table.model_shapes, cdf, (10.0, 5.0, 0.0), (0.0, 0.0, 0.0), tuple(NORMAL), A, u[0])
    assert refused[:4] == (STATUS_INVALID, PATH_NONE, -1, -1) and np.isnan(refused.V + refused.Omega).all()


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
        surrogate.sample_global(small_table, V, n, a, "prism", random_state=0, method="table")
    hits = surrogate.sample_global(small_table, V, n, a, "prism", random_state=0, clamp=True,
                                   method="table")
    V_out, status = hits.V, hits.status
    assert np.all(np.isfinite(V_out[status == STATUS_REBOUNDED])) and status[700] in (STATUS_REBOUNDED, STATUS_TRAPPED)
    V[1500] = V[0]
    with pytest.raises(ValueError, match=r"'speed' value 400\.0 m/s \(index 700\)"):
        surrogate.sample_global(small_table, V, n, a, "prism", random_state=0, method="table")
    with pytest.raises(ValueError, match=r"'half_size' parameter must be a scalar or have shape \(3000,\)"):
        surrogate.sample_global(small_table, V, n, np.full(7, 1e-4), "prism")


def test_clamp_uses_the_nearest_edge(small_table):
    far = surrogate.sample_local(small_table, np.full(500, 90.0), 400.0, "prism", random_state=1, clamp=True)
    edge = surrogate.sample_local(small_table, np.full(500, 90.0), 250.0, "prism", random_state=1)
    np.testing.assert_array_equal(far.alpha2, edge.alpha2)
    with pytest.raises(ValueError, match="not finite"):
        surrogate.sample_local(small_table, np.nan, 100.0, "prism", clamp=True)


def test_cli_sample_writes_the_raw_layout(small_table_path, tmp_path):
    out = tmp_path / "s.h5"
    subprocess.run([sys.executable, "-m", "surrogate.cli", "sample", "--table", str(small_table_path),
                    "--alpha1", "45", "--speed", "100", "--mix", "0.1,0.2,0.3,0.4", "-n", "2000", "--seed", "5",
                    "--out", str(out)], check=True, capture_output=True)
    s = read_samples(out)
    assert len(s) == 2000 and s.producer == "surrogate sample" and np.all(s.n_collisions == -1)
    ok = s.rebounded
    np.testing.assert_allclose(np.linalg.norm(s.velocity[ok], axis=1) / 100.0, s.speed_ratio[ok])
    # outside the grid: an error where the table answers every hit (the default, auto, asks the direct model)
    bad = subprocess.run([sys.executable, "-m", "surrogate.cli", "sample", "--table", str(small_table_path),
                          "--alpha1", "10", "--speed", "100", "--shape", "prism", "-n", "5", "--method", "table"],
                         capture_output=True, text=True)
    assert bad.returncode == 2 and "alpha1" in bad.stderr


def test_hits_outside_the_wall_law_s_speeds_are_counted_in_a_warning(small_table):
    """The table's wall holds over 50-300 m/s: sample_global and sample_direct answer hits at 20 and 400 m/s all
    the same, with one WallLawRangeWarning giving their number; none for hits inside the range."""
    assert small_table.wall.speed_range_m_s == (50.0, 300.0)
    a1 = np.radians(60.0)
    speeds = np.array([20.0, 100.0, 400.0, 299.0, 300.0])
    V = np.column_stack([speeds * np.cos(a1), -speeds * np.sin(a1), np.zeros(5)])
    for sample in (surrogate.sample_global, surrogate.sample_direct):
        with pytest.warns(surrogate.WallLawRangeWarning, match=r"^2 of 5 hits have \|V-\| outside 50-300 m/s"):
            hits = sample(small_table, V, NORMAL, A, "prism", random_state=1)
        assert np.all(hits.status[[0, 2]] != STATUS_INVALID)
    with warnings.catch_warnings():
        warnings.simplefilter("error", surrogate.WallLawRangeWarning)
        surrogate.sample_global(small_table, V[1:2], NORMAL, A, "prism", random_state=1)
