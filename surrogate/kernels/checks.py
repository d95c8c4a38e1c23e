"""The input checks of the kernels: where each check of :func:`surrogate.sample_global` first fails, in one
parallel pass (:func:`first_faults`), and the shapes of the arrays of the kernels over many particles
(:func:`check_rows` and the others: a ValueError naming the array, raised before any parallel loop, where a
raise would keep numba from running it in parallel).

The NumPy API must name the first offending value of each kind of bad input
(docs/runtime.md, "From NumPy"). Done with NumPy, those checks cost several
passes over (N, 3) temporaries (norms, dot products, arctangents), as much
as the draws themselves. :func:`first_faults` makes one pass in numba and
returns, for every check in the order the API reports them (the FAULT_*
constants), the first row that fails it, or −1. It computes α1 and |V⁻| as
the sampler's kernel does (:func:`surrogate.kernels.frame.impact_frame`), so the
range check sees the values the draw will use.
"""

import math

import numba
import numpy as np

from surrogate.kernels.draw import U_PER_DRAW
from surrogate.kernels.frame import dot, impact_frame, unit_normal
from surrogate.kernels.locate import SHAPE_FROM_MIX
from surrogate.kernels.options import JIT
from surrogate.kernels.rng import CHUNK_ROWS, n_chunks

FAULT_VELOCITY_NOT_FINITE = 0
FAULT_NORMAL_NOT_FINITE = 1
FAULT_NORMAL_NOT_UNIT = 2       # not frame.unit_normal: | |n| − 1 | > NORMAL_TOLERANCE
FAULT_VELOCITY_ZERO = 3
FAULT_NOT_INTO_WALL = 4         # V·n ≥ 0
FAULT_HALF_SIZE = 5             # not finite or ≤ 0, or |V⁻|/a > SPIN_SCALE_MAX
FAULT_ALPHA1_NOT_FINITE = 6
FAULT_ALPHA1_OUTSIDE = 7        # outside [alpha1_lo, alpha1_hi] deg
FAULT_SPEED_NOT_FINITE = 8      # or outside [SPEED_MIN, SPEED_MAX]
FAULT_SPEED_OUTSIDE = 9         # outside [speed_lo, speed_hi] m/s
N_FAULTS = 10

# |V⁻| the kernels' arithmetic carries, m/s: the squares of the impact frame neither overflow nor lose the
# precision of subnormal numbers
SPEED_MIN, SPEED_MAX = 1e-150, 1e150
SPIN_SCALE_MAX = 1e300      # |V⁻|/a at most, 1/s: Ω⁺ = (|V⁻|/a)(Ω⁺a/|V⁻|) stays finite


@numba.njit(parallel=True, **JIT)
def first_faults(V, n, a, alpha1_lo, alpha1_hi, speed_lo, speed_hi):
    """First failing row of each check (FAULT_* order; −1 if none) over V (N, 3) m/s, unit normals n (N, 3)
    or (1, 3) for all rows, half-sizes a (N,) or (1,) m; the α1 range in degrees and the speed range in
    m/s."""
    chunks = n_chunks(V.shape[0])
    found = np.full((chunks, N_FAULTS), -1, dtype=np.int64)
    last_n, last_a = n.shape[0] - 1, a.shape[0] - 1
    for j in numba.prange(chunks):
        mine = found[j]
        for i in range(j * CHUNK_ROWS, min((j + 1) * CHUNK_ROWS, V.shape[0])):
            k = min(i, last_n)
            _check_row((V[i, 0], V[i, 1], V[i, 2]), (n[k, 0], n[k, 1], n[k, 2]), a[min(i, last_a)],
                       alpha1_lo, alpha1_hi, speed_lo, speed_hi, i, mine)
    first = np.full(N_FAULTS, -1, dtype=np.int64)
    for j in range(chunks):          # chunks in row order: the first chunk with a fault holds its first row
        for k in range(N_FAULTS):
            if first[k] < 0:
                first[k] = found[j, k]
    return first


@numba.njit(inline="always", **JIT)
def _check_row(V, n, a, alpha1_lo, alpha1_hi, speed_lo, speed_hi, i, found):
    """Record row i in ``found`` under every check it fails, unless an earlier row of its chunk did."""
    finite = math.isfinite(V[0] + V[1] + V[2])
    vn = dot(V, n)
    _record(found, FAULT_VELOCITY_NOT_FINITE, not finite, i)
    _record(found, FAULT_NORMAL_NOT_FINITE, not math.isfinite(n[0] + n[1] + n[2]), i)
    _record(found, FAULT_NORMAL_NOT_UNIT, not unit_normal(n), i)
    _record(found, FAULT_VELOCITY_ZERO, dot(V, V) == 0.0, i)
    _record(found, FAULT_NOT_INTO_WALL, vn >= 0.0, i)
    _record(found, FAULT_HALF_SIZE, not (math.isfinite(a) and a > 0.0), i)
    if finite and vn < 0.0:
        alpha1, speed = impact_frame(V, n, 0.0)[:2]
        carried = SPEED_MIN <= speed <= SPEED_MAX       # else α1 and the spin's unit are not to be trusted
        _record(found, FAULT_HALF_SIZE, carried and not speed / a <= SPIN_SCALE_MAX, i)
        _record(found, FAULT_ALPHA1_NOT_FINITE, carried and not math.isfinite(alpha1), i)
        _record(found, FAULT_ALPHA1_OUTSIDE, carried and (alpha1 < alpha1_lo or alpha1 > alpha1_hi), i)
        _record(found, FAULT_SPEED_NOT_FINITE, not carried, i)
        _record(found, FAULT_SPEED_OUTSIDE, speed < speed_lo or speed > speed_hi, i)


@numba.njit(inline="always", **JIT)
def _record(found, k, fails, i):
    if fails and found[k] < 0:
        found[k] = i


# -- the shapes of the arrays of the kernels over many particles ---------------------------------------

@numba.njit(**JIT)
def check_rows(V, n, a, V_out, Omega_out, status):
    """ValueError naming the first array of a block kernel's call that has not one row per particle, with
    its shape and the shape needed. Called before the parallel loops: a raise inside one keeps numba from
    running it in parallel."""
    rows = V.shape[0]
    for name, shape in (("V", V.shape), ("n", n.shape), ("V_out", V_out.shape), ("Omega_out", Omega_out.shape)):
        if shape[0] != rows or shape[1] != 3:
            raise ValueError(shape_error(name, shape, "(" + str(rows) + ", 3)"))
    for name, shape in (("a", a.shape), ("status", status.shape)):
        if shape[0] != rows:
            raise ValueError(shape_error(name, shape, "(" + str(rows) + ",)"))


@numba.njit(**JIT)
def check_uniforms(u, rows, first):
    """ValueError unless the uniforms ``u`` have shape (rows, U_PER_DRAW), rows = len(first)."""
    if u.shape[0] != rows or u.shape[1] != U_PER_DRAW:
        raise ValueError(shape_error("u", u.shape, "(" + str(rows) + ", " + str(U_PER_DRAW) + ")", first))


@numba.njit(**JIT)
def shape_error(name, shape, needed, first="V"):
    """The message of a shape error of the kernels over many particles: one row per particle, as many as
    the array ``first`` has."""
    text = ", ".join([str(x) for x in shape]) + ("," if len(shape) == 1 else "")
    return ("'" + name + "' has shape (" + text + "); needed " + needed
            + ": one row per particle, as many as " + first + " has")


@numba.njit(**JIT)
def check_state(state):
    """ValueError unless ``state`` is one xoshiro256+ state (the one-thread kernels that draw their uniforms): (4,)
    uint64, not all zero (the generator's fixed point; rbs_draw_many gives every row RBS_INVALID for it)."""
    if state.shape[0] != 4 or (state[0] | state[1] | state[2] | state[3]) == 0:
        raise ValueError("'state' must be one xoshiro256+ state, (4,) uint64 not all zero, as surrogate.seed_state "
                         "gives")


@numba.njit(**JIT)
def check_states(states, n_rows):
    """ValueError unless ``states`` holds one xoshiro256+ state per chunk of n_rows rows (the parallel kernels)."""
    if states.shape[0] != n_chunks(n_rows) or states.shape[1] != 4:
        raise ValueError("'states' must hold one xoshiro256+ state (4 words) per CHUNK_ROWS rows, as "
                         "surrogate.kernels.rng.chunk_states(generator, n_rows) gives")


@numba.njit(**JIT)
def check_shapes(shapes, rows, n_shapes):
    """ValueError unless ``shapes`` is empty (every row's shape from the mix) or holds one shape index per row,
    each SHAPE_FROM_MIX (−1) or in [0, n_shapes) (the table's shapes): another index would read outside the
    table."""
    if shapes.shape[0] != 0 and shapes.shape[0] != rows:
        raise ValueError(shape_error("shapes", shapes.shape, "(" + str(rows) + ",) or (0,)"))
    for i in range(shapes.shape[0]):
        if shapes[i] < SHAPE_FROM_MIX or shapes[i] >= n_shapes:
            raise ValueError("'shapes' must hold -1 (drawn from the mix) or a shape index in [0, "
                             + str(n_shapes) + "); row " + str(i) + " holds " + str(shapes[i]))


@numba.njit(**JIT)
def check_keys(keys, rows):
    """ValueError unless ``keys`` is empty (no grain keys) or holds one key per row, each ≥ 0 or NO_KEY (−1,
    none): :mod:`surrogate.kernels.grain`."""
    if keys.shape[0] != 0 and keys.shape[0] != rows:
        raise ValueError(shape_error("keys", keys.shape, "(" + str(rows) + ",) or (0,)"))
    for i in range(keys.shape[0]):
        if keys[i] < -1:
            raise ValueError("'keys' must hold grain keys >= 0 or -1 (none); row " + str(i) + " holds "
                             + str(keys[i]))


@numba.njit(**JIT)
def check_local_rows(alpha1, speed, out, status):
    """ValueError naming the first array of a local-frame call that has not one row per incident state."""
    rows = alpha1.shape[0]
    for name, shape in (("speed", speed.shape), ("status", status.shape)):
        if shape[0] != rows:
            raise ValueError(shape_error(name, shape, "(" + str(rows) + ",)", "alpha1"))
    if out.shape[0] != rows or out.shape[1] != 6:
        raise ValueError(shape_error("out", out.shape, "(" + str(rows) + ", 6)", "alpha1"))
