"""Batch API of the direct model: n particles at one incident state (docs/model.md §5–6).

Reproducibility: random inputs are drawn in NumPy, chunk by chunk, chunk k
from ``SeedSequence(seed, spawn_key=(k,))`` with a fixed chunk size, and the
kernel is deterministic per particle. The result for a seed is therefore
bit-identical whatever the number of threads, and the first m particles of a
run of n > m equal a run of m.
"""

from __future__ import annotations

import math
import secrets
import warnings

import numpy as np

from data_schema.common import package_version
from data_schema.samples import ALPHA1_RANGE_TEXT, SampleSet, alpha1_is_physical
from direct_model.body_rebound import body_rebound_batch
from direct_model.registry import FAMILIES, ConvexPolyhedron, Ellipsoid, built_in_shape
from direct_model.shape_arrays import family_shape_arrays, shape_arrays
from direct_model.shapes import (
    DEFAULT_KAPPA, MIX, SHAPES, AspectRatioLaw, check_kappa, second_moment_factors,
)
from direct_model.wall import CORUNDUM_ON_STEEL, Wall

CHUNK_SIZE = 16384                  # particles drawn at a time: fixed, so a seed gives the same bits for any n
DEFAULT_N_MAX = 1000                # collisions before a particle counts as trapped
DEFAULT_CONTACT_TOL = 1e-10         # contact distance, units of a
DEFAULT_SET_TOL = 1e-9              # points this close to the lowest share a contact, units of a
DEFAULT_MAX_STEPS = 100_000         # contact-search steps per flight before a particle fails


def check_alpha1(alpha1) -> float:
    """Incidence angle in degrees from the wall, in the physical range (0, 90] (ALPHA1_RANGE_DEG)."""
    try:
        value = float(alpha1)
    except (TypeError, ValueError):
        raise ValueError(f"The 'alpha1' parameter must be a number in {ALPHA1_RANGE_TEXT} degrees; "
                         f"got {alpha1!r}.") from None
    if not alpha1_is_physical(value):
        raise ValueError(f"The 'alpha1' parameter must be in {ALPHA1_RANGE_TEXT} degrees; got {value!r}.")
    return value


def check_speed(speed) -> float:
    """Incident speed in m/s: finite and > 0."""
    try:
        value = float(speed)
    except (TypeError, ValueError):
        raise ValueError(f"The 'speed' parameter must be a finite number > 0 m/s; got {speed!r}.") from None
    if not (math.isfinite(value) and value > 0.0):
        raise ValueError(f"The 'speed' parameter must be finite and > 0 m/s; got {value!r}.")
    return value


def _check_count(name, value, minimum) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < minimum:
        shown = int(value) if isinstance(value, np.integer) else value
        raise ValueError(f"The '{name}' parameter must be an integer >= {minimum}; got {shown!r}.")
    return int(value)


def _check_positive(name, value) -> float:
    value_f = float(value)
    if not (math.isfinite(value_f) and value_f > 0.0):
        raise ValueError(f"The '{name}' parameter must be finite and > 0; got {value_f!r}.")
    return value_f


def check_seed(seed) -> int:
    """A non-negative integer seed; None draws a fresh one (recorded with the result)."""
    if seed is None:
        return secrets.randbits(63)
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or not 0 <= seed < 2 ** 63:
        raise ValueError(f"The 'seed' parameter must be an integer in [0, 2**63) or None; got {seed!r}.")
    return int(seed)


def incident_velocity(alpha1: float, speed: float) -> np.ndarray:
    """V⁻ = |V⁻| (cos α1, −sin α1, 0) in m/s, α1 in degrees (lab frame)."""
    a = math.radians(alpha1)
    return np.array([speed * math.cos(a), -speed * math.sin(a), 0.0])


def draw_inputs(rng: np.random.Generator, m: int, code: int, both_hands: np.ndarray, aspect: AspectRatioLaw):
    """Random inputs of m particles: shape indices, (b/a, c/b), hands, quaternions.

    ``code``: every particle's shape index in the batch's shape arrays, or −1 for each one's drawn from the
    four families with weight ¼ (``mix``). The orientation is uniform on SO(3) (normalised 4-D Gaussian
    quaternion). The hand of a shape drawn in both hands (``both_hands[index]``, the tetrahedron's) is ±1 with
    probability ½ each; other shapes get +1. The same number of variates is drawn whatever the shape.
    """
    quats = rng.standard_normal((m, 4))
    ratios = aspect.sample(rng, m)
    hands = np.where(rng.random(m) < 0.5, 1, -1).astype(np.int8)
    mixed = rng.integers(0, len(SHAPES), m).astype(np.int8)
    codes = mixed if code < 0 else np.full(m, code, dtype=np.int8)
    hands[both_hands[codes] == 0] = 1
    return codes, ratios, hands, quats


def simulate(shape, alpha1: float, speed: float, n: int, seed: int | None = None,
             omega_in=(0.0, 0.0, 0.0), *, kappa: float = DEFAULT_KAPPA,
             aspect: AspectRatioLaw = AspectRatioLaw(), wall: Wall = CORUNDUM_ON_STEEL,
             n_max: int = DEFAULT_N_MAX, contact_tol: float = DEFAULT_CONTACT_TOL, set_tol: float = DEFAULT_SET_TOL,
             max_steps: int = DEFAULT_MAX_STEPS, progress=None) -> SampleSet:
    """Simulate the rebound of ``n`` particles at one incident state.

    Parameters
    ----------
    shape : a built-in family's name (``"ellipsoid"``, ``"prism"``, ``"cut_prism"``, ``"tetrahedron"``: any
        of :data:`direct_model.registry.FAMILIES`) or ``"mix"`` (each particle's shape drawn from the paper's
        four with weight ¼); or a shape's record (:mod:`direct_model.registry`, a user's grain say), stretched
        per particle by its own law (``aspect`` and ``kappa`` are the families'), in both hands if it says so.
    alpha1 : incidence angle from the wall, degrees, in (0, 90].
    speed : incident speed |V⁻|, m/s, > 0 (outside the speeds the wall law holds over, its
        ``speed_range_m_s``, a warning is issued: the default law's are 50–300 m/s).
    n : number of particles, ≥ 1.
    seed : integer seed; None draws one, recorded in the result.
    omega_in : incident angular velocity Ω⁻ a/|V⁻|, lab frame (3 numbers).
    kappa : cut-prism truncation fraction in [0, 1).
    aspect : distribution of b/a and c/b.
    wall : the wall law, a :class:`direct_model.wall.Wall` (WallMaterial, TabulatedWall).
    n_max : collisions allowed before a particle counts as trapped, ≥ 1.
    contact_tol : contact distance, units of a (> 0).
    set_tol : points within this of the lowest share a contact, units of a (> 0).
    max_steps : contact-search steps allowed per flight before ``failed``.
    progress : None, or a callable given the number of particles finished after each chunk
        (``tablegen.simulate`` passes its progress bar's update).

    Returns
    -------
    SampleSet with V⁺ (m/s), Ω⁺a/|V⁻| (lab frame), collision counts, status and
    per-particle extras (shape code, hand, b/a, c/b, E_Ω⁺/E_V⁻, search steps, the work of the rebound on the wall
    per unit particle mass W_n and W_t in m²/s², docs/model.md §4.7: ``wall_work_normal``, ``wall_work_tangential``,
    summed up to the trap or the failure).
    """
    record = shape if isinstance(shape, (Ellipsoid, ConvexPolyhedron)) else None
    if record is None and not (isinstance(shape, str) and (shape == MIX or shape in FAMILIES)):
        raise ValueError(f"The 'shape' parameter must be one of {', '.join(FAMILIES)}, {MIX!r} or a shape's record; "
                         f"got {shape!r}.")
    alpha1 = check_alpha1(alpha1)
    speed = check_speed(speed)
    n = _check_count("n", n, 1)
    seed = check_seed(seed)
    kappa = check_kappa(kappa)
    n_max = _check_count("n_max", n_max, 1)
    max_steps = _check_count("max_steps", max_steps, 1)
    contact_tol = _check_positive("contact_tol", contact_tol)
    set_tol = _check_positive("set_tol", set_tol)
    omega_arr = np.asarray(omega_in, dtype=float)
    if omega_arr.shape != (3,) or not np.all(np.isfinite(omega_arr)):
        raise ValueError(f"The 'omega_in' parameter must be 3 finite numbers; got {omega_in!r}.")
    if wall.outside_speed_range(speed):
        warnings.warn(f"speed {speed} m/s is outside {wall.speed_range_text()}, where the wall law {wall.name!r} "
                      f"holds (its speed_range_m_s)", stacklevel=2)

    V0 = incident_velocity(alpha1, speed)
    W0 = omega_arr * speed                      # (m/s)/a
    if record is None and shape not in SHAPES + (MIX,):
        record = built_in_shape(shape, kappa, aspect)       # a family after the paper's four: its record
    if record is None:
        arrays = family_shape_arrays(kappa, aspect, second_moment_factors(kappa))
        code, name, law = (-1 if shape == MIX else SHAPES.index(shape)), shape, aspect
    else:
        arrays, code, name, law = shape_arrays([record]), 0, record.name, record.aspect
        # a record of fixed proportions ignores the ratios; they are drawn all the same (the same variates)
        aspect = law or aspect
    wall_arr = wall.as_array()
    out_V = np.empty((n, 3))
    out_W = np.empty((n, 3))
    out_erot = np.empty(n)
    out_ncoll = np.empty(n, dtype=np.int32)
    out_status = np.empty(n, dtype=np.int8)
    out_failure = np.empty(n, dtype=np.int8)
    out_steps = np.empty(n, dtype=np.int32)
    out_multi = np.empty(n, dtype=np.int32)
    out_work_n = np.empty(n)
    out_work_t = np.empty(n)
    codes = np.empty(n, dtype=np.int8)
    hands = np.empty(n, dtype=np.int8)
    ratios = np.empty((n, 2))

    for k, start in enumerate(range(0, n, CHUNK_SIZE)):
        stop = min(start + CHUNK_SIZE, n)
        rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(k,)))
        c, r, hnd, q = draw_inputs(rng, CHUNK_SIZE, code, arrays.both_hands, aspect)
        m = stop - start
        codes[start:stop], ratios[start:stop], hands[start:stop] = c[:m], r[:m], hnd[:m]
        sl = slice(start, stop)
        body_rebound_batch(arrays, codes[sl], ratios[sl], hands[sl], q[:m], V0, W0, wall_arr, n_max, contact_tol,
                           set_tol, max_steps, out_V[sl], out_W[sl], out_erot[sl], out_ncoll[sl], out_status[sl],
                           out_failure[sl], out_steps[sl], out_multi[sl], out_work_n[sl], out_work_t[sl])
        if progress is not None:
            progress(m)

    return SampleSet(
        velocity=out_V, omega=out_W / speed, n_collisions=out_ncoll, status=out_status,
        alpha1=alpha1, speed=speed, shape=name, seed=seed, producer="tablegen simulate",
        extra={"shape_code": codes, "hand": hands, "b_over_a": ratios[:, 0], "c_over_b": ratios[:, 1],
               "e_rot_ratio": out_erot / (0.5 * speed ** 2), "n_search_steps": out_steps,
               "n_multiple_roots": out_multi, "failure_reason": out_failure,
               "wall_work_normal": out_work_n, "wall_work_tangential": out_work_t},
        provenance={"omega_in": omega_arr, "kappa": kappa, "n_max": n_max,
                    "contact_tol": contact_tol, "set_tol": set_tol, "max_steps": max_steps,
                    **dict(zip(("aspect_mean", "aspect_sd", "aspect_low", "aspect_high"),
                               (law.mean, law.sd, law.low, law.high) if law else (np.nan,) * 4)),
                    "wall_law": wall.name, "wall_family": wall.family,
                    **{f"wall_{name}": value for name, value in (*wall.parameters().items(), *wall.arrays().items())},
                    "chunk_size": CHUNK_SIZE, "package_version": package_version()})
