"""Shared numba options for every jitted kernel of the direct model.

One dict so that all kernels compile the same way. ``cache=True`` is safe here:
kernels read no module globals that change at run time (tables and parameters are
always passed in as arrays). ``fastmath`` stays off: the physics tests compare
results to round-off and IEEE semantics keep them reproducible.
"""

JIT = dict(cache=True, nogil=True, fastmath=False, error_model="numpy")
