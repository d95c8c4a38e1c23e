"""Shared numba options for every jitted kernel of the direct model.

One dict so that all kernels compile the same way (and one variant of it for those that allocate nothing). ``cache=True`` is safe here:
kernels read no module globals that change at run time (tables and parameters are
always passed in as arrays). ``fastmath`` stays off: the physics tests compare
results to round-off and IEEE semantics keep them reproducible.
"""

JIT = dict(cache=True, nogil=True, fastmath=False, error_model="numpy")

# The kernels on a rebound's path (the free flight, the search, the collision, the body): they allocate nothing,
# so they are compiled without numba's runtime (NRT), which would otherwise add an atomic increment and decrement
# of an array's reference count for most array arguments of every call (numba issue 2345): 1.13-1.2 times the
# rebounds per second of the same kernels with it, the same bits (docs/design/contact_search.md). An allocation in
# one of them fails to compile.
NO_ALLOCATION = dict(JIT, _nrt=False)
