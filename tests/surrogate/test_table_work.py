"""The work of a table draw on the wall (surrogate.kernels.work; docs/design/table_representation.md, "The work on
the wall"): drawn jointly with the rebound, closing its energy, the same bits in the pipeline and one hit at a
time, taking nothing of the random stream; a table of format 4.0 gives NaN and the same rebounds."""

import h5py
import numpy as np

import surrogate
from data_schema.samples import STATUS_INVALID, STATUS_REBOUNDED, STATUS_TRAPPED
from data_schema.table import WORK_DATASETS
from surrogate.kernels import CHUNK_ROWS, chunk_states, table_rebound, table_rebound_uniforms
from tests.helpers.tables import edited_copy

A = 1e-3                                       # half-size, m
NORMAL = (0.0, 1.0, 0.0)


def _incident(m, seed, alpha1=(1.0, 90.0), speed=(30.0, 300.0)):
    """m incident velocities at α1 and |V⁻| drawn in the ranges (on and off the small table's grid, outside it
    too: the law at its edge), random directions in the wall y = 0."""
    rng = np.random.default_rng(seed)
    a, v, phi = np.radians(rng.uniform(*alpha1, m)), rng.uniform(*speed, m), rng.uniform(0, 2 * np.pi, m)
    return np.column_stack([v * np.cos(a) * np.cos(phi), -v * np.sin(a), v * np.cos(a) * np.sin(phi)])


def _uniforms(seed, m):
    """The uniforms of each of m rows as sample_global draws them (random_state=seed)."""
    states = chunk_states(np.random.default_rng(seed), m)
    return np.vstack([table_rebound_uniforms(states[j].copy(), min(CHUNK_ROWS, m - j * CHUNK_ROWS))
                      for j in range(len(states))])


def test_each_row_s_work_is_the_single_hit_s_and_closes_the_rebound_s_energy(small_table):
    """The pipeline (sample_global, method "table") gives every row the work table_rebound gives it alone with the
    row's uniforms, bit for bit, on and off the grid, both interpolations, trapped draws included; each is ≥ 0
    and W_n + W_t + ½|V⁺|² ≤ ½|V⁻|² (the rest is the drawn rotational energy, ≥ 0), to round-off."""
    m = 2 * CHUNK_ROWS + 77
    V = _incident(m, 1)
    u = _uniforms(3, m)
    cdf = surrogate.mix_cdf(small_table, "mix")
    for interpolation in ("scaled", "stochastic"):
        hits = surrogate.sample_global(small_table, V, NORMAL, A, "mix", random_state=3, method="table", clamp=True,
                                       interpolation=interpolation)
        assert np.count_nonzero(hits.status == STATUS_TRAPPED) > 0 and np.all(hits.status != STATUS_INVALID)
        for i in range(m):
            one = table_rebound(small_table.kernel_data, cdf, tuple(V[i]), NORMAL, A, u[i], interpolation == "scaled")
            assert one.status == hits.status[i]
            assert np.array([one.wall_work_normal, one.wall_work_tangential]).tobytes() == \
                np.array([hits.wall_work_normal[i], hits.wall_work_tangential[i]]).tobytes(), i
        work = hits.wall_work_normal + hits.wall_work_tangential
        assert np.all(hits.wall_work_normal >= 0.0) and np.all(hits.wall_work_tangential >= 0.0)
        energy = 0.5 * np.sum(V * V, axis=1)
        left = energy - 0.5 * np.sum(hits.V * hits.V, axis=1)      # NaN for a trapped row
        ok = hits.status == STATUS_REBOUNDED
        assert np.all(work[ok] <= left[ok] + 1e-12 * energy[ok])
        assert np.all(work[~ok] <= energy[~ok])


def _drop_work(f):
    """A table file edited back to format 4.0: no work datasets."""
    for name in WORK_DATASETS:
        del f[f"cells/{name}"]
    f.attrs["format_version"] = np.array([4, 0], dtype=f.attrs["format_version"].dtype)


def test_the_work_takes_nothing_of_the_stream_and_a_4_0_table_gives_nan(small_table_path, tmp_path):
    """The small table without its work datasets (as format 4.0 wrote it) draws the same rebounds, bit for bit,
    and NaN work (the path "auto" takes too)."""
    older = surrogate.load(edited_copy(small_table_path, tmp_path, "format_4_0.h5", _drop_work))
    table = surrogate.load(small_table_path)
    assert table.kernel_data.has_work and not older.kernel_data.has_work
    V = _incident(CHUNK_ROWS + 5, 2, alpha1=(30.0, 90.0), speed=(50.0, 250.0))
    for method in ("table", "auto"):
        new = surrogate.sample_global(table, V, NORMAL, A, "mix", random_state=4, method=method)
        old = surrogate.sample_global(older, V, NORMAL, A, "mix", random_state=4, method=method)
        for name in ("status", "path", "shape", "V", "Omega", "wall_hits"):
            assert getattr(new, name).tobytes() == getattr(old, name).tobytes(), name
        assert np.isnan(old.wall_work_normal).all() and np.isnan(old.wall_work_tangential).all()
        assert np.isfinite(new.wall_work_normal).all()
    with h5py.File(small_table_path, "r") as f:
        assert tuple(f.attrs["format_version"]) == (4, 1)


def test_the_command_lines_say_a_4_0_table_holds_no_work(small_table_path, tmp_path, capsys):
    """surrogate sample prints the mean W_n and W_t per hit (the draws' own, in J/kg and in units of ½|V⁻|²), and
    says so when the table holds none; tablegen report leaves its work section out for such a table."""
    from data_schema.samples import read_samples
    from surrogate.cli import main as surrogate_main
    from tablegen.study.report import table_data
    from tests.helpers.cli import run_cli

    older = edited_copy(small_table_path, tmp_path, "format_4_0.h5", _drop_work)
    argv = ["sample", "--alpha1", "60", "--speed", "150", "-n", "500", "--seed", "2", "--out"]
    code, _, text = run_cli(surrogate_main, argv + [str(tmp_path / "s.h5"), "--table", str(small_table_path)], capsys)
    samples = read_samples(tmp_path / "s.h5")
    means = [samples.extra[f"wall_work_{name}"].mean() for name in ("normal", "tangential")]
    assert code == 0 and (f"work on the wall per unit mass, mean over 500 hits: normal W_n {means[0]:.6g} J/kg "
                          f"({means[0] / (0.5 * 150.0 ** 2):.4f} of 1/2|V-|^2), tangential W_t {means[1]:.6g} J/kg") in text
    code, _, text = run_cli(surrogate_main, argv + [str(tmp_path / "o.h5"), "--table", str(older)], capsys)
    assert code == 0 and "work on the wall: not in this table (format 4.0; rebuild it for W_n, W_t)" in text
    assert table_data(older, shapes=("prism",), alpha1=(60.0,), n=50, seed=1).work == {}


def test_the_closure_between_grid_speeds_is_the_least_relative_change():
    """closed_normal (the split of W between grid speeds): W_n and W_t = total − W_n sum to the total, stay in
    [0, total], keep estimates that already sum to it (to a rounding), and minimise (δ_n/n)² + (δ_t/t)² over the changes that close
    the sum: checked against a fine search over W_n, within the search's step."""
    from surrogate.kernels.work import closed_normal
    rng = np.random.default_rng(64)
    for _ in range(200):
        n, t = rng.uniform(0.0, 1.0, 2) * rng.choice([1e-4, 1.0], 2)
        total = (n + t) * rng.uniform(0.8, 1.2)
        work_n = closed_normal(n, t, total)
        assert 0.0 <= work_n <= total
        grid = np.linspace(max(0.0, total - 10 * t - 1.0), min(total, n * 10 + 1.0), 200_001)
        grid = grid[(grid >= 0.0) & (grid <= total)]
        cost = ((grid - n) / n) ** 2 + ((total - grid - t) / t) ** 2
        best = grid[np.argmin(cost)]
        assert abs(work_n - best) <= 2 * (grid[1] - grid[0]) + 1e-12 * total, (n, t, total, work_n, best)
        assert abs(closed_normal(n, t, n + t) - n) <= 4e-16 * (n + t)       # (n + t) − n − t: a rounding at most
