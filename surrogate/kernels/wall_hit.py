"""Every wall hit answered, spinning or not: the table where it is valid, the direct model elsewhere.

A table holds the law of particles that do not spin before they hit (Ω⁻ = 0), on its α1 and |V⁻| grid. For
any other hit the direct model (:mod:`surrogate.kernels.direct_path`) answers, per particle, at run time.
:func:`rebound_path` says which *path* answers a hit (a pure function of the state and the method);
:func:`rebound` answers one hit by that path; :func:`rebound_parallel_rng` answers many on all
threads.

Methods (integer codes, as in C): METHOD_AUTO, the table iff |Ω⁻| a/|V⁻| ≤ SPIN_TOLERANCE and α1 lies in the
table's [first, last] α1 grid range and |V⁻| in its speed range (inclusive; α1 and |V⁻| computed as the
table path computes them, :func:`surrogate.kernels.frame.incidence`), otherwise the direct model;
METHOD_TABLE, always the table (the law of the nearest grid edge outside the grid, Ω⁻ ignored);
METHOD_DIRECT, always the direct model. Paths (:mod:`surrogate.kernels.hit`): PATH_TABLE, PATH_DIRECT; PATH_NONE
for a hit refused.

One hit consumes U_PER_DRAW = 13 uniforms whatever path answers it, so streams stay aligned. The table path
is :func:`surrogate.kernels.table_path.table_rebound` with those 13. The direct path draws the shape from the mix
with u[0] exactly as the table path does (:func:`surrogate.kernels.locate.locate`), maps the table's shape to
its index in the direct model's shapes (``model_shapes``, into ``shape_arrays``), and gives the model u[1..7] as
its U_PER_REBOUND uniforms (u[1 + k]
is the model's u[k]; the axis at normal impact is u[7]). :func:`rebound_parallel_rng` also takes one shape per
particle (``shapes``, the table's shape index, or SHAPE_FROM_MIX): a particle given its shape still consumes its
u[0], on either path (:func:`surrogate.kernels.locate.row_shape`). A particle of a grain key (``key``,
``keys``) hits as its own grain: its shape from the key on either path, its proportions and hand too on the
direct path (:mod:`surrogate.kernels.grain`).

Like the table path's kernels (:mod:`surrogate.kernels.table_path`), :func:`rebound` converts its arguments to one
set of types; its ``_typed`` twin, inlined (a call would pass the table's arrays once more), only picks the path,
whose kernels (``table_rebound_typed``, the direct path) are compiled once per process. The single-hit kernels
run without numba's reference counting (``KERNEL``), their scratch space in their stack frame
(:func:`surrogate.kernels.memory.stack_scratch`).

Units and frames: V in m/s, Ω in rad/s, a in m, all in the caller's frame; n the unit wall normal into the
gas. Statuses: STATUS_REBOUNDED, STATUS_TRAPPED, STATUS_FAILED (direct model only: a collision solve or a
contact search failed; NaN vectors), STATUS_INVALID (NaN vectors).
"""

import math

import numba
import numpy as np

from data_schema.samples import STATUS_FAILED, STATUS_INVALID, STATUS_REBOUNDED, STATUS_TRAPPED
from direct_model.runtime import N_PARAMS, SCRATCH_SIZE, U_PER_REBOUND
from direct_model.wall import MAX_ROUGHNESS_DEG
from surrogate.kernels.direct_path import direct_rebound_typed
from surrogate.kernels.draw import U_PER_DRAW
from surrogate.kernels.facet import facet_key, facet_normal
from surrogate.kernels.frame import NAN3, dot, float3, incidence, incidence_angle, particle_ok, uniforms_ok
from surrogate.kernels.hit import PATH_DIRECT, PATH_NONE, PATH_TABLE, hit, invalid_hit, put_hit
from surrogate.kernels.grain import NO_KEY, grain_shape, keyed_shapes, keyed_uniforms
from surrogate.kernels.layout import AXIS_GRID
from surrogate.kernels.locate import SHAPE_FROM_MIX, mix_shape
from surrogate.kernels.memory import stack_scratch
from surrogate.kernels.checks import check_keys, check_shapes
from surrogate.kernels.options import JIT, KERNEL
from surrogate.kernels.pipeline import no_uniforms, run_blocks, table_rebound_uniforms
from surrogate.kernels.rng import CHUNK_ROWS, grain_uniform
from surrogate.kernels.table_path import table_rebound_typed, table_shape_rebound

METHOD_AUTO, METHOD_TABLE, METHOD_DIRECT = 0, 1, 2
# largest |Ω⁻| a/|V⁻| the table answers under METHOD_AUTO: where the table's law and the direct model's with
# that spin stay within classifier accuracy 0.52, measured (docs/design/spin_tolerance.md; 0.0015 fails)
SPIN_TOLERANCE = 0.001
MAX_WALL_HITS = 10      # facet hits of one hit on a rough wall; a rebound still into the mean wall then is trapped


@numba.njit(inline="always", **JIT)
def _grid_bounds(data):
    """The table's grid ranges: (first α1, last α1) in degrees, (first |V⁻|, last |V⁻|) in m/s."""
    return ((data.alpha1_axis[AXIS_GRID], data.alpha1_axis[AXIS_GRID + data.n_alpha1 - 1]),
            (data.speed_axis[AXIS_GRID], data.speed_axis[AXIS_GRID + data.n_speed - 1]))


@numba.njit(inline="always", **JIT)
def _auto_path(bounds, V, omega, n, a):
    """:func:`rebound_path` under METHOD_AUTO, ``bounds`` from :func:`_grid_bounds`."""
    vn, _, _, _, vt, speed = incidence(V, n)
    alpha1 = incidence_angle(vn, vt)
    spin = a * math.sqrt(dot(omega, omega)) / speed
    (alpha1_lo, alpha1_hi), (speed_lo, speed_hi) = bounds
    table = ((spin <= SPIN_TOLERANCE) & (alpha1 >= alpha1_lo) & (alpha1 <= alpha1_hi) & (speed >= speed_lo)
             & (speed <= speed_hi))
    valid = ((vn < 0.0) & math.isfinite(V[0] + V[1] + V[2]) & particle_ok(n, a)
             & math.isfinite(omega[0] + omega[1] + omega[2]))
    return np.int8(PATH_TABLE if table else PATH_DIRECT) if valid else np.int8(PATH_NONE)


@numba.njit(**KERNEL)
def rebound_path(data, V, omega, n, a, method):
    """Which path answers a hit: PATH_TABLE or PATH_DIRECT; PATH_NONE for a bad input.

    Parameters
    ----------
    data : ``table.kernel_data``.
    V : incident velocity V⁻, m/s, caller's frame (3-tuple or (3,) array); must move into the wall (V·n < 0).
    omega : incident angular velocity Ω⁻, rad/s, caller's frame; finite.
    n : unit wall normal into the gas (| |n| − 1 | ≤ NORMAL_TOLERANCE).
    a : half-size (half the largest extent), m, finite and > 0.
    method : METHOD_AUTO, METHOD_TABLE or METHOD_DIRECT (module doc).

    A pure function of the state: a caller learns the path of a hit without drawing anything.
    """
    path = _auto_path(_grid_bounds(data), V, omega, n, a)
    if path == PATH_NONE or method == METHOD_AUTO:
        return path
    if method == METHOD_TABLE:
        return PATH_TABLE
    return PATH_DIRECT if method == METHOD_DIRECT else PATH_NONE


@numba.njit(**KERNEL)
def rebound(data, params, shape_arrays, model_shapes, mix_cdf, V, omega, n, a, u, method=METHOD_AUTO, scaled=True,
            key=None, roughness_deg=0.0):
    """One hit answered by its path (:func:`rebound_path`): a :class:`surrogate.kernels.hit.Hit` (status, path,
    the particle's shape in the table, the direct path's collisions, V⁺ in m/s and Ω⁺ in rad/s in the caller's
    frame; read it by name, ``hit.V``).

    Parameters
    ----------
    data : ``table.kernel_data``.
    params : ``table.direct_parameters`` (:func:`direct_model.runtime.model_parameters`); a table without
        them: an empty array, and a hit the direct model must answer is STATUS_INVALID.
    shape_arrays : ``table.shape_arrays``, the direct model's shapes (:class:`direct_model.shape_arrays.ShapeArrays`).
    model_shapes : ``table.model_shapes``, (n_shapes,) int64: each table shape's index in ``shape_arrays``.
    mix_cdf : cumulative shape weights, table shape order (:func:`surrogate.mix_cdf`).
    V, omega, n, a, method : as :func:`rebound_path`.
    u : (U_PER_DRAW,) array of uniforms in [0, 1) (module doc for how each path uses them).
    scaled : the table path's interpolation (:func:`surrogate.kernels.table_path.table_rebound`).
    key : None (the default: no key, the draws of u alone; the keyed code is not even compiled) or the
        particle's grain key, an int ≥ 0 (:mod:`surrogate.kernels.grain`: its shape on either path, and on the
        direct path its proportions and hand, are the key's, whatever u[0], u[4], u[5], u[6] are; the 13
        uniforms are still all checked).
    roughness_deg : the wall's roughness Δγ, degrees, in [0, MAX_ROUGHNESS_DEG]: 0 (the default) a smooth wall
        (the hit above, bit for bit); above, :func:`rough_rebound`'s facet hits.

    Status STATUS_REBOUNDED, STATUS_TRAPPED, STATUS_FAILED (direct path only) or STATUS_INVALID (bad input,
    a uniform outside [0, 1) whatever the path, a method not in the three, a key < 0; then path PATH_NONE);
    NaN vectors unless rebounded.
    """
    code = np.int64(NO_KEY) if key is None else np.int64(key) if key >= 0 else np.int64(_BAD_KEY)
    return _rebound(data, params, shape_arrays, model_shapes, mix_cdf, float3(V), float3(omega), float3(n), float(a),
                    u, np.int64(method), scaled != 0, code, float(roughness_deg))


_BAD_KEY = NO_KEY - 1       # :func:`rebound`'s code of a key given < 0: refused (NO_KEY is no key at all)


@numba.njit(**KERNEL)
def _rebound(data, params, shape_arrays, model_shapes, mix_cdf, V, omega, n, a, u, method, scaled, key,
             roughness_deg):
    """:func:`rebound` with its arguments of one set of types (``key``: NO_KEY for none, _BAD_KEY for one < 0):
    compiled once per type of ``u`` whatever types the callers pass (only their conversion is compiled for
    them)."""
    if roughness_deg != 0.0:
        return _rough_on_stack(data, params, shape_arrays, model_shapes, mix_cdf, np.int64(SHAPE_FROM_MIX), key, V,
                               omega, n, a, u, scaled, method, roughness_deg)     # int64: _rough_chunk's types
    path = rebound_path(data, V, omega, n, a, method)
    if key != NO_KEY:
        return _keyed_rebound(data, params, shape_arrays, model_shapes, mix_cdf, V, omega, n, a, u, scaled, path,
                              key)
    return rebound_typed(data, params, shape_arrays, model_shapes, mix_cdf, V, omega, n, a, u, scaled, path)


@numba.njit(inline="always", **JIT)
def _keyed_rebound(data, params, shape_arrays, model_shapes, mix_cdf, V, omega, n, a, u, scaled, path, key):
    """:func:`rebound` of a particle of grain key ``key`` along its path ``path``: u with the key's slots."""
    if key < 0 or path == PATH_NONE or not uniforms_ok(u):
        return invalid_hit()
    keyed = stack_scratch(U_PER_DRAW)
    keyed_uniforms(key, u, path == PATH_DIRECT, keyed)
    return rebound_typed(data, params, shape_arrays, model_shapes, mix_cdf, V, omega, n, a, keyed, scaled, path)


@numba.njit(inline="always", **KERNEL)
def rebound_typed(data, params, shape_arrays, model_shapes, mix_cdf, V, omega, n, a, u, scaled, path):
    """:func:`rebound` along its path ``path`` with the uniforms ``u``: V, omega and n 3-tuples of float64, a a
    float64, ``scaled`` a bool (module doc)."""
    if path == PATH_TABLE:
        return table_rebound_typed(data, mix_cdf, V, n, a, u, scaled)
    if path == PATH_DIRECT:
        return _direct_path_on_stack(params, shape_arrays, model_shapes, mix_cdf, V, omega, n, a, u)
    return invalid_hit()


@numba.njit(**KERNEL)
def _direct_path_on_stack(params, shape_arrays, model_shapes, mix_cdf, V, omega, n, a, u):
    """The direct path of :func:`rebound_typed`, its scratch space in this kernel's stack frame."""
    return _direct_path(params, shape_arrays, model_shapes, mix_cdf, SHAPE_FROM_MIX, V, omega, n, a, u,
                        stack_scratch(SCRATCH_SIZE))


@numba.njit(inline="always", **JIT)
def _direct_path(params, shape_arrays, model_shapes, mix_cdf, shape, V, omega, n, a, u, scratch):
    """The direct path of :func:`rebound` with its scratch space given; ``shape`` the table's shape index, or
    SHAPE_FROM_MIX to draw it from the mix with u[0]."""
    if not (uniforms_ok(u) and params.shape[0] == N_PARAMS and model_shapes.shape[0] == mix_cdf.shape[0]):
        return invalid_hit()
    if shape == SHAPE_FROM_MIX:
        shape = mix_shape(mix_cdf, u[0])       # the table path's shape draw
    result = direct_rebound_typed(params, shape_arrays, model_shapes[shape], V, omega, n, a, u[1:1 + U_PER_REBOUND],
                                  scratch)
    return hit(result.status, result.path, shape, result.n_collisions, result.V, result.Omega, 1,
               result.wall_work_normal, result.wall_work_tangential)


@numba.njit(**KERNEL)
def _rough_on_stack(data, params, shape_arrays, model_shapes, mix_cdf, shape, key, V, omega, n, a, u, scaled, method,
                    roughness_deg):
    """:func:`rough_rebound`, its scratch space in this kernel's stack frame."""
    return rough_rebound(data, params, shape_arrays, model_shapes, mix_cdf, shape, key, V, omega, n, a, u, scaled,
                         method, roughness_deg, stack_scratch(SCRATCH_SIZE), stack_scratch(U_PER_DRAW))


@numba.njit(inline="always", **JIT)
def rough_rebound(data, params, shape_arrays, model_shapes, mix_cdf, shape, key, V, omega, n, a, u, scaled, method,
                  roughness_deg, scratch, facet_u):
    """One hit on a rough wall of roughness Δγ = ``roughness_deg`` (> 0, degrees; docs/model.md §12): a
    :class:`surrogate.kernels.hit.Hit` whose ``wall_hits`` counts its facet hits.

    The hit on the mean wall (unit normal n) is checked as :func:`rebound`'s; its shape is ``shape`` (the table's
    index), or with SHAPE_FROM_MIX the grain key's (``key`` ≥ 0) or the mix's with u[0]. Then, up to
    MAX_WALL_HITS times: a facet under the particle (:func:`surrogate.kernels.facet.facet_normal`), the hit on it
    along its own path (:func:`rebound_path` with the facet's normal and ``method``: the table where it holds,
    the direct model elsewhere, a grain key's slots as :func:`rebound`'s), and, if the rebound still moves into
    the mean wall (V⁺·n ≤ 0), the next facet hit from that rebound's V⁺, Ω⁺, of the same shape. The first facet
    hit takes u; the facets and every later hit take keyed uniforms of the hit's facet key
    (:mod:`surrogate.kernels.facet`). A rebound still into the mean wall after MAX_WALL_HITS facet hits is
    STATUS_TRAPPED; a facet not found (probability below 1e-13) STATUS_FAILED. ``path`` and ``n_collisions``
    are the last facet hit's. The wall work (``wall_work_normal``, ``wall_work_tangential``, m²/s²) is the sum of
    the facet hits' (summed in their order from 0; those before a facet not found), NaN if any of them was
    answered by a table without the work (format 4.0). ``scratch`` (SCRATCH_SIZE,) and ``facet_u`` (U_PER_DRAW,)
    float64: work space."""
    path = rebound_path(data, V, omega, n, a, method)
    if (path == PATH_NONE or key < NO_KEY or not uniforms_ok(u) or not 0.0 < roughness_deg <= MAX_ROUGHNESS_DEG
            or shape < SHAPE_FROM_MIX or shape >= mix_cdf.shape[0]):
        return invalid_hit()
    if shape == SHAPE_FROM_MIX:
        shape = grain_shape(mix_cdf, key) if key >= 0 else mix_shape(mix_cdf, u[0])
    facets = facet_key(u)
    slot = 0
    for k in range(U_PER_DRAW):
        facet_u[k] = u[k]
    result = invalid_hit()
    work_n, work_t = 0.0, 0.0           # the facet hits' wall work (a NaN, a table without it, stays NaN)
    for wall_hits in range(1, MAX_WALL_HITS + 1):
        found, facet, slot = facet_normal(V, n, roughness_deg, facets, slot)
        if not found:
            return hit(STATUS_FAILED, path, shape, -1, NAN3, NAN3, wall_hits, work_n, work_t)
        path = rebound_path(data, V, omega, facet, a, method)
        if key >= 0:
            keyed_uniforms(key, facet_u, path == PATH_DIRECT, facet_u)
        result = _shape_rebound(data, params, shape_arrays, model_shapes, mix_cdf, shape, V, omega, facet, a, facet_u,
                                scaled, path, scratch)
        work_n += result.wall_work_normal
        work_t += result.wall_work_tangential
        if result.status != STATUS_REBOUNDED or dot(result.V, n) > 0.0:
            return hit(result.status, result.path, shape, result.n_collisions, result.V, result.Omega, wall_hits,
                       work_n, work_t)
        V, omega = result.V, result.Omega
        for k in range(U_PER_DRAW):
            facet_u[k] = grain_uniform(facets, slot + k)
        slot += U_PER_DRAW
    return hit(STATUS_TRAPPED, result.path, shape, result.n_collisions, NAN3, NAN3, MAX_WALL_HITS, work_n, work_t)


@numba.njit(inline="always", **JIT)
def _shape_rebound(data, params, shape_arrays, model_shapes, mix_cdf, shape, V, omega, n, a, u, scaled, path, scratch):
    """:func:`rebound_typed` of a particle of the table's shape ``shape`` (u[0] unused)."""
    if path == PATH_TABLE:
        return table_shape_rebound(data, shape, V, n, a, u, scaled)
    if path == PATH_DIRECT:
        return _direct_path(params, shape_arrays, model_shapes, mix_cdf, shape, V, omega, n, a, u, scratch)
    return invalid_hit()


@numba.njit(**JIT)
def _auto_paths(data, V, omega, n, a, lo, hi, path):
    """path[lo:hi] under METHOD_AUTO (:func:`_auto_path`), omega with one row per row of V or one for all.
    Compiled on its own, not inlined into the parallel loop (numba's parallel analysis rejects the frame's
    tuples there)."""
    bounds = _grid_bounds(data)
    last_omega = omega.shape[0] - 1
    for i in range(lo, hi):
        w = min(i, last_omega)
        path[i] = _auto_path(bounds, (V[i, 0], V[i, 1], V[i, 2]), (omega[w, 0], omega[w, 1], omega[w, 2]),
                             (n[i, 0], n[i, 1], n[i, 2]), a[i])


@numba.njit(parallel=True, **JIT)
def rebound_parallel_rng(data, params, shape_arrays, model_shapes, mix_cdf, shapes, keys, V, omega, n, a, states,
                         method, out, scaled=True):
    """:func:`rebound` for every row of V (N, 3), omega (N, 3) or (1, 3) for all rows, n (N, 3) and
    a (N,), on all threads, into ``out`` (:class:`surrogate.kernels.hit.Rebounds` of N rows: row i is the
    :class:`surrogate.kernels.hit.Hit` of hit i).

    ``shapes``: (N,) int64, each row's shape (its index in the table, or SHAPE_FROM_MIX to draw it from
    ``mix_cdf``), or empty, every row's from the mix (:func:`surrogate.kernels.locate.row_shape`); ValueError
    for another length or an index outside the table's shapes. ``keys``: (N,) int64, each row's grain key
    (≥ 0, or NO_KEY), or empty, no keys: a keyed row's results are :func:`rebound`'s with its ``key``
    (:func:`surrogate.kernels.grain.keyed_shapes`; on the direct path its proportions and hand too); ValueError
    for another length or a key < −1.

    The uniforms are those :func:`surrogate.kernels.parallel.table_rebound_parallel_rng` draws: chunk j's rows
    (CHUNK_ROWS rows) from a copy of ``states[j]``, U_PER_DRAW per row. Where the table answers every row
    the results are that kernel's, bit for bit; they never depend on the number of threads. The table's
    pipeline answers every row of a chunk that has a table row (at the table's cost; the rows of the other
    path are answered again), then the direct model answers the direct rows with the same row's uniforms
    (:func:`surrogate.kernels.pipeline.table_rebound_uniforms`). Rows are not checked here
    (:func:`surrogate.sample_global` checks them first): a row with a bad input gets :func:`rebound`'s record of
    a refused hit (STATUS_INVALID, PATH_NONE). A method code outside the three is a ValueError. The smooth wall:
    :func:`rough_rebound_parallel_rng` answers a rough one.
    """
    if not METHOD_AUTO <= method <= METHOD_DIRECT:
        raise ValueError("The 'method' code must be METHOD_AUTO (0), METHOD_TABLE (1) or METHOD_DIRECT (2).")
    check_shapes(shapes, V.shape[0], mix_cdf.shape[0])
    check_keys(keys, V.shape[0])
    row_shapes = keyed_shapes(mix_cdf, shapes, keys)     # a copy of shapes without keys
    rows = V.shape[0]
    for j in numba.prange(states.shape[0]):
        _path_chunk(data, params, shape_arrays, model_shapes, mix_cdf, row_shapes, keys, V, omega, n, a, states[j],
                    method, out, scaled, j * CHUNK_ROWS, min((j + 1) * CHUNK_ROWS, rows))


@numba.njit(**JIT)
def _path_chunk(data, params, shape_arrays, model_shapes, mix_cdf, row_shapes, keys, V, omega, n, a, state, method,
                out, scaled, lo, hi):
    """Rows [lo, hi) of :func:`rebound_parallel_rng` along their paths (one chunk, its uniforms from a copy of
    ``state``). Called, not inlined: numba's parallel passes then see one call in the loop, not the chunk's work
    (docs/design/test_time.md)."""
    path = out.path
    if method == METHOD_AUTO:
        _auto_paths(data, V, omega, n, a, lo, hi, path)
    else:
        path[lo:hi] = PATH_TABLE if method == METHOD_TABLE else PATH_DIRECT
    n_table = 0
    for i in range(lo, hi):
        n_table += path[i] == PATH_TABLE
    if n_table > 0:
        run_blocks(data, mix_cdf, row_shapes[lo:hi], V[lo:hi], n[lo:hi], a[lo:hi], no_uniforms(), state.copy(),
                   out.V[lo:hi], out.Omega[lo:hi], out.status[lo:hi], out.shape[lo:hi], out.wall_work_normal[lo:hi],
                   out.wall_work_tangential[lo:hi], scaled)
    for i in range(lo, hi):
        if path[i] == PATH_TABLE:       # the pipeline's rows completed as rebound's records (hit.hit)
            out.n_collisions[i], out.wall_hits[i] = -1, 1
            if out.status[i] == STATUS_INVALID:
                path[i], out.shape[i], out.wall_hits[i] = PATH_NONE, -1, 0
    if n_table == hi - lo:
        return
    keyed = keys.shape[0] > 0
    last_omega = omega.shape[0] - 1
    u = table_rebound_uniforms(state.copy(), hi - lo)
    scratch = np.empty(SCRATCH_SIZE)
    for i in range(lo, hi):
        if path[i] == PATH_TABLE:
            continue
        w = min(i, last_omega)
        result = invalid_hit()
        if path[i] == PATH_DIRECT:
            shape = row_shapes[i] if row_shapes.shape[0] > 0 else SHAPE_FROM_MIX
            if keyed and keys[i] >= 0:
                keyed_uniforms(keys[i], u[i - lo], True, u[i - lo])
            result = _direct_path(
                params, shape_arrays, model_shapes, mix_cdf, shape, (V[i, 0], V[i, 1], V[i, 2]),
                (omega[w, 0], omega[w, 1], omega[w, 2]), (n[i, 0], n[i, 1], n[i, 2]), a[i], u[i - lo], scratch)
        put_hit(out, i, result)


@numba.njit(parallel=True, **JIT)
def rough_rebound_parallel_rng(data, params, shape_arrays, model_shapes, mix_cdf, shapes, keys, V, omega, n, a,
                               states, method, out, scaled, roughness_deg):
    """:func:`rebound_parallel_rng` on a rough wall of roughness ``roughness_deg`` (degrees, in
    (0, MAX_ROUGHNESS_DEG]; else a ValueError): row i is :func:`rough_rebound`'s with the uniforms that kernel
    gives row i (one by one, without the table's pipeline). The same bits whatever the number of threads."""
    if not METHOD_AUTO <= method <= METHOD_DIRECT:
        raise ValueError("The 'method' code must be METHOD_AUTO (0), METHOD_TABLE (1) or METHOD_DIRECT (2).")
    if not 0.0 < roughness_deg <= MAX_ROUGHNESS_DEG:
        raise ValueError("The roughness must be in (0, MAX_ROUGHNESS_DEG] degrees.")
    check_shapes(shapes, V.shape[0], mix_cdf.shape[0])
    check_keys(keys, V.shape[0])
    row_shapes = keyed_shapes(mix_cdf, shapes, keys)
    rows = V.shape[0]
    for j in numba.prange(states.shape[0]):
        _rough_chunk(data, params, shape_arrays, model_shapes, mix_cdf, row_shapes, keys, V, omega, n, a, states[j],
                     method, out, scaled, roughness_deg, j * CHUNK_ROWS, min((j + 1) * CHUNK_ROWS, rows))


@numba.njit(**JIT)
def _rough_chunk(data, params, shape_arrays, model_shapes, mix_cdf, row_shapes, keys, V, omega, n, a, state, method,
                 out, scaled, roughness_deg, lo, hi):
    """Rows [lo, hi) of :func:`rough_rebound_parallel_rng`: :func:`rough_rebound` row by row, with the uniforms the
    table's pipeline would give the rows."""
    u = table_rebound_uniforms(state.copy(), hi - lo)
    last_omega = omega.shape[0] - 1
    for i in range(lo, hi):
        w = min(i, last_omega)
        shape = row_shapes[i] if row_shapes.shape[0] > 0 else SHAPE_FROM_MIX
        key = keys[i] if keys.shape[0] > 0 else NO_KEY
        # the single-hit kernel itself: one compilation of the rough hit serves both
        put_hit(out, i, _rough_on_stack(data, params, shape_arrays, model_shapes, mix_cdf, np.int64(shape),
                                        np.int64(key), (V[i, 0], V[i, 1], V[i, 2]),
                                        (omega[w, 0], omega[w, 1], omega[w, 2]), (n[i, 0], n[i, 1], n[i, 2]),
                                        float(a[i]), u[i - lo], scaled, np.int64(method), float(roughness_deg)))
