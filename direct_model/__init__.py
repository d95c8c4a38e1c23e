"""The direct model: the rebound of a particle from a wall, collision by collision (docs/model.md).

shapes (bodies and their random draws), wall (the wall law), collision (one impulse), rotation (exact
torque-free rotation), flight (contact search), body_rebound (one particle, numba kernels), simulate (the
batch API, :func:`direct_model.simulate.simulate`), options (the numba options of every kernel).
Any convex grain (docs/model.md §3): polyhedron (a hull's mass properties and canonical frame), registry
(the record of a shape; the four families as records), shape_arrays (the shapes as the kernels take them, one
particle's body), support (a hull's support point by hill climbing).

It imports nothing from :mod:`tablegen` (the table build runs it, and so does the runtime,
:mod:`surrogate`), and its kernels need numpy and numba only; the batch API's aspect-ratio draws and the
convex-hull mass properties use scipy (the ``build`` extra).
"""
