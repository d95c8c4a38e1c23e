"""Numba kernels of the runtime sampler: O(1) work per reflected state, callable from a solver's ``@njit`` code.

They are plain functions over the arrays of a table (``table.kernel_data``)
and uniforms: :data:`U_PER_DRAW` per draw, pre-drawn or drawn from a
caller-owned xoshiro256+ state (:mod:`surrogate.rng`). Entry points:

* one particle, global frame: :func:`rebound_tuple` (vectors as tuples: the
  form for a solver's per-hit loop) and :func:`rebound` (the same on (3,)
  arrays), defined here;
* many particles on one thread, their table reads overlapped in a pipeline
  of blocks (:mod:`surrogate.blocks`): :func:`rebound_many` (uniforms given),
  :func:`rebound_many_rng` (uniforms from 32 SIMD lanes seeded from a state;
  :func:`rebound_uniforms` returns them); the same bits as :func:`rebound`
  row by row;
* many particles on all threads (:mod:`surrogate.batch`):
  :func:`rebound_batch`, :func:`rebound_batch_rng`;
* the local frame (:mod:`surrogate.draw`): :func:`draw_local`,
  :func:`draw_velocity`, and in parallel :func:`draw_local_batch`,
  :func:`draw_local_batch_rng`.

The impact frame (:func:`impact_frame`, :mod:`surrogate.frame`) is ex (the
tangential direction of V⁻), n, ez = ex × n. The global kernels take V⁻ in
m/s and return V⁺ in m/s and Ω⁺ in rad/s; the local ones use the model's lab
frame (wall y = 0, normal +Y, impact plane XY, α1 in degrees from the wall),
V⁺ in units of |V⁻| and Ω⁺ in units of |V⁻|/a.
"""

import numba

from surrogate.batch import draw_local_batch, draw_local_batch_rng, rebound_batch, rebound_batch_rng
from surrogate.blocks import BLOCK, rebound_many, rebound_many_rng, rebound_uniforms
from surrogate.draw import U_PER_DRAW, _cell, _draw_in_cell, _hint_draw, draw_local, draw_velocity, locate
from surrogate.frame import _NAN3, STATUS_INVALID, _moves_into_wall, _to_global, impact_frame
from surrogate.jit import JIT, KERNEL


__all__ = ["BLOCK", "STATUS_INVALID", "U_PER_DRAW", "draw_local", "draw_local_batch", "draw_local_batch_rng",
           "draw_velocity", "impact_frame", "locate", "rebound", "rebound_batch", "rebound_batch_rng",
           "rebound_many", "rebound_many_rng", "rebound_tuple", "rebound_uniforms"]


@numba.njit(**KERNEL)
def rebound(data, mix_cdf, V, n, a, u, V_out, W_out, scaled=True):
    """Reflected state of one particle in the global frame; returns the status.

    Parameters
    ----------
    data : ``table.kernel_data``.
    mix_cdf : cumulative shape weights (table shape order).
    V : (3,) incident velocity, m/s; must move into the wall (V·n < 0).
    n : (3,) unit wall normal pointing into the gas (not checked here).
    a : particle half-size (half its largest extent), m.
    u : (U_PER_DRAW,) uniforms in [0, 1).
    V_out, W_out : (3,) outputs: V⁺ in m/s and Ω⁺ in rad/s (NaN unless rebounded).
    scaled : between grid points, move the draw to the incident state
        (default; :func:`draw_velocity`); False: plain stochastic interpolation.

    Returns STATUS_REBOUNDED, STATUS_TRAPPED, or STATUS_INVALID when V does not
    move into the wall (V·n ≥ 0, zero or non-finite). The impact frame is ex
    (tangential direction of V), n, ez = ex × n; the local draw is rotated back
    into the global frame. The mirror symmetry of the model is applied with a
    random sign inside :func:`draw_velocity`. An α1 or |V⁻| outside the table's
    grid uses the law at the nearest grid edge (check ``table.alpha1_range``
    and ``table.speed_range`` beforehand if that matters).
    """
    status, V_new, W_new = _rebound(data, mix_cdf, V, n, a, u, scaled)
    _store(V_new, W_new, V_out, W_out)
    return status


@numba.njit(**KERNEL)
def rebound_tuple(data, mix_cdf, V, n, a, u, scaled=True):
    """:func:`rebound` returning its outputs: (status, V⁺, Ω⁺), V⁺ in m/s and Ω⁺ in rad/s as 3-tuples.

    V and n may be 3-tuples or (3,) arrays. For a solver loop over particle
    arrays, passing ``(V[i, 0], V[i, 1], V[i, 2])`` rather than the row
    ``V[i]`` creates no array view, so the loop does no reference counting
    (numba's atomic counts on views cost tens of ns per call: bench_sampler.py, (b) and its variant).
    """
    return _rebound(data, mix_cdf, V, n, a, u, scaled)


@numba.njit(inline="always", **JIT)
def _rebound(data, mix_cdf, V, n, a, u, scaled):
    """:func:`rebound_tuple`."""
    if not _moves_into_wall(V, n):
        return STATUS_INVALID, _NAN3, _NAN3
    alpha1, speed, cos_a1, sin_a1, ex, ez = impact_frame(V, n, u[12])
    cell = _cell(data, mix_cdf, alpha1, speed, u)
    _hint_draw(data, cell, u)
    status, vx, vy, vz, wx, wy, wz = _draw_in_cell(data, cell, cos_a1, sin_a1, u, scaled)
    V_new, W_new = _to_global(status, vx, vy, vz, wx, wy, wz, speed, a, ex, n, ez)
    return status, V_new, W_new


@numba.njit(inline="always", **JIT)
def _store(V_new, W_new, V_out, W_out):
    for k in range(3):
        V_out[k] = V_new[k]
        W_out[k] = W_new[k]
