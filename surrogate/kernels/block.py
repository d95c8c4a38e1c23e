"""The block form of a draw's records: BLOCK particles side by side, for the many-particle kernels.

The pipeline (:mod:`surrogate.kernels.pipeline`) takes BLOCK particles at a
time through the stages of a draw. Each stage keeps its record of the block
(frame, cell, gathered values, results) in a flat float64 or int64 array,
field-major: field f of particle b at f · BLOCK + b. The stride is then a
compile-time constant, which the SIMD loops over a block need. Each stage
defines its record's fields beside its code; this module gives the reads and
writes they share, and the block's uniforms (uniform k of particle b at
k · BLOCK + b).
"""

import numba
import numpy as np

from surrogate.kernels.memory import load, load3, load6
from surrogate.kernels.options import JIT

BLOCK = 32      # particles whose table reads the pipeline puts in flight together


@numba.njit(inline="always", **JIT)
def field(x, f, b):
    """Field f of particle b."""
    return load(x, f * BLOCK + b)


@numba.njit(inline="always", **JIT)
def fields3(x, f, b):
    """Fields f … f + 2 of particle b as a 3-tuple of float64."""
    return load3(x, f * BLOCK + b, BLOCK)


@numba.njit(inline="always", **JIT)
def fields6(x, f, b):
    """Fields f … f + 5 of particle b as a 6-tuple of float64."""
    return load6(x, f * BLOCK + b, BLOCK)


@numba.njit(inline="always", **JIT)
def put3(x, f, b, values):
    """Fields f … f + 2 of particle b: the 3-tuple ``values`` (written out: a tuple indexed by a loop variable
    compiles to a jump table)."""
    x[f * BLOCK + b], x[(f + 1) * BLOCK + b], x[(f + 2) * BLOCK + b] = values


@numba.njit(inline="always", **JIT)
def put6(x, f, b, values):
    """Fields f … f + 5 of particle b: the 6-tuple ``values``."""
    put3(x, f, b, values[:3])
    put3(x, f + 3, b, values[3:])


@numba.njit(inline="always", **JIT)
def uniforms(ub, b):
    """The 13 uniforms of particle b (surrogate.kernels.draw.U_PER_DRAW) as a tuple, from the block's uniforms
    ``ub``."""
    return load6(ub, b, BLOCK) + load6(ub, 6 * BLOCK + b, BLOCK) + (np.float64(load(ub, 12 * BLOCK + b)),)
