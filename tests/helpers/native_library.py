"""Building the native library with CMake and driving it through ctypes (the tests' side of it).

:func:`build` configures and builds ``native/`` into a folder; :class:`Native` loads the public shared library
(``librebound_scatter.so``: the names of native/include/rebound_scatter.h and nothing else) and wraps the functions
the tests call, on NumPy arrays; ``Native.internal`` is a second handle, on the test-only library of the same
sources (``librebound_scatter_testing.so``, built with RBS_BUILD_TESTS), for the internal functions the tests
compare piece by piece (the direct model's kernels, the free flight, the table path and the direct path alone).
The records of the header (rbs_hit, rbs_options, rbs_result, ...) are mirrored as ctypes Structures below, each
created with its ``size`` set to its ctypes.sizeof, as the header's RBS_*_INIT set it (test_native_api.py checks
the layouts against the header). Nothing here imports the Python packages: the Python side of every comparison
comes through :mod:`tests.helpers.python_side`.
"""

from __future__ import annotations

import ctypes
import os
import shutil
from pathlib import Path

import numpy as np

from tests.helpers import REPO, background

NATIVE = REPO / "native"
HEADER = NATIVE / "include" / "rebound_scatter.h"
INSTALL_HINT = ("run native/install-deps.sh (as root on Debian/Ubuntu it installs gcc, g++, cmake, libhdf5-dev, "
                "gfortran and pkg-config; elsewhere it prints what to install)")

U_PER_DRAW = 13                         # RBS_U_PER_DRAW
BLOCK = 32                              # RBS_BLOCK
LOCAL_SIZE = 6                          # RBS_LOCAL_SIZE
NO_KEY = -1                             # RBS_NO_KEY
VERSION_NUMBER = 1_004_001              # RBS_VERSION_NUMBER of 1.4.1
ROUGHNESS_OF_TABLE = -1.0               # RBS_ROUGHNESS_OF_TABLE: rbs_options.roughness_deg's default
MAX_ROUGHNESS_DEG = 45.0                # RBS_MAX_ROUGHNESS_DEG
MAX_WALL_HITS = 10                      # RBS_MAX_WALL_HITS

# rbs_status: one status space (the hits' codes are surrogate's STATUS_*)
OK, TRAPPED, FAILED = 0, 1, 2
INVALID, ERR_IO, ERR_FORMAT, ERR_VERSION, ERR_MEMORY = -1, -2, -3, -4, -5
STATUSES = {"RBS_OK": OK, "RBS_TRAPPED": TRAPPED, "RBS_FAILED": FAILED, "RBS_INVALID": INVALID,
            "RBS_ERR_IO": ERR_IO, "RBS_ERR_FORMAT": ERR_FORMAT, "RBS_ERR_VERSION": ERR_VERSION,
            "RBS_ERR_MEMORY": ERR_MEMORY}
# rbs_method, rbs_path, rbs_interpolation, rbs_family, rbs_kind, rbs_dtype
METHOD_AUTO, METHOD_TABLE, METHOD_DIRECT = 0, 1, 2
PATH_NONE, PATH_TABLE, PATH_DIRECT = -1, 0, 1
INTERPOLATION_SCALED, INTERPOLATION_STOCHASTIC = 0, 1
FAMILY_NONE, FAMILY_ELLIPSOID, FAMILY_PRISM, FAMILY_CUT_PRISM, FAMILY_TETRAHEDRON = -1, 0, 1, 2, 3
KIND_SMOOTH, KIND_POLYHEDRON = 0, 1
DTYPE_FLOAT64, DTYPE_FLOAT32 = 0, 1
ENUMS = {"rbs_status": STATUSES,
         "rbs_method": {"RBS_METHOD_AUTO": METHOD_AUTO, "RBS_METHOD_TABLE": METHOD_TABLE,
                        "RBS_METHOD_DIRECT": METHOD_DIRECT},
         "rbs_path": {"RBS_PATH_NONE": PATH_NONE, "RBS_PATH_TABLE": PATH_TABLE, "RBS_PATH_DIRECT": PATH_DIRECT},
         "rbs_interpolation": {"RBS_INTERPOLATION_SCALED": INTERPOLATION_SCALED,
                               "RBS_INTERPOLATION_STOCHASTIC": INTERPOLATION_STOCHASTIC},
         "rbs_family": {"RBS_FAMILY_NONE": FAMILY_NONE, "RBS_FAMILY_ELLIPSOID": FAMILY_ELLIPSOID,
                        "RBS_FAMILY_PRISM": FAMILY_PRISM, "RBS_FAMILY_CUT_PRISM": FAMILY_CUT_PRISM,
                        "RBS_FAMILY_TETRAHEDRON": FAMILY_TETRAHEDRON},
         "rbs_kind": {"RBS_KIND_SMOOTH": KIND_SMOOTH, "RBS_KIND_POLYHEDRON": KIND_POLYHEDRON},
         "rbs_dtype": {"RBS_DTYPE_FLOAT64": DTYPE_FLOAT64, "RBS_DTYPE_FLOAT32": DTYPE_FLOAT32}}


class BuildError(RuntimeError):
    pass


def missing_tools(fortran: bool = True, cxx: bool = True) -> list:
    """The build tools not found on PATH."""
    tools = ["cmake", "cc"] + (["c++"] if cxx else []) + (["gfortran"] if fortran else [])
    missing = [t for t in tools if shutil.which(t) is None]
    if "cc" in missing and shutil.which("gcc"):
        missing.remove("cc")
    if "c++" in missing and shutil.which("g++"):
        missing.remove("c++")
    return missing


def run(command, cwd=None, env=None, timeout=600):
    # background.run: a build started with the session is killed with it (tests.helpers.background.stop)
    return background.run(command, cwd=cwd, env=env, timeout=timeout)


def build(folder: Path, options: dict, targets=None) -> Path:
    """Configure native/ into ``folder`` with CMake (Release, -Werror, the given -D options) and build it;
    BuildError with CMake's output (and the install hint) on failure."""
    folder.mkdir(parents=True, exist_ok=True)
    configure = ["cmake", "-S", str(NATIVE), "-B", str(folder), "-DCMAKE_BUILD_TYPE=Release", "-DRBS_WERROR=ON"]
    # RBS_BUILD_TESTS: the test library too (librebound_scatter_testing.so, every internal function exported)
    configure += [f"-D{k}={v}" for k, v in {"RBS_BUILD_TESTS": "ON", **options}.items()]
    done = run(configure)
    if done.returncode != 0:
        raise BuildError(f"CMake could not configure native/ ({INSTALL_HINT}):\n{done.stdout[-3000:]}\n"
                         f"{done.stderr[-3000:]}")
    command = ["cmake", "--build", str(folder), "-j", "2"]
    if targets:
        command += ["--target", *targets]
    done = run(command)
    if done.returncode != 0:
        raise BuildError(f"building native/ failed ({INSTALL_HINT}):\n{done.stdout[-5000:]}\n{done.stderr[-3000:]}")
    return folder


# ---------------------------------------------------------------- the header's records

_d3 = ctypes.c_double * 3
_vp = ctypes.c_void_p


class Rng(ctypes.Structure):
    """rbs_rng: one xoshiro256+ state."""

    _fields_ = [("s", ctypes.c_uint64 * 4)]


class Record(ctypes.Structure):
    """A record of the header that begins with ``size_t size``: created with its size set to its own ctypes.sizeof
    (what the header's RBS_*_INIT does), unless ``size`` is given. ``LAST_1_0``: the last field of its version 1.0
    (None: its last field), whose end is the smallest size the library takes."""

    _fields_ = [("size", ctypes.c_size_t)]
    LAST_1_0 = None

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        if not args and "size" not in kwargs:
            self.size = ctypes.sizeof(type(self))

    @classmethod
    def grown(cls, extra: int = 24):
        """The record as a later header might declare it: ``extra`` bytes of new fields at its end (``later``)."""
        return type(f"{cls.__name__}Grown", (cls,), {"_fields_": [("later", ctypes.c_uint8 * extra)]})


class Hit(Record):
    """rbs_hit (RBS_HIT_INIT: no grain key)."""

    _fields_ = [("V", _d3), ("Omega", _d3), ("n", _d3), ("a", ctypes.c_double), ("grain_key", ctypes.c_int64),
                ("u", ctypes.POINTER(ctypes.c_double)), ("rng", ctypes.POINTER(Rng))]

    def __init__(self, *args, **kwargs):
        kwargs.setdefault("grain_key", NO_KEY)
        super().__init__(*args, **kwargs)


class Options(Record):
    """rbs_options (RBS_OPTIONS_INIT: auto, scaled, the table's roughness)."""

    _fields_ = [("method", ctypes.c_int), ("interpolation", ctypes.c_int), ("roughness_deg", ctypes.c_double)]
    LAST_1_0 = "interpolation"

    def __init__(self, *args, **kwargs):
        kwargs.setdefault("roughness_deg", ROUGHNESS_OF_TABLE)
        super().__init__(*args, **kwargs)


class Result(Record):
    """rbs_result (RBS_RESULT_INIT)."""

    _fields_ = [("status", ctypes.c_int), ("path", ctypes.c_int), ("shape", ctypes.c_int),
                ("n_collisions", ctypes.c_int), ("V", _d3), ("Omega", _d3), ("wall_hits", ctypes.c_int),
                ("wall_work_normal", ctypes.c_double), ("wall_work_tangential", ctypes.c_double)]
    LAST_1_0 = "Omega"

    def __init__(self, *args, **kwargs):
        for name, value in (("status", INVALID), ("path", PATH_NONE), ("shape", -1), ("n_collisions", -1)):
            kwargs.setdefault(name, value)
        super().__init__(*args, **kwargs)


class Hits(Record):
    """rbs_hits."""

    _fields_ = [("count", ctypes.c_size_t), ("V", _vp), ("n", _vp), ("a", _vp), ("u", _vp), ("rng", _vp)]


class Results(Record):
    """rbs_results."""

    _fields_ = [("V", _vp), ("Omega", _vp), ("status", _vp)]


class TableInfo(Record):
    """rbs_table_info."""

    _fields_ = [(name, ctypes.c_int) for name in ("n_shapes", "n_alpha1", "n_speed", "n_clusters", "n_levels",
                                                    "n_dictionary", "n_pieces", "format_major", "format_minor")] + \
        [("particles_per_cell", ctypes.c_longlong), ("n_max", ctypes.c_longlong),
         ("alpha1_min_deg", ctypes.c_double), ("alpha1_max_deg", ctypes.c_double),
         ("speed_min_m_s", ctypes.c_double), ("speed_max_m_s", ctypes.c_double), ("kernel_bytes", ctypes.c_size_t)]


class ShapeInfo(Record):
    """rbs_shape_info."""

    _fields_ = [("name", ctypes.c_char_p), ("kind", ctypes.c_int), ("family", ctypes.c_int),
                ("n_vertices", ctypes.c_int), ("vertices", ctypes.POINTER(ctypes.c_double)),
                ("inertia", _d3), ("aspect", ctypes.c_double * 4), ("both_hands", ctypes.c_int)]


class WallInfo(Record):
    """rbs_wall_info (its fields of 1.0 up to speed_range_m_s, then a tabulated law's arrays (1.1) and the wall's
    roughness (1.2))."""

    _fields_ = [("family", ctypes.c_char_p), ("name", ctypes.c_char_p), ("n_parameters", ctypes.c_int),
                ("parameter_names", ctypes.POINTER(ctypes.c_char_p)),
                ("parameter_values", ctypes.POINTER(ctypes.c_double)), ("speed_range_m_s", ctypes.c_double * 2),
                ("n_contact_speeds", ctypes.c_int), ("contact_speed_m_s", ctypes.POINTER(ctypes.c_double)),
                ("n_contact_sines", ctypes.c_int), ("contact_sine", ctypes.POINTER(ctypes.c_double)),
                ("restitution", ctypes.POINTER(ctypes.c_double)), ("roughness_deg", ctypes.c_double)]
    LAST_1_0 = "speed_range_m_s"


class Grain(Record):
    """rbs_grain (RBS_GRAIN_INIT: shape −1)."""

    _fields_ = [("shape", ctypes.c_int), ("ratio_ba", ctypes.c_double), ("ratio_cb", ctypes.c_double),
                ("hand", ctypes.c_double)]

    def __init__(self, *args, **kwargs):
        kwargs.setdefault("shape", -1)
        super().__init__(*args, **kwargs)


RECORDS = {"rbs_hit": Hit, "rbs_options": Options, "rbs_result": Result, "rbs_hits": Hits, "rbs_results": Results,
           "rbs_table_info": TableInfo, "rbs_shape_info": ShapeInfo, "rbs_wall_info": WallInfo, "rbs_grain": Grain}


def fields(record) -> list:
    """The field names of a record class, ``size`` first, as the header declares them."""
    names = []
    for klass in reversed(record.__mro__):
        names += [name for name, _ in vars(klass).get("_fields_", [])]
    return names


class ShapeArrays(ctypes.Structure):
    """rbs_shape_arrays (native/src/shapes.h, internal): pointers into a direct_model.shape_arrays.ShapeArrays'
    arrays."""

    FIELDS = ("kind", "vertex_start", "vertices", "second_moments", "aspect", "aspect_cdf", "both_hands",
              "half_extents", "graph_start", "graph", "starts", "far_start", "far")
    _fields_ = [("n_shapes", ctypes.c_int)] + [(name, ctypes.c_void_p) for name in FIELDS]

    @classmethod
    def of(cls, arrays):
        """The struct over ``arrays`` (C-contiguous; the caller keeps them alive while C reads them)."""
        assert all(getattr(arrays, name).flags.c_contiguous for name in cls.FIELDS)
        return cls(len(arrays.kind), *(getattr(arrays, name).ctypes.data for name in cls.FIELDS))


# ---------------------------------------------------------------- helpers of the calls


def ref(x):
    """What a pointer argument takes: None (NULL), an address (an int), or a ctypes object by reference (which keeps
    the object alive for the call, a temporary record too)."""
    if x is None or isinstance(x, int):
        return x
    return ctypes.byref(x)


def address(x) -> int | None:
    """The address of a ctypes object for a pointer field of a record (the caller keeps the object alive)."""
    return None if x is None else ctypes.addressof(x)


def _rng(state) -> Rng:
    return Rng((ctypes.c_uint64 * 4)(*[int(x) for x in state]))


def _state(rng: Rng) -> np.ndarray:
    return np.array(list(rng.s), dtype=np.uint64)


def _ptr(a: np.ndarray):
    return a.ctypes.data


def _f64(x) -> np.ndarray:
    return np.ascontiguousarray(x, dtype=np.float64)


def options(method=METHOD_AUTO, interpolation=INTERPOLATION_SCALED, record=Options,
            roughness_deg=ROUGHNESS_OF_TABLE) -> Options:
    return record(method=method, interpolation=interpolation, roughness_deg=roughness_deg)


def hit(V, Omega, n, a, u=None, rng: Rng | None = None, key: int = NO_KEY, record=Hit):
    """An rbs_hit (or a ``record`` of its layout grown) and the arrays it points to (keep them while C reads)."""
    h = record(V=_d3(*_f64(V)), Omega=_d3(*_f64(Omega)), n=_d3(*_f64(n)), a=float(a), grain_key=int(key))
    kept = None
    if u is not None:
        kept = _f64(u)
        h.u = kept.ctypes.data_as(ctypes.POINTER(ctypes.c_double))
    if rng is not None:
        h.rng = ctypes.pointer(rng)
    return h, kept


class OwnedMix:
    """An rbs_mix of rbs_mix_new_*, freed with rbs_mix_free on garbage collection (it keeps its table object
    alive, so that the table is not closed by the collector first)."""

    def __init__(self, table: "NativeTable", pointer: int):
        self.table, self.pointer = table, pointer

    def __del__(self):
        if self.pointer:
            self.table.lib.c.rbs_mix_free(self.pointer)
            self.pointer = None


def _mix_ref(mix):
    return mix.pointer if isinstance(mix, OwnedMix) else mix


class NativeTable:
    """An open rbs_table (closed by :meth:`close` or on garbage collection)."""

    def __init__(self, lib: "Native", handle: int, path):
        self.lib, self.handle, self.path = lib, handle, Path(path)
        self._single = {}

    def close(self):
        if self.handle:
            self._single.clear()
            self.lib.c.rbs_table_close(self.handle)
            self.handle = None

    def __del__(self):
        self.close()

    @property
    def shapes(self) -> tuple:
        c = self.lib.c
        return tuple(c.rbs_table_shape_name(self.handle, i).decode() for i in range(c.rbs_table_n_shapes(self.handle)))

    def info(self) -> TableInfo:
        info = TableInfo()
        assert self.lib.c.rbs_table_info_get(self.handle, ref(info)) == OK
        return info

    def ranges(self):
        """((α1 first, last) deg, (|V⁻| first, last) m/s) of rbs_table_info."""
        info = self.info()
        return (info.alpha1_min_deg, info.alpha1_max_deg), (info.speed_min_m_s, info.speed_max_m_s)

    def grids(self):
        """(α1 grid, |V⁻| grid) of rbs_table_alpha1_grid, rbs_table_speed_grid, copied."""
        out = []
        for function in (self.lib.c.rbs_table_alpha1_grid, self.lib.c.rbs_table_speed_grid):
            count = ctypes.c_int(-1)
            data = function(self.handle, ctypes.byref(count))
            out.append(np.ctypeslib.as_array(data, shape=(count.value,)).copy())
        return tuple(out)

    def kernel_array(self, name: str) -> np.ndarray:
        data, count, dtype = ctypes.c_void_p(), ctypes.c_size_t(), ctypes.c_int()
        code = self.lib.c.rbs_table_kernel_array(self.handle, name.encode(), ctypes.byref(data), ctypes.byref(count),
                                                 ctypes.byref(dtype))
        if code != OK:
            assert code == INVALID, code
            raise KeyError(name)
        ctype = {DTYPE_FLOAT64: ctypes.c_double, DTYPE_FLOAT32: ctypes.c_float}[dtype.value]
        if count.value == 0:        # an empty array (a table without the work on the wall): no data to point at
            return np.empty(0, dtype=np.dtype(ctype))
        array = np.ctypeslib.as_array(ctypes.cast(data, ctypes.POINTER(ctype)), shape=(count.value,))
        return array.copy()

    def shape_info(self, i: int) -> dict | None:
        """rbs_table_shape_info of shape i as a dict (vertices copied), or None (RBS_INVALID)."""
        info = ShapeInfo()
        code = self.lib.c.rbs_table_shape_info(self.handle, i, ref(info))
        if code != OK:
            assert code == INVALID, code
            return None
        n = info.n_vertices
        vertices = (np.ctypeslib.as_array(info.vertices, shape=(n, 3)).copy() if n else np.zeros((0, 3)))
        assert n or not info.vertices
        return {"name": info.name.decode(), "kind": info.kind, "family": info.family, "n_vertices": n,
                "vertices": vertices, "inertia": np.array(info.inertia[:]), "aspect": np.array(info.aspect[:]),
                "both_hands": info.both_hands}

    def wall(self) -> dict:
        """rbs_table_wall as a dict: family, name, parameters {name: value}, speed_range_m_s (low, high), the
        arrays {name: copied values} of a tabulated law (contact_speed_m_s, contact_sine, restitution (speeds,
        sines)), {} where the record's pointers are NULL (the exponential family; their counts then 0), and
        roughness_deg."""
        info = WallInfo()
        assert self.lib.c.rbs_table_wall(self.handle, ref(info)) == OK
        names = [info.parameter_names[i].decode() for i in range(info.n_parameters)]
        values = [info.parameter_values[i] for i in range(info.n_parameters)]
        ns, nz = info.n_contact_speeds, info.n_contact_sines
        pointers = {"contact_speed_m_s": (info.contact_speed_m_s, (ns,)), "contact_sine": (info.contact_sine, (nz,)),
                    "restitution": (info.restitution, (ns, nz))}
        given = [bool(pointer) for pointer, _ in pointers.values()]
        assert all(given) or (not any(given) and ns == nz == 0), (given, ns, nz)
        arrays = {name: np.ctypeslib.as_array(pointer, shape=shape).copy()
                  for name, (pointer, shape) in pointers.items() if pointer}
        return {"family": info.family.decode(), "name": info.name.decode(), "parameters": dict(zip(names, values)),
                "n_parameters": info.n_parameters, "speed_range_m_s": tuple(info.speed_range_m_s), "arrays": arrays,
                "roughness_deg": info.roughness_deg}

    # -- mixes
    def mix_new(self, shape="mix", weights: dict | None = None):
        """(OwnedMix or None, message): rbs_mix_new_from_weights with ``weights``, else rbs_mix_new_from_shape
        (``"mix"`` there gives the equal mix; ``shape=None``: rbs_mix_new_equal)."""
        c, message = self.lib.c, ctypes.create_string_buffer(1024)
        if weights is not None:
            names = (ctypes.c_char_p * max(1, len(weights)))(*[k.encode() for k in weights])
            values = np.ascontiguousarray(list(weights.values()) or [0.0], dtype=np.float64)
            pointer = c.rbs_mix_new_from_weights(self.handle, len(weights), names, _ptr(values), message,
                                                 len(message))
        elif shape is None:
            pointer = c.rbs_mix_new_equal(self.handle)
        else:
            pointer = c.rbs_mix_new_from_shape(self.handle, shape.encode(), message, len(message))
        return (OwnedMix(self, pointer) if pointer else None), message.value.decode()

    def mix(self, spec="mix") -> OwnedMix:
        """The mix of a spec as surrogate.mix_cdf takes it: a dict of weights, a shape's name, or "mix" (the equal
        mix, rbs_mix_new_equal); fails the test if the library refuses it."""
        mix, message = self.mix_new(weights=spec) if isinstance(spec, dict) else \
            self.mix_new(None if spec == "mix" else spec)
        assert mix is not None, message
        return mix

    def single(self, shape: int) -> OwnedMix:
        """The mix of the table's shape ``shape`` alone (kept)."""
        if shape not in self._single:
            self._single[shape] = self.mix(self.shapes[shape])
        return self._single[shape]

    def grain_info(self, mix, key: int):
        """(code, rbs_grain as a dict or None) of rbs_grain_info."""
        grain = Grain()
        code = self.lib.c.rbs_grain_info(self.handle, _mix_ref(mix), ctypes.c_int64(key), ref(grain))
        return code, ({name: getattr(grain, name) for name in ("shape", "ratio_ba", "ratio_cb", "hand")}
                      if code == OK else None)

    # -- one hit
    def hit(self, mix, V, Omega, n, a, u=None, state=None, key: int = NO_KEY, method=METHOD_AUTO,
            interpolation=INTERPOLATION_SCALED, roughness_deg=ROUGHNESS_OF_TABLE):
        """rbs_rebound of one hit, uniforms ``u`` or drawn from the rng ``state``: (its rbs_result, the advanced
        state or None). The returned status is checked to be the result's."""
        rng = None if state is None else _rng(state)
        h, kept = hit(V, Omega, n, a, u, rng, key)
        result, opts = Result(), options(method, interpolation, roughness_deg=roughness_deg)
        code = self.lib.c.rbs_rebound(self.handle, _mix_ref(mix), ref(h), ref(opts), ref(result))
        assert code == result.status, (code, result.status)
        del kept
        return result, (None if rng is None else _state(rng))

    def rebound(self, mix, V, Omega, n, a, u=None, state=None, key: int = NO_KEY, method=METHOD_AUTO,
                interpolation=INTERPOLATION_SCALED):
        """(status, V⁺ m/s, Ω⁺ rad/s) of rbs_rebound; with ``state`` instead of ``u``, also the advanced state."""
        result, after = self.hit(mix, V, Omega, n, a, u, state, key, method, interpolation)
        out = (result.status, np.array(result.V[:]), np.array(result.Omega[:]))
        return out if after is None else (*out, after)

    def direct(self, shape: int, V, Omega, n, a, u7):
        """The direct path of the table's shape ``shape`` (its one-shape mix, RBS_METHOD_DIRECT) with the direct
        model's 7 uniforms ``u7`` as u[1..7] of the hit: (status, V⁺, Ω⁺), the old rbs_direct_rebound's answer."""
        return self.rebound(self.single(shape), V, Omega, n, a, direct_uniforms(u7), method=METHOD_DIRECT)

    def rebound_path(self, V, Omega, n, a, method=METHOD_AUTO):
        h, _ = hit(V, Omega, n, a)
        return self.lib.c.rbs_rebound_path(self.handle, ref(h), ref(options(method)))

    # -- many hits
    def draw_many(self, mix, V, n, a, u=None, state=None, interpolation=INTERPOLATION_SCALED, method=METHOD_AUTO):
        """(status, V⁺, Ω⁺) of rbs_draw_many for the rows, uniforms ``u`` (count, 13), or drawn from the rng
        ``state`` (then also the advanced state); its return code is checked to be RBS_OK."""
        V, n, a = (_f64(x) for x in (V, n, a))
        count = V.shape[0]
        assert n.shape == (count, 3) and a.shape == (count,)
        rng = None if state is None else _rng(state)
        hits = Hits(count=count, V=_ptr(V), n=_ptr(n), a=_ptr(a), rng=address(rng))
        if u is not None:
            u = _f64(u)
            assert u.shape == (count, U_PER_DRAW)
            hits.u = _ptr(u)
        V_out, W_out, status = np.empty((count, 3)), np.empty((count, 3)), np.empty(count, dtype=np.int8)
        results = Results(V=_ptr(V_out), Omega=_ptr(W_out), status=_ptr(status))
        code = self.lib.c.rbs_draw_many(self.handle, _mix_ref(mix), ref(hits), ref(options(method, interpolation)),
                                        ref(results))
        assert code == OK, code
        return (status, V_out, W_out) if rng is None else (status, V_out, W_out, _state(rng))

    def draw_local(self, mix, alpha1, speed, u, interpolation=INTERPOLATION_SCALED):
        u = _f64(u)
        out = np.empty(LOCAL_SIZE)
        status = self.lib.c.rbs_draw_local(self.handle, _mix_ref(mix), ctypes.c_double(alpha1),
                                           ctypes.c_double(speed), _ptr(u), ref(options(METHOD_AUTO, interpolation)),
                                           _ptr(out))
        return status, out

    def shapes_drawn(self, mix, u0) -> np.ndarray:
        """The shape (rbs_result.shape) each uniform u[0] of ``u0`` draws from ``mix``, on the table path of one
        valid hit."""
        u = np.full(U_PER_DRAW, 0.5)
        shapes = []
        for x in u0:
            u[0] = x
            result, _ = self.hit(mix, (100.0, -100.0, 0.0), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0), 1e-4, u,
                                 method=METHOD_TABLE)
            shapes.append(result.shape)
        return np.array(shapes)


def direct_uniforms(u7) -> np.ndarray:
    """The 13 uniforms of a hit whose direct path takes ``u7`` (its u[1..7]; u[0] and u[8..12] ½)."""
    u = np.full(U_PER_DRAW, 0.5)
    u[1:8] = _f64(u7)
    return u


def mix_probes(cdf) -> np.ndarray:
    """Uniforms u[0] at and just below each inner boundary of a mix's cdf, and at both ends of [0, 1): the shapes
    they draw tell the cdf's values bit for bit."""
    cdf = np.asarray(cdf, dtype=np.float64)
    inner = cdf[:-1]
    probes = np.concatenate([[0.0, np.nextafter(1.0, 0.0)], inner, np.nextafter(inner, 0.0)])
    return probes[(probes >= 0.0) & (probes < 1.0)]


def mix_shapes(cdf, u0) -> np.ndarray:
    """surrogate.kernels.locate.mix_shape, in NumPy: the first k with u0 < cdf[k]."""
    cdf = np.asarray(cdf, dtype=np.float64)
    return np.sum(np.asarray(u0)[:, None] >= cdf[None, :-1], axis=1)


# ---------------------------------------------------------------- the libraries

_i, _d, _sz, _u64, _i64, _ll = ctypes.c_int, ctypes.c_double, ctypes.c_size_t, ctypes.c_uint64, ctypes.c_int64, \
    ctypes.c_longlong
_s = ctypes.c_char_p
# every RBS_API function of the header: restype, argtypes (records and arrays as addresses)
PUBLIC = {
    "rbs_rebound": (_i, [_vp, _vp, _vp, _vp, _vp]),
    "rbs_rebound_path": (_i, [_vp, _vp, _vp]),
    "rbs_draw_many": (_i, [_vp, _vp, _vp, _vp, _vp]),
    "rbs_draw_many_uniforms": (None, [_vp, _sz, _vp]),
    "rbs_draw_local": (_i, [_vp, _vp, _d, _d, _vp, _vp, _vp]),
    "rbs_table_open": (_i, [_s, ctypes.POINTER(_vp), _s, _sz]),
    "rbs_table_close": (None, [_vp]),
    "rbs_table_path": (_s, [_vp]),
    "rbs_table_info_get": (_i, [_vp, _vp]),
    "rbs_table_alpha1_grid": (ctypes.POINTER(_d), [_vp, ctypes.POINTER(_i)]),
    "rbs_table_speed_grid": (ctypes.POINTER(_d), [_vp, ctypes.POINTER(_i)]),
    "rbs_table_n_shapes": (_i, [_vp]),
    "rbs_table_shape_name": (_s, [_vp, _i]),
    "rbs_table_shape_info": (_i, [_vp, _i, _vp]),
    "rbs_table_wall": (_i, [_vp, _vp]),
    "rbs_table_kernel_array": (_i, [_vp, _s, ctypes.POINTER(_vp), ctypes.POINTER(_sz), ctypes.POINTER(_i)]),
    "rbs_mix_new_from_weights": (_vp, [_vp, _i, ctypes.POINTER(_s), _vp, _s, _sz]),
    "rbs_mix_new_from_shape": (_vp, [_vp, _s, _s, _sz]),
    "rbs_mix_new_equal": (_vp, [_vp]),
    "rbs_mix_free": (None, [_vp]),
    "rbs_grain_info": (_i, [_vp, _vp, _i64, _vp]),
    "rbs_grain_key": (_i64, [_u64, _u64, _u64]),
    "rbs_rng_seed": (None, [_vp, _u64]),
    "rbs_rng_seed_stream": (None, [_vp, _u64, _u64]),
    "rbs_rng_uniform": (_d, [_vp]),
    "rbs_rng_fill": (None, [_vp, _vp, _sz]),
    "rbs_status_string": (_s, [_i]),
    "rbs_version": (_s, []),
    "rbs_version_number": (_i, []),
}
# the internal functions the tests bind in the test-only library (native/src's headers)
INTERNAL = {
    "rbs_table_rebound": (_i, [_vp, _vp, _vp, _vp, _d, _vp, _i, _vp, _vp]),
    "rbs_direct_rebound": (_i, [_vp, _i, _vp, _vp, _vp, _d, _vp, _vp, _vp]),
    "rbs_collide": (_i, [_vp] * 7),
    "rbs_wall_work": (None, [_vp] * 5 + [ctypes.POINTER(_d)] * 2),
    "rbs_body_vertices": (_i, [_i, _d, _d, _d, _d, _d, _vp]),
    "rbs_bounding_radius": (_d, [_i, _vp, _vp, _i]),
    "rbs_particle_body": (_i, [_vp, _i, _d, _d, _d, _vp, _vp, _vp, _vp]),
    "rbs_rebound_model_frame": (_i, [_vp, _vp, _i, _d, _d, _d, _d, _d, _vp, _vp, _vp]),
    "rbs_rebound_model_frame_counted": (_i, [_vp, _vp, _i, _d, _d, _d, _d, _d, _vp, _vp, _vp, ctypes.POINTER(_ll),
                                             _vp]),
    "rbs_body_rebound": (_i, [_i, _vp, _i, _vp, _vp, _d, _vp, _vp, _vp, _vp, _ll, _d, _d, _ll, _vp, _vp,
                              ctypes.POINTER(_ll), ctypes.POINTER(_ll), _vp]),
    "rbs_normal_quantile": (_d, [_d]),
    "rbs_aspect_ratio": (_d, [_vp, _vp, _d]),
    "rbs_uniform_quaternion": (None, [_d, _d, _d, _vp]),
    "rbs_quaternion_to_matrix": (None, [_vp, _vp]),
    "rbs_rotation_init": (None, [_vp, _vp, _vp, _vp]),
    "rbs_rotation_at": (None, [_vp, _d, _vp, _vp]),
    "rbs_carlson_rf": (_d, [_d, _d, _d]),
    "rbs_carlson_rj": (_d, [_d, _d, _d, _d]),
    "rbs_restitution_factor": (_d, [_d, _vp]),
    "rbs_facet_key": (_i64, [_vp]),
    "rbs_facet_normal": (_i, [_vp, _vp, _d, _i64, ctypes.POINTER(_i64), _vp]),
}


def _declare(library, signatures: dict) -> None:
    for name, (restype, argtypes) in signatures.items():
        function = getattr(library, name)
        function.restype, function.argtypes = restype, argtypes


def _library(folder: Path, stem: str) -> Path:
    candidates = sorted(folder.glob(f"{stem}.so*"))
    if not candidates:
        raise BuildError(f"no {stem}.so in {folder}")
    return candidates[0]


class Native:
    """The public shared library of a build folder, its functions typed for ctypes; :attr:`internal` the
    test-only library beside it."""

    def __init__(self, build_dir: Path):
        self.build_dir = Path(build_dir)
        self.path = _library(self.build_dir, "librebound_scatter")
        self.c = ctypes.CDLL(str(self.path))
        _declare(self.c, PUBLIC)
        self._internal = None

    @property
    def internal(self):
        """librebound_scatter_testing.so of the same build (RBS_BUILD_TESTS=ON): the same sources without hidden
        visibility, so the internal functions (INTERNAL) are exported; never the library a program links."""
        if self._internal is None:
            self._internal = ctypes.CDLL(str(_library(self.build_dir, "librebound_scatter_testing")))
            _declare(self._internal, INTERNAL)
            _declare(self._internal, PUBLIC)
        return self._internal

    def open(self, path):
        """(code, NativeTable or None, message)."""
        handle, message = ctypes.c_void_p(), ctypes.create_string_buffer(2048)
        code = self.c.rbs_table_open(str(path).encode(), ctypes.byref(handle), message, len(message))
        if code != OK:
            assert not handle.value, "rbs_table_open failed but set *table"
        return code, (NativeTable(self, handle.value, path) if code == OK else None), message.value.decode()

    def table(self, path) -> NativeTable:
        code, table, message = self.open(path)
        if code != OK:
            raise RuntimeError(f"rbs_table_open failed ({code}): {message}")
        return table

    def status_string(self, code: int) -> str:
        return self.c.rbs_status_string(code).decode()

    def version(self) -> str:
        return self.c.rbs_version().decode()

    def version_number(self) -> int:
        return self.c.rbs_version_number()

    # -- random numbers
    def seed(self, seed: int, stream: int | None = None) -> np.ndarray:
        rng = Rng()
        if stream is None:
            self.c.rbs_rng_seed(ref(rng), ctypes.c_uint64(seed))
        else:
            self.c.rbs_rng_seed_stream(ref(rng), ctypes.c_uint64(seed), ctypes.c_uint64(stream))
        return _state(rng)

    def fill(self, state: np.ndarray, count: int):
        rng, u = _rng(state), np.empty(count)
        self.c.rbs_rng_fill(ref(rng), _ptr(u), ctypes.c_size_t(count))
        return u, _state(rng)

    def uniform(self, state: np.ndarray):
        rng = _rng(state)
        x = self.c.rbs_rng_uniform(ref(rng))
        return x, _state(rng)

    def grain_key(self, seed: int, id1: int, id2: int) -> int:
        return self.c.rbs_grain_key(ctypes.c_uint64(seed), ctypes.c_uint64(id1), ctypes.c_uint64(id2))

    def draw_many_uniforms(self, state: np.ndarray, count: int):
        rng, u = _rng(state), np.empty((count, U_PER_DRAW))
        self.c.rbs_draw_many_uniforms(ref(rng), ctypes.c_size_t(count), _ptr(u))
        return u, _state(rng)

    # -- torque-free flight (rotation.c: internal functions of the test-only library)
    def rotation_init(self, K, R0, ell, params: np.ndarray) -> None:
        """rbs_rotation_init into ``params`` (float64, C-contiguous, written in place)."""
        K, R0, ell = (_f64(x) for x in (K, R0, ell))
        assert params.dtype == np.float64 and params.flags.c_contiguous
        self.internal.rbs_rotation_init(_ptr(K), _ptr(R0), _ptr(ell), _ptr(params))

    def rotation_at(self, params: np.ndarray, t: float):
        """(R (3x3, body -> lab), omega (lab)) of rbs_rotation_at."""
        params = _f64(params)
        R, omega = np.empty((3, 3)), np.empty(3)
        self.internal.rbs_rotation_at(_ptr(params), ctypes.c_double(t), _ptr(R), _ptr(omega))
        return R, omega


def environment_without_preload() -> dict:
    env = dict(os.environ)
    env.pop("LD_PRELOAD", None)
    return env
