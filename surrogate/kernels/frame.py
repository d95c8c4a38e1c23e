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

from data_schema.samples import STATUS_INVALID, STATUS_REBOUNDED
from direct_model.elementary import fma, sincos
from surrogate.kernels.block import BLOCK, field, fields3, put3, uniforms
from surrogate.kernels.fastmath import atan2_first_quadrant, bits
from surrogate.kernels.options import JIT


NORMAL_IMPACT = 1e-12   # a tangential speed below this fraction of |V| is normal impact: ex drawn in the wall plane
NORMAL_TOLERANCE = 1e-6     # | |n| − 1 | allowed for a wall normal (RBS_NORMAL_TOLERANCE)
# (1 ∓ NORMAL_TOLERANCE)²: the bounds of n·n, so the kernels' unit check needs no square root
NORMAL_MIN2 = (1.0 - NORMAL_TOLERANCE) * (1.0 - NORMAL_TOLERANCE)
NORMAL_MAX2 = (1.0 + NORMAL_TOLERANCE) * (1.0 + NORMAL_TOLERANCE)


@numba.njit(inline="always", **JIT)
def impact_frame(V, n, u_axis):
    """Impact frame of V on a wall of unit normal n.

    ex is the direction of the tangential part of V (uniform in the wall plane,
    from ``u_axis``, at normal impact: tangential part below NORMAL_IMPACT |V|); the
    frame is (ex, n, ez = ex × n). Returns (α1 in degrees, |V|, cos α1, sin α1,
    ex, ez) with ex and ez as 3-tuples.
    """
    vn, tx, ty, tz, vt, speed = incidence(V, n)
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
    return (incidence_angle(vn, vt), speed, vt * inv_speed, -vn * inv_speed, (ex0, ex1, ex2), ez)


@numba.njit(inline="always", **JIT)
def incidence(V, n):
    """The parts of V on a wall of unit normal n that :func:`impact_frame` builds on: (V·n, the tangential
    part's three components, its length, |V|)."""
    vn = dot(V, n)
    tx, ty, tz = fma(-vn, n[0], V[0]), fma(-vn, n[1], V[1]), fma(-vn, n[2], V[2])
    vt = math.sqrt(fma(tx, tx, fma(ty, ty, tz * tz)))
    return vn, tx, ty, tz, vt, math.sqrt(fma(vn, vn, vt * vt))


@numba.njit(inline="always", **JIT)
def incidence_angle(vn, vt):
    """α1 in degrees from the wall, from V·n and the tangential speed (:func:`incidence`)."""
    return math.degrees(atan2_first_quadrant(-vn, vt))


NAN3 = (np.nan, np.nan, np.nan)     # the V⁺ and Ω⁺ of a draw that did not rebound


@numba.njit(inline="always", **JIT)
def float3(x):
    """A 3-vector (3-tuple or (3,) array) as a 3-tuple of float64."""
    return float(x[0]), float(x[1]), float(x[2])


@numba.njit(inline="always", **JIT)
def moves_into_wall(V, n):
    """V·n < 0 and V finite: a particle that hits the wall (else STATUS_INVALID at once)."""
    return dot(V, n) < 0.0 and math.isfinite(V[0] + V[1] + V[2])


@numba.njit(inline="always", **JIT)
def unit_normal(n):
    """| |n| − 1 | ≤ NORMAL_TOLERANCE, as bounds on n·n (no square root)."""
    nn = dot(n, n)
    return (nn >= NORMAL_MIN2) & (nn <= NORMAL_MAX2)


@numba.njit(inline="always", **JIT)
def particle_ok(n, a):
    """The rest of what a draw needs of its particle: a unit normal (:func:`unit_normal`) and a (m) finite
    and > 0. Checked with the result (:func:`to_global`), not before the draw: the table reads stay in
    range whatever the particle."""
    return unit_normal(n) & (a > 0.0) & math.isfinite(a)


_ONE_BITS_MINUS_1 = np.uint64(0x3FF0000000000000 - 1)    # the bits of 1.0, minus 1


@numba.njit(inline="always", **JIT)
def uniforms_ok(u):
    """The U_PER_DRAW = 13 uniforms of a draw (an array or a tuple) all in [+0, 1); NaN and −0 are not
    (rbs_uniforms_ok: on the bits b, b | (bits(1) − 1 − b) has its top bit clear exactly then). Checked with
    the result: the table indices are clamped into the drawn cell, so bad uniforms read in range and what
    they draw is discarded."""
    bad = (_outside(u[0]) | _outside(u[1]) | _outside(u[2]) | _outside(u[3]) | _outside(u[4]) | _outside(u[5])
           | _outside(u[6]) | _outside(u[7]) | _outside(u[8]) | _outside(u[9]) | _outside(u[10]) | _outside(u[11])
           | _outside(u[12]))
    return (bad >> np.uint64(63)) == np.uint64(0)


@numba.njit(inline="always", **JIT)
def _outside(x):
    """Top bit set unless x is in [+0, 1) (:func:`uniforms_ok`)."""
    b = bits(np.float64(x))
    return b | (_ONE_BITS_MINUS_1 - b)


@numba.njit(inline="always", **JIT)
def rebound_ok(V, W, n):
    """V⁺ and Ω⁺ (3-tuples) that may be reported as a rebound: all finite, and V⁺ leaving the wall
    (V⁺·n > 0); what overflows or underflows at extreme |V⁻| or a is not."""
    return (math.isfinite(V[0]) & math.isfinite(V[1]) & math.isfinite(V[2]) & math.isfinite(W[0])
            & math.isfinite(W[1]) & math.isfinite(W[2]) & (dot(V, n) > 0.0))


@numba.njit(inline="always", **JIT)
def dot(a, b):
    """a·b of two 3-vectors (tuples or arrays), the same bits wherever it is inlined."""
    return fma(a[0], b[0], fma(a[1], b[1], a[2] * b[2]))


@numba.njit(inline="always", **JIT)
def to_global(status, ok, vx, vy, vz, wx, wy, wz, speed, a, ex, n, ez):
    """A local draw (units |V⁻|, |V⁻|/a) as (status, V⁺ in m/s, Ω⁺ in rad/s) in the frame (ex, n, ez),
    3-tuples; the status is STATUS_INVALID unless ``ok`` (:func:`particle_ok`, :func:`uniforms_ok`) and,
    for a rebound, :func:`rebound_ok`. NaN unless rebounded."""
    w = speed / a
    v, o = (vx, vy, vz), (wx, wy, wz)
    V = (speed * dot(v, (ex[0], n[0], ez[0])), speed * dot(v, (ex[1], n[1], ez[1])),
         speed * dot(v, (ex[2], n[2], ez[2])))
    W = (w * dot(o, (ex[0], n[0], ez[0])), w * dot(o, (ex[1], n[1], ez[1])), w * dot(o, (ex[2], n[2], ez[2])))
    ok = ok & ((status != STATUS_REBOUNDED) | rebound_ok(V, W, n))
    status = status if ok else STATUS_INVALID
    rebounded = status == STATUS_REBOUNDED
    return status, V if rebounded else NAN3, W if rebounded else NAN3


# -- the frame record of a block ----------------------------------------------------------------------

FRAME_VALID, FRAME_ALPHA1, FRAME_SPEED, FRAME_COS, FRAME_SIN, FRAME_A, FRAME_EX, FRAME_EZ, FRAME_N = (
    0, 1, 2, 3, 4, 5, 6, 9, 12)    # valid (1.0 or 0.0), α1 deg, |V⁻| m/s, cos α1, sin α1, a m, ex, ez, n
FRAME_OK = 15                      # particle_ok and uniforms_ok (1.0 or 0.0), applied with the result (to_global)
FRAME_FIELDS = 16


@numba.njit(inline="always", **JIT)
def frame_block(V, n, a, ub, given, start, m, fr):
    """The frame records ``fr`` of the m rows from ``start`` (their uniforms ``ub``, checked if ``given``),
    computed for rows that do not move into the wall too (valid 0). V and n flat, row after row: a
    compile-time stride, which keeps the SIMD loop free of run-time stride checks."""
    for b in range(m):      # no branch and no table read: SIMD across the block
        i = start + b
        Vi, ni = (V[3 * i], V[3 * i + 1], V[3 * i + 2]), (n[3 * i], n[3 * i + 1], n[3 * i + 2])
        alpha1, speed, cos_a1, sin_a1, ex, ez = impact_frame(Vi, ni, ub[12 * BLOCK + b])
        put3(fr, FRAME_VALID, b, (1.0 if moves_into_wall(Vi, ni) else 0.0, alpha1, speed))
        # uniforms drawn from the lanes are in [0, 1): checked only when ``given`` (table_rebound_many), as pipeline.c
        fr[FRAME_OK * BLOCK + b] = 1.0 if particle_ok(ni, a[i]) & (not given or uniforms_ok(uniforms(ub, b))) else 0.0
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
