"""Stage 3 of a draw, arithmetic: the reflected state from its gathered values alone
(:func:`arithmetic`). The chain of the six state variables, the fold into the
physical ranges, the move to the incident α1 and |V⁻|, the mirror sign: no
table read and no branch (every choice a select), so the pipeline runs it as a
SIMD loop over a block and one particle calls the same function; the two give
the same bits by construction.

Its block form: :func:`arithmetic_block` draws the m particles of a gathered
block (:mod:`surrogate.kernels.gather`), turns them back to the global frame
and stores them in the caller's rows; its scratch ``out`` holds the results
(OUT_* fields, :mod:`surrogate.kernels.block`).
"""

import math

import numba
import numpy as np

from data_schema.samples import STATUS_INVALID, STATUS_REBOUNDED, STATUS_TRAPPED
from direct_model.elementary import fma, sincos
from surrogate.kernels.block import BLOCK, field, put3
from surrogate.kernels.frame import FRAME_OK, frame_at, is_valid, to_global
from surrogate.kernels.gather import gathered_at
from surrogate.kernels.options import JIT, KERNEL


@numba.njit(inline="always", **JIT)
def _chain(q, b):
    """The folded state (α2, |β2|, s, Ω_x, Ω_y, Ω_z) of one component from its residual quantiles ``q``.

    Chain variable k (α2, |β2|, s, Ω_z, Ω_x, Ω_y) is its residual quantile
    shifted by the component's slopes ``b`` on the variables already drawn
    (x_k on x_i at b[k(k−1)/2 + i]), then folded into the physical ranges
    (:func:`_folded`).
    """
    # each x_k gathers its terms in the order the x_i become available: one fused multiply-add after x_{k−1}
    x0 = q[0]
    x1 = fma(b[0], x0, q[1])
    x2 = fma(b[2], x1, fma(b[1], x0, q[2]))
    x3 = fma(b[5], x2, fma(b[4], x1, fma(b[3], x0, q[3])))
    x4 = fma(b[9], x3, fma(b[8], x2, fma(b[7], x1, fma(b[6], x0, q[4]))))
    x5 = fma(b[14], x4, fma(b[13], x3, fma(b[12], x2, fma(b[11], x1, fma(b[10], x0, q[5])))))
    return _folded(x0, x1, x2, x4, x5, x3)


@numba.njit(inline="always", **JIT)
def _folded(alpha2, beta2, s, wx, wy, wz):
    """The state (state order) reflected into the range of a rebound: α2 into [0, π], β2 below π/2, s into [0, 1].

    The linear shifts of the chain and of the α1 move can step outside by a
    hair for a rare draw (docs/format.md, "The stored law of a cell").
    Reflected at the edge, such a draw stays a rebound that
    leaves the wall (V⁺·n = s sin α2 cos β2 > 0) and gains no kinetic energy
    (s ≤ 1: tables are built with Ω⁻ = 0, so |V⁺| ≤ |V⁻|); a cap would put it
    on the edge, where s = 0 or β2 = π/2 gives V⁺·n = 0 and s = 1 an elastic
    rebound. β2 < 0 is left as drawn: it is a valid state (the mirror sign is
    drawn afterwards).
    """
    alpha2, s = abs(alpha2), abs(s)
    return (2.0 * math.pi - alpha2 if alpha2 > math.pi else alpha2, math.pi - beta2 if beta2 > 0.5 * math.pi else beta2,
            2.0 - s if s > 1.0 else s, wx, wy, wz)


@numba.njit(inline="always", **JIT)
def _moved(state, terms):
    """The folded ``state`` of a draw moved to the incident α1 with the ``terms`` of
    :func:`surrogate.kernels.gather._alpha1_terms`,
    variable by variable, like the unit-base interpolation of transport codes, then folded again. The
    centred variables (β2, Ω_x, Ω_y: mean 0 by the mirror symmetry) are only scaled."""
    return _folded(_shifted(state[0], terms[0]), state[1] * terms[1][0], _shifted(state[2], terms[2]),
                   state[3] * terms[3][0], state[4] * terms[4][0], _shifted(state[5], terms[5]))


@numba.njit(inline="always", **JIT)
def _shifted(x, term):
    """m + (x − m_cell) · ratio."""
    ratio, mean_cell, mean = term
    return fma(x - mean_cell, ratio, mean)


@numba.njit(inline="always", **JIT)
def _velocity(alpha2, beta2, s):
    """V⁺ (local frame, units of |V⁻|) of a rebound at (α2, β2) with speed ratio s."""
    sb, cb = sincos(beta2)
    sa, ca = sincos(alpha2)
    scb = s * cb
    return scb * ca, scb * sa, s * sb


@numba.njit(inline="always", **JIT)
def at_alpha1(gathered, scaled):
    """The folded state (state order) of the draw of the ``gathered`` values (:func:`surrogate.kernels.gather.gather`)
    at its grid speed: the chain (:func:`_chain`), then with ``scaled`` the move to the incident α1 when wa > 0
    (:func:`_moved`)."""
    q, slopes, _, _, _, wa, _, ratio, shift, _, _ = gathered
    state = _chain(q, slopes)
    terms = ((ratio[0], shift[0], shift[1]), (ratio[1], 0.0, 0.0), (ratio[2], shift[2], shift[3]),
             (ratio[3], 0.0, 0.0), (ratio[4], 0.0, 0.0), (ratio[5], shift[4], shift[5]))
    return _pick6(scaled and wa > 0.0, _moved(state, terms), state)


@numba.njit(inline="always", **JIT)
def restitutions(f_target, f_grid, sin_alpha1):
    """(a(V), a(V_iv)): the wall law's normal restitution a = 1 − (1 − f) sin α1 at the incident and the drawn grid
    speed, from its factors f there (:func:`to_speed`)."""
    return 1.0 - (1.0 - f_target) * sin_alpha1, 1.0 - (1.0 - f_grid) * sin_alpha1


@numba.njit(inline="always", **JIT)
def speed_factors(regime, f_target, f_grid, sin_alpha1):
    """(few, f, g) of :func:`to_speed`: whether the regime is 0; the factor f of V⁺ − V⁻ (regime 0) or of the
    normal rebound velocity (regime 1); the factor g of the spin and of V⁺ − V⁻ off the normal."""
    a_target, a_grid = restitutions(f_target, f_grid, sin_alpha1)
    # both laws computed, the regime's picked by selects: the regime varies from draw to draw, a branch
    # on it would be mispredicted often
    few = regime == 0.0
    f = (1.0 + a_target) / (1.0 + a_grid) if few else a_target / a_grid
    return few, f, f if few else 1.0


@numba.njit(inline="always", **JIT)
def to_speed(regime, f_target, f_grid, cos_alpha1, sin_alpha1, vx, vy, vz, wx, wy, wz):
    """A rebound drawn at grid speed V_iv, moved to the incident speed V; returns (vx, vy, vz, wx, wy, wz).

    ``f_target``, ``f_grid``: the wall's restitution factor f, its a_nc at normal impact (exp(−k V^p) for
    the exponential law), at V and at V_iv (:func:`surrogate.kernels.gather.restitution_factors`). Local
    frame, V⁺ in units of |V⁻|, Ω⁺ in units of |V⁻|/a. With a(V) = 1 − (1 − f(V)) sin α1, the normal
    restitution of the wall law for a contact point moving like the centre of mass (a tabulated law's
    own a_nc where it is linear in the sine from 1 at sine 0, as calibrate writes it):

    * regime 0 (at most two collisions): the velocity change V⁺ − V⁻ and the
      spin Ω⁺ are multiplied by (1 + a(V))/(1 + a(V_iv)). For one
      frictionless collision this is exact: the impulse is (1 + a) times the
      incident normal velocity over the contact's effective inverse mass.
    * regime 1 (more collisions): the normal rebound velocity is multiplied
      by a(V)/a(V_iv), the rest kept (the last, slow contacts set it).

    One law per regime because neither alone follows the direct model near
    normal impact for every shape (docs/design/table_representation.md). A
    normal velocity the shift would reverse is reflected (the rebound must
    leave the wall), and so is a speed it would lift above |V⁻| (|V⁺| = s > 1
    becomes 2 − s, as the chain's s is folded: a rebound gains no kinetic
    energy).
    """
    few, f, g = speed_factors(regime, f_target, f_grid, sin_alpha1)
    vx_few, vy_few = fma(f, vx - cos_alpha1, cos_alpha1), abs(fma(f, vy + sin_alpha1, -sin_alpha1))
    vx, vy, vz = vx_few if few else vx, vy_few if few else vy * f, g * vz
    s = math.sqrt(fma(vx, vx, fma(vy, vy, vz * vz)))
    shrink = (2.0 - s) / s if s > 1.0 else 1.0      # × 1.0 changes no bit of the other draws
    return vx * shrink, vy * shrink, vz * shrink, g * wx, g * wy, g * wz


# |V⁺|²/|V⁻|² a rebound may reach above 1: the round-off of the sines and cosines that build V⁺ from s ≤ 1
SPEED_TOLERANCE = 1e-12


@numba.njit(inline="always", **JIT)
def drawn_ok(vx, vy, vz):
    """A drawn V⁺ (local frame, units of |V⁻|) that may be reported as a rebound, whatever table was loaded:
    leaving the wall (V⁺_y > 0) and no faster than it came (|V⁺| ≤ |V⁻| up to :data:`SPEED_TOLERANCE`; tables
    are built with Ω⁻ = 0, so a table draw never gains kinetic energy). A valid table's draws always pass (the
    folds of :func:`_folded` and :func:`to_speed`); values outside docs/format.md's bounds might not."""
    return (vy > 0.0) & (speed_ratio_squared(vx, vy, vz) <= 1.0 + SPEED_TOLERANCE)


@numba.njit(inline="always", **JIT)
def speed_ratio_squared(vx, vy, vz):
    """s² = |V⁺|²/|V⁻|² of a local-frame V⁺ in units of |V⁻|."""
    return fma(vx, vx, fma(vy, vy, vz * vz))


@numba.njit(inline="always", **JIT)
def arithmetic(gathered, cos_alpha1, sin_alpha1, scaled):
    """The reflected state from the values :func:`surrogate.kernels.gather.gather` returns, at cos α1, sin α1:
    (status, V⁺_x, V⁺_y, V⁺_z, Ω_x, Ω_y, Ω_z), local frame, V⁺ in units of |V⁻|, Ω in units of |V⁻|/a;
    NaN and STATUS_TRAPPED when trapped; STATUS_INVALID for a draw that fails :func:`drawn_ok`.

    The chain (:func:`_chain`), then with ``scaled`` the move to the incident α1 when wa > 0
    (:func:`_moved`) and to the incident speed when wv > 0 (:func:`to_speed`), then the mirror sign.
    No table read and no branch (every choice a select), so a loop of it over a block of particles runs
    as SIMD instructions.
    """
    q, slopes, regime, trapped, mirror, wa, wv, ratio, shift, f_target, f_grid = gathered
    state = at_alpha1(gathered, scaled)
    vx, vy, vz = _velocity(state[0], state[1], state[2])
    local = (vx, vy, vz, state[3], state[4], state[5])
    moved = to_speed(regime, f_target, f_grid, cos_alpha1, sin_alpha1, vx, vy, vz, state[3], state[4], state[5])
    vx, vy, vz, wx, wy, wz = _pick6(scaled and wv > 0.0, moved, local)
    status, vx, vy, vz, wx, wy, wz = _mirrored(mirror, vx, vy, vz, wx, wy, wz)
    status = status if drawn_ok(vx, vy, vz) else STATUS_INVALID
    out = _pick6(trapped > 0.5, NAN6, (vx, vy, vz, wx, wy, wz))
    return (STATUS_TRAPPED if trapped > 0.5 else status,) + out


NAN6 = (np.nan, np.nan, np.nan, np.nan, np.nan, np.nan)


@numba.njit(inline="always", **JIT)
def _pick6(c, x, y):
    """x if c else y for two 6-tuples, element by element (selects, which vectorise)."""
    return (x[0] if c else y[0], x[1] if c else y[1], x[2] if c else y[2], x[3] if c else y[3],
            x[4] if c else y[4], x[5] if c else y[5])


@numba.njit(inline="always", **JIT)
def _mirrored(u, vx, vy, vz, wx, wy, wz):
    """(STATUS_REBOUNDED, state) with the mirror symmetry Z → −Z applied when u < 1/2."""
    mirror = -1.0 if u < 0.5 else 1.0
    return STATUS_REBOUNDED, vx, vy, mirror * vz, mirror * wx, mirror * wy, wz


# -- the results of a block --------------------------------------------------------------------------

OUT_STATUS, OUT_V, OUT_OMEGA = 0, 1, 4      # status, V⁺ (m/s), Ω⁺ (rad/s), global frame
OUT_S2 = 7                                  # s² = |V⁺|²/|V⁻|² of the local draw, for its work on the wall
OUT_FIELDS = 8


@numba.njit(**KERNEL)
def arithmetic_block(g, fr, out, V_out, Omega_out, status, start, m, scaled):
    """Stage 3 for the m particles of a gathered block (gathered records ``g``, frame records ``fr``): the
    draws (SIMD), back in the global frame, stored in rows start … start + m − 1 of the caller's arrays."""
    for b in range(m):      # no branch and no table read: SIMD across the block
        _draw_global(g, fr, out, b, scaled)
    for b in range(m):
        i = start + b
        if is_valid(fr, b):
            status[i] = int(out[OUT_STATUS * BLOCK + b])
            for k in range(3):
                V_out[i, k], Omega_out[i, k] = out[(OUT_V + k) * BLOCK + b], out[(OUT_OMEGA + k) * BLOCK + b]
        else:       # what one particle's rebound returns for a row that does not move into the wall
            status[i] = STATUS_INVALID
            for k in range(3):
                V_out[i, k], Omega_out[i, k] = np.nan, np.nan


@numba.njit(inline="always", **JIT)
def _draw_global(g, fr, out, b, scaled):
    """Particle b's draw (:func:`arithmetic`), then :func:`surrogate.kernels.frame.to_global`, into ``out``."""
    _, speed, cos_a1, sin_a1, a, ex, ez, n = frame_at(fr, b)
    status, vx, vy, vz, wx, wy, wz = arithmetic(gathered_at(g, b), cos_a1, sin_a1, scaled)
    status, V_new, Omega_new = to_global(status, field(fr, FRAME_OK, b) != 0.0, vx, vy, vz, wx, wy, wz, speed, a,
                                         ex, n, ez)
    out[OUT_STATUS * BLOCK + b] = status
    out[OUT_S2 * BLOCK + b] = speed_ratio_squared(vx, vy, vz)
    put3(out, OUT_V, b, V_new)
    put3(out, OUT_OMEGA, b, Omega_new)
