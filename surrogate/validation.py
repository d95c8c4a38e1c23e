"""The checks at the boundary of the NumPy API, in one place (in the manner of scikit-learn's
``utils/validation.py``).

Every public function of :mod:`surrogate`, and the ``surrogate`` command line, turns its arguments into
the arrays the kernels take through these functions, so that the same bad value gets the same message
from every entry point. Each ``check_*`` returns the value in the form the kernels take (float64,
C-contiguous, a kernel code) or raises a one-line ValueError naming the parameter, the value (with its
index) and the allowed range. Nothing here draws or writes: a caller runs every check before the kernels.

The incident states are checked by the kernels in one parallel pass
(:func:`surrogate.kernels.checks.first_faults`, which finds the first row failing each FAULT_* check);
:func:`fault_error` words what it finds.

Units and frames: velocities in m/s, angular velocities in rad/s, half-sizes in m, all in the caller's
frame; α1 in degrees from the wall.
"""

from __future__ import annotations

import math

import numpy as np

from data_schema.samples import ALPHA1_RANGE_DEG, SHAPE_NAMES
from direct_model.wall import MAX_ROUGHNESS_DEG, check_roughness as check_roughness_value
from surrogate.kernels.checks import (FAULT_ALPHA1_NOT_FINITE, FAULT_ALPHA1_OUTSIDE, FAULT_HALF_SIZE,
                                      FAULT_NORMAL_NOT_FINITE, FAULT_NORMAL_NOT_UNIT, FAULT_NOT_INTO_WALL,
                                      FAULT_SPEED_NOT_FINITE, FAULT_SPEED_OUTSIDE, FAULT_VELOCITY_NOT_FINITE,
                                      FAULT_VELOCITY_ZERO, SPEED_MAX, SPEED_MIN, SPIN_SCALE_MAX, first_faults)
from surrogate.kernels.frame import NORMAL_TOLERANCE
from surrogate.kernels.hit import REBOUNDS_ARRAYS, Rebounds, empty_rebounds
from surrogate.kernels.layout import frozen
from surrogate.kernels.wall_hit import METHOD_AUTO, METHOD_DIRECT, METHOD_TABLE

WEIGHT_SUM_TOLERANCE = 1e-9     # |Σ weights − 1| allowed for a mix
# physical range of a local incident state: (low, high, high included); clamp=True never reaches beyond it. For
# |V⁻|, the range the kernels' arithmetic carries (surrogate.kernels.checks.SPEED_MIN, SPEED_MAX)
PHYSICAL_RANGE = {"alpha1": (*ALPHA1_RANGE_DEG, True), "speed": (SPEED_MIN, SPEED_MAX, True)}
METHODS = {"auto": METHOD_AUTO, "table": METHOD_TABLE, "direct": METHOD_DIRECT}
INTERPOLATIONS = ("stochastic", "scaled")


# -- numbers and arrays ------------------------------------------------------------------------------

def check_random_state(random_state) -> np.random.Generator:
    """A Generator from an int seed ≥ 0, a Generator (used as is) or None (fresh entropy)."""
    if isinstance(random_state, np.random.Generator):
        return random_state
    if random_state is None or (isinstance(random_state, (int, np.integer)) and not isinstance(random_state, bool)
                                and random_state >= 0):
        return np.random.default_rng(random_state)
    raise ValueError(f"The 'random_state' parameter must be a non-negative int, a numpy Generator or None; "
                     f"got {random_state!r}.")


def check_real(name: str, value) -> np.ndarray:
    """``value`` as float64, refusing complex numbers (NumPy would silently drop their imaginary part) and
    what is not a number."""
    arr = np.asarray(value)
    if np.iscomplexobj(arr):
        raise ValueError(f"The '{name}' parameter must be real; got complex values (dtype {arr.dtype}).")
    try:
        return np.asarray(arr, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"The '{name}' parameter must be real numbers; got {value!r}.") from None


def check_vectors(name: str, value, n: int | None = None) -> np.ndarray:
    """(N, 3) float64, C-contiguous, from (N, 3) or (3,) (one row); with ``n``, N must be n or 1."""
    arr = check_real(name, value)
    if arr.ndim == 1:
        arr = arr[None, :]
    if arr.ndim != 2 or arr.shape[1] != 3 or (n is not None and arr.shape[0] not in (1, n)):
        raise ValueError(f"The '{name}' parameter must have shape (N, 3); got {np.shape(value)}.")
    return np.ascontiguousarray(arr)


def check_half_size(half_size, n: int) -> np.ndarray:
    """The half-sizes a (m) as (n,) or (1,) float64 from (n,) or a scalar (their range: :func:`check_incident`)."""
    a = check_real("half_size", half_size)
    if a.ndim > 1 or a.size not in (1, n):
        raise ValueError(f"The 'half_size' parameter must be a scalar or have shape ({n},); got {a.shape}.")
    return np.ascontiguousarray(a.reshape(-1))


def check_omega(omega, n: int) -> np.ndarray:
    """Ω⁻ (rad/s) as (n, 3) or (1, 3) float64 from (n, 3), (3,) or None (no spin: one zero row); ValueError
    for another shape or a non-finite row."""
    if omega is None:
        return np.zeros((1, 3))
    W = check_real("omega", omega)
    if W.ndim == 1 and W.shape == (3,):
        W = W[None, :]
    if W.ndim != 2 or W.shape[1] != 3 or W.shape[0] not in (1, n):
        raise ValueError(f"The 'omega' parameter must have shape ({n}, 3) or (3,) (rad/s); got {W.shape}.")
    bad = np.flatnonzero(~np.isfinite(W).all(axis=1))
    if bad.size:
        raise ValueError(f"The 'omega' vector at index {bad[0]} is not finite: {W[bad[0]].tolist()}.")
    return np.ascontiguousarray(W)


def as_rows(x: np.ndarray, n: int) -> np.ndarray:
    """``x`` with n rows (its one row repeated if it has one): the kernels read row i of every input."""
    return x if len(x) == n else np.ascontiguousarray(np.broadcast_to(x, (n,) + x.shape[1:]))


# -- shapes ------------------------------------------------------------------------------------------

def check_shape(table, shape, n: int | None = None) -> tuple:
    """(mix_cdf, shapes) of ``shape`` for ``table``: the cumulative weights of the mix (:func:`mix_cdf`) and
    the per-particle shape indices in the table's order, (n,) int64, or (0,) when every particle's shape is
    drawn from the mix.

    ``shape`` is a shape name, ``"mix"``, a dict {name: weight}, a sequence of weights (ellipsoid, prism,
    cut_prism, tetrahedron) or, with ``n``, one shape name per particle ((n,) strings; the mix returned is
    then the table's equal one, which no particle uses).
    """
    if isinstance(shape, np.ndarray) and shape.ndim == 0:
        shape = shape.item()
    if _per_particle(shape):
        names = np.asarray(shape, dtype=object).reshape(-1)
        if n is None:
            raise ValueError(f"The 'shape' parameter must be a shape name or a mix here (one shape name per particle "
                             f"is for sample_global and sample_direct); got {names.size} names.")
        if np.ndim(shape) != 1 or len(names) != n:
            raise ValueError(f"The 'shape' parameter must be one shape name per particle, shape ({n},); got "
                             f"{np.shape(shape)}.")
        return mix_cdf(table, "mix"), _shape_indices(table, names)
    _check_mix_form(shape)
    return mix_cdf(table, shape), np.zeros(0, dtype=np.int64)


def _per_particle(shape) -> bool:
    """Whether ``shape`` is a sequence of names (rather than one name, a dict or weights)."""
    if isinstance(shape, (str, dict)) or not isinstance(shape, (list, tuple, np.ndarray)):
        return False
    values = np.asarray(shape, dtype=object).reshape(-1)
    return values.size > 0 and all(isinstance(s, str) for s in values)


def _shape_indices(table, names) -> np.ndarray:
    """(n,) int64: the table's index of each name; ValueError naming the first unknown or absent one."""
    index = {name: k for k, name in enumerate(table.shapes)}
    for i, name in enumerate(names):
        if name not in SHAPE_NAMES and name not in index:
            raise ValueError(f"The 'shape' at index {i} must be one of the table's shapes ({', '.join(table.shapes)}) "
                             f"or a built-in ({', '.join(SHAPE_NAMES)}); got {name!r}.")
        if name not in index:
            raise ValueError(f"The 'shape' at index {i}, {name!r}, is not in the table {table.path} (it holds "
                             f"{', '.join(table.shapes)}).")
    return np.array([index[name] for name in names], dtype=np.int64)


def _check_mix_form(shape) -> None:
    """ValueError unless ``shape`` has a form :func:`mix_cdf` takes: a name, a dict {name: weight} or a
    sequence of weights, the weights real numbers (a string or None would otherwise be a TypeError)."""
    if isinstance(shape, str):
        return
    if isinstance(shape, dict):
        names, weights = list(shape), list(shape.values())
    elif isinstance(shape, (list, tuple, np.ndarray)):
        names, weights = [], list(np.asarray(shape, dtype=object).ravel())
    else:
        raise ValueError(f"The 'shape' parameter must be a shape name, 'mix', a dict {{name: weight}}, "
                         f"{len(SHAPE_NAMES)} weights or one shape name per particle; got {shape!r}.")
    for name in names:
        if not isinstance(name, str):
            raise ValueError(f"The 'shape' mix must name shapes by strings ({', '.join(SHAPE_NAMES)}); got {name!r}.")
    for w in weights:
        if isinstance(w, (bool, np.bool_)) or not isinstance(w, (int, float, np.integer, np.floating)):
            raise ValueError(f"The mix weights must be real numbers; got {w!r}.")


def mix_cdf(table, shape) -> np.ndarray:
    """Cumulative shape weights in the table's shape order, as the kernels take them.

    ``shape`` is a shape name, ``"mix"`` (equal weights over the table's shapes), a dict {shape: weight},
    or a sequence of four weights in the order ellipsoid, prism, cut_prism, tetrahedron. Weights must be
    non-negative and sum to 1 (within WEIGHT_SUM_TOLERANCE); a shape with positive weight must be in the
    table.
    """
    _check_mix_form(shape)
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
        if name not in SHAPE_NAMES and name not in table.shapes:
            raise ValueError(f"The 'shape' parameter must name one of the table's shapes ({', '.join(table.shapes)}) "
                             f"or a built-in ({', '.join(SHAPE_NAMES)}); got {name!r}.")
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


# -- options -----------------------------------------------------------------------------------------

def check_grain_key(grain_key, n: int) -> np.ndarray:
    """The grain keys as the kernels take them: (n,) int64 (:mod:`surrogate.kernels.grain`), or (0,) for None
    (no keys). ``grain_key`` is one integer ≥ 0 per particle ((n,); an integer scalar for all n), below 2**63;
    a float, bool or object array, a negative or too large value, another length is a ValueError naming it."""
    if grain_key is None:
        return np.zeros(0, dtype=np.int64)
    if isinstance(grain_key, (bool, float, np.bool_, np.floating)):     # a scalar: name its value
        raise ValueError(f"The 'grain_key' parameter must be integers in [0, 2**63), one per particle; got "
                         f"{grain_key!r} ({type(grain_key).__name__}).")
    keys = np.asarray(grain_key)
    if keys.dtype.kind not in "iu":
        raise ValueError(f"The 'grain_key' parameter must be integers in [0, 2**63), one per particle; got an array "
                         f"of dtype {keys.dtype} (a float, bool or object key is refused, not rounded).")
    if keys.ndim == 0:
        keys = np.full(n, keys, dtype=keys.dtype)
    if keys.shape != (n,):
        raise ValueError(f"The 'grain_key' parameter must be one key per particle, shape ({n},); got {keys.shape}.")
    bad = np.flatnonzero(keys < 0) if keys.dtype.kind == "i" else np.flatnonzero(keys > np.iinfo(np.int64).max)
    if bad.size:
        raise ValueError(f"The 'grain_key' at index {bad[0]} must be in [0, 2**63); got {keys[bad[0]]}.")
    return np.ascontiguousarray(keys, dtype=np.int64)


def check_method(method) -> int:
    """The kernels' code (METHOD_*) of a method name: "auto", "table" or "direct"."""
    if not isinstance(method, str) or method not in METHODS:
        raise ValueError(f"The 'method' parameter must be one of {', '.join(METHODS)}; got {method!r}.")
    return METHODS[method]


def check_roughness(table, roughness_deg) -> float:
    """The roughness Δγ a call applies, degrees: the table's wall's (``table.wall.roughness_deg``) for None, else
    ``roughness_deg``, a number in [0, MAX_ROUGHNESS_DEG] (0: a smooth wall)."""
    if roughness_deg is None:
        return table.wall.roughness_deg
    try:
        return check_roughness_value(roughness_deg)       # the wall record's own check: one set of allowed values
    except ValueError:
        raise ValueError(f"The 'roughness_deg' parameter must be None (the table's wall's) or a number in "
                         f"[0, {MAX_ROUGHNESS_DEG:g}] degrees; got {roughness_deg!r}.") from None


def check_interpolation(interpolation) -> bool:
    """The kernels' ``scaled`` flag of an interpolation name: "scaled" (True) or "stochastic" (False)."""
    if not isinstance(interpolation, str) or interpolation not in INTERPOLATIONS:
        raise ValueError(f"The 'interpolation' parameter must be one of {', '.join(INTERPOLATIONS)}; "
                         f"got {interpolation!r}.")
    return interpolation == "scaled"


def check_out(out, n: int, inputs) -> Rebounds:
    """The :class:`surrogate.kernels.hit.Rebounds` a call over n hits fills: a new one, or ``out`` once checked
    (ValueError naming the first field that is not an array of the dtype and shape of
    :func:`surrogate.kernels.hit.empty_rebounds`, C-contiguous, writeable and sharing no memory with ``inputs``
    or another field)."""
    if out is None:
        return empty_rebounds(n)
    if not isinstance(out, Rebounds):
        raise ValueError(f"The 'out' parameter must be None or a surrogate.Rebounds "
                         f"(surrogate.empty_rebounds({n})); got {type(out).__name__}.")
    for i, (name, (dtype, tail)) in enumerate(REBOUNDS_ARRAYS.items()):
        arr, shape = out[i], (n, *tail)
        if not isinstance(arr, np.ndarray) or arr.shape != shape or arr.dtype != dtype:
            got = f"dtype {arr.dtype}, shape {arr.shape}" if isinstance(arr, np.ndarray) else type(arr).__name__
            raise ValueError(f"out.{name} must be an array of dtype {np.dtype(dtype)} and shape {shape}; "
                             f"got {got}.")
        if not (arr.flags.c_contiguous and arr.flags.writeable):
            raise ValueError(f"out.{name} must be C-contiguous and writeable.")
        if any(np.may_share_memory(arr, x) for x in (*inputs, *out[:i])):
            raise ValueError(f"out.{name} shares memory with an input or another field of out.")
    return out


# -- incident states ---------------------------------------------------------------------------------

def check_local_states(table, alpha1, speed, clamp: bool) -> tuple:
    """(α1 deg, |V⁻| m/s) as two flat float64 arrays, ``alpha1`` and ``speed`` broadcast together.

    Non-finite values and values outside the physical range (PHYSICAL_RANGE) are always an error; values
    outside the table's range unless ``clamp`` (the kernels then use the law of the nearest grid edge,
    applied to the particle's actual speed).
    """
    a, v = np.broadcast_arrays(check_real("alpha1", alpha1), check_real("speed", speed))
    a, v = np.ascontiguousarray(a.ravel()), np.ascontiguousarray(v.ravel())
    _check_range("alpha1", a, table.alpha1_range, clamp, "deg")
    _check_range("speed", v, table.speed_range, clamp, "m/s")
    return a, v


def _check_range(name, values, bounds, clamp, units) -> None:
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


def check_incident(table, V, nrm, a, grid: bool) -> None:
    """The incident states (V (N, 3) m/s, unit normals ``nrm`` and half-sizes ``a`` (m) with N rows or one
    for all) in one parallel pass (:func:`surrogate.kernels.checks.first_faults`): raise for the first
    check, in FAULT_* order, that a row fails, naming that check's first such row (:func:`fault_error`).
    With ``grid``, an α1 or |V⁻| outside the table's grid ranges is an error too."""
    first = first_faults(V, nrm, a, *table.alpha1_range, *table.speed_range)
    for fault in np.flatnonzero(first >= 0):
        if grid or fault not in (FAULT_ALPHA1_OUTSIDE, FAULT_SPEED_OUTSIDE):
            raise fault_error(int(fault), int(first[fault]), table, V, nrm, a)


def fault_error(fault: int, i: int, table, V, nrm, a) -> ValueError:
    """The error for check ``fault`` (FAULT_* of :mod:`surrogate.kernels.checks`) failing first at particle i."""
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

