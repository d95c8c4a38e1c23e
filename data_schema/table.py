"""Rebound tables: the conditional law of the reflected state on a grid of incident states.

Written by ``tablegen build``, read by the runtime sampler. Layout (docs/format.md):

    /                      attrs: file_type = "rebound_table", format_version = (3, 4),
                           created (ISO 8601 UTC), package_version, model_sha256, config (TOML text),
                           config_sha256, master_seed
    /grid                  alpha1_deg (n_alpha,), speed_m_s (n_speed,), shapes (n_shape,) strings;
                           attrs: kappa, n_max, particles_per_cell,
                           restitution_k, restitution_p (the wall's normal-restitution law),
                           friction_q, wall_law (its friction exponent and name; since 3.1, optional);
                           aspect_ratio_{mean,sd,low,high}, contact_tol, set_tol, max_steps,
                           second_moment_factors (the rest of the direct model's parameters; required since
                           3.3); law and shape_codes, checksummed copies of the attributes (LAW_ATTRIBUTES;
                           3.2: restitution_k, restitution_p only) and names the law depends on (since 3.2;
                           since 3.4 shape_codes holds USER_SHAPE_CODE for a shape that is not a family)
    /shapes                (since 3.4) the definition of every shape the table holds, one row per shape
                           (data_schema.shape_records: name, kind, vertices, triangles, inertia, aspect law, hands)
    /resolution            attrs: clusters, dictionary_size, levels
    /cells/<name>          one dataset per quantity, leading dimensions (n_shape, n_alpha, n_speed)

Every numeric dataset carries HDF5's Fletcher-32 checksum (since 3.1), so a
corrupted file fails to load with an error naming the dataset. What makes a
table valid (docs/format.md, "What makes a table valid") is checked by
:func:`check_contract` here and by the C library's loader, alike.

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
"""

from __future__ import annotations

import dataclasses
import hashlib
import tomllib
from pathlib import Path

import h5py
import numpy as np

from data_schema.common import DataFormatError, check_file, write_header
from data_schema.samples import SHAPE_NAMES
from data_schema.shape_records import (SHAPE_DATASETS, SHAPES_GROUP, USER_SHAPE_CODE, check_shape_datasets,
                                       family_records, records_from_arrays, write_shape_records)
from data_schema.output import hdf5_bytes, write_output

TABLE_FILE_TYPE = "rebound_table"
TABLE_VERSION = (3, 4)
SHAPES_SINCE = 4        # the minor version from which a table holds group /shapes

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


# the direct model's tolerances every build used before tables recorded them (grid attributes; the defaults
# of direct_model.simulate, which tablegen never changed)
BUILT_WITH_TOLERANCES = {"contact_tol": 1e-10, "set_tol": 1e-9, "max_steps": 100_000}
# s per shape code (J/m = s (b²+c², a²+c², a²+b²)) as builds computed them at κ = 0.3, every preset's κ, before
# tables recorded them (direct_model.shapes.second_moment_factors(0.3), bit for bit)
BUILT_WITH_KAPPA = 0.3
BUILT_WITH_SECOND_MOMENT_FACTORS = (0.2, 0.33333333333333337, 0.3309571404654277, 0.20000000000000004)
# the aspect-ratio law's attributes, by their key in the configuration's aspect_ratio table
ASPECT_RATIO_ATTRIBUTES = {"aspect_ratio_mean": "mean", "aspect_ratio_sd": "sd", "aspect_ratio_low": "low",
                           "aspect_ratio_high": "high"}


# chain order of the folded state inside a cluster (module doc)
CHAIN_NAMES = ("alpha2", "abs_beta2", "speed_ratio", "omega_z", "omega_x_folded", "omega_y_folded")
CHAIN_TO_STATE = (0, 1, 2, 5, 3, 4)   # chain variable k is folded state column CHAIN_TO_STATE[k]
N_CHAIN = len(CHAIN_NAMES)
N_SLOPES = N_CHAIN * (N_CHAIN - 1) // 2


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
        """Bytes of one cell's datasets (:data:`CELL_DATASETS`)."""
        return sum(int(np.prod(shape)) * np.dtype(CELL_DATASETS[name][0]).itemsize
                   for name, shape in self.cell_shapes().items())

    def cell_shapes(self) -> dict:
        """Shape of each per-cell dataset (without the three leading grid dimensions)."""
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
        }


# the checksummed copies of the law's attributes and shape names in group grid (since 3.2)
LAW_DATASETS = ("law", "shape_codes")
# the grid attributes grid/law copies, in its order (3.3; a 3.2 table copies the first two): every attribute the
# runtime reads, the table path's wall law and the direct model's parameters (second_moment_factors: 4 numbers)
LAW_ATTRIBUTES = ("restitution_k", "restitution_p", "friction_q", "kappa", "n_max", "aspect_ratio_mean",
                  "aspect_ratio_sd", "aspect_ratio_low", "aspect_ratio_high", "contact_tol", "set_tol", "max_steps",
                  "second_moment_factors")
INTEGER_ATTRIBUTES = ("n_max", "particles_per_cell", "max_steps", "clusters", "dictionary_size", "levels")

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

    def arrays(self) -> dict:
        return {name: getattr(self, name) for name in CELL_DATASETS}


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
    restitution_k: float                 # normal restitution exp(−k |V_c|^p) of the wall law, (m/s)^(−p)
    restitution_p: float
    model_sha256: str = ""               # hash of the direct model's source that computed the cells ("" before 3.1)
    friction_q: float = float("nan")     # friction factor exp(q cos γ) of the wall law (NaN if not recorded)
    wall_law: str = ""                   # name of the wall law ("" if not recorded)
    # the rest of the direct model's parameters (docs/format.md; tables before these were recorded: see
    # :meth:`from_hdf5`): the aspect-ratio law (mean, sd, low, high) of b/a and c/b, the contact and
    # contact-set tolerances (units of a), the search-step budget per flight, and s per shape code
    aspect_ratio: tuple = (float("nan"),) * 4
    contact_tol: float = BUILT_WITH_TOLERANCES["contact_tol"]
    set_tol: float = BUILT_WITH_TOLERANCES["set_tol"]
    max_steps: int = BUILT_WITH_TOLERANCES["max_steps"]
    second_moment_factors: tuple = (float("nan"),) * 4
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
        for name, shape in expected.items():
            if self.cells[name].shape != lead + shape:
                raise ValueError(f"dataset 'cells/{name}' has shape {self.cells[name].shape}, "
                                 f"expected {lead + shape}")
        if self.records and tuple(r.name for r in self.records) != tuple(self.shapes):
            raise ValueError(f"the records name {[r.name for r in self.records]}, the table {list(self.shapes)}")

    def shape_records(self) -> tuple:
        """The registry record of each shape, table order: ``records``, or the families' at κ and the aspect law."""
        return self.records or family_records(self.shapes, self.kappa, self.aspect_ratio)

    def law_values(self) -> np.ndarray:
        """The attributes of :data:`LAW_ATTRIBUTES` in order, as float64: the content of ``grid/law`` (3.3)."""
        values = [self.restitution_k, self.restitution_p, self.friction_q, self.kappa, self.n_max,
                  *self.aspect_ratio, self.contact_tol, self.set_tol, self.max_steps, *self.second_moment_factors]
        return np.array(values, dtype=np.float64)

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
        # checksummed copies of what the law depends on beyond the cell datasets (3.2; every law attribute
        # since 3.3): a flipped bit of an attribute or a swapped shape name fails to load
        grid.create_dataset("law", data=self.law_values(), fletcher32=True)
        grid.create_dataset("shape_codes", data=shape_codes(self.shapes), fletcher32=True)
        grid.attrs["kappa"] = self.kappa
        grid.attrs["n_max"] = self.n_max
        grid.attrs["particles_per_cell"] = self.particles_per_cell
        grid.attrs["restitution_k"] = self.restitution_k
        grid.attrs["restitution_p"] = self.restitution_p
        grid.attrs["friction_q"] = self.friction_q
        grid.attrs["wall_law"] = self.wall_law
        for name, value in zip(ASPECT_RATIO_ATTRIBUTES, self.aspect_ratio):
            grid.attrs[name] = value
        for name in BUILT_WITH_TOLERANCES:
            grid.attrs[name] = getattr(self, name)
        grid.attrs["second_moment_factors"] = np.asarray(self.second_moment_factors, dtype=np.float64)
        res = f.create_group("resolution")
        for field in dataclasses.fields(self.resolution):
            res.attrs[field.name] = getattr(self.resolution, field.name)
        write_shape_records(f, self.shape_records())
        cells = f.create_group("cells")
        for name, (dtype, units, meaning) in CELL_DATASETS.items():
            values = np.asarray(self.cells[name], dtype=dtype)
            # one chunk per cell: whole chunks only (automatic chunk shapes padded the table by a fifth)
            ds = cells.create_dataset(name, data=values, fletcher32=True, chunks=(1, 1, 1) + values.shape[3:])
            ds.attrs["units"] = units
            ds.attrs["meaning"] = meaning

    @classmethod
    def from_hdf5(cls, f: h5py.File) -> "ReboundTable":
        """Read a table written by :meth:`to_hdf5`; DataFormatError naming what is missing."""
        where = f.filename
        for group in ("grid", "resolution", "cells"):
            if group not in f:
                raise DataFormatError(f"{where}: missing group '{group}'")
        for name in ("alpha1_deg", "speed_m_s", "shapes"):
            if name not in f["grid"]:
                raise DataFormatError(f"{where}: missing dataset 'grid/{name}'")
        missing = [n for n in CELL_DATASETS if n not in f["cells"]]
        if missing:
            raise DataFormatError(f"{where}: missing dataset(s) {', '.join('cells/' + n for n in missing)}")
        grid = f["grid"]
        alpha1_deg, speed_m_s = (_read(grid, name) for name in ("alpha1_deg", "speed_m_s"))
        cells = {name: _read(f["cells"], name) for name in CELL_DATASETS}
        law = {name: _read(grid, name) for name in LAW_DATASETS if name in grid}
        missing = [name for name in LAW_DATASETS if name not in law]
        if _minor(f) >= 2 and missing:
            raise DataFormatError(f"{where}: missing dataset(s) {', '.join('grid/' + n for n in missing)} (table "
                                  f"format 3.2)")
        minor = _minor(f)
        if minor >= SHAPES_SINCE and SHAPES_GROUP not in f:
            raise DataFormatError(f"{where}: missing group '{SHAPES_GROUP}' (table format 3.{SHAPES_SINCE})")
        shapes = _read_group(f[SHAPES_GROUP]) if SHAPES_GROUP in f else None
        try:
            resolution = TableResolution(**{name: _number(f["resolution"], name)
                                            for name in ("clusters", "dictionary_size", "levels")})
            table = cls(
                alpha1_deg=alpha1_deg, speed_m_s=speed_m_s,
                shapes=tuple(s.decode() if isinstance(s, bytes) else str(s) for s in grid["shapes"][()]),
                resolution=resolution, cells=cells, kappa=_number(grid, "kappa"),
                n_max=_number(grid, "n_max"), particles_per_cell=_number(grid, "particles_per_cell"),
                config_text=str(f.attrs["config"]), config_sha256=str(f.attrs["config_sha256"]),
                master_seed=int(f.attrs["master_seed"]), created=str(f.attrs["created"]),
                package_version=str(f.attrs["package_version"]),
                model_sha256=str(f.attrs.get("model_sha256", "")),
                restitution_k=_number(grid, "restitution_k"), restitution_p=_number(grid, "restitution_p"),
                friction_q=_number(grid, "friction_q") if "friction_q" in grid.attrs or minor >= 3 else float("nan"),
                wall_law=str(grid.attrs.get("wall_law", "")), format_version=(3, minor),
                **_direct_model_attributes(f, minor))
        except (OSError, KeyError, TypeError) as exc:
            raise DataFormatError(f"{where}: cannot read the table (truncated or corrupt?): {exc}") from exc
        except ValueError as exc:
            if isinstance(exc, DataFormatError):
                raise DataFormatError(f"{where}: {exc}") from None
            raise DataFormatError(f"{where}: inconsistent table: {exc}") from exc
        check_contract(table, where, law, shapes)
        return dataclasses.replace(table, records=_records(table, shapes, where))


def shape_codes(names) -> np.ndarray:
    """``grid/shapes``' checksummed copy ``grid/shape_codes``: each family's code, USER_SHAPE_CODE for another."""
    return np.array([SHAPE_NAMES.index(s) if s in SHAPE_NAMES else USER_SHAPE_CODE for s in names], dtype=np.uint8)


def _records(table: ReboundTable, shapes: dict | None, where: str) -> tuple:
    """The records of a checked table: from its /shapes datasets, or (before 3.4) the families'."""
    def refuse(text):
        raise DataFormatError(f"{where}: {text}")

    if shapes is not None:
        return records_from_arrays(shapes, table.shapes, table.kappa, table.aspect_ratio, refuse)
    try:
        return family_records(table.shapes, table.kappa, table.aspect_ratio)
    except ValueError as exc:       # κ and the law are the direct model's parameters: the C loader's words
        refuse(f"the direct model's parameters are out of range: {exc} (the built-in shapes' records cannot be "
               f"made from the table's kappa {table.kappa!r} and aspect-ratio law {list(table.aspect_ratio)})")


def _minor(f: h5py.File) -> int:
    """The minor format version of an open table (checked a pair by check_file)."""
    return int(f.attrs["format_version"][1])


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


def check_contract(table: ReboundTable, where: str, law: dict, shapes: dict | None = None) -> None:
    """DataFormatError naming the file and the value unless ``table`` obeys what makes a table valid beyond its
    layout (docs/format.md, "What makes a table valid"; the C loader checks the same). ``law`` holds the
    datasets of :data:`LAW_DATASETS` the file has (3.2), which must equal the attributes and names: the first two
    of :data:`LAW_ATTRIBUTES` in a 3.2 table, all of them since 3.3. ``shapes`` holds the datasets of group
    /shapes (3.4; :func:`data_schema.shape_records.check_shape_datasets`); a table without them holds the families
    only."""
    def refuse(text):
        raise DataFormatError(f"{where}: {text}")

    if shapes is not None:
        check_shape_datasets(shapes, table.shapes, refuse)
    elif not all(name in SHAPE_NAMES for name in table.shapes) or len(set(table.shapes)) != len(table.shapes):
        refuse(f"dataset 'grid/shapes' must name distinct shapes among {', '.join(SHAPE_NAMES)} (a table before "
               f"format 3.{SHAPES_SINCE}); got {list(table.shapes)}")
    alpha1, speed = np.asarray(table.alpha1_deg, dtype=np.float64), np.asarray(table.speed_m_s, dtype=np.float64)
    if not (np.all((alpha1 > 0.0) & (alpha1 <= 90.0)) and np.all(np.diff(alpha1) > 0.0)):
        refuse(f"dataset 'grid/alpha1_deg' must be strictly increasing in (0, 90] deg; got {alpha1.tolist()}")
    low, high = SPEED_GRID_RANGE
    if not (np.all((speed >= low) & (speed <= high)) and np.all(np.diff(speed) > 0.0)):
        refuse(f"dataset 'grid/speed_m_s' must be strictly increasing in [{low:g}, {high:g}] m/s; got {speed.tolist()}")
    if np.any(speed[1:] > MAX_SPEED_RATIO * speed[:-1]):
        refuse(f"dataset 'grid/speed_m_s' has consecutive speeds more than a factor {MAX_SPEED_RATIO:g} apart; got "
               f"{speed.tolist()}")
    for name in ("restitution_k", "restitution_p"):
        value = getattr(table, name)
        if not (np.isfinite(value) and value > 0.0):
            refuse(f"the attribute '{name}' of group 'grid' must be finite and > 0; got {float(value)!r}")
    if "law" in law:
        copied = table.law_values() if table.format_version[1] >= 3 else table.law_values()[:2]
        found = np.asarray(law["law"], dtype=np.float64).ravel()
        if found.shape != copied.shape:
            refuse(f"dataset 'grid/law' has shape {np.shape(law['law'])}, expected ({len(copied)},)")
        differ = np.flatnonzero(found.view(np.uint64) != copied.view(np.uint64))
        if differ.size:
            names = list(LAW_ATTRIBUTES[:-1]) + [f"second_moment_factors[{k}]" for k in range(4)]
            refuse(f"the attribute {names[differ[0]]} of group 'grid' ({copied[differ[0]]!r}) differs from its "
                   f"checksummed copy in 'grid/law' ({found[differ[0]]!r})")
    if "shape_codes" in law and np.ravel(law["shape_codes"]).tolist() != shape_codes(table.shapes).tolist():
        refuse(f"dataset 'grid/shapes' {list(table.shapes)} differs from its checksummed copy 'grid/shape_codes' "
               f"{np.ravel(law['shape_codes']).tolist()}")
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
             ("indicatrix_3d", lambda x: np.isfinite(x) & (x >= 0.0), "finite and >= 0"))
    for name, ok, wanted in rules:
        values = np.asarray(cells[name])
        bad = np.flatnonzero(~ok(values).ravel())
        if bad.size:
            refuse(f"dataset 'cells/{name}' holds {values.ravel()[bad[0]].item()!r} at element {bad[0]}; its values "
                   f"must be {wanted}")
    check_dictionary(np.asarray(cells["shape_dictionary"]), table.resolution.levels, refuse)
    weight_sum = np.asarray(cells["cluster_weight"]).sum(axis=-1).ravel()
    bad = np.flatnonzero(np.abs(weight_sum - 1.0) > WEIGHT_SUM_TOLERANCE)
    if bad.size:
        refuse(f"dataset 'cells/cluster_weight' of cell {bad[0]} sums to {float(weight_sum[bad[0]])!r}; each cell's weights "
               f"must sum to 1 within {WEIGHT_SUM_TOLERANCE:g}")
    drawn = np.asarray(cells["status_counts"])[..., :2].sum(axis=-1).ravel()
    if np.any(drawn <= 0):
        refuse(f"dataset 'cells/status_counts' of cell {np.flatnonzero(drawn <= 0)[0]} has no rebounded or trapped "
               f"particle")


def check_dictionary(dictionary: np.ndarray, levels: int, refuse) -> None:
    """``refuse`` (called with the message) unless every row of ``cells/shape_dictionary`` is a standardised
    quantile function: non-decreasing, its knots within ±√L (the largest |knot| of L + 1 knots of mean 0 and
    standard deviation 1; the build's non-decreasing pass only repeats knots) up to float32 round-off."""
    bound = np.float32(np.sqrt(levels) * (1.0 + DICTIONARY_BOUND_TOLERANCE))
    flat = dictionary.reshape(-1)
    bad = np.flatnonzero(~(np.abs(flat) <= bound))
    if bad.size:
        refuse(f"dataset 'cells/shape_dictionary' holds {flat[bad[0]].item()!r} at element {bad[0]}; its values must "
               f"be in [-{bound:.9g}, {bound:.9g}] (sqrt of the levels {levels})")
    rows = dictionary.reshape(-1, dictionary.shape[-1])
    bad = np.flatnonzero(np.any(np.diff(rows, axis=1) < 0.0, axis=1))
    if bad.size:
        refuse(f"dataset 'cells/shape_dictionary' row {bad[0]} decreases; each row (a quantile function) must be "
               f"non-decreasing")


def _direct_model_attributes(f: h5py.File, minor: int) -> dict:
    """The direct model's parameters of a table (ReboundTable fields). Tables that did not record them were built
    with the aspect-ratio law of their configuration, the tolerances BUILT_WITH_TOLERANCES and, at κ = 0.3,
    BUILT_WITH_SECOND_MOMENT_FACTORS (NaN at another κ: not known without the build's code). Since 3.3 every one
    is required."""
    grid = f["grid"]
    recorded = minor >= 3 or all(name in grid.attrs for name in ASPECT_RATIO_ATTRIBUTES)
    if recorded:
        aspect = tuple(_number(grid, name) for name in ASPECT_RATIO_ATTRIBUTES)
    else:
        law = tomllib.loads(str(f.attrs["config"])).get("simulation", {}).get("aspect_ratio", {})
        aspect = tuple(float(law.get(key, "nan")) for key in ASPECT_RATIO_ATTRIBUTES.values())
    if minor >= 3 or "second_moment_factors" in grid.attrs:
        kfac = _number(grid, "second_moment_factors", None)
    elif _number(grid, "kappa") == BUILT_WITH_KAPPA:
        kfac = BUILT_WITH_SECOND_MOMENT_FACTORS
    else:
        kfac = (float("nan"),) * len(BUILT_WITH_SECOND_MOMENT_FACTORS)
    return dict(aspect_ratio=aspect, second_moment_factors=kfac,
                **{name: _number(grid, name) if minor >= 3 or name in grid.attrs else default
                   for name, default in BUILT_WITH_TOLERANCES.items()})


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
FINGERPRINT_GROUPS = ("grid", "resolution", "cells", SHAPES_GROUP)     # those the table has (shapes: 3.4)


def table_fingerprint(path) -> str:
    """SHA-256 of what a table holds (docs/format.md, "Fingerprint"), hex: the root attributes of
    :data:`FINGERPRINT_ROOT_ATTRIBUTES`, then for each group of :data:`FINGERPRINT_GROUPS` its attributes and
    its datasets in the order of their names, each hashed as its name, dtype, shape and little-endian bytes
    (strings as UTF-8). Datasets' ``units`` and ``meaning`` attributes are descriptions and are left out; the
    checksums and HDF5's chunking do not enter. A config and a seed give one fingerprint whatever built them."""
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

    check_file(path, TABLE_FILE_TYPE, TABLE_VERSION[0])
    with h5py.File(path, "r") as f:
        for name in FINGERPRINT_ROOT_ATTRIBUTES:
            feed(f"@{name}", f.attrs[name])
        for group in (g for g in FINGERPRINT_GROUPS if g in f):
            for name in sorted(f[group].attrs):
                feed(f"{group}@{name}", f[group].attrs[name])
            for name in sorted(f[group]):
                feed(f"{group}/{name}", _read(f[group], name))
    return digest.hexdigest()


def write_table(path, table: ReboundTable, overwrite: bool = False) -> Path:
    """Write ``table`` to an HDF5 file at ``path``, whole or not at all; return the path.

    ``overwrite`` replaces only a table file (:func:`data_schema.output.check_output`).
    """
    def write(f):
        write_header(f, TABLE_FILE_TYPE, TABLE_VERSION)
        table.to_hdf5(f)

    return write_output(path, hdf5_bytes(write), TABLE_FILE_TYPE, overwrite)


def read_table(path) -> ReboundTable:
    """Read a rebound table, after :func:`data_schema.check_file`."""
    check_file(path, TABLE_FILE_TYPE, TABLE_VERSION[0])
    try:
        with h5py.File(path, "r") as f:
            return ReboundTable.from_hdf5(f)
    except OSError as exc:
        raise DataFormatError(f"{path}: cannot read the table (truncated or corrupt?): {exc}") from exc
