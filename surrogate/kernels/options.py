"""numba options shared by the runtime sampler's kernels.

``cache=True`` is safe: the kernels read no module global that changes at
run time (tables come in as arrays). ``fastmath`` stays off, so that the
per-particle and the block kernels give the same bits. With
``error_model="numpy"`` a division by zero gives inf or NaN instead of
raising, so the hot path carries no such check.
"""

JIT = dict(cache=True, nogil=True, fastmath=False, error_model="numpy")
# The per-particle kernels allocate nothing, so they are compiled without numba's reference
# counting (_nrt=False): with it, every array taken from the table tuple or sliced from a row
# costs an atomic increment and decrement that numba cannot prune across branches
# (docs/design/sampler_cost.md). Callers keep their own reference counting.
KERNEL = dict(JIT, _nrt=False)
