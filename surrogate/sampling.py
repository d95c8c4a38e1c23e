"""NumPy API of the runtime sampler: validated, vectorised draws of reflected states.

Two entry points:

* :func:`sample_local` — for arrays of incidence angle α1 (deg) and speed |V⁻|
  (m/s), the reflected state (α2, β2, s, Ω⁺a/|V⁻|) in the local frame (wall
  y = 0, normal +Y, impact plane XY);
* :func:`sample_global` — the solver's API: incident velocities, spins and wall
  normals in any global frame in, V⁺ (m/s) and Ω⁺ (rad/s) out; every hit answered,
  by the table where it is valid and by the direct model elsewhere (``method``).

Both accept a shape name or a mix of shapes, ``random_state`` (int, Generator
or None; not ``seed`` as in :mod:`tablegen`, because a Generator is accepted too, as under that name in
NumPy's and scikit-learn's APIs) and ``clamp``: where the table answers every draw (``sample_local``,
``sample_global`` with ``method="table"``) an incident state outside the table's grid
is an error by default; with ``clamp=True`` the dimensionless law at the nearest grid
edge is used (and scaled by the particle's actual speed). ``sample_global``'s default
``method="auto"`` sends such states, and spinning particles (``omega``), to the direct model instead
(:mod:`surrogate.kernels.wall_hit`).
Between grid points the law of a neighbouring grid point is drawn with its
interpolation weight and, by default (``interpolation="scaled"``), moved to the
incident state: in α1 to the interpolated means and standard deviations, in
|V⁻| by the wall's restitution law (:func:`surrogate.kernels.draw.draw_velocity`).
Each particle gets a status: 0 rebounded, 1 trapped (rolling along or
deposited on the wall, drawn with its tabulated probability; its V⁺ and Ω⁺
are NaN, not a made-up rebound), 2 failed (the direct model only: NaN, never dropped).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from data_schema.samples import ALPHA1_RANGE_DEG, SHAPE_NAMES
from data_schema.table import STATE_NAMES
from surrogate.kernels.checks import (FAULT_ALPHA1_NOT_FINITE, FAULT_ALPHA1_OUTSIDE, FAULT_HALF_SIZE,
                                      FAULT_NORMAL_NOT_FINITE, FAULT_NORMAL_NOT_UNIT, FAULT_NOT_INTO_WALL,
                                      FAULT_SPEED_NOT_FINITE, FAULT_SPEED_OUTSIDE, FAULT_VELOCITY_NOT_FINITE,
                                      FAULT_VELOCITY_ZERO, SPEED_MAX, SPEED_MIN, SPIN_SCALE_MAX, first_faults)
from surrogate.kernels.frame import NORMAL_TOLERANCE
from surrogate.kernels.parallel import draw_local_parallel_rng
from surrogate.kernels.rng import chunk_states
from surrogate.kernels.wall_hit import METHOD_AUTO, METHOD_DIRECT, METHOD_TABLE, PATH_DIRECT, rebound_parallel_rng
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


def _check_shape(shape) -> None:
    """ValueError unless ``shape`` has a form :func:`mix_cdf` takes: a name, a dict {name: weight} or a
    sequence of weights, the weights real numbers (a string or None would otherwise be a TypeError)."""
    if isinstance(shape, str):
        return
    if isinstance(shape, dict):
        names, weights = list(shape), list(shape.values())
    elif isinstance(shape, (list, tuple, np.ndarray)):
        names, weights = [], list(np.asarray(shape, dtype=object).ravel())
    else:
        raise ValueError(f"The 'shape' parameter must be a shape name, 'mix', a dict {{name: weight}} or "
                         f"{len(SHAPE_NAMES)} weights; got {shape!r}.")
    for name in names:
        if not isinstance(name, str):
            raise ValueError(f"The 'shape' mix must name shapes by strings ({', '.join(SHAPE_NAMES)}); got {name!r}.")
    for w in weights:
        if isinstance(w, (bool, np.bool_)) or not isinstance(w, (int, float, np.integer, np.floating)):
            raise ValueError(f"The mix weights must be real numbers; got {w!r}.")


def _real(name: str, value) -> np.ndarray:
    """``value`` as float64, refusing complex numbers (NumPy would silently drop their imaginary part)."""
    arr = np.asarray(value)
    if np.iscomplexobj(arr):
        raise ValueError(f"The '{name}' parameter must be real; got complex values (dtype {arr.dtype}).")
    try:
        return np.asarray(arr, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"The '{name}' parameter must be real numbers; got {value!r}.") from None


INTERPOLATIONS = ("stochastic", "scaled")


def _scaled(interpolation: str) -> bool:
    if interpolation not in INTERPOLATIONS:
        raise ValueError(f"The 'interpolation' parameter must be one of {', '.join(INTERPOLATIONS)}; "
                         f"got {interpolation!r}.")
    return interpolation == "scaled"


# physical range of the incident state: (low, high, high included); clamp=True never reaches beyond it. For
# |V⁻|, the range the kernels' arithmetic carries (surrogate.kernels.checks.SPEED_MIN, SPEED_MAX)
PHYSICAL_RANGE = {"alpha1": (*ALPHA1_RANGE_DEG, True), "speed": (SPEED_MIN, SPEED_MAX, True)}


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
    raising; α1 outside (0, 90] deg or |V⁻| outside (1e-150, 1e150] m/s (what
    the arithmetic carries) always raises.
    """
    a, v = np.broadcast_arrays(_real("alpha1", alpha1), _real("speed", speed))
    a, v = a.ravel(), v.ravel()
    _check_range("alpha1", a, table.alpha1_range, clamp, "deg")
    _check_range("speed", v, table.speed_range, clamp, "m/s")
    _check_shape(shape)
    cdf = mix_cdf(table, shape)
    scaled = _scaled(interpolation)
    states = chunk_states(check_random_state(random_state), len(a))
    out = np.empty((len(a), len(STATE_NAMES)))
    status = np.empty(len(a), dtype=np.int8)
    draw_local_parallel_rng(table.kernel_data, cdf, np.ascontiguousarray(a), np.ascontiguousarray(v), states, out,
                         status, scaled)
    return LocalDraws(alpha2=out[:, 0], beta2=out[:, 1], speed_ratio=out[:, 2], omega=out[:, 3:], status=status)


def _vectors(name, value, n=None):
    arr = _real(name, value)
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
    first = first_faults(V, nrm, a, *table.alpha1_range, *table.speed_range)
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
    # hypot, not the sum of squares: no overflow for the huge velocities these messages are about
    vn, speed = float(np.dot(V[i], nrm[j])), math.hypot(*V[i])
    if fault == FAULT_NOT_INTO_WALL:
        return ValueError(f"The 'velocity' at index {i} does not move into the wall: V.n = {vn!r} m/s must be < 0.")
    if fault == FAULT_HALF_SIZE:
        return ValueError(f"The 'half_size' at index {k} must be finite and > 0 m, with |V-|/a <= "
                          f"{SPIN_SCALE_MAX:g} 1/s (the unit of the spin); got {float(a[k])!r} m for "
                          f"|V-| = {speed!r} m/s.")
    alpha1 = math.degrees(math.atan2(-vn, math.hypot(*(V[i] - vn * nrm[j]))))
    if fault == FAULT_ALPHA1_NOT_FINITE:
        return _not_finite("alpha1", i, alpha1)
    if fault == FAULT_ALPHA1_OUTSIDE:
        return _outside("alpha1", i, alpha1, table.alpha1_range, "deg")
    if fault == FAULT_SPEED_NOT_FINITE:
        return ValueError(f"The 'speed' |V-| = {speed!r} m/s at index {i} is outside [{SPEED_MIN:g}, {SPEED_MAX:g}] "
                          f"m/s, the range the sampler's arithmetic carries.")
    return _outside("speed", i, speed, table.speed_range, "m/s")


OUT_NAMES = ("V_out", "Omega_out", "status", "path")


def _outputs(out, n: int, inputs, count: int = 3) -> tuple:
    """The first ``count`` of the (V_out, Omega_out, status, path) arrays of :func:`sample_global`: new ones,
    or the ``out`` arrays once checked (ValueError naming the first that is not as documented)."""
    wanted = ((n, 3), np.float64), ((n, 3), np.float64), ((n,), np.int8), ((n,), np.int8)
    if out is None:
        return tuple(np.empty(shape, dtype=dtype) for shape, dtype in wanted[:count])
    if not isinstance(out, tuple) or len(out) != count:
        raise ValueError(f"The 'out' parameter must be None or a tuple of {count} arrays "
                         f"({', '.join(OUT_NAMES[:count])}); got {type(out).__name__}"
                         f"{f' of {len(out)}' if isinstance(out, tuple) else ''}.")
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


METHODS = {"auto": METHOD_AUTO, "table": METHOD_TABLE, "direct": METHOD_DIRECT}


def method_code(method) -> int:
    """The kernels' code (METHOD_*) of a method name: "auto", "table" or "direct"."""
    if not isinstance(method, str) or method not in METHODS:
        raise ValueError(f"The 'method' parameter must be one of {', '.join(METHODS)}; got {method!r}.")
    return METHODS[method]


def _omega(omega, n: int) -> np.ndarray:
    """Ω⁻ as (N, 3) or (1, 3) float64 (None: one zero row); ValueError for another shape or a non-finite row."""
    if omega is None:
        return np.zeros((1, 3))
    W = _real("omega", omega)
    if W.ndim == 1 and W.shape == (3,):
        W = W[None, :]
    if W.ndim != 2 or W.shape[1] != 3 or W.shape[0] not in (1, n):
        raise ValueError(f"The 'omega' parameter must have shape ({n}, 3) or (3,) (rad/s); got {W.shape}.")
    bad = np.flatnonzero(~np.isfinite(W).all(axis=1))
    if bad.size:
        raise ValueError(f"The 'omega' vector at index {bad[0]} is not finite: {W[bad[0]].tolist()} rad/s.")
    return np.ascontiguousarray(W)


def _check_direct_parameters(table: SurrogateTable, path: np.ndarray, V, W, a) -> None:
    """ValueError if a hit needs the direct model (path PATH_DIRECT) and ``table`` does not record its
    parameters."""
    if table.direct_parameters is not None:
        return
    needs = np.flatnonzero(path == PATH_DIRECT)
    if needs.size:
        i = int(needs[0])
        spin = float(np.linalg.norm(W[min(i, len(W) - 1)]) * a[min(i, len(a) - 1)] / np.linalg.norm(V[i]))
        raise ValueError(f"The hit at index {i} (|Omega-|a/|V-| = {spin!r}) needs the direct model, whose parameters "
                         f"the table {table.path} does not record (built before tables recorded them); rebuild "
                         f"it with this version, or pass method='table'.")


def sample_global(table: SurrogateTable, velocity, normal, half_size, shape="ellipsoid", random_state=None,
                  clamp: bool = False, interpolation: str = "scaled", out=None, *, omega=None, method: str = "auto",
                  return_path: bool = False):
    """Reflected velocities and spins of particles hitting walls, in the global frame: every hit answered, by
    the table where it is valid and by the direct model elsewhere.

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
        (:func:`surrogate.kernels.rng.chunk_states`), U_PER_DRAW = 13 per hit whatever
        path answers it: the same seed gives the same bits whatever the number of threads.
    interpolation : between grid points, ``"scaled"`` (default: the law of a
        neighbouring grid point drawn with its interpolation weight, then moved
        to the incident α1 by the interpolated means and standard deviations and
        to the incident speed by the wall's restitution law) or ``"stochastic"``
        (the neighbour's law as is); see :func:`surrogate.kernels.draw.draw_velocity`
        and docs/VALIDATION.md for how they compare.
    clamp : with ``method="table"``, outside the table's α1 or |V⁻| range use the law
        at the nearest grid edge instead of raising. Never beyond the physical range: here every
        state that moves into its wall is physical (α1 in (0, 90]), with |V⁻| in
        [1e-150, 1e150] m/s (what the arithmetic carries). The other methods send such states
        to the direct model.
    out : None (default: new arrays) or a tuple (V_out, Omega_out, status) of
        arrays to write the results into and return (with ``return_path``, a fourth: path): C-contiguous,
        writeable, float64 (N, 3), float64 (N, 3), int8 (N,) (and int8 (N,)), sharing no memory with
        the inputs. A solver calling this every time step can keep them, which
        spares it the allocation and the first touch of fresh pages.
    omega : None (default: no spin) or (N, 3) or (3,) incident angular velocities Ω⁻, rad/s, in the frame of
        ``velocity``.
    method : ``"auto"`` (default): the table iff |Ω⁻|a/|V⁻| ≤ :data:`surrogate.SPIN_TOLERANCE` and α1, |V⁻|
        lie in the table's grid ranges (inclusive), the direct model (:func:`surrogate.sample_direct`'s,
        microseconds per hit) for every other hit; ``"table"``: the table for every hit, Ω⁻ ignored (the
        behaviour before spin was taken into account; ``clamp`` applies); ``"direct"``: the direct model
        for every hit. With Ω⁻ zero and every state in the grid, ``"auto"`` gives ``"table"``'s bits.
    return_path : also return which path answered each hit (0 the table, 1 the direct model;
        :data:`surrogate.kernels.PATH_TABLE`, :data:`surrogate.kernels.PATH_DIRECT`).

    Returns
    -------
    (V_out (N, 3) m/s, Omega_out (N, 3) rad/s, status (N,) int8), and path (N,) int8 with ``return_path``.
    Status 0 rebounded, 1 trapped, 2 failed (the direct model only: a collision solve or a contact search
    failed; rare, never dropped: count them with ``status == surrogate.STATUS_FAILED``); NaN rows unless
    rebounded. Every check runs before anything is written: on a ValueError the ``out`` arrays are unchanged.
    The direct model needs ``table.direct_parameters``: with a table that lacks them, a hit the model must
    answer is a ValueError.
    """
    V = np.ascontiguousarray(_vectors("velocity", velocity))
    n_particles = V.shape[0]
    nrm = np.ascontiguousarray(_vectors("normal", normal, n_particles))
    a = _real("half_size", half_size)
    if a.ndim > 1 or a.size not in (1, n_particles):
        raise ValueError(f"The 'half_size' parameter must be a scalar or have shape ({n_particles},); "
                         f"got {a.shape}.")
    a = np.ascontiguousarray(a.reshape(-1))
    code = method_code(method)
    W = _omega(omega, n_particles)
    # the grid's range is an error only where the table must answer every hit
    _check_incident(table, V, nrm, a, clamp or code != METHOD_TABLE)
    _check_shape(shape)
    cdf = mix_cdf(table, shape)
    scaled = _scaled(interpolation)
    outputs = _outputs(out, n_particles, (V, nrm, a, W), 4 if return_path else 3)
    old_table = table.direct_parameters is None and code != METHOD_TABLE
    # a table without the model's parameters: draw into fresh arrays, so that ``out`` stays unchanged if a hit
    # needs the model
    V_out, Omega_out, status, path = (_outputs(None, n_particles, (), 4) if old_table
                                      else (*outputs[:3], outputs[3] if return_path else np.empty(n_particles, np.int8)))
    params = np.zeros(0) if table.direct_parameters is None else table.direct_parameters
    states = chunk_states(check_random_state(random_state), n_particles)
    rebound_parallel_rng(table.kernel_data, params, table.model_shapes, cdf, np.zeros(0, np.int64), V, W,
                         _rows(nrm, n_particles), _rows(a, n_particles), states, code, V_out, Omega_out, status, path,
                         scaled)
    if old_table:
        _check_direct_parameters(table, path, V, W, a)
        for target, result in zip(outputs, (V_out, Omega_out, status, path)):
            target[...] = result
    return tuple(outputs)
