"""The wall's normal restitution factor exp(−k V^p) between grid speeds, as precomputed polynomial pieces.

The sampler's speed step (:func:`surrogate.draw._to_speed`) needs
f(V) = exp(−k V^p) (V in m/s) at every particle's incident speed. Computed
directly that is a ``pow`` and an ``exp`` call per draw, about a tenth of the
kernel's cost. Instead, :func:`restitution_pieces` cuts every interval
[V_j, V_{j+1}] of the table's speed grid into S equal pieces, S the same for
all intervals and large enough that each piece spans at most a factor
:data:`PIECE_RATIO` in V, and interpolates f on each piece by a polynomial of
degree :data:`DEGREE` at Chebyshev points. Bounding the ratio keeps every
piece away from V = 0, where V^p is singular, so the interpolant is exact
to about 1e-14 absolute (the factor is at most 1 and enters
a(V) = 1 − (1 − f) sin α1 additively; tests/test_kernel_math.py checks
≤ 1e-12 on grids from 0.1 to 1000 m/s and laws from k V^p = 0.02 V^0.3 to
0.1 V^1.5). :func:`restitution_at` evaluates it (on the pieces flattened,
as the kernels hold them) from the grid interval and weight the kernel has
already located: one multiply, one floor, a Horner loop.
"""

from __future__ import annotations

import numba
import numpy as np
from numpy.polynomial import chebyshev

from surrogate.fused import fma
from surrogate.jit import JIT
from surrogate.memory import load

DEGREE = 9          # polynomial degree of a piece
PIECE_RATIO = 1.25  # a piece [V_lo, V_hi] has V_hi ≤ PIECE_RATIO · V_lo


def restitution_pieces(speed_grid, k: float, p: float) -> np.ndarray:
    """Polynomial pieces of exp(−k V^p) over each interval of ``speed_grid`` (m/s, increasing, > 0).

    Returns coefficients (max(n − 1, 1), S, DEGREE + 1): piece i of interval j
    covers V_j + [i, i + 1]·(V_{j+1} − V_j)/S, in powers of x ∈ [−1, 1]
    across the piece (lowest power first). A one-point grid has no interval;
    it gets one piece of zeros that the kernels never read (their speed
    weight is always 0 there).
    """
    grid = np.asarray(speed_grid, dtype=np.float64)
    if len(grid) == 1:
        return np.zeros((1, 1, DEGREE + 1))
    pieces = max(1, int(np.ceil(np.max(np.diff(grid) / grid[:-1]) / (PIECE_RATIO - 1.0))))
    coef = np.zeros((len(grid) - 1, pieces, DEGREE + 1))
    for j in range(len(grid) - 1):
        edges = np.linspace(grid[j], grid[j + 1], pieces + 1)
        for i in range(pieces):
            lo, half = edges[i], 0.5 * (edges[i + 1] - edges[i])
            series = chebyshev.chebinterpolate(lambda x: np.exp(-k * (lo + (x + 1.0) * half) ** p), DEGREE)
            power = chebyshev.cheb2poly(series)
            coef[j, i, :len(power)] = power
    return coef


@numba.njit(inline="always", **JIT)
def restitution_at(pieces, n_pieces, j, w):
    """exp(−k V^p) at V = V_j + w (V_{j+1} − V_j), w ∈ [0, 1], from :func:`restitution_pieces` flattened
    (``pieces`` 1-D, ``n_pieces`` its S: piece i of interval j starts at (j S + i)(DEGREE + 1))."""
    t = w * n_pieces
    i = min(int(t), n_pieces - 1)
    x = 2.0 * (t - i) - 1.0
    start = (j * n_pieces + i) * (DEGREE + 1)
    value = load(pieces, start + DEGREE)
    for d in range(DEGREE - 1, -1, -1):
        value = fma(value, x, load(pieces, start + d))
    return value
