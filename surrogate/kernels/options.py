"""numba options shared by the runtime sampler's kernels: the direct model's (:mod:`direct_model.options`).

``cache=True`` is safe: the kernels read no module global that changes at
run time (tables come in as arrays). ``fastmath`` stays off, so that the
per-particle and the block kernels give the same bits. With
``error_model="numpy"`` a division by zero gives inf or NaN instead of
raising, so the hot path carries no such check. The per-particle kernels
allocate nothing and take ``KERNEL``, without numba's reference counting: with it,
every array taken from the table tuple or sliced from a row would cost an
atomic increment and decrement that numba cannot prune across branches
(docs/design/sampler_cost.md). Callers keep their own reference counting.
"""

from direct_model.options import JIT, KERNEL

__all__ = ["JIT", "KERNEL"]
