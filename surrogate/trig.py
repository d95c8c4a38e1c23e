"""Trigonometry inlined into the sampler kernels: :func:`sincos` and :func:`atan2_first_quadrant`.

A call to libm (``sin``/``cos``, which LLVM merges into ``sincos``, or
``atan2``) costs the call itself and, because every floating-point register
is caller-saved, the spilling of the kernel's live values around it. These
are instead a few multiply-adds that the compiler schedules with the rest of
the kernel, on the argument ranges the kernels use, to a few units in the
last place (tests/test_kernel_math.py compares them with libm on dense grids).

* :func:`sincos`, |x| ≤ 2π: Cody–Waite reduction by the nearest multiple q
  of π/2 (π/2 split into two doubles, so the reduced angle r, |r| ≤ π/4, is
  accurate to about 1e-17), the Taylor polynomials of sin r to r¹⁵ and
  cos r to r¹⁶ (truncation below 5e-17 for |r| ≤ π/4), the quadrant's signs.
* :func:`atan2_first_quadrant`, x, y ≥ 0: the ratio t = min/max ∈ [0, 1]
  (π/2 − atan for y > x), then atan t = atan c + atan z with c the nearest
  of 0, 1/4, 1/2, 3/4, 1 and z = (t − c)/(1 + c t), |z| ≤ 1/8, taken in one
  division from x and y; atan z by its Taylor series to z¹⁷ (truncation
  below 1e-18).
"""

import math

import numba

from surrogate.fused import fma
from surrogate.jit import JIT

_HALF_PI_HI = 1.5707963267948966       # π/2 rounded to a double
_HALF_PI_LO = 6.123233995736766e-17    # π/2 − _HALF_PI_HI
_TWO_OVER_PI = 2.0 / math.pi
# Taylor coefficients (−1)^k / n!: sin r = r + r³ S3 + ... + r¹⁵ S15, cos r = 1 + r² C2 + ... + r¹⁶ C16
# (Horner steps as fused multiply-adds, surrogate.fused)
S3, S5, S7, S9, S11, S13, S15 = ((-1.0) ** k / math.factorial(2 * k + 1) for k in range(1, 8))
C2, C4, C6, C8, C10, C12, C14, C16 = ((-1.0) ** k / math.factorial(2 * k) for k in range(1, 9))


@numba.njit(inline="always", **JIT)
def sincos(x):
    """(sin x, cos x) for |x| ≤ 2π (x in radians), to a few ulp."""
    q = math.floor(x * _TWO_OVER_PI + 0.5)
    r = (x - q * _HALF_PI_HI) - q * _HALF_PI_LO
    z = r * r
    p = fma(z, fma(z, fma(z, fma(z, fma(z, fma(z, S15, S13), S11), S9), S7), S5), S3)
    s = fma(r * z, p, r)
    p = fma(z, fma(z, fma(z, fma(z, fma(z, fma(z, fma(z, C16, C14), C12), C10), C8), C6), C4), C2)
    c = fma(z, p, 1.0)
    quadrant = int(q) & 3       # x = r + quadrant·π/2 (mod 2π); selects, not branches
    odd = (quadrant & 1) == 1
    sign = 1.0 - (quadrant & 2)
    return sign * (c if odd else s), sign * (-s if odd else c)


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
