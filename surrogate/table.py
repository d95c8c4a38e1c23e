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
from data_schema.table import ReboundTable, read_table


class KernelData(NamedTuple):
    """Arrays of a table as numba kernels take them (see :mod:`surrogate.kernels`)."""

    alpha1_deg: np.ndarray     # (n_alpha,) grid
    alpha1_lookup: np.ndarray  # (m,) interval index on a uniform auxiliary grid
    alpha1_scale: np.ndarray   # (2,) origin and inverse step of that grid
    speed: np.ndarray          # (n_speed,) grid, m/s
    speed_lookup: np.ndarray
    speed_scale: np.ndarray
    p_trapped: np.ndarray      # (n_shape, n_alpha, n_speed)
    alpha2_q: np.ndarray
    beta2_q: np.ndarray
    speed_q: np.ndarray
    spin: np.ndarray


def interval_lookup(grid: np.ndarray):
    """Index map for O(1) location of x in a strictly increasing grid.

    A uniform auxiliary grid with step no larger than half the smallest grid
    spacing stores, for each of its points, the index j of the grid interval
    [g_j, g_{j+1}) holding it; a query reads that index and corrects it by at
    most one step. Returns (lookup, (origin, 1/step)).
    """
    grid = np.asarray(grid, dtype=np.float64)
    if len(grid) == 1:
        return np.zeros(1, dtype=np.int64), np.array([grid[0], 0.0])
    step = np.diff(grid).min() / 2.0
    m = int(np.ceil((grid[-1] - grid[0]) / step)) + 1
    points = grid[0] + step * np.arange(m)
    lookup = np.clip(np.searchsorted(grid, points, side="right") - 1, 0, len(grid) - 2)
    return lookup.astype(np.int64), np.array([grid[0], 1.0 / step])


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
        a_lookup, a_scale = interval_lookup(table.alpha1_deg)
        v_lookup, v_scale = interval_lookup(table.speed_m_s)
        data = KernelData(
            alpha1_deg=_frozen(np.asarray(table.alpha1_deg, dtype=np.float64)), alpha1_lookup=_frozen(a_lookup),
            alpha1_scale=_frozen(a_scale), speed=_frozen(np.asarray(table.speed_m_s, dtype=np.float64)),
            speed_lookup=_frozen(v_lookup), speed_scale=_frozen(v_scale),
            p_trapped=_frozen(counts[..., STATUS_TRAPPED] / landed),
            alpha2_q=_frozen(table.cells["alpha2_q"]), beta2_q=_frozen(table.cells["beta2_q"]),
            speed_q=_frozen(table.cells["speed_q"]), spin=_frozen(table.cells["spin"]))
        return cls(path=path, shapes=tuple(table.shapes), alpha1_deg=data.alpha1_deg, speed_m_s=data.speed,
                   particles_per_cell=table.particles_per_cell, n_max=table.n_max,
                   config_sha256=table.config_sha256, kernel_data=data)


def load(path) -> SurrogateTable:
    """Load a table file for sampling (checked by :func:`data_schema.check_file`)."""
    return SurrogateTable.from_table(read_table(path), str(path))
