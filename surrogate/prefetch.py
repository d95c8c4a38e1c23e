"""A cache hint for numba kernels: ``prefetch(array, index)`` starts loading the cache line of ``array[index]``.

It compiles to LLVM's ``llvm.prefetch`` (read, high locality), an instruction
that neither waits for the data nor faults on any address. The sampler's
block kernel (:func:`surrogate.kernels.rebound_many`) uses it to have the
table reads of many particles in flight at once instead of one dependent
cache miss after another per particle.
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
        # read (0), keep in all cache levels (3), data cache (1)
        builder.call(hint, [builder.bitcast(pointer, byte_pointer), i32(0), i32(3), i32(1)])
        return context.get_dummy_value()

    return types.none(array, index), codegen
