"""The in-memory table of the runtime sampler.

:func:`load` reads a table file through :mod:`data_schema` (which checks its
type and version) and returns an immutable :class:`SurrogateTable`: read-only,
C-contiguous arrays plus the O(1) grid look-ups, and nothing held in module
globals (numba would freeze those at compile time). ``table.kernel_data`` is
the same content as a named tuple of arrays, the form numba kernels take.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from data_schema.table import ReboundTable, read_table
from surrogate.kernels.layout import KernelData, check_kernel_data, frozen, kernel_data


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
        """The sampler's table from a table read by :mod:`data_schema`; DataFormatError if its derived arrays
        are not finite (:func:`surrogate.kernels.layout.check_kernel_data`)."""
        data = kernel_data(table)
        check_kernel_data(data, path)
        speed = np.asarray(table.speed_m_s, dtype=np.float64)
        return cls(path=path, shapes=tuple(table.shapes), alpha1_deg=frozen(np.asarray(table.alpha1_deg, float)),
                   speed_m_s=frozen(speed), particles_per_cell=table.particles_per_cell, n_max=table.n_max,
                   config_sha256=table.config_sha256, restitution_k=table.restitution_k,
                   restitution_p=table.restitution_p, kernel_data=data)


def load(path) -> SurrogateTable:
    """Load a table file for sampling (checked by :func:`data_schema.check_file`)."""
    return SurrogateTable.from_table(read_table(path), str(path))
