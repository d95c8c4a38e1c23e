"""The direct path: the direct model at run time, in the caller's frame, one particle per call
(:func:`direct_rebound`) or many on all threads (:func:`direct_rebound_parallel_rng`); docs/model.md §10.

Where the table's law does not apply (a spinning particle, say), a solver asks the model itself.
Per hit the model frame is built as the table's draws build theirs
(:func:`surrogate.kernels.frame.impact_frame`): ey = n, ex the direction of the tangential part of V⁻
(uniform in the wall plane at normal impact, from u[U_AXIS]), ez = ex × ey; there
:func:`direct_model.runtime.rebound_model_frame` runs the whole rebound, and V⁺, Ω⁺ come back in the
caller's frame. Units: V in m/s, Ω in rad/s, a in m. The model parameters and the shapes come from the table
(``table.direct_parameters``, ``table.shape_arrays``), so a table and its direct model never disagree.
:func:`direct_rebound` converts its arguments to one set of types and calls :func:`direct_rebound_typed`, which
every kernel of the direct path calls: the model is compiled once per process whatever types the callers pass.
Both run without numba's reference counting (``KERNEL``), the scratch space of :func:`direct_rebound` in its stack
frame (:func:`surrogate.kernels.memory.stack_scratch`).
"""

import math

import numba
import numpy as np

from data_schema.samples import STATUS_FAILED, STATUS_REBOUNDED, STATUS_TRAPPED
from direct_model.runtime import SCRATCH_SIZE, U_AXIS, U_PER_REBOUND, rebound_model_frame
from surrogate.kernels.checks import check_keys
from surrogate.kernels.frame import NAN3, dot, float3, impact_frame, moves_into_wall, particle_ok, to_global
from surrogate.kernels.hit import PATH_DIRECT, hit, invalid_hit, put_hit
from surrogate.kernels.grain import key_model_uniforms
from surrogate.kernels.memory import stack_scratch
from surrogate.kernels.options import JIT, KERNEL
from surrogate.kernels.rng import CHUNK_ROWS, fill_uniforms


@numba.njit(**KERNEL)
def direct_rebound(params, shape_arrays, shape, V, omega, n, a, u):
    """One particle's rebound by the direct model, in the caller's frame: a :class:`surrogate.kernels.hit.Hit`
    (V⁺ in m/s and Ω⁺ in rad/s; its ``shape`` the index given here, its ``path`` PATH_DIRECT).

    Parameters
    ----------
    params : ``table.direct_parameters`` (:func:`direct_model.runtime.model_parameters`).
    shape_arrays : ``table.shape_arrays``, the direct model's shapes (:class:`direct_model.shape_arrays.ShapeArrays`).
    shape : the particle's shape, an index into ``shape_arrays``: today the four families' codes 0..3 (ellipsoid,
        prism, cut prism, tetrahedron; ``table.model_shapes`` maps the table's shapes to them).
    V : incident velocity V⁻, m/s (3-tuple or (3,) array); must move into the wall (V·n < 0).
    omega : incident angular velocity Ω⁻, rad/s; exactly zero: the body starts touching the wall (the
        tables' case), otherwise the flight in from a clear start is simulated (docs/model.md §5.3).
    n : unit wall normal pointing into the gas (| |n| − 1 | ≤ surrogate.kernels.frame.NORMAL_TOLERANCE).
    a : half-size (half the largest extent), m, > 0.
    u : (≥ U_PER_REBOUND,) uniforms in [0, 1) (:mod:`direct_model.runtime`), e.g. from
        :func:`surrogate.kernels.rng.fill_uniforms`.

    Status STATUS_REBOUNDED; STATUS_TRAPPED (still colliding after n_max collisions) or STATUS_FAILED
    (a collision solve or a contact search failed) with NaN vectors; STATUS_INVALID (the record of
    :func:`surrogate.kernels.hit.invalid_hit`) for an input outside the ranges above. The hit's
    ``wall_work_normal`` and ``wall_work_tangential``: the work of its collisions on the wall per unit particle
    mass, m²/s² (W_n and W_t of :class:`direct_model.body_rebound.BodyRebound`; up to the trap or the failure),
    NaN for STATUS_INVALID.
    """
    return direct_rebound_typed(params, shape_arrays, np.int64(shape), float3(V), float3(omega), float3(n), float(a), u,
                                stack_scratch(SCRATCH_SIZE))


@numba.njit(inline="always", **JIT)
def _valid(shape_arrays, shape, V, omega, n, a, u):
    """The inputs of :func:`direct_rebound` are in their ranges."""
    ok = (moves_into_wall(V, n) and particle_ok(n, a)
          and math.isfinite(omega[0] + omega[1] + omega[2]) and 0 <= shape < shape_arrays.kind.shape[0]
          and u.shape[0] >= U_PER_REBOUND)
    for k in range(U_PER_REBOUND if ok else 0):
        ok = ok and 0.0 <= u[k] < 1.0
    return ok


@numba.njit(**KERNEL)
def direct_rebound_typed(params, shape_arrays, shape, V, omega, n, a, u, scratch):
    """:func:`direct_rebound` with its scratch space given: ``shape`` an int64, V, omega and n 3-tuples of float64,
    a a float64, ``scratch`` (SCRATCH_SIZE,) float64 (module doc)."""
    if not _valid(shape_arrays, shape, V, omega, n, a, u):
        return invalid_hit()
    ex, ez = _frame_axes(V, n, u[U_AXIS])
    # Ω⁻ in (m/s)/a, the model's unit (direct_model.body_rebound): rad/s times a
    rebound = rebound_model_frame(params, shape_arrays, shape, dot(V, ex), dot(V, n), a * dot(omega, ex),
                                  a * dot(omega, n), a * dot(omega, ez), u, scratch)
    # the wall work in m²/s² as the model gives it (a scalar of the rebound: no frame, V in m/s and W × r too)
    work_n, work_t = rebound.wall_work_normal, rebound.wall_work_tangential
    if rebound.status != STATUS_REBOUNDED:
        status = STATUS_TRAPPED if rebound.status == STATUS_TRAPPED else STATUS_FAILED
        return hit(status, PATH_DIRECT, shape, rebound.n_collisions, NAN3, NAN3, 1, work_n, work_t)
    (vx, vy, vz), (wx, wy, wz) = rebound.V, rebound.Omega
    status, V_new, Omega_new = to_global(rebound.status, True, vx, vy, vz, wx, wy, wz, 1.0, a, ex, n, ez)
    return hit(status, PATH_DIRECT, shape, rebound.n_collisions, V_new, Omega_new, 1, work_n, work_t)


@numba.njit(**KERNEL)
def _frame_axes(V, n, u_axis):
    """ex and ez of the impact frame (:func:`impact_frame`), as 3-tuples."""
    _, _, _, _, ex, ez = impact_frame(V, n, u_axis)
    return ex, ez


@numba.njit(parallel=True, **JIT)
def direct_rebound_parallel_rng(params, shape_arrays, model_shapes, shapes, keys, V, omega, n, a, states, out):
    """:func:`direct_rebound` for every row i of V, omega, n (N, 3) and a (N,), on all threads, into ``out``
    (:class:`surrogate.kernels.hit.Rebounds` of N rows). Row i is of the table's shape ``shapes[i]`` (its index in
    the table, written to ``out.shape``), whose index in ``shape_arrays`` is ``model_shapes[shapes[i]]``. Chunk j
    of CHUNK_ROWS rows draws its uniforms, U_PER_REBOUND per row in row order, from a copy of the xoshiro256+
    state ``states[j]`` (:func:`surrogate.kernels.rng.chunk_states`), so the results do not depend on the number
    of threads. ``keys``: (N,) int64 grain keys (≥ 0; NO_KEY −1: none) or empty (none): a keyed row's
    proportions and hand are its key's (:func:`surrogate.kernels.grain.key_model_uniforms`; its shape is the
    caller's ``shapes[i]``, :func:`surrogate.kernels.grain.grain_shape` for a grain of the mix)."""
    check_keys(keys, V.shape[0])
    for j in numba.prange(states.shape[0]):
        _direct_chunk(params, shape_arrays, model_shapes, shapes, keys, V, omega, n, a, states[j].copy(), out,
                      j * CHUNK_ROWS, min((j + 1) * CHUNK_ROWS, V.shape[0]))


@numba.njit(**JIT)
def _direct_chunk(params, shape_arrays, model_shapes, shapes, keys, V, omega, n, a, state, out, lo, hi):
    """Rows [lo, hi) of :func:`direct_rebound_parallel_rng`, their uniforms from ``state``. Called, not inlined:
    numba 0.68's parallel loops drop the writes their body makes to the arrays of a tuple such as ``out``."""
    u = np.empty(U_PER_REBOUND)
    scratch = np.empty(SCRATCH_SIZE)
    for i in range(lo, hi):
        fill_uniforms(state, u)
        if keys.shape[0] > 0 and keys[i] >= 0:
            key_model_uniforms(keys[i], u)
        result = direct_rebound_typed(params, shape_arrays, np.int64(model_shapes[shapes[i]]),
                                      (V[i, 0], V[i, 1], V[i, 2]), (omega[i, 0], omega[i, 1], omega[i, 2]),
                                      (n[i, 0], n[i, 1], n[i, 2]), float(a[i]), u, scratch)
        put_hit(out, i, hit(result.status, result.path, shapes[i], result.n_collisions, result.V, result.Omega,
                            result.wall_hits, result.wall_work_normal, result.wall_work_tangential))
