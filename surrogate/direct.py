"""The direct model from NumPy: the rebound of many particles, each computed by the model itself with the
parameters a table was built with (docs/model.md §10). For the states a table does not cover: a spinning
particle (Ω⁻ ≠ 0), an α1 or |V⁻| off its grid. It costs microseconds per particle, not nanoseconds."""

from __future__ import annotations

import numpy as np

from direct_model.shapes import SHAPES
from surrogate.kernels.checks import first_faults
from surrogate.kernels.direct_path import direct_rebound_parallel_rng
from surrogate.kernels.rng import chunk_states
from surrogate.sampling import _fault_error, _outputs, _rows, _vectors, check_random_state
from surrogate.table import SurrogateTable


def direct_model_parameters(table: SurrogateTable) -> np.ndarray:
    """The direct model's parameters of ``table`` as the run-time kernel takes them
    (:func:`surrogate.kernels.direct_path.direct_rebound`): a read-only float64 array, layout P_* of
    :mod:`direct_model.runtime`. ValueError if the table does not record them."""
    if table.direct_parameters is None:
        raise ValueError(f"The table {table.path} does not record the direct model's second-moment factors (built "
                         f"at kappa != 0.3 before tables recorded them); rebuild it with this version.")
    return table.direct_parameters


def _shape_codes(shape, n: int) -> np.ndarray:
    """(n,) int64 shape codes from a shape name or from n names or codes; ValueError naming a bad one."""
    values = np.asarray(shape)
    if values.ndim > 1 or values.size not in (1, n):
        raise ValueError(f"The 'shape' parameter must be a shape name or have shape ({n},); got {values.shape}.")
    flat = values.reshape(-1)
    if flat.dtype.kind in "iu":
        bad = np.flatnonzero((flat < 0) | (flat >= len(SHAPES)))
        if bad.size:
            raise ValueError(f"The 'shape' code at index {bad[0]} must be in [0, {len(SHAPES) - 1}]; "
                             f"got {int(flat[bad[0]])}.")
        codes = flat.astype(np.int64)
    else:
        names = [str(s) for s in flat]
        bad = [i for i, s in enumerate(names) if s not in SHAPES]
        if bad:
            raise ValueError(f"The 'shape' at index {bad[0]} must be one of {', '.join(SHAPES)}; "
                             f"got {names[bad[0]]!r}.")
        codes = np.array([SHAPES.index(s) for s in names], dtype=np.int64)
    return np.ascontiguousarray(np.broadcast_to(codes, (n,)))


def sample_direct(table: SurrogateTable, velocity, normal, half_size, omega=(0.0, 0.0, 0.0), shape="ellipsoid",
                   random_state=None, out=None):
    """Reflected velocities and spins of particles hitting walls, from the direct model, in the caller's frame.

    Parameters
    ----------
    table : a loaded table (:func:`surrogate.load`): the model's parameters (aspect-ratio law, κ, n_max, the
        wall law, the tolerances) are those it was built with.
    velocity : (N, 3) incident velocities V⁻, m/s; each must move into its wall (V⁻·n < 0). Any α1 in
        (0°, 90°] and any speed (the wall law was measured for 50–300 m/s).
    normal : (N, 3) or (3,) unit wall normals pointing into the gas (|n| − 1 within 1e-6).
    half_size : (N,) or scalar, half-size a in m (half the largest extent), > 0.
    omega : (N, 3) or (3,) incident angular velocities Ω⁻, rad/s; exactly zero: the body starts touching the
        wall (as in the tables), otherwise the flight in from a clear start is simulated.
    shape : a shape name (:data:`direct_model.shapes.SHAPES`), or (N,) names or codes.
    random_state : int, Generator or None; one xoshiro256+ stream per chunk of particles seeded from it
        (:func:`surrogate.kernels.rng.chunk_states`): the same seed gives the same bits whatever the number
        of threads.
    out : None or (V_out, Omega_out, status) arrays to fill (as :func:`surrogate.sample_global`).

    Returns
    -------
    (V_out (N, 3) m/s, Omega_out (N, 3) rad/s, status (N,) int8): STATUS_REBOUNDED (0), STATUS_TRAPPED (1)
    or STATUS_FAILED (2, a collision solve or contact search failed); NaN rows unless rebounded.
    """
    params = direct_model_parameters(table)
    V = np.ascontiguousarray(_vectors("velocity", velocity))
    n = V.shape[0]
    nrm = np.ascontiguousarray(_vectors("normal", normal, n))
    W = np.ascontiguousarray(_vectors("omega", omega, n))
    a = np.asarray(half_size, dtype=np.float64)
    if a.ndim > 1 or a.size not in (1, n):
        raise ValueError(f"The 'half_size' parameter must be a scalar or have shape ({n},); got {a.shape}.")
    a = np.ascontiguousarray(a.reshape(-1))
    # every state moving into its wall is in the model's range: only the physical checks can fail
    first = first_faults(V, nrm, a, 0.0, 90.0, 0.0, np.inf)
    faults = np.flatnonzero(first >= 0)
    if faults.size:
        raise _fault_error(int(faults[0]), int(first[faults[0]]), table, V, nrm, a)
    bad = np.flatnonzero(~np.isfinite(W).all(axis=1))
    if bad.size:
        raise ValueError(f"The 'omega' vector at index {bad[0]} is not finite: {W[bad[0]].tolist()}.")
    codes = _shape_codes(shape, n)
    V_out, Omega_out, status = _outputs(out, n, (V, nrm, a, W))
    states = chunk_states(check_random_state(random_state), n)
    direct_rebound_parallel_rng(params, codes, V, _rows(W, n), _rows(nrm, n), _rows(a, n), states, V_out, Omega_out,
                                status)
    return V_out, Omega_out, status
