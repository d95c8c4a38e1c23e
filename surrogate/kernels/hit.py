"""What a wall hit did, as a record: :class:`Hit` for one hit (what the single-hit kernels return), :class:`Rebounds`
for many (what :func:`surrogate.sample_global` and :func:`surrogate.sample_direct` return and the many-hit kernels
fill).

Both have the fields of the C library's ``rbs_result``, in its order (``size`` aside): a new output of a hit is a
new field here and there (tests/native/test_native_api.py checks the three agree), not a longer tuple or a new
function. Read them by name: ``hit.V``, ``rebounds.status``.

Units and frames: V⁺ in m/s and Ω⁺ in rad/s, in the caller's frame; NaN unless the status is STATUS_REBOUNDED.
On a rough wall (:mod:`surrogate.kernels.facet`) one hit may take several facet hits: ``path`` and
``n_collisions`` are then those of the last, ``wall_hits`` their number.

What a hit does to the wall (docs/model.md §4.7): ``wall_work_normal`` W_n and ``wall_work_tangential`` W_t, the
work of its collisions on the wall per unit particle mass in m²/s² (J/kg), each ≥ 0, their sum the particle's drop of
translational plus rotational kinetic energy (up to the trap or the failure for a hit trapped or failed). Both
paths give them (on a rough wall summed over the facet hits): the direct model from its collisions, the table
drawn jointly with the rebound (:mod:`surrogate.kernels.work`; a trapped draw its cell's trapped particles' mean).
NaN from a table without the work (format 4.0), and for STATUS_INVALID.
"""

from typing import NamedTuple

import numba
import numpy as np

from data_schema.samples import STATUS_INVALID
from surrogate.kernels.frame import NAN3
from surrogate.kernels.options import JIT

PATH_NONE, PATH_TABLE, PATH_DIRECT = -1, 0, 1      # which path answered a hit; PATH_NONE: refused (STATUS_INVALID)


class Hit(NamedTuple):
    """One answered hit (the twin of C's ``rbs_result``)."""

    status: int         # STATUS_REBOUNDED, STATUS_TRAPPED, STATUS_FAILED (direct path) or STATUS_INVALID
    path: int           # PATH_TABLE or PATH_DIRECT; PATH_NONE for STATUS_INVALID
    shape: int          # the particle's shape: its index in the table (drawn from the mix or given); −1 if invalid
    n_collisions: int   # direct path: the rebound's collisions (up to the trap); table path and invalid: −1
    V: tuple            # V⁺, m/s (3 floats)
    Omega: tuple        # Ω⁺, rad/s (3 floats)
    wall_hits: int      # the hits on the wall this hit took: 1 on a smooth wall; on a rough one ≥ 1 (re-hits of a
                        # rebound into the mean wall, up to MAX_WALL_HITS); 0 for STATUS_INVALID
    wall_work_normal: float      # W_n, m²/s²: the work of the hit's normal impulses on the wall per unit particle
                                 # mass (module doc); NaN for STATUS_INVALID and from a table without the work
    wall_work_tangential: float  # W_t, m²/s²: that of its tangential impulses (the cutting of ductile walls); NaN
                                 # as W_n


class Rebounds(NamedTuple):
    """Many answered hits, one row each: the fields of :class:`Hit` as arrays (:func:`empty_rebounds`)."""

    status: np.ndarray          # (N,) int8
    path: np.ndarray            # (N,) int8
    shape: np.ndarray           # (N,) int32
    n_collisions: np.ndarray    # (N,) int32
    V: np.ndarray               # (N, 3) float64, m/s
    Omega: np.ndarray           # (N, 3) float64, rad/s
    wall_hits: np.ndarray       # (N,) int32
    wall_work_normal: np.ndarray        # (N,) float64, m²/s²
    wall_work_tangential: np.ndarray    # (N,) float64, m²/s²


# the dtype and trailing shape of each field of Rebounds
REBOUNDS_ARRAYS = {"status": (np.int8, ()), "path": (np.int8, ()), "shape": (np.int32, ()),
                   "n_collisions": (np.int32, ()), "V": (np.float64, (3,)), "Omega": (np.float64, (3,)),
                   "wall_hits": (np.int32, ()), "wall_work_normal": (np.float64, ()),
                   "wall_work_tangential": (np.float64, ())}


def empty_rebounds(n: int) -> Rebounds:
    """A :class:`Rebounds` of n rows to fill (uninitialised), e.g. the ``out`` a solver keeps between time steps."""
    return Rebounds(**{name: np.empty((n, *tail), dtype=dtype) for name, (dtype, tail) in REBOUNDS_ARRAYS.items()})


@numba.njit(inline="always", **JIT)
def hit(status, path, shape, n_collisions, V, Omega, wall_hits=1, wall_work_normal=np.nan,
        wall_work_tangential=np.nan):
    """A :class:`Hit` with its integers as int64 and its floats as float64 (its vectors 3-tuples): one type whatever
    the kernel that builds it, so every branch of a kernel returns the same type. A STATUS_INVALID hit gets
    PATH_NONE, shape and n_collisions −1, NaN vectors, wall_hits 0 and NaN wall work whatever is passed (as
    rbs_rebound writes it); the wall work's default is NaN."""
    if status == STATUS_INVALID:
        return Hit(np.int64(STATUS_INVALID), np.int64(PATH_NONE), np.int64(-1), np.int64(-1), NAN3, NAN3,
                   np.int64(0), np.nan, np.nan)
    return Hit(np.int64(status), np.int64(path), np.int64(shape), np.int64(n_collisions),
               (float(V[0]), float(V[1]), float(V[2])), (float(Omega[0]), float(Omega[1]), float(Omega[2])),
               np.int64(wall_hits), float(wall_work_normal), float(wall_work_tangential))


@numba.njit(inline="always", **JIT)
def invalid_hit():
    """The record of a refused hit (:func:`hit`'s for STATUS_INVALID)."""
    return hit(STATUS_INVALID, PATH_NONE, -1, -1, NAN3, NAN3)


@numba.njit(inline="always", **JIT)
def put_hit(out, i, h):
    """Row i of the :class:`Rebounds` ``out`` := the :class:`Hit` ``h``."""
    out.status[i] = h.status
    out.path[i] = h.path
    out.shape[i] = h.shape
    out.n_collisions[i] = h.n_collisions
    out.wall_hits[i] = h.wall_hits
    out.wall_work_normal[i] = h.wall_work_normal
    out.wall_work_tangential[i] = h.wall_work_tangential
    for k in range(3):
        out.V[i, k] = h.V[k]
        out.Omega[i, k] = h.Omega[k]
