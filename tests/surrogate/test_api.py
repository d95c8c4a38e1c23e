"""The NumPy API and the command line: reproducible seeds, checks before any write, clamping, outputs."""

import subprocess
import sys

import numpy as np
import pytest

import surrogate
from data_schema.samples import STATUS_REBOUNDED, STATUS_TRAPPED, read_samples
from surrogate.kernels.rng import CHUNK_ROWS


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


def test_global_writes_into_given_outputs_or_leaves_them_untouched(small_table):
    """out=(V_out, Omega_out, status): the same bits as new arrays, written into those objects; an out array
    of the wrong dtype, shape or layout, read-only, or overlapping an input is a ValueError naming it, and
    no out array is written when any check (theirs or the inputs') fails."""
    m = 2 * CHUNK_ROWS + 5
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
        surrogate.sample_global(small_table, V, n, a, "prism", random_state=0, method="table")
    V_out, _, status = surrogate.sample_global(small_table, V, n, a, "prism", random_state=0, clamp=True,
                                               method="table")
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
