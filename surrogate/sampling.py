"""NumPy API of the runtime sampler: validated, vectorised draws of reflected states.

Three entry points:

* :func:`sample_global` — the solver's API: incident velocities, spins and wall
  normals in any global frame in, a record of every hit out (:class:`Rebounds`: V⁺ in m/s, Ω⁺ in rad/s, status,
  path, shape, collisions); every hit answered, by the table where it is valid and by the direct model elsewhere
  (``method``);
* :func:`sample_direct` — the same hits answered by the direct model alone, with the parameters the table
  was built with (:mod:`surrogate.kernels.direct_path`; microseconds per hit, not nanoseconds);
* :func:`sample_local` — for arrays of incidence angle α1 (deg) and speed |V⁻|
  (m/s), the reflected state (α2, β2, s, Ω⁺a/|V⁻|) in the local frame (wall
  y = 0, normal +Y, impact plane XY), from the table.

One ``shape`` contract: a shape name, ``"mix"`` (equal weights over the table's shapes), a dict
{name: weight}, a sequence of four weights (ellipsoid, prism, cut_prism, tetrahedron), or, for
:func:`sample_global` and :func:`sample_direct`, one shape name per particle ((N,) strings); a shape must be
in the table (:func:`surrogate.validation.check_shape`). One ``omega`` contract: keyword-only, (N, 3) or (3,)
in rad/s in the frame of ``velocity``, None for no spin. ``random_state`` is an int, a Generator or None
(not ``seed`` as in :mod:`tablegen`, because a Generator is accepted too, as under that name in NumPy's and
scikit-learn's APIs). Every argument goes through :mod:`surrogate.validation` before anything is drawn or
written, so a bad value gets the same one-line ValueError from each of them.

``clamp``: where the table answers every draw (``sample_local``, ``sample_global`` with ``method="table"``)
an incident state outside the table's grid is an error by default; with ``clamp=True`` the dimensionless
law at the nearest grid edge is used (and scaled by the particle's actual speed). ``sample_global``'s default
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

import warnings
from typing import NamedTuple

import numpy as np

from data_schema.table import STATE_NAMES
from surrogate.kernels.direct_path import direct_rebound_parallel_rng
from surrogate.kernels.grain import keyed_shapes
from surrogate.kernels.hit import Rebounds
from surrogate.kernels.layout import frozen
from surrogate.kernels.locate import mix_shapes
from surrogate.kernels.parallel import draw_local_parallel_rng
from surrogate.kernels.rng import chunk_states
from surrogate.kernels.wall_hit import METHOD_DIRECT, METHOD_TABLE, rebound_parallel_rng, rough_rebound_parallel_rng
from surrogate.table import SurrogateTable
from surrogate.validation import (as_rows, check_grain_key,
                                  check_half_size, check_incident, check_interpolation, check_local_states,
                                  check_method, check_omega, check_out, check_random_state, check_roughness,
                                  check_shape, check_vectors)


class WallLawRangeWarning(UserWarning):
    """Hits answered with |V⁻| outside the speeds the table's wall law holds over (``table.wall.speed_range_m_s``):
    the law is applied there all the same."""


def warn_outside_law(table: SurrogateTable, V: np.ndarray, stacklevel: int = 3) -> int:
    """The number of rows of V (N, 3), m/s, whose |V⁻| lies outside the table's wall law's speed range, and a
    :class:`WallLawRangeWarning` saying so if there are any (none for a law that states no range)."""
    wall = table.wall
    if not wall.speed_range_stated or V.shape[0] == 0:
        return 0
    low, high = wall.speed_range_m_s
    squared = V[:, 0] * V[:, 0] + V[:, 1] * V[:, 1] + V[:, 2] * V[:, 2]   # element by element: no SIMD sum
    outside = int(np.count_nonzero((squared < low * low) | (squared > high * high)))
    if outside:
        warnings.warn(f"{outside} of {V.shape[0]} hits have |V-| outside {wall.speed_range_text()}, where the wall "
                      f"law {wall.name!r} holds; it is applied there all the same", WallLawRangeWarning,
                      stacklevel=stacklevel)
    return outside


class LocalDraws(NamedTuple):
    """Reflected states in the local frame (arrays of length n)."""

    alpha2: np.ndarray        # rad, in [0, π]
    beta2: np.ndarray         # rad, in [−π/2, π/2]
    speed_ratio: np.ndarray   # |V⁺|/|V⁻|
    omega: np.ndarray         # (n, 3) Ω⁺ a/|V⁻|, local frame
    status: np.ndarray        # int8: 0 rebounded, 1 trapped


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
    a, v = check_local_states(table, alpha1, speed, clamp)
    cdf, _ = check_shape(table, shape)
    scaled = check_interpolation(interpolation)
    states = chunk_states(check_random_state(random_state), len(a))
    out = np.empty((len(a), len(STATE_NAMES)))
    status = np.empty(len(a), dtype=np.int8)
    draw_local_parallel_rng(table.kernel_data, cdf, a, v, states, out, status, scaled)
    return LocalDraws(alpha2=out[:, 0], beta2=out[:, 1], speed_ratio=out[:, 2], omega=out[:, 3:], status=status)


def _incident(table: SurrogateTable, velocity, normal, half_size, omega) -> tuple:
    """The hits of :func:`sample_global` and :func:`sample_direct` checked, as the kernels take them: V (N, 3),
    the normals (N, 3) or (1, 3), the half-sizes (N,) or (1,), Ω⁻ (N, 3) or (1, 3)."""
    V = check_vectors("velocity", velocity)
    n_particles = V.shape[0]
    return V, check_vectors("normal", normal, n_particles), check_half_size(half_size, n_particles), \
        check_omega(omega, n_particles)


def sample_global(table: SurrogateTable, velocity, normal, half_size, shape="ellipsoid", random_state=None,
                  clamp: bool = False, interpolation: str = "scaled", out=None, *, omega=None, method: str = "auto",
                  grain_key=None, roughness_deg=None) -> Rebounds:
    """Reflected velocities and spins of particles hitting walls, in the global frame: every hit answered, by
    the table where it is valid and by the direct model elsewhere.

    Parameters
    ----------
    table : a loaded table (:func:`surrogate.load`).
    velocity : (N, 3) incident velocities V⁻, m/s; each must move into its wall (V⁻·n < 0).
    normal : (N, 3) or (3,) wall unit normals pointing into the gas; normals whose
        length differs from 1 by more than 1e-6 are rejected, not normalised.
    half_size : (N,) or scalar, particle half-size a in m (half the largest extent).
    shape : the shapes of the particles (module doc): a shape name, ``"mix"``, a dict {name: weight}, four
        weights, or one shape name per particle ((N,) strings).
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
    out : None (default: a new record) or a :class:`Rebounds` of N rows to write the results into and return
        (:func:`surrogate.empty_rebounds`; C-contiguous, writeable, sharing no memory with the inputs). A solver
        calling this every time step can keep it, which spares it the allocation and the first touch of fresh
        pages.
    omega : None (default: no spin) or (N, 3) or (3,) incident angular velocities Ω⁻, rad/s, in the frame of
        ``velocity`` (finite).
    method : ``"auto"`` (default): the table iff |Ω⁻|a/|V⁻| ≤ :data:`surrogate.SPIN_TOLERANCE` and α1, |V⁻|
        lie in the table's grid ranges (inclusive), the direct model (:func:`surrogate.sample_direct`'s,
        microseconds per hit) for every other hit; ``"table"``: the table for every hit, Ω⁻ ignored (the
        behaviour before spin was taken into account; ``clamp`` applies); ``"direct"``: the direct model
        for every hit. With Ω⁻ zero and every state in the grid, ``"auto"`` gives ``"table"``'s bits.
    grain_key : None (default: every hit a new grain drawn from the stream) or (N,) integers in [0, 2**63), one
        per particle, kept for its life (:func:`surrogate.grain_key` derives them): the particle hits as the same
        grain every time. Its shape is the key's on either path (a shape given per particle wins); on the direct
        path its proportions b/a, c/b and its hand are the key's too, while the table path draws them from the
        shape's law, which the table holds over random proportions (:func:`surrogate.grain_of` gives a key's
        grain). The orientation at impact and the table's draw stay random per hit; the stream advances as
        without keys. None gives the bits of a call without the keyword.
    roughness_deg : None (default: the table's wall's, ``table.wall.roughness_deg``) or the wall's roughness Δγ in
        degrees, in [0, 45]: 0 a smooth wall; above, each hit lands on a facet of the wall tilted at random and
        may hit again (docs/model.md §12; :func:`surrogate.kernels.wall_hit.rough_rebound`), its facets drawn from
        the hit's own uniforms, so the stream advances as on a smooth wall. A rough wall answers hit by hit,
        without the table's block pipeline (its cost per hit: docs/performance.md).

    Returns
    -------
    :class:`Rebounds`, one row per hit, read by name: ``V`` (N, 3) V⁺ in m/s, ``Omega`` (N, 3) Ω⁺ in rad/s (NaN
    rows unless rebounded), ``status`` (N,) int8: 0 rebounded, 1 trapped, 2 failed (the direct model only: a
    collision solve or a contact search failed; rare, never dropped: count them with
    ``status == surrogate.STATUS_FAILED``); ``path`` (N,) int8: which path answered the hit (0 the table, 1 the
    direct model; :data:`surrogate.kernels.PATH_TABLE`, :data:`surrogate.kernels.PATH_DIRECT`); ``shape`` (N,)
    int32: the particle's shape, its index in ``table.shapes``; ``n_collisions`` (N,) int32: the direct path's
    collisions, −1 on the table path (on a rough wall: ``path`` and ``n_collisions`` of the last facet hit);
    ``wall_hits`` (N,) int32: the hits on the wall each took, 1 on a smooth wall, up to
    :data:`surrogate.MAX_WALL_HITS` on a rough one (a rebound still into the wall then counts as trapped), 0 for
    a refused hit; ``wall_work_normal``, ``wall_work_tangential`` (N,) float64: the work of the hit on the wall per
    unit particle mass, m²/s² (W_n, plastic indentation, and W_t, cutting; docs/model.md §4.7), from the direct
    path (summed over a rough hit's facet hits, up to the trap or the failure), NaN where the table answered (it
    does not hold them yet) and for a refused hit. Every check runs before anything is written: on a ValueError
    ``out`` is unchanged. Hits whose |V⁻| lies outside the speeds the table's wall law holds over
    (``table.wall.speed_range_m_s``) are answered all the same, with one :class:`WallLawRangeWarning` giving
    their number.
    The direct model takes the families and the table's user grains (convex polyhedra), with the parameters the
    table was built with (``table.direct_parameters``).
    """
    V, nrm, a, W = _incident(table, velocity, normal, half_size, omega)
    n_particles = V.shape[0]
    code = check_method(method)
    # the grid's range is an error only where the table must answer every hit
    check_incident(table, V, nrm, a, grid=not clamp and code == METHOD_TABLE)
    warn_outside_law(table, V)
    cdf, shapes = check_shape(table, shape, n_particles)
    keys = check_grain_key(grain_key, n_particles)
    if code == METHOD_DIRECT:
        _check_direct_shapes(table, cdf, shapes)
    scaled = check_interpolation(interpolation)
    roughness = check_roughness(table, roughness_deg)
    out = check_out(out, n_particles, (V, nrm, a, W))
    params = frozen(table.direct_parameters)       # read-only, as the loaded table's: one compilation of the kernels
    states = chunk_states(check_random_state(random_state), n_particles)
    rows = (V, W, as_rows(nrm, n_particles), as_rows(a, n_particles), states, code, out, scaled)
    if roughness != 0.0:
        rough_rebound_parallel_rng(table.kernel_data, params, table.shape_arrays, table.model_shapes, cdf, shapes,
                                   keys, *rows, roughness)
    else:
        rebound_parallel_rng(table.kernel_data, params, table.shape_arrays, table.model_shapes, cdf, shapes, keys,
                             *rows)
    return out


def sample_direct(table: SurrogateTable, velocity, normal, half_size, shape="ellipsoid", random_state=None, *,
                  omega=None, out=None, grain_key=None, roughness_deg=None) -> Rebounds:
    """Reflected velocities and spins of particles hitting walls, from the direct model alone, in the caller's
    frame (docs/model.md §10): for any hit to be computed by the model itself, a spinning one or one off the
    table's grid (:func:`sample_global`'s ``method="auto"`` does this where the table does not apply).

    Parameters
    ----------
    table : a loaded table (:func:`surrogate.load`): the model's parameters (aspect-ratio law, κ, n_max, the
        wall law, the tolerances) are those it was built with (``table.direct_parameters``).
    velocity : (N, 3) incident velocities V⁻, m/s; each must move into its wall (V⁻·n < 0). Any α1 in
        (0°, 90°] and any speed (the wall law was measured for 50–300 m/s).
    normal : (N, 3) or (3,) unit wall normals pointing into the gas (|n| − 1 within 1e-6).
    half_size : (N,) or scalar, half-size a in m (half the largest extent), > 0.
    shape : as :func:`sample_global`'s. With a mix of several shapes, each particle's shape is drawn first,
        one uniform per particle from ``random_state`` (:func:`surrogate.kernels.locate.mix_shapes`).
    random_state : int, Generator or None; one xoshiro256+ stream per chunk of particles seeded from it
        (:func:`surrogate.kernels.rng.chunk_states`), U_PER_REBOUND uniforms per particle: the same seed gives
        the same bits whatever the number of threads.
    omega : None (default: no spin) or (N, 3) or (3,) incident angular velocities Ω⁻, rad/s; exactly zero: the
        body starts touching the wall (as in the tables), otherwise the flight in from a clear start is
        simulated.
    out : None or a :class:`Rebounds` to fill (as :func:`sample_global`'s).
    grain_key : None or (N,) integers in [0, 2**63), one per particle (as :func:`sample_global`'s): a keyed
        particle's shape (unless given per particle), proportions and hand are its key's
        (:func:`surrogate.grain_of`), its orientation random per hit. The stream advances as without keys.
    roughness_deg : None (default: the table's wall's) or Δγ in degrees, in [0, 45], as :func:`sample_global`'s:
        above 0, every facet hit by the direct model, each row's uniforms those :func:`sample_global` would give
        it (U_PER_DRAW per row; its shape drawn first, as here without roughness).

    Returns
    -------
    :class:`Rebounds` (as :func:`sample_global`'s): status STATUS_REBOUNDED (0), STATUS_TRAPPED (1) or
    STATUS_FAILED (2, a collision solve or contact search failed), NaN rows unless rebounded; path PATH_DIRECT;
    n_collisions the rebound's collisions (up to the trap); wall_work_normal and wall_work_tangential its work on
    the wall (m²/s², up to the trap or the failure). Hits outside the wall law's speed range: as
    :func:`sample_global`.
    """
    params = frozen(table.direct_parameters)       # read-only, as the loaded table's: one compilation of the kernels
    V, nrm, a, W = _incident(table, velocity, normal, half_size, omega)
    n_particles = V.shape[0]
    # every state moving into its wall is in the model's range: the table's grid is no error here
    check_incident(table, V, nrm, a, grid=False)
    warn_outside_law(table, V)
    cdf, shapes = check_shape(table, shape, n_particles)
    _check_direct_shapes(table, cdf, shapes)
    keys = check_grain_key(grain_key, n_particles)
    roughness = check_roughness(table, roughness_deg)
    out = check_out(out, n_particles, (V, nrm, a, W))
    generator = check_random_state(random_state)
    if shapes.size == 0:
        shapes = _mix_rows(cdf, n_particles, generator)      # drawn with keys too: the stream advances alike
        if keys.size:
            shapes = keyed_shapes(cdf, np.zeros(0, dtype=np.int64), keys)
    states = chunk_states(generator, n_particles)
    if roughness != 0.0:
        rough_rebound_parallel_rng(table.kernel_data, params, table.shape_arrays, table.model_shapes, cdf, shapes,
                                   keys, V, as_rows(W, n_particles), as_rows(nrm, n_particles),
                                   as_rows(a, n_particles), states, METHOD_DIRECT, out, True, roughness)
        return out
    direct_rebound_parallel_rng(params, table.shape_arrays, table.model_shapes, shapes, keys, V,
                                as_rows(W, n_particles), as_rows(nrm, n_particles), as_rows(a, n_particles), states,
                                out)
    return out


def _check_direct_shapes(table: SurrogateTable, cdf: np.ndarray, shapes: np.ndarray) -> None:
    """ValueError naming a shape the direct model would have to answer but cannot (those of ``shapes``, or of
    positive weight in ``cdf``): a smooth body that is no built-in family, whose semi-axes the table does not
    hold (:attr:`surrogate.table.SurrogateTable.model_shapes` −1); the table path draws any shape."""
    used = np.unique(shapes) if shapes.size else np.flatnonzero(np.diff(cdf, prepend=0.0) > 0.0)
    refused = [table.shapes[k] for k in used if table.model_shapes[k] < 0]
    if refused:
        raise ValueError(f"The direct model cannot answer the shape {refused[0]!r}: a smooth body that is no "
                         f"built-in family; draw it from the table (sample_global with method='table').")


def _mix_rows(cdf: np.ndarray, n: int, generator: np.random.Generator) -> np.ndarray:
    """(n,) table shape indices drawn from the mix ``cdf``, one uniform per row from ``generator``; a mix of
    one shape draws nothing."""
    weights = np.diff(cdf, prepend=0.0)
    if np.count_nonzero(weights) == 1:
        return np.full(n, int(np.flatnonzero(weights)[0]), dtype=np.int64)
    return mix_shapes(cdf, generator.random(n))
