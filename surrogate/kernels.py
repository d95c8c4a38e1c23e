"""Numba kernels of the runtime sampler: O(1) work per reflected state.

These are plain functions over the arrays of a table (``table.kernel_data``, a
named tuple of arrays) and pre-drawn uniforms, so a flow solver can call them
from its own ``@njit`` loop. Every draw consumes exactly :data:`U_PER_DRAW`
uniforms from [0, 1)::

    u[0] shape from the mix        u[1] α1 neighbour       u[2] speed neighbour
    u[3] trapped or not            u[4] α2                 u[5] |β2|
    u[6] s and spin                u[7] mirror sign        u[8] in-wall axis at normal impact

Between grid points the sampler uses stochastic interpolation: the cell of the
neighbour at x_{j+1} is used with probability w = (x − x_j)/(x_{j+1} − x_j), as
Monte Carlo transport codes do between incident-energy points; a multimodal
law stays multimodal (no averaging of quantiles).

Frames and units: the local frame is the model's lab frame (wall y = 0,
normal +Y, impact plane XY, α1 from the wall); angles in radians except α1
(degrees), Ω in units of |V⁻|/a locally. The global kernel returns V⁺ in m/s
and Ω⁺ in rad/s.
"""

import math

import numba
import numpy as np

from data_schema.samples import STATUS_REBOUNDED, STATUS_TRAPPED

U_PER_DRAW = 9
WORK_SIZE = 12          # scratch floats :func:`rebound` needs
STATUS_INVALID = -1     # returned by :func:`rebound` for an incident state that does not hit the wall
JIT = dict(cache=True, nogil=True, fastmath=False, error_model="numpy")


@numba.njit(**JIT)
def locate(grid, lookup, scale, x):
    """(j, w): grid interval [g_j, g_{j+1}] holding x and the weight of g_{j+1} (O(1)).

    x must lie within the grid; a one-point grid gives (0, 0).
    """
    n = grid.shape[0]
    if n == 1:
        return 0, 0.0
    k = int((x - scale[0]) * scale[1])
    k = min(max(k, 0), lookup.shape[0] - 1)
    j = lookup[k]
    if j < n - 2 and x >= grid[j + 1]:
        j += 1
    w = (x - grid[j]) / (grid[j + 1] - grid[j])
    return j, min(max(w, 0.0), 1.0)


@numba.njit(**JIT)
def _lerp_row(q, u):
    """Quantile function q (levels k/L, k = 0..L) at probability u ∈ [0, 1): (value, interval)."""
    levels = q.shape[0] - 1
    p = u * levels
    k = min(int(p), levels - 1)
    return q[k] + (p - k) * (q[k + 1] - q[k]), k


@numba.njit(**JIT)
def draw_folded(data, s, ia, iv, u_alpha2, u_beta2, u_speed, out):
    """Draw the folded state (α2, |β2|, s, Ω_x, Ω_y, Ω_z) of one cell into out[0:6].

    Chain (data_schema.table): α2 from its quantile function; its equal-count
    bin b = ⌊u·B1⌋ selects the |β2| quantile function; the |β2| bin c = ⌊u·B2⌋
    selects the leaf whose s quantile function gives s and, from the same
    interval index, the spin atom.
    """
    a_q = data.alpha2_q[s, ia, iv]
    b_q = data.beta2_q[s, ia, iv]
    s_q = data.speed_q[s, ia, iv]
    out[0], _ = _lerp_row(a_q, u_alpha2)
    b = min(int(u_alpha2 * b_q.shape[0]), b_q.shape[0] - 1)
    out[1], _ = _lerp_row(b_q[b], u_beta2)
    c = min(int(u_beta2 * s_q.shape[1]), s_q.shape[1] - 1)
    out[2], j = _lerp_row(s_q[b, c], u_speed)
    spin = data.spin[s, ia, iv, b, c, j]
    out[3], out[4], out[5] = spin[0], spin[1], spin[2]


@numba.njit(**JIT)
def draw_local(data, mix_cdf, alpha1, speed, u, out):
    """One reflected state at (α1 deg, |V⁻| m/s) in the local frame; returns the status.

    ``mix_cdf`` is the cumulative shape weights in the table's shape order
    (last entry 1). On return out[0:6] = (α2, β2, s, Ω_x a/|V⁻|, Ω_y a/|V⁻|,
    Ω_z a/|V⁻|) for a rebound, NaN for a trapped particle. α1 and |V⁻| must lie
    within the table's grid (the Python API checks or clamps them).
    """
    shape = 0
    while shape < mix_cdf.shape[0] - 1 and u[0] >= mix_cdf[shape]:
        shape += 1
    ja, wa = locate(data.alpha1_deg, data.alpha1_lookup, data.alpha1_scale, alpha1)
    jv, wv = locate(data.speed, data.speed_lookup, data.speed_scale, speed)
    ia = ja + 1 if u[1] < wa else ja
    iv = jv + 1 if u[2] < wv else jv
    if u[3] < data.p_trapped[shape, ia, iv]:
        out[:6] = np.nan
        return STATUS_TRAPPED
    draw_folded(data, shape, ia, iv, u[4], u[5], u[6], out)
    if u[7] < 0.5:
        out[1] = -out[1]
        out[3] = -out[3]
        out[4] = -out[4]
    return STATUS_REBOUNDED


@numba.njit(**JIT)
def impact_frame(V, n, u_axis, ex, ez):
    """In-wall axes of the impact frame: ex along the tangential part of V, ez = ex × n.

    At normal impact (tangential part below 1e-12 |V|) ex is uniform in the wall
    plane, from ``u_axis``. Returns (α1 in degrees, |V|).
    """
    vn = V[0] * n[0] + V[1] * n[1] + V[2] * n[2]
    tx, ty, tz = V[0] - vn * n[0], V[1] - vn * n[1], V[2] - vn * n[2]
    vt = math.sqrt(tx * tx + ty * ty + tz * tz)
    speed = math.sqrt(vn * vn + vt * vt)
    if vt > 1e-12 * speed:
        ex[0], ex[1], ex[2] = tx / vt, ty / vt, tz / vt
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
        phi = 2.0 * math.pi * u_axis
        c, s = math.cos(phi), math.sin(phi)
        ex[0], ex[1], ex[2] = c * px + s * qx, c * py + s * qy, c * pz + s * qz
    ez[0] = ex[1] * n[2] - ex[2] * n[1]
    ez[1] = ex[2] * n[0] - ex[0] * n[2]
    ez[2] = ex[0] * n[1] - ex[1] * n[0]
    return math.degrees(math.atan2(-vn, vt)), speed


@numba.njit(**JIT)
def rebound(data, mix_cdf, V, n, a, u, V_out, W_out, work):
    """Reflected state of one particle in the global frame; returns the status.

    Parameters
    ----------
    data : ``table.kernel_data``.
    mix_cdf : cumulative shape weights (table shape order).
    V : (3,) incident velocity, m/s; must move into the wall (V·n < 0).
    n : (3,) unit wall normal pointing into the gas.
    a : particle half-size (half its largest extent), m.
    u : (U_PER_DRAW,) uniforms in [0, 1).
    V_out, W_out : (3,) outputs: V⁺ in m/s and Ω⁺ in rad/s (NaN unless rebounded).
    work : (WORK_SIZE,) scratch array.

    Returns STATUS_REBOUNDED, STATUS_TRAPPED, or STATUS_INVALID when V does not
    move into the wall (V·n ≥ 0, zero or non-finite). The impact frame is ex
    (tangential direction of V), n, ez = ex × n; the local draw is rotated back
    into the global frame. The mirror symmetry of the model is applied with a
    random sign inside :func:`draw_local`. An α1 or |V⁻| outside the table's
    grid uses the law at the nearest grid edge (check ``table.alpha1_range``
    and ``table.speed_range`` beforehand if that matters); n is assumed unit.
    """
    ex = work[0:3]
    ez = work[3:6]
    state = work[6:12]
    vn = V[0] * n[0] + V[1] * n[1] + V[2] * n[2]
    if not vn < 0.0 or not math.isfinite(V[0] + V[1] + V[2]):
        V_out[:] = np.nan
        W_out[:] = np.nan
        return STATUS_INVALID
    alpha1, speed = impact_frame(V, n, u[8], ex, ez)
    status = draw_local(data, mix_cdf, alpha1, speed, u, state)
    if status != STATUS_REBOUNDED:
        V_out[:] = np.nan
        W_out[:] = np.nan
        return status
    alpha2, beta2 = state[0], state[1]
    vs = state[2] * speed
    lx, ly, lz = vs * math.cos(beta2) * math.cos(alpha2), vs * math.cos(beta2) * math.sin(alpha2), vs * math.sin(beta2)
    w = speed / a
    for k in range(3):
        V_out[k] = lx * ex[k] + ly * n[k] + lz * ez[k]
        W_out[k] = w * (state[3] * ex[k] + state[4] * n[k] + state[5] * ez[k])
    return status


@numba.njit(parallel=True, **JIT)
def rebound_batch(data, mix_cdf, V, n, a, u, V_out, W_out, status):
    """:func:`rebound` for every row (parallel); u has shape (N, U_PER_DRAW)."""
    for i in numba.prange(V.shape[0]):
        work = np.empty(WORK_SIZE)
        status[i] = rebound(data, mix_cdf, V[i], n[i], a[i], u[i], V_out[i], W_out[i], work)


@numba.njit(parallel=True, **JIT)
def draw_local_batch(data, mix_cdf, alpha1, speed, u, out, status):
    """:func:`draw_local` for every row (parallel)."""
    for i in numba.prange(alpha1.shape[0]):
        status[i] = draw_local(data, mix_cdf, alpha1[i], speed[i], u[i], out[i])
