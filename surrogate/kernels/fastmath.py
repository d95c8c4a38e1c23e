"""Fast math of the sampler kernels: inverse trigonometry and the wall's restitution factor.

A call to libm costs the call itself and, because every floating-point
register is caller-saved, the spilling of the kernel's live values around
it; ``a * b + c`` without contraction costs two roundings. So the hot path
calls no libm function. Besides the fused multiply-add and sincos the kernels
share with the direct model (:mod:`direct_model.elementary`):

* :func:`atan2_first_quadrant`, x, y ≥ 0: t = min/max, atan t = atan c +
  atan z with c the nearest of 0, 1/4, 1/2, 3/4, 1 and z = (t − c)/(1 + c t),
  |z| ≤ 1/8, atan z by its Taylor series to z¹⁷ (truncation below 1e-18);
* :func:`restitution_at` — the wall's restitution factor (exp(−k V^p) for the
  exponential law; V in m/s) at a particle's incident speed from polynomial
  pieces (:func:`restitution_pieces`, made when a table is loaded): every
  interval of the speed grid cut into S equal pieces, each spanning at most a
  factor :data:`PIECE_RATIO` in V (away from V = 0, where V^p is singular),
  interpolated at Chebyshev points by a polynomial of degree :data:`DEGREE`,
  exact to about 1e-14 absolute for the exponential law (a tabulated law's
  kinks at its speed nodes are rounded off within the piece that holds them).

tests/surrogate/test_kernel_math.py compares each with libm or NumPy on dense grids.
"""

from __future__ import annotations

import math

import numba
import numpy as np
from llvmlite import ir
from numba import types
from numba.extending import intrinsic

from direct_model.elementary import fma
from direct_model.wall import EXPONENTIAL_CODE, W_FAMILY, W_K, W_P, tabulated_restitution
from surrogate.kernels.memory import load
from surrogate.kernels.options import JIT


@numba.njit(inline="always", **JIT)
def clamp_index(i, last):
    """An index i (last ≥ 0) kept in [0, last]: i if it is there, else last (rbs_clamp_index). A negative i,
    INT64_MIN from int(NaN) or an out-of-range float included, is beyond last as unsigned: one compare, as
    the upper clamp alone, and a uniform outside [0, 1) still reads in range."""
    return i if np.uint64(i) <= np.uint64(last) else last


@intrinsic
def bits(typingctx, x):
    """The bits of a float64 as a uint64 (rbs_bits)."""
    if not isinstance(x, types.Float) or x.bitwidth != 64:
        return None

    def codegen(context, builder, signature, args):
        return builder.bitcast(args[0], ir.IntType(64))

    return types.uint64(x), codegen


_ATAN_AT_NODES = tuple(math.atan(0.25 * node) for node in range(5))


@numba.njit(inline="always", **JIT)
def atan2_first_quadrant(y, x):
    """atan2(y, x) in radians for x ≥ 0, y ≥ 0, not both 0, to a few ulp."""
    swap = y > x
    lo, hi = (x, y) if swap else (y, x)
    # the node c = node/4 nearest to t = lo/hi, chosen without dividing (midpoints 1/8, 3/8, 5/8, 7/8)
    node = (lo > 0.125 * hi) + (lo > 0.375 * hi) + (lo > 0.625 * hi) + (lo > 0.875 * hi)
    c = 0.25 * node
    z = fma(-c, hi, lo) / fma(c, lo, hi)
    w = z * z
    p = fma(w, fma(w, fma(w, fma(w, fma(w, fma(w, fma(w, -1.0 / 17.0, 1.0 / 15.0), -1.0 / 13.0), 1.0 / 11.0),
                                 -1.0 / 9.0), 1.0 / 7.0), -1.0 / 5.0), 1.0 / 3.0)
    atan_z = fma(-z * w, p, z)
    # atan c by selects (a tuple indexed by ``node`` would compile to a jump table, which no SIMD loop takes)
    atan_c = _ATAN_AT_NODES[0] if node == 0 else _ATAN_AT_NODES[1] if node == 1 else _ATAN_AT_NODES[2] if node == 2 \
        else _ATAN_AT_NODES[3] if node == 3 else _ATAN_AT_NODES[4]
    angle = atan_c + atan_z
    return 0.5 * math.pi - angle if swap else angle


DEGREE = 9          # polynomial degree of a piece
PIECE_RATIO = 1.25  # a piece [V_lo, V_hi] has V_hi ≤ PIECE_RATIO · V_lo


def restitution_factor(speed: float, wall) -> float:
    """The wall's restitution factor f(V) at V = ``speed`` (m/s): the normal-impact restitution a_nc(V, 1) of
    the wall law (``wall``: the kernels' array, direct_model.wall layout W_*), exp(−k V^p) for the exponential
    family, from the C library's exp and pow, called one value at a time as native/src/layout.c calls them (no
    array function whose SIMD kernel depends on the CPU)."""
    if wall[W_FAMILY] == EXPONENTIAL_CODE:
        return math.exp(-wall[W_K] * math.pow(speed, wall[W_P]))
    return float(tabulated_restitution(wall, speed, 1.0))


N_NODES = DEGREE + 1
# Chebyshev nodes of the first kind on [−1, 1], x_q = cos(π (2q + 1) / (2 N)) correctly rounded, as
# literals (a cos call could be folded at compile time in C and rounded otherwise than libm at run time)
CHEBYSHEV_NODES = tuple(float.fromhex(h) for h in (
    "0x1.f9b24942fe45cp-1", "0x1.c83201d3d2c6dp-1", "0x1.6a09e667f3bcdp-1", "0x1.d0e2e2b44de01p-2",
    "0x1.4060b67a85375p-3", "-0x1.4060b67a85375p-3", "-0x1.d0e2e2b44de01p-2", "-0x1.6a09e667f3bcdp-1",
    "-0x1.c83201d3d2c6dp-1", "-0x1.f9b24942fe45cp-1"))


def _chebyshev_power_coefficients() -> tuple:
    """The integer coefficients of T_0 … T_DEGREE in powers of x (T_{j+1} = 2x T_j − T_{j−1}), exact in float64:
    [T_j]_i at [j][i]."""
    rows = [[1] + [0] * DEGREE, [0, 1] + [0] * (DEGREE - 1)]
    for j in range(2, N_NODES):
        rows.append([2 * (rows[j - 1][i - 1] if i > 0 else 0) - rows[j - 2][i] for i in range(N_NODES)])
    return tuple(tuple(float(c) for c in row) for row in rows)


CHEBYSHEV_POWERS = _chebyshev_power_coefficients()


def restitution_pieces(speed_grid, wall) -> np.ndarray:
    """Polynomial pieces of the wall's restitution factor f(V) (:func:`restitution_factor`; exp(−k V^p) for the
    exponential family) over each interval of ``speed_grid`` (m/s, increasing, > 0).

    Returns coefficients (max(n − 1, 1), S, DEGREE + 1): piece i of interval j
    covers V_j + [i, i + 1]·(V_{j+1} − V_j)/S, in powers of x ∈ [−1, 1]
    across the piece (lowest power first). A one-point grid has no interval;
    it gets one piece of zeros that the kernels never read (their speed
    weight is always 0 there).

    Each piece interpolates at the Chebyshev nodes: c_j = (2 − δ_j0)/N Σ_q f(x_q) T_j(x_q), then
    power_i = Σ_j c_j [T_j]_i. Every sum is a plain loop in index order over scalars, the only library
    calls are exp and pow on one value at a time, so the bits are the same whichever SIMD kernels numpy
    and its BLAS pick on this CPU; native/src/layout.c (rbs_restitution_pieces) repeats the same
    operations in the same order.
    """
    grid = [float(v) for v in np.asarray(speed_grid, dtype=np.float64).ravel()]
    if len(grid) == 1:
        return np.zeros((1, 1, N_NODES))
    widest = 0.0
    for j in range(len(grid) - 1):
        widest = max(widest, (grid[j + 1] - grid[j]) / grid[j])
    pieces = max(1, math.ceil(widest / (PIECE_RATIO - 1.0)))
    # T_j(x_q) at [j][q], by the recurrence
    basis = [[1.0] * N_NODES, list(CHEBYSHEV_NODES)]
    for j in range(2, N_NODES):
        basis.append([2.0 * x * t1 - t0 for x, t1, t0 in zip(CHEBYSHEV_NODES, basis[j - 1], basis[j - 2])])
    coef = np.zeros((len(grid) - 1, pieces, N_NODES))
    for j in range(len(grid) - 1):
        width = grid[j + 1] - grid[j]
        half = 0.5 * width / pieces
        for i in range(pieces):
            start = grid[j] + width * i / pieces
            f = [restitution_factor(start + (x + 1.0) * half, wall) for x in CHEBYSHEV_NODES]
            series = []
            for d in range(N_NODES):
                total = 0.0
                for q in range(N_NODES):
                    total += f[q] * basis[d][q]
                series.append(total / N_NODES if d == 0 else total * 2.0 / N_NODES)
            for e in range(N_NODES):
                total = 0.0
                for d in range(N_NODES):
                    total += series[d] * CHEBYSHEV_POWERS[d][e]
                coef[j, i, e] = total
    return coef


@numba.njit(inline="always", **JIT)
def restitution_at(pieces, n_pieces, j, w):
    """exp(−k V^p) at V = V_j + w (V_{j+1} − V_j), w ∈ [0, 1], from :func:`restitution_pieces` flattened
    (``pieces`` 1-D, ``n_pieces`` its S: piece i of interval j starts at (j S + i)(DEGREE + 1))."""
    t = w * n_pieces
    i = clamp_index(int(t), n_pieces - 1)
    x = 2.0 * (t - i) - 1.0
    start = (j * n_pieces + i) * (DEGREE + 1)
    value = load(pieces, start + DEGREE)
    for d in range(DEGREE - 1, -1, -1):
        value = fma(value, x, load(pieces, start + d))
    return value
