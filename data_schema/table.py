"""Rebound tables: the conditional law of the reflected state on a grid of incident states.

Written by ``tablegen build``, read by the runtime sampler. Layout (docs/format.md):

    /                      attrs: file_type = "rebound_table", format_version = (4, 0),
                           created (ISO 8601 UTC), package_version, model_sha256, config (TOML text),
                           config_sha256, master_seed
    /grid                  alpha1_deg (n_alpha,), speed_m_s (n_speed,), shapes (n_shape,) strings, shape_codes
                           (the checksummed copy of shapes: each family's code, USER_SHAPE_CODE for another);
                           attr: particles_per_cell
    /model/parameters      one row of a compound type: the direct model's parameters by name (MODEL_FIELDS)
    /wall                  attrs: family (the wall law family, direct_model.wall.WALL_FAMILIES), name (the
                           wall's label); parameters: one row of a compound type, the family's parameters by name
                           and speed_range_m_s (2 numbers: the |V⁻| the law holds over, [0, inf]: not stated),
                           then, for a rough wall only, roughness_deg (Δγ, degrees; absent: 0, smooth);
                           the family's arrays by name (tabulated: contact_speed_m_s, contact_sine, restitution)
    /shapes                the definition of every shape the table holds, one row per shape
                           (data_schema.shape_records: name, kind, vertices, triangles, inertia, aspect law, hands)
    /resolution            attrs: clusters, dictionary_size, levels
    /cells/<name>          one dataset per quantity, leading dimensions (n_shape, n_alpha, n_speed); the work
                           datasets (WORK_DATASETS, format 4.1) all or none: a table of 4.0 draws no wall work

Every numeric dataset carries HDF5's Fletcher-32 checksum, so a corrupted
file fails to load with an error naming the dataset; the two parameter rows
are read by field name. What makes a table valid (docs/format.md, "What
makes a table valid") is checked by :func:`check_contract` here and by the
C library's loader, alike. A table of format 3 (before rebound-scatter 1.0)
is refused with how to rebuild it from the configuration it stores
(:func:`stored_config`).

Representation of one cell (docs/format.md): the reflected state of the
rebounded particles, folded by the mirror symmetry Z → −Z to β2 ≥ 0 (Ω_x, Ω_y
multiplied by sign β2) and written in chain order

    x = (α2, |β2|, s = |V⁺|/|V⁻|, Ω_z, Ω_x', Ω_y')     (Ω in units of |V⁻|/a),

is a mixture of C components ("clusters"). Inside cluster c the law is a
triangular chain of conditional inverse CDFs (a discretised inverse Rosenblatt
transform), each a shift, linear in the variables already drawn, of a residual
quantile function::

    x_k = loc[c, k] + scale[c, k] · S_k,m(u_k) + Σ_{j<k} slope[c, k, j] · x_j,   m = shape_id[c, k]

where S_k,m is one of M standardised quantile functions of variable k (the
shape dictionary), stored at probabilities i/L, i = 0..L, and linearly
interpolated. Cluster c is drawn with probability ``cluster_weight[c]``.
Drawing needs one multiply, one floor and one linear interpolation per
variable and no search.

Each cluster holds rebounds of one collision regime (``cluster_regime``):
0 for rebounds of at most :data:`FEW_COLLISIONS` collisions, 1 for more. The
sampler moves a draw between grid speeds by a law that depends on the regime
(docs/format.md, "Between grid points").

The work of a rebound on the wall (format 4.1, docs/design/table_representation.md, "The work on the wall"):
each component continues its chain with two more variables, the rotational energy fraction
r = E_Ω⁺/E⁻ and the root of the normal share ν = √(W_n/(W_n + W_t)), each linear in the six before it (and r) plus
a residual quantile function of their own dictionary; a draw gives W = W_n + W_t = E⁻(1 − s² − r), W_n = ν² W.
The trapped particles' mean work is kept per cell.
"""

from __future__ import annotations

import dataclasses
import hashlib
import math
from pathlib import Path

import h5py
import numpy as np

from data_schema.common import DataFormatError, check_file, write_header
from data_schema.samples import SHAPE_NAMES
from data_schema.shape_records import (SHAPE_DATASETS, SHAPES_GROUP, USER_SHAPE_CODE, check_shape_datasets,
                                       family_records, records_from_arrays, write_shape_records)
from data_schema.output import hdf5_bytes, write_output
from direct_model.wall import MAX_ROUGHNESS_DEG, WALL_FAMILIES, Wall, check_speed_range, wall_family, wall_record

TABLE_FILE_TYPE = "rebound_table"
TABLE_VERSION = (4, 1)      # 4.1: the work datasets (a 4.0 table is read, without them)
# the major versions whose stored configuration `tablegen info --config` reads: 3 (before rebound-scatter 1.0,
# refused by the readers with how to rebuild it) and this one
CONFIG_MAJORS = (3, TABLE_VERSION[0])

# grid speeds a table may hold, m/s (docs/format.md, "What makes a table valid"): the direct model's arithmetic
# fails far outside (1e-100 m/s gives no rebound), and the runtime moves draws between consecutive grid speeds
# by polynomial pieces spanning 25 % of speed each, so their ratio sets the pieces per interval (16: 60)
SPEED_GRID_RANGE = (1e-3, 1e4)
MAX_SPEED_RATIO = 16.0
WEIGHT_SUM_TOLERANCE = 1e-9     # |Σ cluster_weight − 1| allowed per cell
# |value| allowed in the cell datasets a draw reads besides the dictionary (cluster_loc, cluster_scale,
# cluster_slope, mean, std): built tables hold far less (the default table: |slope| < 1700, |loc| < 400); the bound
# keeps every product of a draw's chain finite (at most (10⁶)⁶), and drawn_ok refuses what the fold cannot mend
CELL_VALUE_BOUND = 1e6
# relative round-off allowed on the bound √L of a standardised quantile function (stored as float32)
DICTIONARY_BOUND_TOLERANCE = 1e-6
N_COLLISION_CLASSES = 11            # 1, 2, ..., 10 collisions and more than 10
FEW_COLLISIONS = 2                  # regime 0 of a cluster: rebounds of at most this many collisions
STATE_NAMES = ("alpha2", "beta2", "speed_ratio", "omega_x", "omega_y", "omega_z")
STATE_UNITS = ("rad", "rad", "1", "1", "1", "1")
# indicatrix grids: α2 ∈ [0, π], β2 ∈ [−π/2, π/2], 2.5° bins
INDICATRIX_ALPHA2_EDGES = np.linspace(0.0, np.pi, 73)
INDICATRIX_BETA2_EDGES = np.linspace(-np.pi / 2, np.pi / 2, 73)



# chain order of the folded state inside a cluster (module doc)
CHAIN_NAMES = ("alpha2", "abs_beta2", "speed_ratio", "omega_z", "omega_x_folded", "omega_y_folded")
CHAIN_TO_STATE = (0, 1, 2, 5, 3, 4)   # chain variable k is folded state column CHAIN_TO_STATE[k]
N_CHAIN = len(CHAIN_NAMES)
N_SLOPES = N_CHAIN * (N_CHAIN - 1) // 2
# the work variables that continue each component's chain (module doc): r = E_Ω⁺/E⁻ and ν = √(W_n/(W_n + W_t))
WORK_NAMES = ("rotation_fraction", "normal_share_root")
N_WORK = len(WORK_NAMES)
# slopes of work variable w on the chain variables and the work variables before it: N_CHAIN + w of them,
# packed from WORK_SLOPE_START[w]
WORK_SLOPE_START = tuple(sum(N_CHAIN + v for v in range(w)) for w in range(N_WORK))
N_WORK_SLOPES = sum(N_CHAIN + w for w in range(N_WORK))


def slope_index(k: int, j: int) -> int:
    """Position of slope[c, k, j] (j < k) in the packed ``cluster_slope`` rows: k(k−1)/2 + j."""
    return k * (k - 1) // 2 + j


@dataclasses.dataclass(frozen=True)
class TableResolution:
    """Sizes of a cell's representation (see module doc)."""

    clusters: int = 500          # C: mixture components per cell (fewer used when a cell has few rebounds)
    dictionary_size: int = 16    # M: standardised residual quantile functions per chain variable
    levels: int = 24             # L: quantile functions are stored at probabilities i/L, i = 0..L

    def __post_init__(self):
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
                raise ValueError(f"The table resolution '{f.name}' must be an integer >= 1; got {value!r}.")
        if self.dictionary_size > 256:
            raise ValueError(f"The table resolution 'dictionary_size' must be <= 256 (stored as uint8); "
                             f"got {self.dictionary_size!r}.")

    def cell_nbytes(self) -> int:
        """Bytes of one cell's datasets (:data:`CELL_DATASETS` and :data:`WORK_DATASETS`)."""
        return sum(int(np.prod(shape)) * np.dtype(TABLE_CELL_DATASETS[name][0]).itemsize
                   for name, shape in self.cell_shapes().items())

    def cell_shapes(self) -> dict:
        """Shape of each per-cell dataset (without the three leading grid dimensions), the work's included."""
        c = self.clusters
        return {
            "cluster_weight": (c,),
            "cluster_loc": (c, N_CHAIN),
            "cluster_scale": (c, N_CHAIN),
            "cluster_shape": (c, N_CHAIN),
            "cluster_slope": (c, N_SLOPES),
            "cluster_regime": (c,),
            "shape_dictionary": (N_CHAIN, self.dictionary_size, self.levels + 1),
            "status_counts": (3,),
            "collision_counts": (N_COLLISION_CLASSES,),
            "mean": (len(STATE_NAMES),),
            "std": (len(STATE_NAMES),),
            "indicatrix_2d": (len(INDICATRIX_ALPHA2_EDGES) - 1,),
            "indicatrix_3d": (len(INDICATRIX_ALPHA2_EDGES) - 1, len(INDICATRIX_BETA2_EDGES) - 1),
            "work_loc": (c, N_WORK),
            "work_scale": (c, N_WORK),
            "work_shape": (c, N_WORK),
            "work_slope": (c, N_WORK_SLOPES),
            "work_dictionary": (N_WORK, self.dictionary_size, self.levels + 1),
            "work_mean": (N_WORK,),
            "work_std": (N_WORK,),
            "trapped_work": (2,),
        }


INTEGER_ATTRIBUTES = ("particles_per_cell", "clusters", "dictionary_size", "levels")

# the groups holding the two parameter rows, and their dataset: one row of an HDF5 compound type, chunked (1,)
# under Fletcher-32, read by field name (a field of another name is ignored; its order does not matter)
MODEL_GROUP, WALL_GROUP, PARAMETERS = "model", "wall", "parameters"
WALL_ATTRIBUTES = ("family", "name")        # of group wall: the law family and the wall's label, strings
WALL_SPEED_RANGE = "speed_range_m_s"        # the field of wall/parameters after the family's parameters
WALL_ROUGHNESS = "roughness_deg"            # the field after it, written for a rough wall only (absent: 0)
N_SECOND_MOMENT_FACTORS = 4                 # s per shape code of the paper's four families
_INTEGER_RANGE = "an integer in [1, 2**53)"


def _in_integer_range(x, row) -> bool:
    return 1 <= x < 2 ** 53


def _finite_positive(x, row) -> bool:
    return math.isfinite(x) and x > 0.0


# the fields of model/parameters (ReboundTable attributes of the same names, the aspect-ratio law's four as
# aspect_ratio): name -> (dtype, units, its range in words, its check given the value and the row's values). The
# direct model's parameters (direct_model.runtime.model_parameters); both loaders refuse a value out of range
# with these words, in this order.
MODEL_FIELDS = {
    "kappa": ("<f8", "1", "in [0, 1)", lambda x, row: 0.0 <= x < 1.0),
    "n_max": ("<i8", "1", _INTEGER_RANGE, _in_integer_range),
    "aspect_ratio_mean": ("<f8", "1", "finite", lambda x, row: math.isfinite(x)),
    "aspect_ratio_sd": ("<f8", "1", "finite and > 0", _finite_positive),
    "aspect_ratio_low": ("<f8", "1", "in (0, 1)", lambda x, row: 0.0 < x < 1.0),
    "aspect_ratio_high": ("<f8", "1", "in (aspect_ratio_low, 1]", lambda x, row: row["aspect_ratio_low"] < x <= 1.0),
    "contact_tol": ("<f8", "a", "finite and > 0", _finite_positive),
    "set_tol": ("<f8", "a", "finite and > 0", _finite_positive),
    "max_steps": ("<i8", "1", _INTEGER_RANGE, _in_integer_range),
    "second_moment_factors": (("<f8", (N_SECOND_MOMENT_FACTORS,)), "1",
                              f"{N_SECOND_MOMENT_FACTORS} numbers in (0, 1), one per shape code",
                              lambda x, row: 0.0 < x < 1.0),
}
ASPECT_RATIO_FIELDS = ("aspect_ratio_mean", "aspect_ratio_sd", "aspect_ratio_low", "aspect_ratio_high")
MODEL_DTYPE = np.dtype([(name, spec[0]) for name, spec in MODEL_FIELDS.items()])

# name: (dtype, units, meaning) of the per-cell datasets
CELL_DATASETS = {
    "cluster_weight": ("float64", "1", "probability of each mixture component; 0 for unused clusters; sums to 1"),
    "cluster_loc": ("float32", "rad, rad, 1, 1, 1, 1", "location of each chain variable's residual, per cluster"),
    "cluster_scale": ("float32", "rad, rad, 1, 1, 1, 1", "scale of each chain variable's residual, per cluster"),
    "cluster_shape": ("uint8", "1", "index into shape_dictionary of each chain variable's residual, per cluster"),
    "cluster_slope": ("float32", "1", "slopes of x_k on x_j (j < k), packed at k(k-1)/2 + j, per cluster"),
    "cluster_regime": ("uint8", "1", "collision regime of each cluster's rebounds: 0 = at most FEW_COLLISIONS "
                                     "collisions, 1 = more"),
    "shape_dictionary": ("float32", "1", "standardised residual quantile functions at probabilities i/L, "
                                         "per chain variable"),
    "status_counts": ("int64", "1", "particles rebounded, trapped, failed"),
    "collision_counts": ("int64", "1", "rebounds with 1, 2, ..., 10 and more than 10 collisions"),
    "mean": ("float64", "rad, rad, 1, 1, 1, 1", "means of α2, β2, s, Ω_x, Ω_y, Ω_z over rebounds"),
    "std": ("float64", "rad, rad, 1, 1, 1, 1", "standard deviations of the same"),
    "indicatrix_2d": ("float32", "1/rad", "I(α2): density of α2 on INDICATRIX_ALPHA2_EDGES"),
    "indicatrix_3d": ("float32", "1/rad²", "I(α2, β2): density on the α2 × β2 edges, ∫∫ I dα2 dβ2 = 1"),
}
# the per-cell datasets of the work on the wall (format 4.1; all or none): the chain's two work variables
# (WORK_NAMES), their moments, and the trapped particles' mean work
WORK_DATASETS = {
    "work_loc": ("float32", "1, 1", "location of each work variable's residual (r, ν), per cluster"),
    "work_scale": ("float32", "1, 1", "scale of each work variable's residual, per cluster"),
    "work_shape": ("uint8", "1", "index into work_dictionary of each work variable's residual, per cluster"),
    "work_slope": ("float32", "1", "slopes of work variable w on the chain variables and the work variables before "
                                   "it, packed from WORK_SLOPE_START[w], per cluster"),
    "work_dictionary": ("float32", "1", "standardised residual quantile functions at probabilities i/L, per work "
                                        "variable"),
    "work_mean": ("float64", "1, 1", "means of r = E_Ω⁺/E⁻ and ν = √(W_n/(W_n + W_t)) over rebounds"),
    "work_std": ("float64", "1, 1", "standard deviations of the same"),
    "trapped_work": ("float64", "1, 1", "mean W_n/E⁻ and W_t/E⁻ of the trapped particles (0, 0 if none)"),
}
TABLE_CELL_DATASETS = {**CELL_DATASETS, **WORK_DATASETS}     # what this package writes per cell


@dataclasses.dataclass(frozen=True, eq=False)
class CellTable:
    """The representation of one (shape, α1, |V⁻|) cell; arrays as in :data:`CELL_DATASETS`."""

    cluster_weight: np.ndarray
    cluster_loc: np.ndarray
    cluster_scale: np.ndarray
    cluster_shape: np.ndarray
    cluster_slope: np.ndarray
    cluster_regime: np.ndarray
    shape_dictionary: np.ndarray
    status_counts: np.ndarray
    collision_counts: np.ndarray
    mean: np.ndarray
    std: np.ndarray
    indicatrix_2d: np.ndarray
    indicatrix_3d: np.ndarray
    work_loc: np.ndarray | None = None      # the work datasets (WORK_DATASETS): None in a table of format 4.0
    work_scale: np.ndarray | None = None
    work_shape: np.ndarray | None = None
    work_slope: np.ndarray | None = None
    work_dictionary: np.ndarray | None = None
    work_mean: np.ndarray | None = None
    work_std: np.ndarray | None = None
    trapped_work: np.ndarray | None = None

    def arrays(self) -> dict:
        """The cell's datasets by name, the work's if it has them."""
        return {name: getattr(self, name) for name in TABLE_CELL_DATASETS if getattr(self, name) is not None}


@dataclasses.dataclass(frozen=True, eq=False)
class ReboundTable:
    """A whole table: grids, resolution, provenance and the stacked cell arrays.

    ``cells[name]`` has shape (n_shape, n_alpha, n_speed) + the cell shape of
    ``name`` (:meth:`TableResolution.cell_shapes`).
    """

    alpha1_deg: np.ndarray
    speed_m_s: np.ndarray
    shapes: tuple
    resolution: TableResolution
    cells: dict
    kappa: float
    n_max: int
    particles_per_cell: int
    config_text: str
    config_sha256: str
    master_seed: int
    created: str
    package_version: str
    model_sha256: str                    # hash of the direct model's source that computed the cells
    wall: Wall                           # the wall the cells were built with (group /wall)
    # the rest of the direct model's parameters (group /model, MODEL_FIELDS, with kappa and n_max): the
    # aspect-ratio law (mean, sd, low, high) of b/a and c/b, the contact and contact-set tolerances (units of
    # a), the search-step budget per flight, and s per shape code
    aspect_ratio: tuple
    contact_tol: float
    set_tol: float
    max_steps: int
    second_moment_factors: tuple
    format_version: tuple = TABLE_VERSION    # of the file read (what this package writes for a new table)
    # the registry record (direct_model.registry) of each shape, in the order of ``shapes``; () for the built-in
    # families at ``kappa`` and ``aspect_ratio`` (:meth:`shape_records`)
    records: tuple = ()

    def __post_init__(self):
        lead = (len(self.shapes), len(self.alpha1_deg), len(self.speed_m_s))
        expected = self.resolution.cell_shapes()
        missing = set(CELL_DATASETS) - set(self.cells)
        if missing:
            raise ValueError(f"ReboundTable is missing cell datasets {sorted(missing)}")
        work = set(WORK_DATASETS) & set(self.cells)
        if work and work != set(WORK_DATASETS):
            raise ValueError(f"ReboundTable has the work datasets {sorted(work)} but not "
                             f"{sorted(set(WORK_DATASETS) - work)}: all or none")
        for name, shape in expected.items():
            if name in self.cells and self.cells[name].shape != lead + shape:
                raise ValueError(f"dataset 'cells/{name}' has shape {self.cells[name].shape}, "
                                 f"expected {lead + shape}")
        if self.records and tuple(r.name for r in self.records) != tuple(self.shapes):
            raise ValueError(f"the records name {[r.name for r in self.records]}, the table {list(self.shapes)}")

    @property
    def has_work(self) -> bool:
        """Whether the cells hold the work on the wall (:data:`WORK_DATASETS`; format 4.1)."""
        return set(WORK_DATASETS) <= set(self.cells)

    def shape_records(self) -> tuple:
        """The registry record of each shape, table order: ``records``, or the families' at κ and the aspect law."""
        return self.records or family_records(self.shapes, self.kappa, self.aspect_ratio)

    def model_parameters(self) -> dict:
        """The direct model's parameters by the names of :data:`MODEL_FIELDS` (the row of ``model/parameters``)."""
        return {"kappa": self.kappa, "n_max": self.n_max, **dict(zip(ASPECT_RATIO_FIELDS, self.aspect_ratio)),
                "contact_tol": self.contact_tol, "set_tol": self.set_tol, "max_steps": self.max_steps,
                "second_moment_factors": tuple(self.second_moment_factors)}

    def cell(self, shape: str, i_alpha: int, i_speed: int) -> CellTable:
        """The cell of ``shape`` at grid indices (i_alpha, i_speed)."""
        s = self.shapes.index(shape)
        return CellTable(**{name: arr[s, i_alpha, i_speed] for name, arr in self.cells.items()})

    # -- HDF5 ---------------------------------------------------------------
    def to_hdf5(self, f: h5py.File) -> None:
        """Write the table into an open file (header attributes excluded)."""
        f.attrs["created"] = self.created
        f.attrs["package_version"] = self.package_version
        f.attrs["model_sha256"] = self.model_sha256
        f.attrs["config"] = self.config_text
        f.attrs["config_sha256"] = self.config_sha256
        f.attrs["master_seed"] = np.uint64(self.master_seed)
        grid = f.create_group("grid")
        for name, units in (("alpha1_deg", "deg"), ("speed_m_s", "m/s")):
            values = np.asarray(getattr(self, name), dtype=np.float64)
            grid.create_dataset(name, data=values, fletcher32=True).attrs["units"] = units
        grid.create_dataset("shapes", data=np.array(self.shapes, dtype=h5py.string_dtype()))
        # the checksummed copy of the names: two swapped shape names fail to load
        grid.create_dataset("shape_codes", data=shape_codes(self.shapes), fletcher32=True)
        grid.attrs["particles_per_cell"] = self.particles_per_cell
        row = np.zeros(1, dtype=MODEL_DTYPE)
        for name, value in self.model_parameters().items():
            row[name] = value
        _write_row(f.create_group(MODEL_GROUP), row, [spec[1] for spec in MODEL_FIELDS.values()],
                   "the direct model's parameters the cells were built with, by name")
        family = wall_family(self.wall.family)
        wall = f.create_group(WALL_GROUP)
        wall.attrs["family"] = family.name
        wall.attrs["name"] = self.wall.name
        rough = self.wall.roughness_deg != 0.0      # a smooth wall's row as before roughness: the same file
        row = np.array([(*self.wall.parameters().values(), self.wall.speed_range_m_s,
                         *([self.wall.roughness_deg] if rough else []))],
                       dtype=[(p.name, "<f8") for p in family.parameters] + [(WALL_SPEED_RANGE, "<f8", (2,))]
                       + ([(WALL_ROUGHNESS, "<f8")] if rough else []))
        _write_row(wall, row, [p.units for p in family.parameters] + ["m/s"] + (["deg"] if rough else []),
                   f"the {family.name} wall law's parameters, by name, the incident speeds it holds over"
                   + (" and the wall's roughness" if rough else ""))
        for spec, values in zip(family.arrays, self.wall.arrays().values()):
            ds = wall.create_dataset(spec.name, data=values, fletcher32=True)
            ds.attrs["units"] = spec.units
            ds.attrs["meaning"] = spec.meaning
        res = f.create_group("resolution")
        for field in dataclasses.fields(self.resolution):
            res.attrs[field.name] = getattr(self.resolution, field.name)
        write_shape_records(f, self.shape_records())
        cells = f.create_group("cells")
        for name, (dtype, units, meaning) in TABLE_CELL_DATASETS.items():
            if name not in self.cells:      # a table read from format 4.0, written again
                continue
            values = np.asarray(self.cells[name], dtype=dtype)
            # one chunk per cell: whole chunks only (automatic chunk shapes padded the table by a fifth)
            ds = cells.create_dataset(name, data=values, fletcher32=True, chunks=(1, 1, 1) + values.shape[3:])
            ds.attrs["units"] = units
            ds.attrs["meaning"] = meaning

    @classmethod
    def from_hdf5(cls, f: h5py.File) -> "ReboundTable":
        """Read a table written by :meth:`to_hdf5`; DataFormatError naming what is missing."""
        where = f.filename
        for group in ("grid", "resolution", "cells", MODEL_GROUP, WALL_GROUP, SHAPES_GROUP):
            if group not in f:
                raise DataFormatError(f"{where}: missing group '{group}'")
        for name in ("alpha1_deg", "speed_m_s", "shapes", "shape_codes"):
            if name not in f["grid"]:
                raise DataFormatError(f"{where}: missing dataset 'grid/{name}'")
        missing = [n for n in CELL_DATASETS if n not in f["cells"]]
        if missing:
            raise DataFormatError(f"{where}: missing dataset(s) {', '.join('cells/' + n for n in missing)}")
        grid = f["grid"]
        alpha1_deg, speed_m_s, codes = (_read(grid, name) for name in ("alpha1_deg", "speed_m_s", "shape_codes"))
        cells = {name: _read(f["cells"], name) for name in TABLE_CELL_DATASETS if name in f["cells"]}
        shapes = _read_group(f[SHAPES_GROUP])
        model_row, wall_row = (_read_row(f[group]) for group in (MODEL_GROUP, WALL_GROUP))
        try:
            resolution = TableResolution(**{name: _number(f["resolution"], name)
                                            for name in ("clusters", "dictionary_size", "levels")})
            model = _model_fields(model_row)
            table = cls(
                alpha1_deg=alpha1_deg, speed_m_s=speed_m_s,
                shapes=tuple(s.decode() if isinstance(s, bytes) else str(s) for s in grid["shapes"][()]),
                resolution=resolution, cells=cells, kappa=model["kappa"],
                n_max=model["n_max"], particles_per_cell=_number(grid, "particles_per_cell"),
                config_text=str(f.attrs["config"]), config_sha256=str(f.attrs["config_sha256"]),
                master_seed=int(f.attrs["master_seed"]), created=str(f.attrs["created"]),
                package_version=str(f.attrs["package_version"]), model_sha256=str(f.attrs["model_sha256"]),
                wall=_wall(f[WALL_GROUP], wall_row),
                aspect_ratio=tuple(model[name] for name in ASPECT_RATIO_FIELDS), contact_tol=model["contact_tol"],
                set_tol=model["set_tol"], max_steps=model["max_steps"],
                second_moment_factors=model["second_moment_factors"],
                format_version=tuple(int(x) for x in f.attrs["format_version"]))
        except (OSError, KeyError, TypeError) as exc:
            raise DataFormatError(f"{where}: cannot read the table (truncated or corrupt?): {exc}") from exc
        except ValueError as exc:
            if isinstance(exc, DataFormatError):
                raise DataFormatError(f"{where}: {exc}") from None
            raise DataFormatError(f"{where}: inconsistent table: {exc}") from exc
        check_contract(table, where, codes, shapes)
        return dataclasses.replace(table, records=_records(table, shapes, where))


def shape_codes(names) -> np.ndarray:
    """``grid/shapes``' checksummed copy ``grid/shape_codes``: each family's code, USER_SHAPE_CODE for another."""
    return np.array([SHAPE_NAMES.index(s) if s in SHAPE_NAMES else USER_SHAPE_CODE for s in names], dtype=np.uint8)


def _records(table: ReboundTable, shapes: dict, where: str) -> tuple:
    """The records of a checked table, from its /shapes datasets."""
    def refuse(text):
        raise DataFormatError(f"{where}: {text}")

    return records_from_arrays(shapes, table.shapes, table.kappa, table.aspect_ratio, refuse)


def _g(value) -> str:
    """A value in an error message, as the C loader prints it: an integer as it is, a real as %.17g."""
    return str(value) if isinstance(value, int) else f"{float(value):.17g}"


def _write_row(group: h5py.Group, row: np.ndarray, units, meaning: str) -> None:
    """``row`` (one row of a compound type) as ``group/parameters``, chunked (1,) under Fletcher-32."""
    ds = group.create_dataset(PARAMETERS, data=row, chunks=(1,), fletcher32=True)
    ds.attrs["units"] = ", ".join(units)
    ds.attrs["meaning"] = meaning


def _read_row(group: h5py.Group) -> np.ndarray:
    """The one row of ``group/parameters`` (a structured array of one element); DataFormatError naming the dataset
    if it is missing, not one row of a compound type, or cannot be read (the file named but by _read)."""
    where = f"dataset '{group.name.lstrip('/')}/{PARAMETERS}'"
    if PARAMETERS not in group:
        raise DataFormatError(f"{group.file.filename}: missing {where}")
    ds = group[PARAMETERS]
    if not isinstance(ds, h5py.Dataset) or ds.dtype.names is None or ds.shape != (1,):
        raise DataFormatError(f"{group.file.filename}: {where} must hold one row of a compound type, one field "
                              f"per parameter")
    return _read(group, PARAMETERS)


def _field(row: np.ndarray, dataset: str, name: str, kind: str, count: int | None, fields: str):
    """Field ``name`` of ``row`` (read from ``dataset``): an int (``kind`` "integer"), a float ("number") or a
    tuple of ``count`` floats; DataFormatError (no file name) if it is missing or stored as something else."""
    if name not in row.dtype.names:
        raise DataFormatError(f"dataset '{dataset}' has no field '{name}'; the fields read: {fields}")
    stored = row.dtype[name]
    base, shape = (stored.subdtype if stored.subdtype is not None else (stored, ()))
    wanted = () if count is None else (count,)
    if base.kind not in ("iu" if kind == "integer" else "iuf") or shape != wanted:
        what = f"{count} numbers" if count is not None else f"one {kind}"
        raise DataFormatError(f"field '{name}' of dataset '{dataset}' must be stored as {what}")
    value = row[name][0]
    if count is not None:
        return tuple(float(x) for x in value)
    return int(value) if kind == "integer" else float(value)


def _model_fields(row: np.ndarray) -> dict:
    """The fields of ``model/parameters`` by name, each checked against its range (:data:`MODEL_FIELDS`, in
    order); DataFormatError (no file name) naming a field missing, of another type, or out of range."""
    dataset = f"{MODEL_GROUP}/{PARAMETERS}"
    names = ", ".join(MODEL_FIELDS)
    values = {}
    for name, (dtype, _, _, _) in MODEL_FIELDS.items():
        kind = "integer" if np.dtype(dtype).kind == "i" else "number"
        count = N_SECOND_MOMENT_FACTORS if isinstance(dtype, tuple) else None
        values[name] = _field(row, dataset, name, kind, count, names)
    for name, (_, _, allowed, ok) in MODEL_FIELDS.items():
        value = values[name]
        for i, x in enumerate(value if isinstance(value, tuple) else (value,)):
            if not ok(x, values):
                at = f" at index {i}" if isinstance(value, tuple) else ""
                raise DataFormatError(f"field '{name}' of dataset '{dataset}' must be {allowed}; got {_g(x)}{at}")
    return values


def _string_attribute(group: h5py.Group, name: str) -> str:
    """A string attribute of ``group``; DataFormatError (no file name) if it is missing or not a string."""
    where = f"of group '{group.name.lstrip('/')}'"
    if name not in group.attrs:
        raise DataFormatError(f"missing attribute '{name}' {where}")
    try:
        value = group.attrs[name]
    except (OSError, TypeError, ValueError):
        value = None
    if isinstance(value, bytes):
        value = value.decode(errors="replace")
    if not isinstance(value, str):
        raise DataFormatError(f"cannot read the attribute '{name}' {where} as a string")
    return value


def _wall(group: h5py.Group, row: np.ndarray) -> Wall:
    """The wall record of group /wall and its parameters' row: its family by name (one of
    direct_model.wall.WALL_FAMILIES), each of the family's parameters by field name within its range;
    DataFormatError (no file name) naming the attribute or field otherwise."""
    family_name, name = (_string_attribute(group, attribute) for attribute in WALL_ATTRIBUTES)
    try:
        family = wall_family(family_name)
    except ValueError:
        raise DataFormatError(f"the attribute 'family' of group '{WALL_GROUP}' names an unknown wall law family "
                              f"'{family_name}' (this version knows: {', '.join(WALL_FAMILIES)})") from None
    dataset = f"{WALL_GROUP}/{PARAMETERS}"
    fields = f"{', '.join(family.parameter_names)} (the {family.name} wall law)"
    fields += f" and {WALL_SPEED_RANGE}"
    values = {p.name: _field(row, dataset, p.name, "number", None, fields) for p in family.parameters}
    for parameter in family.parameters:
        if not parameter.ok(values[parameter.name]):
            raise DataFormatError(f"field '{parameter.name}' of dataset '{dataset}' must be {parameter.allowed}; "
                                  f"got {_g(values[parameter.name])}")
    speed_range = _field(row, dataset, WALL_SPEED_RANGE, "number", 2, fields)
    try:
        speed_range = check_speed_range(speed_range)
    except ValueError:
        raise DataFormatError(f"field '{WALL_SPEED_RANGE}' of dataset '{dataset}' must be [low, high] m/s with "
                              f"0 <= low < high finite, or [0, inf] (not stated); got [{_g(speed_range[0])}, "
                              f"{_g(speed_range[1])}]") from None
    roughness = 0.0
    if row.dtype.names is not None and WALL_ROUGHNESS in row.dtype.names:
        roughness = _field(row, dataset, WALL_ROUGHNESS, "number", None, fields)
        if not 0.0 <= roughness <= MAX_ROUGHNESS_DEG:
            raise DataFormatError(f"field '{WALL_ROUGHNESS}' of dataset '{dataset}' must be in "
                                  f"[0, {MAX_ROUGHNESS_DEG:g}] degrees; got {_g(roughness)}")
    for spec in family.arrays:
        if spec.name not in group or not isinstance(group[spec.name], h5py.Dataset):
            raise DataFormatError(f"missing dataset '{WALL_GROUP}/{spec.name}' (an array of the {family.name} wall "
                                  f"law: {spec.meaning.split(':')[0]})")
        values[spec.name] = np.asarray(_read(group, spec.name))
        if values[spec.name].dtype.kind not in "iuf" or values[spec.name].ndim != len(spec.dims):
            raise DataFormatError(f"dataset '{WALL_GROUP}/{spec.name}' must hold {len(spec.dims)}-dimensional "
                                  f"numbers; got {values[spec.name].dtype} of shape {values[spec.name].shape}")
    # as lists: an error quotes them as the C loader does
    values.update({spec.name: values[spec.name].tolist() for spec in family.arrays})
    try:
        return wall_record(family.name, values, name, speed_range, float(roughness))
    except ValueError as exc:       # a tabulated law's nodes or values
        raise DataFormatError(f"group '{WALL_GROUP}': {exc}") from None


def _number(group: h5py.Group, name: str, count: int | None = 1):
    """Attribute ``name`` of ``group``: ``count`` numbers (None: 1 to 8) as a float, an int
    (:data:`INTEGER_ATTRIBUTES`) or a tuple of floats; DataFormatError (no file name) naming it if it is
    missing or is not numbers of that kind (a string "0.61", say), the C loader's message."""
    where = f"of group '{group.name.lstrip('/')}'"
    if name not in group.attrs:
        raise DataFormatError(f"missing attribute '{name}' {where}")
    try:
        values = np.asarray(group.attrs[name])
    except (OSError, TypeError, ValueError):
        values = np.asarray("unreadable")
    integer = name in INTEGER_ATTRIBUTES
    size_ok = values.size == count if count is not None else 1 <= values.size <= 8
    if values.dtype.kind not in ("iu" if integer else "iuf") or not size_ok:
        wanted = "one integer" if integer else "one number" if count == 1 else "1 to 8 numbers"
        raise DataFormatError(f"cannot read the attribute '{name}' {where} as {wanted}")
    if count is None:
        return tuple(float(x) for x in values.ravel())
    return int(values.ravel()[0]) if integer else float(values.ravel()[0])


def check_contract(table: ReboundTable, where: str, codes, shapes: dict) -> None:
    """DataFormatError naming the file and the value unless ``table`` obeys what makes a table valid beyond its
    layout (docs/format.md, "What makes a table valid"; the C loader checks the same). ``codes`` is the dataset
    ``grid/shape_codes``, which must be the codes of the names; ``shapes`` holds the datasets of group /shapes
    (:func:`data_schema.shape_records.check_shape_datasets`). The two parameter rows were checked as they were
    read (:func:`_model_fields`, :func:`_wall`)."""
    def refuse(text):
        raise DataFormatError(f"{where}: {text}")

    check_shape_datasets(shapes, table.shapes, refuse)
    alpha1, speed = np.asarray(table.alpha1_deg, dtype=np.float64), np.asarray(table.speed_m_s, dtype=np.float64)
    if not (np.all((alpha1 > 0.0) & (alpha1 <= 90.0)) and np.all(np.diff(alpha1) > 0.0)):
        refuse(f"dataset 'grid/alpha1_deg' must be strictly increasing in (0, 90] deg; got {alpha1.tolist()}")
    low, high = SPEED_GRID_RANGE
    if not (np.all((speed >= low) & (speed <= high)) and np.all(np.diff(speed) > 0.0)):
        refuse(f"dataset 'grid/speed_m_s' must be strictly increasing in [{low:g}, {high:g}] m/s; got {speed.tolist()}")
    if np.any(speed[1:] > MAX_SPEED_RATIO * speed[:-1]):
        refuse(f"dataset 'grid/speed_m_s' has consecutive speeds more than a factor {MAX_SPEED_RATIO:g} apart; got "
               f"{speed.tolist()}")
    if np.ravel(codes).tolist() != shape_codes(table.shapes).tolist():
        refuse(f"dataset 'grid/shapes' {list(table.shapes)} differs from its checksummed copy 'grid/shape_codes' "
               f"{np.ravel(codes).tolist()}")
    cells, m = table.cells, table.resolution.dictionary_size
    bound = CELL_VALUE_BOUND
    rules = (("cluster_weight", lambda x: np.isfinite(x) & (x >= 0.0), "finite and >= 0"),
             ("cluster_loc", lambda x: np.abs(x) <= bound, f"in [-{bound:g}, {bound:g}]"),
             ("cluster_scale", lambda x: (x >= 0.0) & (x <= bound), f"in [0, {bound:g}]"),
             ("cluster_slope", lambda x: np.abs(x) <= bound, f"in [-{bound:g}, {bound:g}]"),
             ("cluster_shape", lambda x: x < m, f"below the dictionary size {m}"),
             ("cluster_regime", lambda x: x <= 1, "0 or 1"),
             ("status_counts", lambda x: x >= 0, ">= 0"),
             ("collision_counts", lambda x: x >= 0, ">= 0"),
             ("mean", lambda x: np.abs(x) <= bound, f"in [-{bound:g}, {bound:g}]"),
             ("std", lambda x: (x >= 0.0) & (x <= bound), f"in [0, {bound:g}]"),
             ("indicatrix_2d", lambda x: np.isfinite(x) & (x >= 0.0), "finite and >= 0"),
             ("indicatrix_3d", lambda x: np.isfinite(x) & (x >= 0.0), "finite and >= 0"),
             ("work_loc", lambda x: np.abs(x) <= bound, f"in [-{bound:g}, {bound:g}]"),
             ("work_scale", lambda x: (x >= 0.0) & (x <= bound), f"in [0, {bound:g}]"),
             ("work_slope", lambda x: np.abs(x) <= bound, f"in [-{bound:g}, {bound:g}]"),
             ("work_shape", lambda x: x < m, f"below the dictionary size {m}"),
             ("work_mean", lambda x: np.abs(x) <= bound, f"in [-{bound:g}, {bound:g}]"),
             ("work_std", lambda x: (x >= 0.0) & (x <= bound), f"in [0, {bound:g}]"),
             ("trapped_work", lambda x: (x >= 0.0) & (x <= 1.0), "in [0, 1] (fractions of E⁻)"))
    for name, ok, wanted in rules:
        if name not in cells:       # the work datasets of a table of format 4.0
            continue
        values = np.asarray(cells[name])
        bad = np.flatnonzero(~ok(values).ravel())
        if bad.size:
            refuse(f"dataset 'cells/{name}' holds {values.ravel()[bad[0]].item()!r} at element {bad[0]}; its values "
                   f"must be {wanted}")
    for name in ("shape_dictionary", "work_dictionary")[:2 if table.has_work else 1]:
        check_dictionary(np.asarray(cells[name]), table.resolution.levels, refuse, name)
    weight_sum = np.asarray(cells["cluster_weight"]).sum(axis=-1).ravel()
    bad = np.flatnonzero(np.abs(weight_sum - 1.0) > WEIGHT_SUM_TOLERANCE)
    if bad.size:
        refuse(f"dataset 'cells/cluster_weight' of cell {bad[0]} sums to {float(weight_sum[bad[0]])!r}; each cell's weights "
               f"must sum to 1 within {WEIGHT_SUM_TOLERANCE:g}")
    drawn = np.asarray(cells["status_counts"])[..., :2].sum(axis=-1).ravel()
    if np.any(drawn <= 0):
        refuse(f"dataset 'cells/status_counts' of cell {np.flatnonzero(drawn <= 0)[0]} has no rebounded or trapped "
               f"particle")


def check_dictionary(dictionary: np.ndarray, levels: int, refuse, name: str) -> None:
    """``refuse`` (called with the message) unless every row of ``cells/<name>`` is a standardised
    quantile function: non-decreasing, its knots within ±√L (the largest |knot| of L + 1 knots of mean 0 and
    standard deviation 1; the build's non-decreasing pass only repeats knots) up to float32 round-off."""
    bound = np.float32(np.sqrt(levels) * (1.0 + DICTIONARY_BOUND_TOLERANCE))
    flat = dictionary.reshape(-1)
    bad = np.flatnonzero(~(np.abs(flat) <= bound))
    if bad.size:
        refuse(f"dataset 'cells/{name}' holds {flat[bad[0]].item()!r} at element {bad[0]}; its values must "
               f"be in [-{bound:.9g}, {bound:.9g}] (sqrt of the levels {levels})")
    rows = dictionary.reshape(-1, dictionary.shape[-1])
    bad = np.flatnonzero(np.any(np.diff(rows, axis=1) < 0.0, axis=1))
    if bad.size:
        refuse(f"dataset 'cells/{name}' row {bad[0]} decreases; each row (a quantile function) must be "
               f"non-decreasing")


def _read_group(group: h5py.Group) -> dict:
    """Every dataset of :data:`SHAPE_DATASETS` in ``group``, converted to its dtype; DataFormatError naming one
    that is missing, of another class (strings, integers, floats: as the C loader's H5Tget_class) or cannot be
    read."""
    arrays = {}
    for name, (dtype, _, _) in SHAPE_DATASETS.items():
        where = f"{group.file.filename}: dataset '{group.name.lstrip('/')}/{name}'"
        if name not in group:
            raise DataFormatError(f"{group.file.filename}: missing dataset '{group.name.lstrip('/')}/{name}'")
        stored, wanted = group[name].dtype, np.dtype(dtype)
        if not isinstance(group[name], h5py.Dataset) or stored.kind.replace("u", "i") != wanted.kind.replace("u", "i"):
            raise DataFormatError(f"{where} is of type {stored}, expected {wanted}")
        arrays[name] = _read(group, name).astype(wanted)
    return arrays


def _read(group: h5py.Group, name: str) -> np.ndarray:
    """A dataset's array; DataFormatError naming it if it cannot be read (its checksum fails, say)."""
    try:
        return group[name][()]
    except (OSError, ValueError) as exc:
        raise DataFormatError(f"{group.file.filename}: dataset '{group[name].name.lstrip('/')}' cannot be read "
                              f"(corrupt file: {' '.join(str(exc).split())})") from exc


# root attributes the fingerprint covers: the layout and the build's recipe (docs/format.md, "Fingerprint"); not
# created, package_version or model_sha256, which say when and by which code, not what the table holds
FINGERPRINT_ROOT_ATTRIBUTES = ("file_type", "format_version", "config", "config_sha256", "master_seed")
FINGERPRINT_GROUPS = ("grid", MODEL_GROUP, WALL_GROUP, "resolution", "cells", SHAPES_GROUP)


def table_fingerprint(path) -> str:
    """SHA-256 of what a table holds (docs/format.md, "Fingerprint"), hex: the root attributes of
    :data:`FINGERPRINT_ROOT_ATTRIBUTES`, then for each group of :data:`FINGERPRINT_GROUPS` its attributes and
    its datasets in the order of their names, each hashed as its name, dtype, shape and little-endian bytes
    (strings as UTF-8); a compound dataset (the parameter rows) as each of its fields in the order of their names,
    ``group/dataset.field``, so the fields' order in the file does not enter. Datasets' ``units`` and
    ``meaning`` attributes are descriptions and are left out; the checksums and HDF5's chunking do not enter. A
    config and a seed give one fingerprint whatever built them."""
    digest = hashlib.sha256()

    def feed(name: str, value) -> None:
        values = np.asarray(value)
        if values.dtype.kind in "OSU":
            items = [x.decode() if isinstance(x, bytes) else str(x) for x in values.ravel()]
            kind, data = "str", "\0".join(items).encode()
        else:
            little = np.ascontiguousarray(values, dtype=values.dtype.newbyteorder("<"))
            kind, data = little.dtype.str, little.tobytes()
        for part in (name.encode(), kind.encode(), repr(values.shape).encode(), len(data).to_bytes(8, "little"), data):
            digest.update(part + b"\0")

    check_table_file(path)
    with h5py.File(path, "r") as f:
        for name in FINGERPRINT_ROOT_ATTRIBUTES:
            feed(f"@{name}", f.attrs[name])
        for group in (g for g in FINGERPRINT_GROUPS if g in f):
            for name in sorted(f[group].attrs):
                feed(f"{group}@{name}", f[group].attrs[name])
            for name in sorted(f[group]):
                values = _read(f[group], name)
                for field in (sorted(values.dtype.names) if values.dtype.names else [None]):
                    if field is None:
                        feed(f"{group}/{name}", values)
                    else:
                        feed(f"{group}/{name}.{field}", values[field])
    return digest.hexdigest()


def write_table(path, table: ReboundTable, overwrite: bool = False) -> Path:
    """Write ``table`` to an HDF5 file at ``path``, whole or not at all; return the path.

    ``overwrite`` replaces only a table file (:func:`data_schema.output.check_output`).
    """
    def write(f):
        write_header(f, TABLE_FILE_TYPE, TABLE_VERSION)
        table.to_hdf5(f)

    return write_output(path, hdf5_bytes(write), TABLE_FILE_TYPE, overwrite)


def _older_table(path, major: int, minor: int) -> str | None:
    """The message (without the path) refusing a table of format 3, written before rebound-scatter 1.0: how to
    rebuild it from the configuration it stores. None for another major version (check_file's message)."""
    if major != 3:
        return None
    return (f"table format {major}.{minor} was written before rebound-scatter 1.0, which reads format "
            f"{TABLE_VERSION[0]}; rebuild it from the configuration it stores: tablegen info --config {path} > "
            f"TABLE.toml && tablegen build --config TABLE.toml -o NEW.h5")


def check_table_file(path) -> None:
    """:func:`data_schema.check_file` for a table: a table of format 3 is refused with how to rebuild it."""
    check_file(path, TABLE_FILE_TYPE, TABLE_VERSION[0], other_major=_older_table)


def stored_config(path) -> str:
    """The build configuration (TOML text) a table of format 3 or 4 stores, its root attribute ``config``, read
    without the rest of the table: ``tablegen build --config`` rebuilds the table from it (user grains are stored
    as their hulls, not as mesh paths). DataFormatError naming the file if it is not such a table."""
    check_file(path, TABLE_FILE_TYPE, CONFIG_MAJORS)
    try:
        with h5py.File(path, "r") as f:
            text = f.attrs.get("config")
    except OSError as exc:
        raise DataFormatError(f"{path}: cannot read the table (truncated or corrupt?): {exc}") from exc
    if isinstance(text, bytes):
        text = text.decode(errors="replace")
    if not isinstance(text, str) or not text.strip():
        raise DataFormatError(f"{path}: the table stores no build configuration (root attribute 'config')")
    return text


def read_table(path) -> ReboundTable:
    """Read a rebound table, after :func:`check_table_file`."""
    check_table_file(path)
    try:
        with h5py.File(path, "r") as f:
            return ReboundTable.from_hdf5(f)
    except OSError as exc:
        raise DataFormatError(f"{path}: cannot read the table (truncated or corrupt?): {exc}") from exc
