"""The in-memory table of the runtime sampler.

:func:`load` reads a table file through :mod:`data_schema` (which checks its
type and version) and returns an immutable :class:`SurrogateTable`: read-only,
C-contiguous arrays plus the O(1) grid look-ups, and nothing held in module
globals (numba would freeze those at compile time). ``table.kernel_data`` is
the same content as a named tuple of arrays, the form numba kernels take.
"""

from __future__ import annotations

import dataclasses
from typing import NamedTuple

import numpy as np

from data_schema.samples import STATUS_REBOUNDED, STATUS_TRAPPED
from data_schema.table import N_CHAIN, N_SLOPES, ReboundTable, read_table
from surrogate.restitution import restitution_pieces


class KernelData(NamedTuple):
    """Arrays of a table as numba kernels take them (see :mod:`surrogate.kernels`)."""

    alpha1_deg: np.ndarray     # (n_alpha,) grid
    alpha1_lookup: np.ndarray  # (m,) interval index on a uniform auxiliary grid
    alpha1_scale: np.ndarray   # (2,) origin and inverse step of that grid
    alpha1_inv_spacing: np.ndarray  # (max(n_alpha − 1, 1),) 1/(g_{j+1} − g_j) of each grid interval (0: one point)
    speed: np.ndarray          # (n_speed,) grid, m/s
    speed_lookup: np.ndarray
    speed_scale: np.ndarray
    speed_inv_spacing: np.ndarray
    p_trapped: np.ndarray      # (n_shape, n_alpha, n_speed)
    clusters: np.ndarray       # (n_shape, n_alpha, n_speed, C, ROW_SIZE) float32, one row per component
    dictionary: np.ndarray     # (n_shape, n_alpha, n_speed, 6, L + 1, M) float32 residual shapes, level-major
    moments: np.ndarray        # (n_shape, n_alpha, n_speed, 3, 6) mean, sd, 1/sd (0 if sd = 0) of (α2, β2, s, Ω_x, Ω_y, Ω_z)
    speed_restitution: np.ndarray  # (n_speed,) the wall's normal restitution factor exp(−k V^p) at the grid speeds
    restitution_pieces: np.ndarray  # (max(n_speed − 1, 1), S, D + 1) exp(−k V^p) between them (surrogate.restitution)


# Layout of a component's row in KernelData.clusters: everything one draw needs
# from a component, contiguous (144 bytes), so a draw touches few cache lines.
ROW_ALIAS_PROB = 0    # Walker alias table: keep the component if the fractional part < this
ROW_ALIAS = 1         # ... else use this component
ROW_LOC = 2           # 6 locations (chain order)
ROW_SCALE = 8         # 6 scales
ROW_SHAPE = 14        # 6 residual shape indices m (KernelData.dictionary[..., k, :, m])
ROW_SLOPE = 20        # 15 slopes, x_k on x_j at k(k−1)/2 + j
ROW_REGIME = 35       # collision regime: 0 = at most FEW_COLLISIONS collisions, 1 = more
ROW_SIZE = 36


def interval_lookup(grid: np.ndarray):
    """Index map for O(1) location of x in a strictly increasing grid.

    A uniform auxiliary grid with step no larger than half the smallest grid
    spacing stores, for each of its points, the index j of the grid interval
    [g_j, g_{j+1}) holding it; a query reads that index and corrects it by at
    most one step. Returns (lookup, (origin, 1/step), 1/(g_{j+1} − g_j) per interval).
    """
    grid = np.asarray(grid, dtype=np.float64)
    if len(grid) == 1:
        return np.zeros(1, dtype=np.int64), np.array([grid[0], 0.0]), np.zeros(1)
    step = np.diff(grid).min() / 2.0
    m = int(np.ceil((grid[-1] - grid[0]) / step)) + 1
    points = grid[0] + step * np.arange(m)
    lookup = np.clip(np.searchsorted(grid, points, side="right") - 1, 0, len(grid) - 2)
    return lookup.astype(np.int64), np.array([grid[0], 1.0 / step]), 1.0 / np.diff(grid)


def alias_table(weights: np.ndarray):
    """Walker's alias table of probabilities ``weights`` (summing to 1): (keep, alias).

    Drawing: t = u·C, c = ⌊t⌋; keep c if t − c < keep[c], else take alias[c].
    Component c is then drawn with probability weights[c] (exactly, up to
    rounding). Zero-weight components have keep = 0 and are never drawn.
    """
    n = len(weights)
    keep = np.asarray(weights, dtype=np.float64) * (n / np.sum(weights))
    alias = np.arange(n)
    small = [i for i in range(n) if keep[i] < 1.0]
    large = [i for i in range(n) if keep[i] >= 1.0]
    while small and large:
        lo, hi = small.pop(), large[-1]
        alias[lo] = hi
        keep[hi] -= 1.0 - keep[lo]
        if keep[hi] < 1.0:
            small.append(large.pop())
    for i in small + large:     # left over only by rounding: their keep is 1 within ~1e-15
        keep[i] = 1.0
    return keep, alias


def kernel_rows(cells: dict) -> tuple:
    """The cell arrays of a table rearranged for the kernels: (clusters, dictionary), see :class:`KernelData`.

    The dictionary is stored level-major, S_k,m(i/L) at [..., k, i, m]: the M
    shapes' values at one level are contiguous (one cache line for M = 16),
    so the lines a draw reads are located by its uniforms alone, before the
    component row that names m arrives, and can be requested together with
    that row (:func:`surrogate.kernels.rebound`). Both arrays start on a
    64-byte cache line, so a 144-byte row spans exactly three lines.
    """
    weight = cells["cluster_weight"]
    lead = weight.shape[:3]
    n_clusters = weight.shape[3]
    dic = cells["shape_dictionary"]
    rows = np.empty(lead + (n_clusters, ROW_SIZE), dtype=np.float32)
    for cell in np.ndindex(*lead):
        rows[cell + (slice(None), ROW_ALIAS_PROB)], rows[cell + (slice(None), ROW_ALIAS)] = alias_table(weight[cell])
    rows[..., ROW_LOC:ROW_LOC + N_CHAIN] = cells["cluster_loc"]
    rows[..., ROW_SCALE:ROW_SCALE + N_CHAIN] = cells["cluster_scale"]
    rows[..., ROW_SHAPE:ROW_SHAPE + N_CHAIN] = cells["cluster_shape"]
    rows[..., ROW_SLOPE:ROW_SLOPE + N_SLOPES] = cells["cluster_slope"]
    rows[..., ROW_REGIME] = cells["cluster_regime"]
    return _aligned_copy(rows), _aligned_copy(np.swapaxes(dic, -1, -2))


def _aligned_copy(a: np.ndarray, alignment: int = 64) -> np.ndarray:
    """A C-contiguous copy of ``a`` that starts at a multiple of ``alignment`` bytes (a cache line)."""
    buffer = np.empty(a.nbytes + alignment, dtype=np.uint8)
    offset = -buffer.ctypes.data % alignment
    out = buffer[offset:offset + a.nbytes].view(a.dtype).reshape(a.shape)
    out[...] = a
    return out


def moments(mean: np.ndarray, std: np.ndarray) -> np.ndarray:
    """Mean, sd and 1/sd (0 where sd = 0) of every cell's state variables stacked on a new axis 3, as
    KernelData.moments holds them (the kernels multiply by 1/sd instead of dividing by sd)."""
    inverse = np.divide(1.0, std, out=np.zeros_like(std, dtype=np.float64), where=std > 0.0)
    return np.stack([mean, std, inverse], axis=3)


def _frozen(a: np.ndarray) -> np.ndarray:
    a = np.ascontiguousarray(a)
    a.setflags(write=False)
    return a


@dataclasses.dataclass(frozen=True, eq=False)
class SurrogateTable:
    """A loaded rebound table (immutable). See :func:`load`."""

    path: str
    shapes: tuple
    alpha1_deg: np.ndarray
    speed_m_s: np.ndarray
    particles_per_cell: int
    n_max: int
    config_sha256: str
    restitution_k: float       # the wall's normal restitution exp(−k V^p) the table was built with, (m/s)^(−p)
    restitution_p: float
    kernel_data: KernelData

    @property
    def alpha1_range(self) -> tuple:
        return float(self.alpha1_deg[0]), float(self.alpha1_deg[-1])

    @property
    def speed_range(self) -> tuple:
        return float(self.speed_m_s[0]), float(self.speed_m_s[-1])

    @classmethod
    def from_table(cls, table: ReboundTable, path: str = "<memory>") -> "SurrogateTable":
        counts = table.cells["status_counts"].astype(np.float64)
        landed = counts[..., STATUS_REBOUNDED] + counts[..., STATUS_TRAPPED]
        a_lookup, a_scale, a_inv = interval_lookup(table.alpha1_deg)
        v_lookup, v_scale, v_inv = interval_lookup(table.speed_m_s)
        rows, dictionary = kernel_rows(table.cells)
        data = KernelData(
            alpha1_deg=_frozen(np.asarray(table.alpha1_deg, dtype=np.float64)), alpha1_lookup=_frozen(a_lookup),
            alpha1_scale=_frozen(a_scale), alpha1_inv_spacing=_frozen(a_inv),
            speed=_frozen(np.asarray(table.speed_m_s, dtype=np.float64)),
            speed_lookup=_frozen(v_lookup), speed_scale=_frozen(v_scale), speed_inv_spacing=_frozen(v_inv),
            p_trapped=_frozen(counts[..., STATUS_TRAPPED] / landed),
            clusters=_frozen(rows), dictionary=_frozen(dictionary),
            moments=_frozen(moments(table.cells["mean"], table.cells["std"])),
            speed_restitution=_frozen(
                np.exp(-table.restitution_k * np.asarray(table.speed_m_s, dtype=np.float64) ** table.restitution_p)),
            restitution_pieces=_frozen(restitution_pieces(table.speed_m_s, table.restitution_k, table.restitution_p)))
        return cls(path=path, shapes=tuple(table.shapes), alpha1_deg=data.alpha1_deg, speed_m_s=data.speed,
                   particles_per_cell=table.particles_per_cell, n_max=table.n_max,
                   config_sha256=table.config_sha256, restitution_k=table.restitution_k,
                   restitution_p=table.restitution_p, kernel_data=data)


def load(path) -> SurrogateTable:
    """Load a table file for sampling (checked by :func:`data_schema.check_file`)."""
    return SurrogateTable.from_table(read_table(path), str(path))
