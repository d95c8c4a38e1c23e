"""NumPy API of the runtime sampler: validated, vectorised draws of reflected states.

Two entry points:

* :func:`sample_local` — for arrays of incidence angle α1 (deg) and speed |V⁻|
  (m/s), the reflected state (α2, β2, s, Ω⁺a/|V⁻|) in the local frame (wall
  y = 0, normal +Y, impact plane XY);
* :func:`sample_global` — the solver's API: incident velocities and wall
  normals in any global frame in, V⁺ (m/s) and Ω⁺ (rad/s) out.

Both accept a shape name or a mix of shapes, ``random_state`` (int, Generator
or None; not ``seed`` as in :mod:`tablegen`, because a Generator is accepted too, as under that name in
NumPy's and scikit-learn's APIs) and ``clamp``: by default an incident state outside the table's grid
is an error; with ``clamp=True`` the dimensionless law at the nearest grid
edge is used (and scaled by the particle's actual speed).
Between grid points the law of a neighbouring grid point is drawn with its
interpolation weight and, by default (``interpolation="scaled"``), moved to the
incident state: in α1 to the interpolated means and standard deviations, in
|V⁻| by the wall's restitution law (:func:`surrogate.kernels.draw.draw_velocity`).
Each particle gets a status: 0 rebounded, 1 trapped (rolling along or
deposited on the wall, drawn with its tabulated probability; its V⁺ and Ω⁺
are NaN, not a made-up rebound).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from data_schema.samples import ALPHA1_RANGE_DEG, SHAPE_NAMES
from data_schema.table import STATE_NAMES
from surrogate.kernels.checks import (FAULT_ALPHA1_NOT_FINITE, FAULT_ALPHA1_OUTSIDE, FAULT_HALF_SIZE,
                                      FAULT_NORMAL_NOT_FINITE, FAULT_NORMAL_NOT_UNIT, FAULT_NOT_INTO_WALL,
                                      FAULT_SPEED_NOT_FINITE, FAULT_SPEED_OUTSIDE, FAULT_VELOCITY_NOT_FINITE,
                                      FAULT_VELOCITY_ZERO, NORMAL_TOLERANCE, first_faults)
from surrogate.kernels.parallel import draw_local_parallel_rng, rebound_parallel_rng
from surrogate.kernels.rng import chunk_states
from surrogate.table import SurrogateTable

WEIGHT_SUM_TOLERANCE = 1e-9     # |Σ weights − 1| allowed for a mix


class LocalDraws(NamedTuple):
    """Reflected states in the local frame (arrays of length n)."""

    alpha2: np.ndarray        # rad, in [0, π]
    beta2: np.ndarray         # rad, in [−π/2, π/2]
    speed_ratio: np.ndarray   # |V⁺|/|V⁻|
    omega: np.ndarray         # (n, 3) Ω⁺ a/|V⁻|, local frame
    status: np.ndarray        # int8: 0 rebounded, 1 trapped


def check_random_state(random_state) -> np.random.Generator:
    """A Generator from an int seed, a Generator (used as is) or None (fresh entropy)."""
    if isinstance(random_state, np.random.Generator):
        return random_state
    if random_state is None or (isinstance(random_state, (int, np.integer)) and not isinstance(random_state, bool)
                                and random_state >= 0):
        return np.random.default_rng(random_state)
    raise ValueError(f"The 'random_state' parameter must be a non-negative int, a numpy Generator or None; "
                     f"got {random_state!r}.")


def mix_cdf(table: SurrogateTable, shape) -> np.ndarray:
    """Cumulative shape weights in the table's shape order.

    ``shape`` is a shape name, ``"mix"`` (equal weights over the table's
    shapes), a dict {shape: weight}, or a sequence of four weights in the order
    ellipsoid, prism, cut_prism, tetrahedron. Weights must
    be non-negative and sum to 1 (within WEIGHT_SUM_TOLERANCE); a shape with positive weight
    must be in the table.
    """
    if isinstance(shape, str) and shape == "mix":
        weights = {name: 1.0 / len(table.shapes) for name in table.shapes}
    elif isinstance(shape, str):
        weights = {shape: 1.0}
    elif isinstance(shape, dict):
        weights = dict(shape)
    else:
        values = list(shape)
        if len(values) != len(SHAPE_NAMES):
            raise ValueError(f"The 'shape' mix must have {len(SHAPE_NAMES)} weights ({', '.join(SHAPE_NAMES)}); "
                             f"got {values!r}.")
        weights = dict(zip(SHAPE_NAMES, values))
    for name, w in weights.items():
        if name not in SHAPE_NAMES:
            raise ValueError(f"The 'shape' parameter must name one of {', '.join(SHAPE_NAMES)}; got {name!r}.")
        if not (np.isfinite(w) and w >= 0):
            raise ValueError(f"The mix weight of {name!r} must be finite and >= 0; got {float(w)!r}.")
        if w > 0 and name not in table.shapes:
            raise ValueError(f"shape {name!r} is not in the table {table.path} (it holds {', '.join(table.shapes)}).")
    total = sum(weights.values())
    if abs(total - 1.0) > WEIGHT_SUM_TOLERANCE:
        raise ValueError(f"The mix weights must sum to 1; got {float(total)!r} from "
                         f"{ {k: float(v) for k, v in weights.items()} }.")
    cdf, total = np.empty(len(table.shapes)), 0.0
    for k, name in enumerate(table.shapes):       # running sum in table order, as rbs_mix_from_weights adds
        total += float(weights.get(name, 0.0))
        cdf[k] = total
    cdf[-1] = 1.0
    return cdf


INTERPOLATIONS = ("stochastic", "scaled")


def _scaled(interpolation: str) -> bool:
    if interpolation not in INTERPOLATIONS:
        raise ValueError(f"The 'interpolation' parameter must be one of {', '.join(INTERPOLATIONS)}; "
                         f"got {interpolation!r}.")
    return interpolation == "scaled"


# physical range of the incident state: (low, high, high included); clamp=True never reaches beyond it
PHYSICAL_RANGE = {"alpha1": (*ALPHA1_RANGE_DEG, True), "speed": (0.0, np.inf, False)}


def _check_range(name, values, bounds, clamp, units) -> None:
    """Non-finite values and values outside the physical range are always an error (PHYSICAL_RANGE);
    values outside the table's range unless ``clamp``.

    With ``clamp`` the kernels use the law of the nearest grid edge (the
    dimensionless reflected state), applied to the particle's actual speed.
    """
    bad = np.flatnonzero(~np.isfinite(values))
    if bad.size:
        raise _not_finite(name, bad[0], values[bad[0]])
    low, high, closed = PHYSICAL_RANGE[name]
    bad = np.flatnonzero((values <= low) | ((values > high) if closed else (values >= high)))
    if bad.size:
        value = float(values[bad[0]])
        shown = f"({low:g}, {high:g}{']' if closed else ')'}"
        raise ValueError(f"The '{name}' value {value!r} {units} (index {bad[0]}) is outside the physical range "
                         f"{shown} {units}; clamp=True extends only the table's range [{bounds[0]:g}, "
                         f"{bounds[1]:g}] up to it.")
    if clamp:
        return
    lo, hi = bounds
    bad = np.flatnonzero((values < lo) | (values > hi))
    if bad.size:
        raise _outside(name, bad[0], values[bad[0]], bounds, units)


def _not_finite(name, index, value) -> ValueError:
    return ValueError(f"The '{name}' value at index {index} is not finite: {float(value)!r}.")


def _outside(name, index, value, bounds, units) -> ValueError:
    return ValueError(f"The '{name}' value {float(value)!r} {units} (index {index}) is outside the table's range "
                      f"[{bounds[0]:g}, {bounds[1]:g}]; pass clamp=True to use the law at the nearest grid edge.")


def sample_local(table: SurrogateTable, alpha1, speed, shape="ellipsoid", random_state=None,
                 clamp: bool = False, interpolation: str = "scaled") -> LocalDraws:
    """Draw one reflected state per entry of ``alpha1`` (deg) and ``speed`` (m/s).

    ``alpha1`` and ``speed`` are broadcast together; their common shape is
    flattened to n draws. ``interpolation``: ``"scaled"`` (default) or
    ``"stochastic"`` (see :func:`sample_global`). ``clamp``: an α1 or |V⁻|
    outside the table's range uses the law at the nearest grid edge instead of
    raising; α1 outside (0, 90] deg or |V⁻| ≤ 0 m/s is non-physical and always
    raises.
    """
    a, v = np.broadcast_arrays(np.asarray(alpha1, dtype=np.float64), np.asarray(speed, dtype=np.float64))
    a, v = a.ravel(), v.ravel()
    _check_range("alpha1", a, table.alpha1_range, clamp, "deg")
    _check_range("speed", v, table.speed_range, clamp, "m/s")
    cdf = mix_cdf(table, shape)
    scaled = _scaled(interpolation)
    states = chunk_states(check_random_state(random_state), len(a))
    out = np.empty((len(a), len(STATE_NAMES)))
    status = np.empty(len(a), dtype=np.int8)
    draw_local_parallel_rng(table.kernel_data, cdf, np.ascontiguousarray(a), np.ascontiguousarray(v), states, out,
                         status, scaled)
    return LocalDraws(alpha2=out[:, 0], beta2=out[:, 1], speed_ratio=out[:, 2], omega=out[:, 3:], status=status)


def _vectors(name, value, n=None):
    arr = np.asarray(value, dtype=np.float64)
    if arr.ndim == 1:
        arr = arr[None, :]
    if arr.ndim != 2 or arr.shape[1] != 3 or (n is not None and arr.shape[0] not in (1, n)):
        raise ValueError(f"The '{name}' parameter must have shape (N, 3); got {np.shape(value)}.")
    return arr


def _rows(x, n):
    """``x`` with n rows (its one row repeated if it has one): the kernels read row i of every input."""
    return x if len(x) == n else np.ascontiguousarray(np.broadcast_to(x, (n,) + x.shape[1:]))


def _check_incident(table: SurrogateTable, V, nrm, a, clamp: bool) -> None:
    """The checks of :func:`sample_global` in one parallel pass (:func:`surrogate.kernels.checks.first_faults`):
    raise for the first check, in FAULT_* order, that a row fails, naming that check's first such row.
    ``nrm`` and ``a`` have N rows or one for all."""
    first = first_faults(V, nrm, a, NORMAL_TOLERANCE, *table.alpha1_range, *table.speed_range)
    for fault in np.flatnonzero(first >= 0):
        if not (clamp and fault in (FAULT_ALPHA1_OUTSIDE, FAULT_SPEED_OUTSIDE)):
            raise _fault_error(int(fault), int(first[fault]), table, V, nrm, a)


def _fault_error(fault: int, i: int, table: SurrogateTable, V, nrm, a) -> ValueError:
    """The error for check ``fault`` (surrogate.kernels.checks) failing first at particle i."""
    j, k = min(i, len(nrm) - 1), min(i, len(a) - 1)      # the rows of its normal and of its half-size
    if fault == FAULT_VELOCITY_NOT_FINITE:
        return ValueError(f"The 'velocity' vector at index {i} is not finite: {V[i].tolist()}.")
    if fault == FAULT_NORMAL_NOT_FINITE:
        return ValueError(f"The 'normal' vector at index {j} is not finite: {nrm[j].tolist()}.")
    if fault == FAULT_NORMAL_NOT_UNIT:
        return ValueError(f"The 'normal' at index {j} has length {float(np.linalg.norm(nrm[j]))!r}; wall normals "
                          f"must be unit vectors (|n| - 1 within {NORMAL_TOLERANCE}).")
    if fault == FAULT_VELOCITY_ZERO:
        return ValueError(f"The 'velocity' at index {i} is zero; a particle must move into the wall.")
    vn, speed = float(np.dot(V[i], nrm[j])), float(np.linalg.norm(V[i]))
    if fault == FAULT_NOT_INTO_WALL:
        return ValueError(f"The 'velocity' at index {i} does not move into the wall: V.n = {vn!r} m/s must be < 0.")
    if fault == FAULT_HALF_SIZE:
        return ValueError(f"The 'half_size' at index {k} must be finite and > 0 m; got {float(a[k])!r}.")
    alpha1 = float(np.degrees(np.arctan2(-vn, np.sqrt(max(speed ** 2 - vn ** 2, 0.0)))))
    if fault == FAULT_ALPHA1_NOT_FINITE:
        return _not_finite("alpha1", i, alpha1)
    if fault == FAULT_ALPHA1_OUTSIDE:
        return _outside("alpha1", i, alpha1, table.alpha1_range, "deg")
    if fault == FAULT_SPEED_NOT_FINITE:
        return _not_finite("speed", i, speed)
    return _outside("speed", i, speed, table.speed_range, "m/s")


OUT_NAMES = ("V_out", "Omega_out", "status")


def _outputs(out, n: int, inputs) -> tuple:
    """The (V_out, Omega_out, status) arrays of :func:`sample_global`: new ones, or the ``out`` arrays once
    checked (ValueError naming the first that is not as documented)."""
    if out is None:
        return np.empty((n, 3)), np.empty((n, 3)), np.empty(n, dtype=np.int8)
    if not isinstance(out, tuple) or len(out) != 3:
        raise ValueError(f"The 'out' parameter must be None or a tuple of 3 arrays ({', '.join(OUT_NAMES)}); "
                         f"got {type(out).__name__}.")
    wanted = ((n, 3), np.float64), ((n, 3), np.float64), ((n,), np.int8)
    for i, (name, arr, (shape, dtype)) in enumerate(zip(OUT_NAMES, out, wanted)):
        if not isinstance(arr, np.ndarray) or arr.shape != shape or arr.dtype != dtype:
            got = f"dtype {arr.dtype}, shape {arr.shape}" if isinstance(arr, np.ndarray) else type(arr).__name__
            raise ValueError(f"out[{i}] ({name}) must be an array of dtype {np.dtype(dtype)} and shape {shape}; "
                             f"got {got}.")
        if not (arr.flags.c_contiguous and arr.flags.writeable):
            raise ValueError(f"out[{i}] ({name}) must be C-contiguous and writeable.")
        if any(np.may_share_memory(arr, x) for x in (*inputs, *out[:i])):
            raise ValueError(f"out[{i}] ({name}) shares memory with an input or another output array.")
    return out


def sample_global(table: SurrogateTable, velocity, normal, half_size, shape="ellipsoid", random_state=None,
                  clamp: bool = False, interpolation: str = "scaled", out=None):
    """Reflected velocities and spins of particles hitting walls, in the global frame.

    Parameters
    ----------
    table : a loaded table (:func:`surrogate.load`).
    velocity : (N, 3) incident velocities V⁻, m/s; each must move into its wall (V⁻·n < 0).
    normal : (N, 3) or (3,) wall unit normals pointing into the gas; normals whose
        length differs from 1 by more than 1e-6 are rejected, not normalised.
    half_size : (N,) or scalar, particle half-size a in m (half the largest extent).
    shape : shape name or mix (see :func:`mix_cdf`).
    random_state : int, Generator or None. The uniforms are drawn inside the
        kernel, one xoshiro256+ stream per chunk of particles seeded from it
        (:func:`surrogate.kernels.rng.chunk_states`): the same seed gives the same
        draws whatever the number of threads.
    interpolation : between grid points, ``"scaled"`` (default: the law of a
        neighbouring grid point drawn with its interpolation weight, then moved
        to the incident α1 by the interpolated means and standard deviations and
        to the incident speed by the wall's restitution law) or ``"stochastic"``
        (the neighbour's law as is); see :func:`surrogate.kernels.draw.draw_velocity`
        and docs/VALIDATION.md for how they compare.
    clamp : outside the table's α1 or |V⁻| range, use the law at the nearest grid
        edge instead of raising. Never beyond the physical range: here every
        state that moves into its wall is physical (α1 in (0, 90], |V⁻| > 0).
    out : None (default: new arrays) or a tuple (V_out, Omega_out, status) of
        arrays to write the results into and return: C-contiguous, writeable,
        float64 (N, 3), float64 (N, 3) and int8 (N,), sharing no memory with
        the inputs. A solver calling this every time step can keep them, which
        spares it the allocation and the first touch of fresh pages.

    Returns
    -------
    (V_out (N, 3) m/s, Omega_out (N, 3) rad/s, status (N,) int8); NaN rows for
    trapped particles. Every check runs before anything is written: on a
    ValueError the ``out`` arrays are unchanged.
    """
    V = np.ascontiguousarray(_vectors("velocity", velocity))
    n_particles = V.shape[0]
    nrm = np.ascontiguousarray(_vectors("normal", normal, n_particles))
    a = np.asarray(half_size, dtype=np.float64)
    if a.ndim > 1 or a.size not in (1, n_particles):
        raise ValueError(f"The 'half_size' parameter must be a scalar or have shape ({n_particles},); "
                         f"got {a.shape}.")
    a = np.ascontiguousarray(a.reshape(-1))
    _check_incident(table, V, nrm, a, clamp)
    cdf = mix_cdf(table, shape)
    scaled = _scaled(interpolation)
    V_out, Omega_out, status = _outputs(out, n_particles, (V, nrm, a))
    states = chunk_states(check_random_state(random_state), n_particles)
    rebound_parallel_rng(table.kernel_data, cdf, V, _rows(nrm, n_particles), _rows(a, n_particles), states, V_out, Omega_out,
                      status, scaled)
    return V_out, Omega_out, status
