"""The in-memory table of the runtime sampler.

:func:`load` reads a table file through :mod:`data_schema` (which checks its
type and version) and returns an immutable :class:`SurrogateTable`: read-only,
C-contiguous arrays plus the O(1) grid look-ups, and nothing held in module
globals (numba would freeze those at compile time). ``table.kernel_data`` is
the same content as a named tuple of arrays, the form numba kernels take.
"""

from __future__ import annotations

import dataclasses
import functools

import numpy as np

from data_schema.common import DataFormatError
from data_schema.shape_records import shape_datasets
from data_schema.table import ReboundTable, read_table
from direct_model.registry import ConvexPolyhedron
from direct_model.runtime import family_shapes, model_parameters
from direct_model.shape_arrays import ShapeArrays
from direct_model.shapes import SHAPES, AspectRatioLaw
from direct_model.wall import Wall
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
    wall: Wall                 # the wall the table was built with (its group /wall): its law family, parameters, name
    kernel_data: KernelData
    # the parameters of the direct model the table was built with (its group /model and the wall), as the
    # kernels take them (:func:`direct_model.runtime.model_parameters`)
    direct_parameters: np.ndarray
    # the registry record (direct_model.registry) of each shape, table order, as the table holds it (group /shapes)
    records: tuple = ()

    @functools.cached_property
    def shape_arrays(self) -> ShapeArrays:
        """The direct model's shapes as the kernels take them (:class:`direct_model.shape_arrays.ShapeArrays`):
        the four families in code order at the κ, aspect-ratio law and factors s of :attr:`direct_parameters`,
        then the table's other polyhedra (its user grains, and families after the paper's four) in table order."""
        return family_shapes(self.direct_parameters, self._stored_polyhedra)

    @functools.cached_property
    def model_shapes(self) -> np.ndarray:
        """Each of the table's shapes, in the table's order, as its index in :attr:`shape_arrays`: a family's code
        (:data:`direct_model.shapes.SHAPES`), 4 + k for the table's k-th other polyhedron, −1 for a smooth body other
        than the ellipsoid (the direct path then answers STATUS_INVALID): read-only int64 (n_shapes,), as
        :func:`surrogate.kernels.rebound` takes it."""
        others = iter(range(len(SHAPES), len(SHAPES) + len(self._stored_polyhedra)))
        return frozen(np.array([SHAPES.index(r.name) if r.name in SHAPES
                                else next(others) if isinstance(r, ConvexPolyhedron) else -1 for r in self.records],
                               dtype=np.int64))

    @functools.cached_property
    def shape_datasets(self) -> dict:
        """The records as the datasets of the table's group /shapes (:data:`data_schema.shape_records.SHAPE_DATASETS`:
        name, kind, vertex_start, vertices, inertia, aspect, both_hands, ...), read-only."""
        return {name: frozen(values) for name, values in shape_datasets(self.records).items()}

    @property
    def _stored_polyhedra(self) -> tuple:
        """The table's polyhedra other than the paper's four families (user grains, later families), in table
        order: the direct model takes them from their stored records. A smooth body other than the ellipsoid has no
        semi-axes on file, and the direct path refuses it (:attr:`model_shapes` −1)."""
        return tuple(r for r in self.records if r.name not in SHAPES and isinstance(r, ConvexPolyhedron))

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
                   config_sha256=table.config_sha256, wall=table.wall, kernel_data=data,
                   direct_parameters=_read_direct_parameters(table, path), records=table.shape_records())


def _read_direct_parameters(table: ReboundTable, path: str) -> np.ndarray:
    """``SurrogateTable.direct_parameters`` from the table's groups /model and /wall (their ranges checked as they
    were read); DataFormatError naming a value out of range."""
    try:
        return model_parameters(AspectRatioLaw(*table.aspect_ratio), table.kappa, table.n_max, table.wall,
                                table.contact_tol, table.set_tol, table.max_steps, table.second_moment_factors)
    except ValueError as exc:
        raise DataFormatError(f"{path}: the direct model's parameters are out of range: {exc}") from None


def load(path) -> SurrogateTable:
    """Load a table file for sampling (checked by :func:`data_schema.check_file`)."""
    return SurrogateTable.from_table(read_table(path), str(path))
