"""Shared numba options for every jitted kernel of the direct model.

One dict so that all kernels compile the same way, and its variant for those that allocate nothing (as
:mod:`surrogate.kernels.options` has them for the sampler). ``cache=True`` is safe here: kernels read no
module globals that change at run time (tables and parameters are always passed in as arrays).
``fastmath`` stays off: the physics tests compare results to round-off and IEEE semantics keep them
reproducible.
"""

JIT = dict(cache=True, nogil=True, fastmath=False, error_model="numpy")

# The kernels on a rebound's path (the free flight, the search, the collision, the body) allocate nothing, so they
# are compiled without numba's reference counting (_nrt=False), which would add an atomic increment and decrement
# for most array arguments of every call (numba issue 2345): 1.13-1.2 times the rebounds per second, the same bits
# (docs/design/contact_search.md). An allocation in one of them fails to compile.
KERNEL = dict(JIT, _nrt=False)
