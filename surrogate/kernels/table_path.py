"""The table path, one particle: in the global frame :func:`table_rebound` (for a solver's per-hit loop); in
the local frame :func:`draw_local`.

Each public kernel converts its arguments to one set of types (3-tuples and scalars of float64, ``scaled`` a
bool) and calls its ``_typed`` twin, which holds the work: whatever types the callers pass, the work is compiled
once per process (docs/design/test_time.md).

The impact frame (:func:`surrogate.kernels.frame.impact_frame`), then one draw
(:mod:`surrogate.kernels.draw`: locate, gather, arithmetic) and the way back
to the global frame. V⁻ in m/s in, V⁺ in m/s and Ω⁺ in rad/s out.
"""

import math

import numba
import numpy as np

from data_schema.samples import STATUS_INVALID, STATUS_REBOUNDED
from surrogate.kernels.draw import draw_velocity
from surrogate.kernels.frame import (float3, impact_frame, moves_into_wall, particle_ok, rebound_ok, to_global,
                                     uniforms_ok)
from surrogate.kernels.hit import PATH_TABLE, hit, invalid_hit
from surrogate.kernels.locate import first_row, hint, locate_in_shape, mix_shape
from surrogate.kernels.options import JIT, KERNEL
from surrogate.kernels.work import draw_with_work, hint_work


@numba.njit(**KERNEL)
def table_rebound(data, mix_cdf, V, n, a, u, scaled=True):
    """Reflected state of one particle in the global frame, drawn from the table: a
    :class:`surrogate.kernels.hit.Hit` (V⁺ in m/s, Ω⁺ in rad/s; ``path`` PATH_TABLE, ``shape`` the shape drawn
    from the mix, ``n_collisions`` −1, ``wall_work_normal`` and ``wall_work_tangential`` W_n, W_t in m²/s² drawn
    with the rebound (:mod:`surrogate.kernels.work`; NaN from a table without the work, format 4.0)).

    Parameters
    ----------
    data : ``table.kernel_data``.
    mix_cdf : cumulative shape weights (table shape order).
    V : incident velocity, m/s (3-tuple or (3,) array); must move into the wall (V·n < 0).
    n : unit wall normal pointing into the gas (| |n| − 1 | ≤ NORMAL_TOLERANCE; 3-tuple or (3,) array).
    a : particle half-size (half its largest extent), m, finite and > 0.
    u : (U_PER_DRAW,) uniforms in [0, 1).
    scaled : between grid points, move the draw to the incident state
        (default; :func:`draw_velocity`); False: plain stochastic interpolation.

    Status STATUS_REBOUNDED, STATUS_TRAPPED, or STATUS_INVALID when V does not
    move into the wall (V·n ≥ 0, zero or non-finite), n is not a unit vector,
    a is not finite and > 0, a uniform is outside [0, 1), or the result would
    not be finite or would not leave the wall (as rbs_table_rebound); NaN vectors unless rebounded. The
    impact frame is ex (tangential direction of V), n, ez = ex × n; the local draw is rotated back
    into the global frame. The mirror symmetry of the model is applied with a
    random sign (:func:`surrogate.kernels.arithmetic.arithmetic`). An α1 or |V⁻| outside the table's
    grid uses the law at the nearest grid edge (check ``table.alpha1_range``
    and ``table.speed_range`` beforehand if that matters).

    For a solver loop over particle arrays, passing ``(V[i, 0], V[i, 1], V[i, 2])`` rather than the row
    ``V[i]`` creates no array view, so the loop does no reference counting
    (numba's atomic counts on views: docs/design/sampler_cost.md).
    """
    return table_rebound_typed(data, mix_cdf, float3(V), float3(n), float(a), u, scaled != 0)


@numba.njit(**KERNEL)
def table_rebound_typed(data, mix_cdf, V, n, a, u, scaled):
    """:func:`table_rebound` with V and n 3-tuples of float64, a a float64 and ``scaled`` a bool (module doc)."""
    return table_shape_rebound(data, np.int64(mix_shape(mix_cdf, u[0])), V, n, a, u, scaled)   # int64: as rough hits


@numba.njit(**KERNEL)
def table_shape_rebound(data, shape, V, n, a, u, scaled):
    """:func:`table_rebound_typed` of a particle of the table's shape ``shape`` (a valid index; u[0] unused).
    Compiled on its own, not inlined: the rough wall's facet hits call it too (one compilation of the draw)."""
    if not moves_into_wall(V, n):
        return invalid_hit()
    alpha1, speed, cos_a1, sin_a1, ex, ez = impact_frame(V, n, u[12])
    cell = locate_in_shape(data, shape, alpha1, speed, u)
    hint(data, cell, u)
    hint_work(data, cell[0], first_row(data, cell[0], u[4])[2], u)
    status, vx, vy, vz, wx, wy, wz, work_n, work_t = draw_with_work(data, cell, cos_a1, sin_a1, speed, u, scaled)
    ok = particle_ok(n, a) & uniforms_ok(u)
    status, V_new, Omega_new = to_global(status, ok, vx, vy, vz, wx, wy, wz, speed, a, ex, n, ez)
    return hit(status, PATH_TABLE, cell[0] // (data.n_alpha1 * data.n_speed), -1, V_new, Omega_new, 1, work_n,
               work_t)


@numba.njit(inline="always", **JIT)
def local_ok(alpha1, speed):
    """A local incident state a draw takes: α1 in (0, 90] deg, |V⁻| finite and > 0 m/s."""
    return alpha1 > 0.0 and alpha1 <= 90.0 and speed > 0.0 and math.isfinite(speed)


@numba.njit(**KERNEL)
def draw_local(data, mix_cdf, alpha1, speed, u, scaled=True):
    """One reflected state at (α1 deg, |V⁻| m/s) in the local frame: (status, α2, β2, s, Ω_x, Ω_y, Ω_z).

    Angles in radians, s = |V⁺|/|V⁻|, Ω in units of |V⁻|/a; the state is NaN
    for a trapped particle. See :func:`surrogate.kernels.draw.draw_velocity` (same arguments).
    STATUS_INVALID (and NaN) for α1 outside (0, 90] or NaN, |V⁻| not finite
    and > 0, a uniform outside [0, 1), or a draw that is not a finite rebound
    leaving the wall (as rbs_draw_local).
    """
    return draw_local_typed(data, mix_cdf, float(alpha1), float(speed), u, scaled != 0)


@numba.njit(**KERNEL)
def draw_local_typed(data, mix_cdf, alpha1, speed, u, scaled):
    """:func:`draw_local` with α1 and |V⁻| float64 and ``scaled`` a bool (module doc)."""
    if not local_ok(alpha1, speed):
        return STATUS_INVALID, np.nan, np.nan, np.nan, np.nan, np.nan, np.nan
    status, vx, vy, vz, wx, wy, wz = draw_velocity(data, mix_cdf, alpha1, speed, u, scaled)
    ok = uniforms_ok(u) & ((status != STATUS_REBOUNDED) | rebound_ok((vx, vy, vz), (wx, wy, wz), (0.0, 1.0, 0.0)))
    status = status if ok else STATUS_INVALID
    if status != STATUS_REBOUNDED:
        return status, np.nan, np.nan, np.nan, np.nan, np.nan, np.nan
    s = math.sqrt(vx * vx + vy * vy + vz * vz)
    return status, math.atan2(vy, vx), math.asin(vz / s) if s > 0.0 else 0.0, s, wx, wy, wz
