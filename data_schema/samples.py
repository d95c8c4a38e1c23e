"""Raw per-particle rebound samples: one incident state, many reflected states.

Written by ``tablegen simulate --out`` (direct model) and by the runtime
sampler, so both can be compared with the same tools. Layout (docs/format.md):

    /                      attrs: file_type = "rebound_samples", format_version = (1, 0)
    /samples               group; attrs: alpha1_deg, speed_m_s, shape, seed, producer,
                           plus provenance (free-form scalars and strings)
    /samples/u, v, w       float64 (n,)  reflected centre-of-mass velocity V⁺, m/s, lab frame
    /samples/omega_x, omega_y, omega_z
                           float64 (n,)  reflected angular velocity Ω⁺ a/|V⁻|, lab frame
    /samples/n_collisions  int32 (n,)    collisions in the rebound; −1 where unknown
    /samples/status        int8 (n,)     0 rebounded, 1 trapped, 2 failed
    /samples/<extra>       optional 1-D per-particle datasets (see OPTIONAL_DATASETS; among them the
                           rebound's work on the wall W_n, W_t in m²/s², wall_work_normal, wall_work_tangential)

Lab frame: wall y = 0 with normal +Y into the gas, impact plane XY, incident
velocity V⁻ = |V⁻|(cos α1, −sin α1, 0). For trapped and failed particles the
velocity and spin hold the state at the last collision and are not a rebound.
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import h5py
import numba
import numpy as np

from data_schema import kernel_cache  # noqa: F401  (keys this module's kernels by their sources)
from data_schema.common import DataFormatError, check_file, write_header
from data_schema.output import hdf5_bytes, write_output

# particle shapes; a shape's code in files (dataset ``shape_code``) is its index here
SHAPE_NAMES = ("ellipsoid", "prism", "cut_prism", "tetrahedron")

SAMPLES_FILE_TYPE = "rebound_samples"
SAMPLES_VERSION = (1, 0)

STATUS_REBOUNDED = 0   # left the wall for good
STATUS_TRAPPED = 1     # still colliding after n_max collisions (rolling/deposited)
STATUS_FAILED = 2      # numerical failure (collision solver or contact search)
STATUS_NAMES = {STATUS_REBOUNDED: "rebounded", STATUS_TRAPPED: "trapped", STATUS_FAILED: "failed"}
STATUS_INVALID = -1    # runtime sampler only, never in a file: the incident state does not move into the wall

# the physical incidence angle α1 from the wall, deg: (low, high], high = normal impact
ALPHA1_RANGE_DEG = (0.0, 90.0)
ALPHA1_RANGE_TEXT = f"({ALPHA1_RANGE_DEG[0]:g}, {ALPHA1_RANGE_DEG[1]:g}]"


def alpha1_is_physical(alpha1):
    """Whether α1 (deg; a number or an array, element by element) is in the physical range ALPHA1_RANGE_DEG."""
    low, high = ALPHA1_RANGE_DEG
    return (alpha1 > low) & (alpha1 <= high)

# why a particle has STATUS_FAILED (optional dataset ``failure_reason``; 0 for the others)
FAILURE_NONE = 0
FAILURE_COLLISION_SOLVER = 1    # the normal-impulse equation did not converge
FAILURE_SEARCH_BUDGET = 2       # the contact search used up its step budget
FAILURE_NOT_APPROACHING = 3     # a contact was found whose point does not approach the wall
FAILURE_NAMES = {FAILURE_COLLISION_SOLVER: "collision solver did not converge",
                 FAILURE_SEARCH_BUDGET: "contact search step budget exhausted",
                 FAILURE_NOT_APPROACHING: "contact point not approaching"}

REQUIRED_DATASETS = {
    "u": ("float64", "m/s"), "v": ("float64", "m/s"), "w": ("float64", "m/s"),
    "omega_x": ("float64", "1"), "omega_y": ("float64", "1"), "omega_z": ("float64", "1"),
    "n_collisions": ("int32", "1"), "status": ("int8", "1"),
}
OPTIONAL_DATASETS = {
    "shape_code": ("int8", "0 ellipsoid, 1 prism, 2 cut_prism, 3 tetrahedron"),
    "hand": ("int8", "tetrahedron hand ±1 (+1 for the achiral shapes)"),
    "b_over_a": ("float64", "1"),
    "c_over_b": ("float64", "1"),
    "e_rot_ratio": ("float64", "rotational energy after / incident kinetic energy"),
    "n_search_steps": ("int32", "contact-search steps in the rebound"),
    "n_multiple_roots": ("int32", "collisions whose normal equation had 3 positive roots"),
    "failure_reason": ("int8", "0 none, 1 collision solver, 2 search budget, 3 not approaching"),
    "wall_work_normal": ("float64", "m²/s²: work on the wall per unit particle mass, normal impulses"),
    "wall_work_tangential": ("float64", "m²/s²: work on the wall per unit particle mass, tangential impulses"),
}
REQUIRED_ATTRS = ("alpha1_deg", "speed_m_s", "shape", "seed", "producer")


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _angles(velocity, alpha2, beta2, norm):
    for i in range(velocity.shape[0]):
        u, v, w = velocity[i, 0], velocity[i, 1], velocity[i, 2]
        norm[i] = math.sqrt(u * u + v * v + w * w)
        alpha2[i] = math.atan2(v, u)
        sine = w / norm[i]
        beta2[i] = math.asin(1.0 if sine > 1.0 else -1.0 if sine < -1.0 else sine)


def rebound_angles(velocity: np.ndarray) -> tuple:
    """(α2, β2, |V⁺|) of reflected velocities (n, 3) in the lab frame: radians, radians, the velocity's units.

    One particle at a time with the C library's atan2 and asin (numba calls them), not numpy's array
    functions, whose SIMD kernels round differently on AVX2 and AVX-512 CPUs: the tables built from these
    angles are then the same on any x86-64 CPU.
    """
    velocity = np.ascontiguousarray(velocity, dtype=np.float64).reshape(-1, 3)
    alpha2, beta2, norm = (np.empty(len(velocity)) for _ in range(3))
    _angles(velocity, alpha2, beta2, norm)
    return alpha2, beta2, norm


@numba.njit(cache=True, nogil=True)
def _velocities(alpha2, beta2, speed, velocity):
    for i in range(alpha2.shape[0]):
        cb = math.cos(beta2[i])
        velocity[i, 0] = speed[i] * (cb * math.cos(alpha2[i]))
        velocity[i, 1] = speed[i] * (cb * math.sin(alpha2[i]))
        velocity[i, 2] = speed[i] * math.sin(beta2[i])


def angles_to_velocity(alpha2, beta2, speed) -> np.ndarray:
    """The reflected velocities (n, 3) with angles α2, β2 (radians) and magnitudes ``speed``, lab frame: the
    inverse of :func:`rebound_angles`, one particle at a time with the C library's cos and sin."""
    alpha2, beta2, speed = (np.ascontiguousarray(x, dtype=np.float64).ravel()
                            for x in np.broadcast_arrays(alpha2, beta2, speed))
    velocity = np.empty((len(alpha2), 3))
    _velocities(alpha2, beta2, speed, velocity)
    return velocity


@dataclasses.dataclass(frozen=True, eq=False)
class SampleSet:
    """Reflected states of ``n`` particles at one incident state.

    Attributes
    ----------
    velocity : (n, 3) float64, V⁺ in m/s, lab frame.
    omega : (n, 3) float64, Ω⁺ a/|V⁻|, lab frame.
    n_collisions : (n,) int32, −1 where unknown.
    status : (n,) int8, STATUS_* codes.
    alpha1 : incidence angle α1 in degrees from the wall.
    speed : incident speed |V⁻| in m/s.
    shape : shape name, ``"mix"``, or a mix description.
    seed : the seed the samples were drawn with (None if unseeded).
    producer : what made them, e.g. ``"tablegen simulate"``.
    extra : optional per-particle arrays, keys from OPTIONAL_DATASETS.
    provenance : further scalar/string metadata (parameters of the run).
    """

    velocity: np.ndarray
    omega: np.ndarray
    n_collisions: np.ndarray
    status: np.ndarray
    alpha1: float
    speed: float
    shape: str
    seed: int | None
    producer: str
    extra: dict = dataclasses.field(default_factory=dict)
    provenance: dict = dataclasses.field(default_factory=dict)

    def __post_init__(self):
        n = len(self.status)
        for name, arr, shape in (("velocity", self.velocity, (n, 3)), ("omega", self.omega, (n, 3)),
                                 ("n_collisions", self.n_collisions, (n,))):
            if np.shape(arr) != shape:
                raise ValueError(f"SampleSet.{name} must have shape {shape}; got {np.shape(arr)}")
        for key, arr in self.extra.items():
            if key not in OPTIONAL_DATASETS:
                raise ValueError(f"unknown optional dataset {key!r}; allowed: {sorted(OPTIONAL_DATASETS)}")
            if np.shape(arr) != (n,):
                raise ValueError(f"optional dataset {key!r} must have shape {(n,)}; got {np.shape(arr)}")

    def __len__(self):
        return len(self.status)

    # -- derived quantities (docs/model.md §2, §6) --------------------------
    @property
    def rebounded(self) -> np.ndarray:
        """Boolean mask of the particles that rebounded."""
        return self.status == STATUS_REBOUNDED

    @property
    def speed_ratio(self) -> np.ndarray:
        """s = |V⁺|/|V⁻|."""
        return rebound_angles(self.velocity)[2] / self.speed

    @property
    def alpha2(self) -> np.ndarray:
        """In-plane rebound angle α2 = atan2(v⁺, u⁺) ∈ [0, π], radians from +X."""
        return rebound_angles(self.velocity)[0]

    @property
    def beta2(self) -> np.ndarray:
        """Out-of-plane rebound angle β2 = asin(w⁺/|V⁺|) ∈ [−π/2, π/2], radians."""
        return rebound_angles(self.velocity)[1]

    @property
    def e_trans_ratio(self) -> np.ndarray:
        """Translational kinetic energy after / incident kinetic energy = s²."""
        return self.speed_ratio ** 2

    # -- HDF5 ---------------------------------------------------------------
    def to_hdf5(self, group: h5py.Group) -> None:
        """Write the datasets and attributes into ``group``."""
        columns = {"u": self.velocity[:, 0], "v": self.velocity[:, 1], "w": self.velocity[:, 2],
                   "omega_x": self.omega[:, 0], "omega_y": self.omega[:, 1], "omega_z": self.omega[:, 2],
                   "n_collisions": self.n_collisions, "status": self.status}
        for name, (dtype, units) in REQUIRED_DATASETS.items():
            ds = group.create_dataset(name, data=np.asarray(columns[name], dtype=dtype))
            ds.attrs["units"] = units
        for name, arr in self.extra.items():
            dtype, meaning = OPTIONAL_DATASETS[name]
            group.create_dataset(name, data=np.asarray(arr, dtype=dtype)).attrs["units"] = meaning
        group.attrs["alpha1_deg"] = float(self.alpha1)
        group.attrs["speed_m_s"] = float(self.speed)
        group.attrs["shape"] = self.shape
        group.attrs["seed"] = -1 if self.seed is None else int(self.seed)
        group.attrs["producer"] = self.producer
        for key, value in self.provenance.items():
            group.attrs[key] = value

    @classmethod
    def from_hdf5(cls, group: h5py.Group) -> "SampleSet":
        """Read a SampleSet written by :meth:`to_hdf5`; DataFormatError if incomplete."""
        where = f"{group.file.filename}:{group.name}"
        missing = [n for n in REQUIRED_DATASETS if n not in group]
        if missing:
            raise DataFormatError(f"{where}: missing dataset(s) {', '.join(missing)}")
        missing = [n for n in REQUIRED_ATTRS if n not in group.attrs]
        if missing:
            raise DataFormatError(f"{where}: missing attribute(s) {', '.join(missing)}")
        try:
            col = {n: group[n][()] for n in REQUIRED_DATASETS}
            extra = {n: group[n][()] for n in OPTIONAL_DATASETS if n in group}
        except OSError as exc:
            raise DataFormatError(f"{where}: cannot read datasets (truncated or corrupt?): {exc}") from exc
        lengths = {n: len(a) for n, a in col.items()}
        if len(set(lengths.values())) != 1:
            raise DataFormatError(f"{where}: datasets differ in length: {lengths}")
        attrs = dict(group.attrs)
        seed = int(attrs.pop("seed"))
        known = {k: attrs.pop(k) for k in ("alpha1_deg", "speed_m_s", "shape", "producer")}
        return cls(
            velocity=np.stack([col["u"], col["v"], col["w"]], axis=1),
            omega=np.stack([col["omega_x"], col["omega_y"], col["omega_z"]], axis=1),
            n_collisions=col["n_collisions"], status=col["status"],
            alpha1=float(known["alpha1_deg"]), speed=float(known["speed_m_s"]),
            shape=str(known["shape"]), seed=None if seed < 0 else seed,
            producer=str(known["producer"]), extra=extra, provenance=attrs)


def write_samples(path, samples: SampleSet, overwrite: bool = False, inputs=()) -> Path:
    """Write ``samples`` to an HDF5 file at ``path``, whole or not at all; return the path.

    ``overwrite`` replaces only a samples file, never one of ``inputs`` (:func:`data_schema.output.check_output`).
    """
    def write(f):
        write_header(f, SAMPLES_FILE_TYPE, SAMPLES_VERSION)
        samples.to_hdf5(f.create_group("samples"))

    return write_output(path, hdf5_bytes(write), SAMPLES_FILE_TYPE, overwrite, inputs)


def read_samples(path) -> SampleSet:
    """Read a raw-samples file, after :func:`data_schema.check_file`."""
    check_file(path, SAMPLES_FILE_TYPE, SAMPLES_VERSION[0])
    with h5py.File(path, "r") as f:
        if "samples" not in f:
            raise DataFormatError(f"{path}: missing group 'samples'")
        return SampleSet.from_hdf5(f["samples"])
