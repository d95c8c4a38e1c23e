"""Shared numba options for every jitted kernel of the direct model.

One dict so that all kernels compile the same way, and its variant for those that allocate nothing (as
:mod:`surrogate.kernels.options` has them for the sampler). ``cache=True`` is safe here: kernels read no
module globals that change at run time (tables and parameters are always passed in as arrays).
``fastmath`` stays off: the physics tests compare results to round-off and IEEE semantics keep them
reproducible.
Importing :mod:`data_schema.kernel_cache` first keys every kernel's cache by the sources it depends on.
"""

from data_schema import kernel_cache  # noqa: F401  (installed before any kernel is decorated)

JIT = dict(cache=True, nogil=True, fastmath=False, error_model="numpy")

# The kernels on a rebound's path allocate nothing: without numba's reference counting (_nrt=False) a call costs
# no atomic increment and decrement per array argument (numba issue 2345; docs/design/contact_search.md), and an
# allocation in one of them fails to compile.
KERNEL = dict(JIT, _nrt=False)
