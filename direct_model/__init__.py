"""The direct model: n particles at one incident state, collision by collision (docs/model.md).

shapes (bodies and their random draws), wall (the wall law), collision (one impulse), rotation (exact
torque-free rotation), flight (contact search), rebound (one particle, numba kernels), simulate (the
batch API, :func:`tablegen.model.simulate.simulate`), options (the numba options of every kernel).
"""
