"""The inlined functions of the sampler kernels and the flight against their closed forms: the fused
multiply-add and sincos (direct_model.elementary), first-quadrant atan2, the polynomial pieces of the wall's
restitution factor exp(−k V^p), the plain load and the stack scratch of surrogate.kernels.memory, and the
single-hit kernels' compilation without numba's reference counting."""

import math

import numba
import numpy as np
import pytest

from direct_model.elementary import fma, sincos
from direct_model.wall import WallMaterial
from surrogate.kernels.fastmath import atan2_first_quadrant, restitution_at, restitution_factor, restitution_pieces
from surrogate import kernels
from surrogate.kernels.memory import load, stack_scratch

ULP_ONE = np.spacing(1.0)     # 2.2e-16


@numba.njit
def _sincos_all(x, s, c):
    for i in range(x.shape[0]):
        s[i], c[i] = sincos(x[i])


@numba.njit
def _atan2_all(y, x, out):
    for i in range(x.shape[0]):
        out[i] = atan2_first_quadrant(y[i], x[i])


@numba.njit
def _restitution_all(pieces, n_pieces, j, w, out):
    for i in range(w.shape[0]):
        out[i] = restitution_at(pieces, n_pieces, j[i], w[i])


@numba.njit
def _load_all(a, index, out):
    for i in range(index.shape[0]):
        out[i] = load(a, index[i])


@pytest.mark.parametrize("dtype", [np.float32, np.float64, np.int64, np.uint8])
def test_load_reads_the_element_at_the_index(dtype):
    """load(a, i) is a[i] for every i of a read-only array, in any order and with any integer type."""
    a = np.random.default_rng(1).permutation(1000).astype(dtype)
    a.setflags(write=False)
    for index in (np.arange(1000), np.arange(1000)[::-1].astype(np.int32), np.arange(0, 1000, 7).astype(np.uint64)):
        out = np.empty(len(index), dtype=dtype)
        _load_all(a, index, out)
        np.testing.assert_array_equal(out, a[index.astype(np.int64)])


@numba.njit(_nrt=False)
def _two_scratch_arrays(x):
    """Fills a (1448,) and a (3,) stack scratch array (1448: the direct model's scratch size) and reads them back."""
    big, small = stack_scratch(1448), stack_scratch(3)
    for i in range(big.shape[0]):
        big[i] = x + i
    for i in range(small.shape[0]):
        small[i] = -1.0 - i          # would overwrite big[:3] if the two shared memory
    return big.shape[0], small.shape[0], big[0], big[1447], small[0], small[1], small[2], big.sum()


def test_stack_scratch_holds_its_size_without_the_runtime():
    """Two stack arrays of one kernel compiled without numba's runtime are distinct, of their sizes, and keep what
    is written into them (a 1448-long array would be an 11.6 KB heap allocation through the runtime otherwise)."""
    n_big, n_small, first, last, s0, s1, s2, total = _two_scratch_arrays(0.5)
    assert (n_big, n_small) == (1448, 3)
    assert (first, last, s0, s1, s2) == (0.5, 1447.5, -1.0, -2.0, -3.0)
    assert total == sum(0.5 + i for i in range(1448))


@pytest.mark.parametrize("name", ["table_rebound", "draw_local", "direct_rebound", "rebound", "rebound_path"])
def test_single_hit_kernels_run_without_reference_counting(name):
    """A solver calls these once per hit: compiled with numba's runtime, each would increment and decrement the
    reference count of every array it is given (the table's, the shapes', the uniforms) on every call."""
    assert getattr(kernels, name).targetoptions.get("_nrt") is False


@numba.njit
def _fma(a, b, c):
    return fma(a, b, c)


def test_fma_rounds_once():
    """(1 + 2⁻³⁰)(1 − 2⁻³⁰) − 1 = −2⁻⁶⁰ exactly; a multiply then an add rounds the product to 1 and gives 0.
    float32 arguments are widened exactly."""
    a, b = 1.0 + 2.0 ** -30, 1.0 - 2.0 ** -30
    assert a * b - 1.0 == 0.0
    assert _fma(a, b, -1.0) == -(2.0 ** -60)
    assert _fma(np.float32(0.1), np.float32(3.0), 0.5) == float(np.float32(0.1)) * 3.0 + 0.5


def test_sincos_matches_libm_on_its_domain():
    """|x| ≤ 2π, dense grid plus the quadrant edges (multiples of π/4): within 2 ulp of 1 (absolute)."""
    x = np.concatenate([np.linspace(-2 * np.pi, 2 * np.pi, 400_001), np.arange(-8, 9) * (np.pi / 4),
                        np.nextafter(np.arange(-8, 9) * (np.pi / 4), 0.0), [0.0, -0.0, 1e-300]])
    s, c = np.empty_like(x), np.empty_like(x)
    _sincos_all(x, s, c)
    assert np.max(np.abs(s - np.sin(x))) <= 2 * ULP_ONE
    assert np.max(np.abs(c - np.cos(x))) <= 2 * ULP_ONE
    assert np.max(np.abs(s * s + c * c - 1.0)) <= 4 * ULP_ONE
    assert s[-1] == 1e-300 and c[-1] == 1.0          # tiny angles: sin x = x exactly


def test_sincos_beyond_two_pi_adds_at_most_the_rounding_of_x():
    """2π < |x| < 2⁴⁰ (the flight's phases), log-uniform and at multiples of π/2: within 2 ulp of 1 plus ulp(x)
    of libm, the rounding of q·π/2 in the reduction (measured: at most 0.70 ulp(x) above 2π)."""
    rng = np.random.default_rng(3)
    x = np.concatenate([np.exp(rng.uniform(np.log(2 * np.pi), np.log(2.0 ** 40), 100_000)),
                        np.arange(5, 100_001) * (np.pi / 2)])
    x = np.concatenate([x, -x])
    s, c = np.empty_like(x), np.empty_like(x)
    _sincos_all(x, s, c)
    bound = 2 * ULP_ONE + np.spacing(np.abs(x))
    assert np.all(np.abs(s - np.array([math.sin(v) for v in x])) <= bound)
    assert np.all(np.abs(c - np.array([math.cos(v) for v in x])) <= bound)


def test_atan2_first_quadrant_matches_libm():
    """x, y ≥ 0 over radii 1e-3–1e3 and every direction, plus the axes, the diagonal and the node
    boundaries t = 1/8, 3/8, 5/8, 7/8: within 2 ulp of the angle."""
    rng = np.random.default_rng(7)
    theta = np.concatenate([np.linspace(0.0, np.pi / 2, 200_001), rng.uniform(0.0, np.pi / 2, 100_000)])
    radius = rng.uniform(1e-3, 1e3, theta.size)
    y, x = radius * np.sin(theta), radius * np.cos(theta)
    t = np.array([0.125, 0.375, 0.625, 0.875])
    y = np.concatenate([y, [0.0, 2.0, 3.0], t, np.nextafter(t, 0), np.ones(4)])
    x = np.concatenate([x, [1.0, 0.0, 3.0], np.ones(4), np.ones(4), t])
    out = np.empty_like(x)
    _atan2_all(y, x, out)
    exact = np.arctan2(y, x)
    assert np.all(np.abs(out - exact) <= 2 * np.spacing(np.maximum(exact, 1e-300)))
    assert out[theta.size:theta.size + 3].tolist() == [0.0, math.pi / 2, math.pi / 4]


@pytest.mark.parametrize("grid", [[50.0, 100.0, 150.0, 200.0, 250.0, 300.0], list(np.arange(50.0, 301.0, 25.0)),
                                  [1.0, 50.0], [0.1, 10.0, 1000.0], [20.0, 25.0, 400.0], [120.0]])
def test_restitution_pieces_match_the_closed_form(grid):
    """exp(−k V^p) from the pieces at 4001 weights per interval (both ends included), for tablegen's default
    wall (k, p) = (0.1, 0.61) and laws from gentle to steep: absolute error ≤ 1e-12 (the factor is ≤ 1
    and enters a(V) = 1 − (1 − f) sin α1 additively)."""
    grid = np.array(grid)
    for k, p in ((0.1, 0.61), (0.02, 0.3), (0.5, 0.9), (1.0, 1.0), (0.1, 1.5)):
        pieces = restitution_pieces(grid, WallMaterial(k, p).as_array())
        if len(grid) == 1:
            assert pieces.shape[:2] == (1, 1)      # no interval: the kernel never reads it (weight 0)
            continue
        w = np.linspace(0.0, 1.0, 4001)
        for j in range(len(grid) - 1):
            got = np.empty_like(w)
            _restitution_all(pieces.ravel(), pieces.shape[1], np.full(w.size, j), w, got)
            exact = np.exp(-k * (grid[j] + w * (grid[j + 1] - grid[j])) ** p)
            assert np.max(np.abs(got - exact)) <= 1e-12, (grid, k, p, j)


def test_restitution_pieces_of_a_tabulated_law():
    """A tabulated law's factor f(V) = a_nc(V, 1), piecewise linear between its speed nodes: exact where a piece
    holds no node (a polynomial interpolates a line exactly, to round-off), and within the kink's rounding where
    one does (degree-9 Chebyshev interpolation of a slope change Δs over a piece of width h misses by about
    Δs·h/20 at most); the grid's own factors are the law's."""
    from direct_model.wall import TabulatedWall

    wall = TabulatedWall((60.0, 130.0), (0.0, 1.0), ((1.0, 0.8), (1.0, 0.5)), name="t").as_array()
    grid = np.array([50.0, 60.0, 100.0, 150.0, 200.0])
    pieces = restitution_pieces(grid, wall)
    w = np.linspace(0.0, 1.0, 2001)
    for j in range(len(grid) - 1):
        got = np.empty_like(w)
        _restitution_all(pieces.ravel(), pieces.shape[1], np.full(w.size, j), w, got)
        exact = np.array([restitution_factor(v, wall) for v in grid[j] + w * (grid[j + 1] - grid[j])])
        kink = grid[j] < 130.0 < grid[j + 1]
        slope_change, width = 0.3 / 70.0, (grid[j + 1] - grid[j]) / pieces.shape[1]
        assert np.max(np.abs(got - exact)) <= (slope_change * width / 20.0 if kink else 1e-14), j
    assert [restitution_factor(v, wall) for v in grid] == [0.8, 0.8, 0.8 - 0.3 * 40.0 / 70.0, 0.5, 0.5]


def test_chebyshev_nodes_are_correctly_rounded():
    """The node literals are cos(π (2q + 1) / (2N)) rounded to the nearest double (checked at 200 bits), and the
    power-basis rows are numpy's T_0 … T_DEGREE (integers, exact)."""
    import mpmath
    from surrogate.kernels.fastmath import CHEBYSHEV_NODES, CHEBYSHEV_POWERS, N_NODES
    with mpmath.workprec(200):
        exact = [mpmath.cos(mpmath.pi * (2 * q + 1) / (2 * N_NODES)) for q in range(N_NODES)]
        assert list(CHEBYSHEV_NODES) == [float(x) for x in exact]
    for j, row in enumerate(CHEBYSHEV_POWERS):
        expected = np.zeros(N_NODES)
        power = np.polynomial.chebyshev.cheb2poly(np.eye(N_NODES)[j])
        expected[:len(power)] = power
        assert list(row) == expected.tolist(), j
