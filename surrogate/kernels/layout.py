"""The table as the kernels take it: a few flat arrays (:class:`KernelData`), their layouts, and how a
loaded table is turned into them.

Few arrays, because numba passes every array as its data pointer, shape and
strides, and a kernel keeps them in registers; flat, because one offset per
cell and per component then locates every read. The offsets of each record
are the ROW_*, CELL_* and AXIS_* constants below. Derived once when a table
is loaded (:func:`kernel_data`) and checked (:func:`check_kernel_data`):
every array finite, both grids positive and strictly increasing, so a draw
never returns a non-finite state with status "rebounded".
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from data_schema.common import DataFormatError
from data_schema.samples import STATUS_REBOUNDED, STATUS_TRAPPED
from data_schema.table import N_CHAIN, N_SLOPES, N_WORK, N_WORK_SLOPES, ReboundTable
from surrogate.kernels.fastmath import restitution_factor, restitution_pieces

CACHE_LINE_BYTES = 64
FLOAT32_PER_CACHE_LINE = CACHE_LINE_BYTES // 4


class KernelData(NamedTuple):
    """A table as the kernels take it: flat arrays (layouts below) and their sizes; the methods give shaped,
    read-only views for inspection and tests."""

    alpha1_axis: np.ndarray    # float64 axis record of the α1 grid, degrees (AXIS_* layout, axis_record)
    speed_axis: np.ndarray     # float64 axis record of the |V⁻| grid, m/s
    cells: np.ndarray          # float64 (n_cells · CELL_SIZE,): per cell P(trapped), mean, sd, 1/sd (CELL_* layout)
    clusters: np.ndarray       # float32 (n_cells · n_clusters · ROW_SIZE,): one row per component (ROW_* layout)
    dictionary: np.ndarray     # float32 (n_cells · 6 · n_levels · n_dictionary,): residual shapes, level-major
    speed_restitution: np.ndarray  # float64 (n_speed,) the wall's restitution factor exp(−k V^p) at the grid speeds
    restitution_pieces: np.ndarray  # float64, exp(−k V^p) between them, flat (fastmath.restitution_pieces)
    n_shapes: int
    n_alpha1: int
    n_speed: int               # cell (shape, i_α1, i_speed) is number (shape · n_alpha1 + i_α1) · n_speed + i_speed
    n_clusters: int            # mixture components per cell
    n_levels: int              # L + 1 quantile levels of a residual shape
    n_dictionary: int          # M residual shapes per chain variable and cell
    n_pieces: int              # restitution pieces per speed interval
    # the work on the wall (format 4.1; empty arrays for a table without it, has_work False): each component's
    # two work variables (WORK_ROW_* layout), their residual shapes (level-major, as ``dictionary``), and per
    # cell their moments and the trapped particles' mean work (WORK_CELL_* layout)
    work_rows: np.ndarray      # float32 (n_cells · n_clusters · WORK_ROW_SIZE,)
    work_dictionary: np.ndarray  # float32 (n_cells · N_WORK · n_levels · n_dictionary,)
    work_cells: np.ndarray     # float64 (n_cells · WORK_CELL_SIZE,)
    has_work: bool

    @property
    def nbytes(self) -> int:
        """Bytes held by the arrays."""
        return sum(x.nbytes for x in self if isinstance(x, np.ndarray))

    def cell_shape(self) -> tuple:
        """(n_shapes, n_alpha1, n_speed)."""
        return self.n_shapes, self.n_alpha1, self.n_speed

    def rows(self) -> np.ndarray:
        """The component rows as (n_shapes, n_alpha1, n_speed, n_clusters, ROW_SIZE)."""
        return self.clusters.reshape(self.cell_shape() + (self.n_clusters, ROW_SIZE))

    def shape_dictionary(self) -> np.ndarray:
        """The residual shapes as (n_shapes, n_alpha1, n_speed, 6, n_levels, n_dictionary): S_k,m(i/L) at
        [..., k, i, m]."""
        return self.dictionary.reshape(self.cell_shape() + (N_CHAIN, self.n_levels, self.n_dictionary))

    def p_trapped(self) -> np.ndarray:
        """P(trapped) of every cell, (n_shapes, n_alpha1, n_speed)."""
        return self.cells.reshape(self.cell_shape() + (CELL_SIZE,))[..., CELL_P_TRAPPED]

    def with_rows(self, rows: np.ndarray) -> "KernelData":
        """A copy whose component rows are ``rows`` (shaped as :meth:`rows`): for experiments and tests."""
        return self._replace(clusters=frozen(aligned_copy(np.asarray(rows, dtype=np.float32).ravel())))


# Layout of a component's row in KernelData.clusters: everything one draw needs
# from a component, contiguous (144 bytes), so a draw touches few cache lines.
ROW_ALIAS_PROB = 0    # Walker alias table: keep the component if the fractional part < this
ROW_ALIAS = 1         # ... else use this component
ROW_LOC = 2           # 6 locations (chain order)
ROW_SCALE = 8         # 6 scales
ROW_SHAPE = 14        # 6 residual shape indices m (KernelData.shape_dictionary()[..., k, :, m])
ROW_SLOPE = 20        # 15 slopes, x_k on x_j at k(k−1)/2 + j
ROW_REGIME = 35       # collision regime: 0 = at most FEW_COLLISIONS collisions, 1 = more
ROW_SIZE = 36

# Layout of a component's work row in KernelData.work_rows: the chain's two work variables (r, ν), 80 bytes
WORK_ROW_LOC = 0      # 2 locations
WORK_ROW_SCALE = 2    # 2 scales
WORK_ROW_SHAPE = 4    # 2 residual shape indices into KernelData.work_dictionary
WORK_ROW_SLOPE = 6    # 13 slopes: r on the six chain variables, ν on them and r (WORK_SLOPE_START)
WORK_ROW_SIZE = 20    # 19 used; 20 keeps rows 16-byte aligned

# Layout of a cell's work record in KernelData.work_cells
WORK_CELL_MEAN = 0    # means of r and ν
WORK_CELL_SD = 2      # their standard deviations
WORK_CELL_INV_SD = 4  # 1/sd (0 where sd = 0)
WORK_CELL_TRAPPED = 6  # the trapped particles' mean W_n/E⁻ and W_t/E⁻
WORK_CELL_SIZE = 8

# Layout of a cell's record in KernelData.cells
CELL_P_TRAPPED = 0    # probability of the trapped outcome
CELL_MEAN = 1         # 6 means of (α2, β2, s, Ω_x, Ω_y, Ω_z)
CELL_SD = 7           # their 6 standard deviations
CELL_INV_SD = 13      # 1/sd (0 where sd = 0): the kernels multiply instead of dividing
CELL_SIZE = 19

# Layout of an axis record (axis_record): a grid of n points and its O(1) look-up
AXIS_ORIGIN = 0       # origin of the uniform auxiliary grid
AXIS_INV_STEP = 1     # its inverse step
AXIS_GRID = 2         # the n grid points, then max(n − 1, 1) inverse spacings, then the look-up indices


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


def axis_record(grid: np.ndarray) -> np.ndarray:
    """The float64 record the kernels locate a value on ``grid`` with (AXIS_* layout).

    [origin, 1/step, g_0 … g_{n−1}, 1/(g_1 − g_0) … (max(n − 1, 1) values), lookup_0 … lookup_{m−1}]
    from :func:`interval_lookup`; the look-up indices are small integers, exact in float64.
    """
    lookup, scale, inverse = interval_lookup(grid)
    return np.concatenate([scale, np.asarray(grid, dtype=np.float64), inverse, lookup.astype(np.float64)])


def alias_table(weights: np.ndarray):
    """Walker's alias table of probabilities ``weights`` (summing to 1): (keep, alias).

    Drawing: t = u·C, c = ⌊t⌋; keep c if t − c < keep[c], else take alias[c].
    Component c is then drawn with probability weights[c] (exactly, up to
    rounding). Zero-weight components have keep = 0 and are never drawn.
    """
    n = len(weights)
    total = 0.0
    for w in np.asarray(weights, dtype=np.float64).tolist():    # in index order: np.sum's order is numpy's choice
        total += w
    keep = np.asarray(weights, dtype=np.float64) * (n / total)
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
    """The cell arrays of a table rearranged for the kernels: (clusters, dictionary), flat (see :class:`KernelData`).

    The dictionary is stored level-major, S_k,m(i/L) at [..., k, i, m]: the M
    shapes' values at one level are contiguous (one cache line for M = 16),
    so the lines a draw reads are located by its uniforms alone, before the
    component row that names m arrives, and can be requested together with
    that row (:func:`surrogate.kernels.locate.hint_row`). Both arrays start on a
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
    return aligned_copy(rows.ravel()), aligned_copy(np.swapaxes(dic, -1, -2).ravel())


def work_arrays(table: ReboundTable) -> tuple:
    """(work_rows, work_dictionary, work_cells), flat (see :class:`KernelData`); empty for a table without the
    work on the wall."""
    if not table.has_work:
        return np.zeros(0, dtype=np.float32), np.zeros(0, dtype=np.float32), np.zeros(0)
    cells = table.cells
    lead = cells["work_loc"].shape[:4]
    rows = np.zeros(lead + (WORK_ROW_SIZE,), dtype=np.float32)
    rows[..., WORK_ROW_LOC:WORK_ROW_LOC + N_WORK] = cells["work_loc"]
    rows[..., WORK_ROW_SCALE:WORK_ROW_SCALE + N_WORK] = cells["work_scale"]
    rows[..., WORK_ROW_SHAPE:WORK_ROW_SHAPE + N_WORK] = cells["work_shape"]
    rows[..., WORK_ROW_SLOPE:WORK_ROW_SLOPE + N_WORK_SLOPES] = cells["work_slope"]
    std = np.asarray(cells["work_std"], dtype=np.float64)
    inverse = np.divide(1.0, std, out=np.zeros_like(std), where=std > 0.0)
    records = np.concatenate([cells["work_mean"], std, inverse, cells["trapped_work"]], axis=-1)
    return (aligned_copy(rows.ravel()), aligned_copy(np.swapaxes(cells["work_dictionary"], -1, -2).ravel()),
            records.ravel())


def aligned_copy(a: np.ndarray, alignment: int = CACHE_LINE_BYTES) -> np.ndarray:
    """A C-contiguous copy of ``a`` that starts at a multiple of ``alignment`` bytes (a cache line)."""
    buffer = np.empty(a.nbytes + alignment, dtype=np.uint8)
    offset = -buffer.ctypes.data % alignment
    out = buffer[offset:offset + a.nbytes].view(a.dtype).reshape(a.shape)
    out[...] = a
    return out


def cell_records(p_trapped: np.ndarray, mean: np.ndarray, std: np.ndarray) -> np.ndarray:
    """Every cell's record (CELL_* layout), flat: P(trapped), the means, sds and 1/sds (0 where sd = 0) of
    its state variables."""
    inverse = np.divide(1.0, std, out=np.zeros_like(std, dtype=np.float64), where=std > 0.0)
    return np.concatenate([p_trapped[..., None], mean, std, inverse], axis=-1).ravel()


def frozen(a: np.ndarray) -> np.ndarray:
    """A read-only, C-contiguous view of ``a`` (a copy if it is not contiguous; ``a`` itself is left as it is): the
    kernels are compiled for read-only arrays, and a writable one would compile them a second time."""
    view = np.ascontiguousarray(a).view()
    view.setflags(write=False)
    return view


def kernel_data(table: ReboundTable) -> KernelData:
    """The arrays the kernels draw from, derived from a table read by :mod:`data_schema` (not checked:
    :func:`check_kernel_data`)."""
    counts = table.cells["status_counts"].astype(np.float64)
    landed = counts[..., STATUS_REBOUNDED] + counts[..., STATUS_TRAPPED]
    rows, dictionary = kernel_rows(table.cells)
    wall = table.wall.as_array()
    pieces = restitution_pieces(table.speed_m_s, wall)
    speed = np.asarray(table.speed_m_s, dtype=np.float64)
    lead = counts.shape[:3]
    dic_shape = table.cells["shape_dictionary"].shape     # (..., 6, M, L + 1)
    return KernelData(
        alpha1_axis=frozen(axis_record(table.alpha1_deg)), speed_axis=frozen(axis_record(speed)),
        cells=frozen(cell_records(counts[..., STATUS_TRAPPED] / landed, table.cells["mean"], table.cells["std"])),
        clusters=frozen(rows), dictionary=frozen(dictionary),
        speed_restitution=frozen(np.array([restitution_factor(v, wall) for v in speed.tolist()])),
        restitution_pieces=frozen(pieces.ravel()),
        n_shapes=lead[0], n_alpha1=lead[1], n_speed=lead[2], n_clusters=table.cells["cluster_weight"].shape[3],
        n_levels=dic_shape[-1], n_dictionary=dic_shape[-2], n_pieces=pieces.shape[1],
        **dict(zip(("work_rows", "work_dictionary", "work_cells"), map(frozen, work_arrays(table)))),
        has_work=table.has_work)


# the stored datasets each kernel array is derived from, for error messages
DERIVED_FROM = {
    "alpha1_axis": "grid/alpha1_deg", "speed_axis": "grid/speed_m_s",
    "cells": "cells/status_counts, cells/mean, cells/std",
    "clusters": "cells/cluster_weight, cluster_loc, cluster_scale, cluster_shape, cluster_slope, cluster_regime",
    "dictionary": "cells/shape_dictionary", "speed_restitution": "grid/speed_m_s and wall/parameters",
    "restitution_pieces": "grid/speed_m_s and wall/parameters",
    "work_rows": "cells/work_loc, work_scale, work_shape, work_slope", "work_dictionary": "cells/work_dictionary",
    "work_cells": "cells/work_mean, work_std, trapped_work",
}


def check_kernel_data(data: KernelData, path: str) -> None:
    """DataFormatError naming ``path`` unless every kernel array is finite and both grids strictly increase: a draw from
    the table can then never be non-finite with status "rebounded"."""
    for name, source in DERIVED_FROM.items():
        values = getattr(data, name)
        bad = np.flatnonzero(~np.isfinite(values))
        if bad.size:
            raise DataFormatError(f"{path}: {bad.size} non-finite values in the kernel array '{name}' derived "
                                  f"from {source} (first at flat index {bad[0]}); the table is corrupt")
    for name, axis, n in (("alpha1", data.alpha1_axis, data.n_alpha1), ("speed", data.speed_axis, data.n_speed)):
        grid = axis[AXIS_GRID:AXIS_GRID + n]
        if np.any(np.diff(grid) <= 0) or grid[0] <= 0:
            raise DataFormatError(f"{path}: the {name} grid must be positive and strictly increasing; got {grid}")
