"""The impact frame of a particle hitting a wall, and the way back to the global frame.

The frame of a hit is (ex, n, ez): ex the direction of the tangential part of
the incident velocity V⁻, n the wall's unit normal (into the gas), ez = ex × n.
In it the local draws of :mod:`surrogate.kernels.draw` live (α1 from the wall, impact
plane spanned by ex and n). :func:`impact_frame` builds it, :func:`to_global`
turns a local draw back into V⁺ (m/s) and Ω⁺ (rad/s) in the caller's frame.
:func:`frame_block` builds the frames of a block of particles (the frame record,
FRAME_* fields, :mod:`surrogate.kernels.block`).
"""

import math

import numba
import numpy as np

from data_schema.samples import STATUS_REBOUNDED
from surrogate.kernels.block import BLOCK, field, fields3, put3
from surrogate.kernels.fastmath import atan2_first_quadrant, fma, sincos
from surrogate.kernels.options import JIT


NORMAL_IMPACT = 1e-12   # a tangential speed below this fraction of |V| is normal impact: ex drawn in the wall plane


@numba.njit(inline="always", **JIT)
def impact_frame(V, n, u_axis):
    """Impact frame of V on a wall of unit normal n.

    ex is the direction of the tangential part of V (uniform in the wall plane,
    from ``u_axis``, at normal impact: tangential part below NORMAL_IMPACT |V|); the
    frame is (ex, n, ez = ex × n). Returns (α1 in degrees, |V|, cos α1, sin α1,
    ex, ez) with ex and ez as 3-tuples.
    """
    vn = dot(V, n)
    tx, ty, tz = fma(-vn, n[0], V[0]), fma(-vn, n[1], V[1]), fma(-vn, n[2], V[2])
    vt = math.sqrt(fma(tx, tx, fma(ty, ty, tz * tz)))
    speed = math.sqrt(fma(vn, vn, vt * vt))
    if vt > NORMAL_IMPACT * speed:
        inv = 1.0 / vt
        ex0, ex1, ex2 = tx * inv, ty * inv, tz * inv
    else:
        # orthonormal basis (p, q) of the wall plane: p = n × e_k with e_k the axis least aligned with n
        if abs(n[0]) <= abs(n[1]) and abs(n[0]) <= abs(n[2]):
            px, py, pz = 0.0, n[2], -n[1]
        elif abs(n[1]) <= abs(n[2]):
            px, py, pz = -n[2], 0.0, n[0]
        else:
            px, py, pz = n[1], -n[0], 0.0
        pn = math.sqrt(px * px + py * py + pz * pz)
        px, py, pz = px / pn, py / pn, pz / pn
        qx, qy, qz = n[1] * pz - n[2] * py, n[2] * px - n[0] * pz, n[0] * py - n[1] * px
        s, c = sincos(2.0 * math.pi * u_axis)
        ex0, ex1, ex2 = c * px + s * qx, c * py + s * qy, c * pz + s * qz
    ez = (ex1 * n[2] - ex2 * n[1], ex2 * n[0] - ex0 * n[2], ex0 * n[1] - ex1 * n[0])
    inv_speed = 1.0 / speed
    return (math.degrees(atan2_first_quadrant(-vn, vt)), speed, vt * inv_speed, -vn * inv_speed, (ex0, ex1, ex2), ez)


NAN3 = (np.nan, np.nan, np.nan)     # the V⁺ and Ω⁺ of a draw that did not rebound


@numba.njit(inline="always", **JIT)
def moves_into_wall(V, n):
    """V·n < 0 and V finite."""
    return dot(V, n) < 0.0 and math.isfinite(V[0] + V[1] + V[2])


@numba.njit(inline="always", **JIT)
def dot(a, b):
    """a·b of two 3-vectors (tuples or arrays), the same bits wherever it is inlined."""
    return fma(a[0], b[0], fma(a[1], b[1], a[2] * b[2]))


@numba.njit(inline="always", **JIT)
def to_global(status, vx, vy, vz, wx, wy, wz, speed, a, ex, n, ez):
    """A local draw (units |V⁻|, |V⁻|/a) as (V⁺ in m/s, Ω⁺ in rad/s) in the frame (ex, n, ez), 3-tuples;
    NaN unless rebounded."""
    if status != STATUS_REBOUNDED:
        return NAN3, NAN3
    w = speed / a
    v, o = (vx, vy, vz), (wx, wy, wz)
    return ((speed * dot(v, (ex[0], n[0], ez[0])), speed * dot(v, (ex[1], n[1], ez[1])),
             speed * dot(v, (ex[2], n[2], ez[2]))),
            (w * dot(o, (ex[0], n[0], ez[0])), w * dot(o, (ex[1], n[1], ez[1])), w * dot(o, (ex[2], n[2], ez[2]))))


# -- the frame record of a block ----------------------------------------------------------------------

FRAME_VALID, FRAME_ALPHA1, FRAME_SPEED, FRAME_COS, FRAME_SIN, FRAME_A, FRAME_EX, FRAME_EZ, FRAME_N = (
    0, 1, 2, 3, 4, 5, 6, 9, 12)    # valid (1.0 or 0.0), α1 deg, |V⁻| m/s, cos α1, sin α1, a m, ex, ez, n
FRAME_FIELDS = 15


@numba.njit(inline="always", **JIT)
def frame_block(V, n, a, ub, start, m, fr):
    """The frame records ``fr`` of the m rows from ``start`` (their uniforms ``ub``), computed for rows that
    do not move into the wall too (valid 0). V and n flat, row after row: a compile-time stride, which keeps
    the SIMD loop free of run-time stride checks."""
    for b in range(m):      # no branch and no table read: SIMD across the block
        i = start + b
        Vi, ni = (V[3 * i], V[3 * i + 1], V[3 * i + 2]), (n[3 * i], n[3 * i + 1], n[3 * i + 2])
        alpha1, speed, cos_a1, sin_a1, ex, ez = impact_frame(Vi, ni, ub[12 * BLOCK + b])
        put3(fr, FRAME_VALID, b, (1.0 if moves_into_wall(Vi, ni) else 0.0, alpha1, speed))
        put3(fr, FRAME_COS, b, (cos_a1, sin_a1, a[i]))
        put3(fr, FRAME_EX, b, ex)
        put3(fr, FRAME_EZ, b, ez)
        put3(fr, FRAME_N, b, ni)


@numba.njit(inline="always", **JIT)
def is_valid(fr, b):
    """Whether particle b of a block moves into its wall (it gets a draw)."""
    return field(fr, FRAME_VALID, b) != 0.0


@numba.njit(inline="always", **JIT)
def frame_at(fr, b):
    """Particle b's frame record: (α1 deg, |V⁻| m/s, cos α1, sin α1, a m, ex, ez, n), vectors as 3-tuples."""
    return (field(fr, FRAME_ALPHA1, b), field(fr, FRAME_SPEED, b), field(fr, FRAME_COS, b), field(fr, FRAME_SIN, b),
            field(fr, FRAME_A, b), fields3(fr, FRAME_EX, b), fields3(fr, FRAME_EZ, b), fields3(fr, FRAME_N, b))
