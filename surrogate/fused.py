"""``fma(a, b, c)``: a·b + c with one rounding, for the sampler kernels' polynomial and linear chains.

Numba compiles without floating-point contraction (``fastmath=False``), so
``a * b + c`` is a multiply then an add: two roundings and, on the chains of
dependent steps a draw is made of (Horner polynomials, the conditional chain
of the state variables), twice the latency of one fused instruction. Letting
LLVM contract on its own (``fastmath={"contract"}``) would be as fast, but it
fuses differently in different surrounding code, so the per-particle and the
block kernels would no longer give the same bits. An explicit ``fma`` is the
same operation wherever it is compiled: LLVM's ``llvm.fma.f64``, one
instruction on CPUs with FMA and the correctly rounded libm ``fma``
otherwise, so results do not depend on the machine either.
"""

from llvmlite import ir
from numba import types
from numba.extending import intrinsic


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
