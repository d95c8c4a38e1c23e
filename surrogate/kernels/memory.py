"""Memory access for the kernels: plain loads, strided loads as tuples, and cache hints.

``load(array, index)`` reads ``array[index]`` of a 1-D array at a computed
offset without numba's negative-index wrap-around (the kernels address the
table's flat arrays by offsets that are ≥ 0 by construction).
:func:`load3`, :func:`load6` and :func:`load15` read 3, 6 or 15 values at a
stride as a tuple of float64 (a table row, or a particle's fields in a block
scratch array).

``prefetch(array, index)`` starts loading the cache line of ``array[index]``:
LLVM's ``llvm.prefetch`` (read, locality 2: ``prefetcht1`` on x86, into the
level-2 cache, which keeps more misses in flight than level 1), neither
waiting for the data nor faulting on any address. The kernels use it to have a
draw's table reads, or those of a block of particles, in flight at once
instead of one dependent cache miss after another (docs/design/sampler_cost.md
has the measurements).

``stack_scratch(size)`` is a (size,) float64 array in the calling kernel's
stack frame, for a single-hit kernel's scratch space: ``np.empty`` needs numba's
runtime, and a kernel compiled with it increments and decrements the reference
count of every array it is passed, on every call. The array lives until the
kernel that called ``stack_scratch`` returns: it is passed down, never returned
or stored.
"""

import numba
import numpy as np
from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic
from numba.np.arrayobj import populate_array

from surrogate.kernels.options import JIT


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


@numba.njit(inline="always", **JIT)
def load3(x, at, step):
    """x[at + j·step] for j = 0, 1, 2, as float64."""
    return np.float64(load(x, at)), np.float64(load(x, at + step)), np.float64(load(x, at + 2 * step))


@numba.njit(inline="always", **JIT)
def load6(x, at, step):
    """x[at + j·step] for j = 0 … 5, as float64."""
    return load3(x, at, step) + load3(x, at + 3 * step, step)


@numba.njit(inline="always", **JIT)
def load15(x, at, step):
    """x[at + j·step] for j = 0 … 14, as float64 (the slopes of a component row)."""
    return load6(x, at, step) + load6(x, at + 6 * step, step) + load3(x, at + 12 * step, step)


@intrinsic
def stack_scratch(typingctx, size):
    """A (``size``,) float64 array, C-contiguous, in the calling kernel's stack frame (module doc); ``size`` a
    compile-time integer (a literal or a module constant). Its values start undefined, as ``np.empty``'s."""
    if not (isinstance(size, types.IntegerLiteral) and size.literal_value > 0):
        return None
    count = size.literal_value
    array_type = types.Array(types.float64, 1, "C")

    def codegen(context, builder, signature, args):
        # alloca_once puts the allocation in the function's entry block: once per call, whatever the loops
        data = cgutils.alloca_once(builder, context.get_value_type(types.float64), size=count)
        array = context.make_array(array_type)(context, builder)
        itemsize = context.get_constant(types.intp, 8)
        populate_array(array, data=data, shape=[context.get_constant(types.intp, count)], strides=[itemsize],
                       itemsize=itemsize, meminfo=None)
        return array._getvalue()

    return array_type(size), codegen
