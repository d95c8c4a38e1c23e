"""Memory access for numba kernels: cache hints and plain loads.

``prefetch(array, index)`` starts loading the cache line of ``array[index]``.
It compiles to LLVM's ``llvm.prefetch`` (read, locality 2: ``prefetcht1`` on
x86, which fills the level-2 cache and not the level-1), an instruction that
neither waits for the data nor faults on any address. The sampler's
kernels (:mod:`surrogate.kernels`) use it to have a draw's table reads, or
those of many particles, in flight at once instead of one dependent cache
miss after another. Into level 2 rather than level 1 because the level-2
cache keeps more misses in flight: ``rebound_many`` requests about 15 lines
per particle for 16 particles at once, and on the 51 MB (six-speed) default table it
cost 157–160 ns per draw with level-1 hints (locality 3) and 141–142 ns with
level-2 hints (interleaved runs, one process; locality 1 measured the same
as 2, non-temporal 159 ns; the per-particle kernel did not change).

``load(array, index)`` reads ``array[index]`` of a 1-D array at a computed
offset without numba's negative-index wrap-around: the kernels address the
table's flat arrays by offsets that are ≥ 0 by construction.
"""

from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic


@intrinsic
def prefetch(typingctx, array, index):
    """Prefetch ``array[index]`` (``index``: a tuple with one integer per dimension; not bounds-checked)."""
    if not (isinstance(array, types.Array) and isinstance(index, types.BaseTuple) and len(index) == array.ndim
            and all(isinstance(t, types.Integer) for t in index)):
        return None

    def codegen(context, builder, signature, args):
        array_type, index_type = signature.args
        data = context.make_array(array_type)(context, builder, value=args[0])
        where = [context.cast(builder, builder.extract_value(args[1], i), t, types.intp)
                 for i, t in enumerate(index_type)]
        pointer = cgutils.get_item_pointer(context, builder, array_type, data, where, wraparound=False)
        i32, byte_pointer = ir.IntType(32), ir.IntType(8).as_pointer()
        hint = builder.module.declare_intrinsic(       # named for llvmlite's pointer type (p0i8 or p0)
            "llvm.prefetch", [byte_pointer], ir.FunctionType(ir.VoidType(), [byte_pointer, i32, i32, i32]))
        # read (0), locality 2 (level-2 cache and below), data cache (1)
        builder.call(hint, [builder.bitcast(pointer, byte_pointer), i32(0), i32(2), i32(1)])
        return context.get_dummy_value()

    return types.none(array, index), codegen


@intrinsic
def load(typingctx, array, index):
    """``array[index]`` for a 1-D array and an integer ``index`` ≥ 0, read without numba's negative-index
    wrap-around (a compare and an add per read, which the compiler cannot drop for a computed offset) and
    without bounds check: the kernels' offsets are in range by construction."""
    if not (isinstance(array, types.Array) and array.ndim == 1 and isinstance(index, types.Integer)):
        return None

    def codegen(context, builder, signature, args):
        array_type, index_type = signature.args
        data = context.make_array(array_type)(context, builder, value=args[0])
        where = context.cast(builder, args[1], index_type, types.intp)
        pointer = cgutils.get_item_pointer(context, builder, array_type, data, [where], wraparound=False)
        return context.unpack_value(builder, array_type.dtype, pointer)

    return array.dtype(array, index), codegen
