"""The same bits whichever SIMD kernels numpy, OpenBLAS and numba pick on this CPU.

numpy and OpenBLAS choose their kernels when they load (AVX-512, AVX2 or baseline SSE), and a sum or a
product can come out in another order, so in other last bits, on another CPU. The runtime must not
depend on that: every array the kernels derive from a table, every mix and every draw must be the
same on an AVX-512 and an AVX2 machine, and equal to the C library's. Each case below runs
tests/helpers/dispatch_child.py in a subprocess with numpy's dispatch targets, OpenBLAS's core type and numba's
target CPU forced down to another level (tests/helpers/cpu_dispatch.py), checks that the process really took
other code paths, and compares its output bit for bit with the C library's and with the default
process's.
"""

from __future__ import annotations

import numpy as np
import pytest

from tests.helpers.cpu_dispatch import CASES
from tests.helpers.dispatch_child import KERNEL_ARRAYS
from tests.helpers.native_library import INTERPOLATION_SCALED, INTERPOLATION_STOCHASTIC, mix_probes, mix_shapes
from tests.helpers.states import max_ulp

WEIGHTS = {"ellipsoid": 0.1, "prism": 0.2, "cut_prism": 0.3, "tetrahedron": 0.4}


@pytest.fixture(scope="module")
def dispatch_runs(dispatch_children):
    """(the input, {case: the child's output}) for the three cases, on one set of incident states and uniforms
    (tests.helpers.cpu_dispatch.child_runs, started with the session)."""
    return dispatch_children.result()


def test_cases_take_other_code_paths(dispatch_runs):
    """Without this, the comparisons below would prove nothing: each forced case runs other kernels."""
    _, runs = dispatch_runs
    paths = {case: runs[case]["paths"] for case in CASES}
    print(f"\ncode paths: {paths}")
    assert paths["baseline"]["numpy"] == [], paths
    assert paths["baseline"]["numba"] == "generic"
    assert paths["no AVX-512"]["openblas"] != paths["baseline"]["openblas"], paths
    assert paths["default"] != paths["baseline"]


@pytest.mark.parametrize("case", CASES)
def test_derived_arrays_equal_the_c_library(dispatch_runs, table_pair, case):
    _, runs = dispatch_runs
    _, native_table = table_pair
    for name in KERNEL_ARRAYS:
        got, expected = runs[case][f"array_{name}"], native_table.kernel_array(name)
        assert got.dtype == expected.dtype and got.shape == expected.shape, (case, name)
        assert np.array_equal(got.view(np.uint8), expected.view(np.uint8)), f"{case}: {name} differs from C"
    # the C mixes are opaque: each draws, at and just below every boundary of the case's cdf, the shape that cdf
    # gives, so their boundaries are the same bits
    for label, mix in (("cdf_mix", native_table.mix()), ("cdf_weighted", native_table.mix(WEIGHTS))):
        cdf = runs[case][label]
        assert len(cdf) == len(native_table.shapes), (case, label)
        u0 = mix_probes(cdf)
        assert native_table.shapes_drawn(mix, u0).tolist() == mix_shapes(cdf, u0).tolist(), (case, label)


@pytest.mark.parametrize("case", CASES)
def test_draws_equal_the_c_library(dispatch_runs, table_pair, case):
    """table_rebound_many's draws under each case equal rbs_draw_many's for the same uniforms, 0 ulp."""
    given, runs = dispatch_runs
    _, native_table = table_pair
    mix = native_table.mix(WEIGHTS)
    for label, interpolation in (("scaled", INTERPOLATION_SCALED), ("stochastic", INTERPOLATION_STOCHASTIC)):
        status, V_c, W_c = native_table.draw_many(mix, given["V"], given["n"], given["a"], given["u"],
                                                  interpolation=interpolation)
        got = runs[case][f"many_{label}"]
        assert np.array_equal(got[:, 6].astype(np.int8), status), (case, label)
        assert max_ulp(got[:, :3], V_c) == 0 and max_ulp(got[:, 3:6], W_c) == 0, (case, label)


@pytest.mark.parametrize("case", CASES[1:])
def test_seeded_draws_equal_the_default_process(dispatch_runs, case):
    """sample_global and sample_local with a fixed seed: the same bits under every case."""
    _, runs = dispatch_runs
    for name in ("global", "local"):
        assert max_ulp(runs[case][name], runs["default"][name]) == 0, (case, name)
