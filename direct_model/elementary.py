"""Elementary functions that the direct model and the sampler kernels inline: the same bits wherever they run.

A call to libm costs the call itself and, because every floating-point register is caller-saved, the
spilling of the kernel's live values around it; its result may also differ between libm versions. So the
flight's phases and the sampler's angles take:

* :func:`fma` — a·b + c rounded once: LLVM's ``llvm.fma.f64`` (one instruction with FMA, the correctly
  rounded libm ``fma`` otherwise), the same operation wherever it is compiled, so the per-particle and the
  block kernels give the same bits (letting LLVM contract on its own would fuse differently in different
  surrounding code);
* :func:`sincos` — Cody–Waite reduction by the nearest multiple q of π/2 (π/2 split into two doubles),
  Taylor polynomials of sin r to r¹⁵ and cos r to r¹⁶ on |r| ≤ π/4 (truncation below 5e-17), the
  quadrant's signs. A few ulp for |x| ≤ 2π; beyond, the rounding of q·π/2 adds about ulp(x)/2 to the
  reduced angle, as much as x's own rounding.

The C library has the same functions (native/src/fastmath.h: ``fma`` of C99, ``rbs_sincos``).
tests/surrogate/test_kernel_math.py compares them with libm on dense grids.
"""

from __future__ import annotations

import math

import numba
from llvmlite import ir
from numba import types
from numba.extending import intrinsic

from direct_model.options import JIT


@intrinsic
def fma(typingctx, a, b, c):
    """a·b + c rounded once, as float64 (float32 or float64 arguments)."""
    if not all(isinstance(t, types.Float) for t in (a, b, c)):
        return None

    def codegen(context, builder, signature, args):
        f64 = ir.DoubleType()
        fused = builder.module.declare_intrinsic("llvm.fma", [f64], ir.FunctionType(f64, [f64, f64, f64]))
        values = [context.cast(builder, v, t, types.float64) for v, t in zip(args, signature.args)]
        return builder.call(fused, values)

    return types.float64(a, b, c), codegen


_HALF_PI_HI = 1.5707963267948966       # π/2 rounded to a double
_HALF_PI_LO = 6.123233995736766e-17    # π/2 − _HALF_PI_HI
_TWO_OVER_PI = 2.0 / math.pi
# Taylor coefficients (−1)^k / n!: sin r = r + r³ S3 + ... + r¹⁵ S15, cos r = 1 + r² C2 + ... + r¹⁶ C16
# (Horner steps as fused multiply-adds)
S3, S5, S7, S9, S11, S13, S15 = ((-1.0) ** k / math.factorial(2 * k + 1) for k in range(1, 8))
C2, C4, C6, C8, C10, C12, C14, C16 = ((-1.0) ** k / math.factorial(2 * k) for k in range(1, 9))


@numba.njit(inline="always", **JIT)
def sincos(x):
    """(sin x, cos x), x in radians, |x| < 2⁶²: a few ulp for |x| ≤ 2π, plus about ulp(x)/2 beyond (module doc)."""
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
