"""Building the native library with CMake and driving it through ctypes (the tests' side of it).

:func:`build` configures and builds ``native/`` into a folder; :class:`Native` loads the shared library
and wraps the functions the tests call, on NumPy arrays. Nothing here imports the Python packages: the
Python side of every comparison comes through :mod:`tests.helpers.python_side`.
"""

from __future__ import annotations

import ctypes
import os
import shutil
import subprocess
from pathlib import Path

import numpy as np

from tests.helpers import REPO, background

NATIVE = REPO / "native"
INSTALL_HINT = ("run native/install-deps.sh (as root on Debian/Ubuntu it installs gcc, g++, cmake, libhdf5-dev, "
                "gfortran and pkg-config; elsewhere it prints what to install)")

U_PER_DRAW = 13
MAX_SHAPES = 4
SCALED, STOCHASTIC = 0, 1
AUTO, TABLE, DIRECT = 0, 1, 2           # RBS_AUTO, RBS_TABLE, RBS_DIRECT
PATH_TABLE, PATH_DIRECT = 0, 1          # RBS_PATH_TABLE, RBS_PATH_DIRECT
INVALID = -1                            # RBS_INVALID
OK, ERR_IO, ERR_FORMAT, ERR_VERSION, ERR_ARGUMENT, ERR_MEMORY = range(6)


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


def run(command, cwd=None, env=None, timeout=600) -> subprocess.CompletedProcess:
    # background.run: a build started with the session is killed with it (tests.helpers.background.stop)
    return background.run(command, cwd=cwd, env=env, timeout=timeout)


def build(folder: Path, options: dict, targets=None) -> Path:
    """Configure native/ into ``folder`` with CMake (Release, -Werror, the given -D options) and build it;
    BuildError with CMake's output (and the install hint) on failure."""
    folder.mkdir(parents=True, exist_ok=True)
    configure = ["cmake", "-S", str(NATIVE), "-B", str(folder), "-DCMAKE_BUILD_TYPE=Release", "-DRBS_WERROR=ON"]
    configure += [f"-D{k}={v}" for k, v in options.items()]
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


_d = ctypes.POINTER(ctypes.c_double)


class Mix(ctypes.Structure):
    _fields_ = [("n_shapes", ctypes.c_int), ("cdf", ctypes.c_double * MAX_SHAPES)]


class ShapeInfo(ctypes.Structure):
    _fields_ = [("name", ctypes.c_char_p), ("kind", ctypes.c_int), ("family", ctypes.c_int),
                ("n_vertices", ctypes.c_int), ("vertices", ctypes.POINTER(ctypes.c_double)),
                ("inertia", ctypes.c_double * 3), ("aspect", ctypes.c_double * 4), ("both_hands", ctypes.c_int),
                ("direct_shape", ctypes.c_int)]


class OwnedMix:
    """A mix of rbs_mix_new_* (sized by the table), freed with rbs_mix_free on garbage collection."""

    def __init__(self, lib, pointer):
        self.lib, self.pointer = lib, pointer

    @property
    def n_shapes(self) -> int:
        return self.pointer.contents.n_shapes

    def __del__(self):
        if self.pointer:
            self.lib.c.rbs_mix_free(self.pointer)
            self.pointer = None


def _mix_ref(mix):
    """What a draw takes for a mix: the pointer of an :class:`OwnedMix`, or a value :class:`Mix` by reference."""
    return mix.pointer if isinstance(mix, OwnedMix) else ctypes.byref(mix)


class Rng(ctypes.Structure):
    _fields_ = [("s", ctypes.c_uint64 * 4)]


class ShapeArrays(ctypes.Structure):
    """rbs_shape_arrays (native/src/shapes.h): pointers into a direct_model.shape_arrays.ShapeArrays' arrays."""

    FIELDS = ("kind", "vertex_start", "vertices", "second_moments", "aspect", "aspect_cdf", "both_hands")
    _fields_ = [("n_shapes", ctypes.c_int)] + [(name, ctypes.c_void_p) for name in FIELDS]

    @classmethod
    def of(cls, arrays):
        """The struct over ``arrays`` (C-contiguous; the caller keeps them alive while C reads them)."""
        assert all(getattr(arrays, name).flags.c_contiguous for name in cls.FIELDS)
        return cls(len(arrays.kind), *(getattr(arrays, name).ctypes.data for name in cls.FIELDS))


class Grain(ctypes.Structure):
    """rbs_grain (rbs_grain_info)."""

    _fields_ = [("shape", ctypes.c_int), ("direct_shape", ctypes.c_int), ("ratio_ba", ctypes.c_double),
                ("ratio_cb", ctypes.c_double), ("hand", ctypes.c_double)]


class Info(ctypes.Structure):
    _fields_ = [("n_shapes", ctypes.c_int), ("n_alpha1", ctypes.c_int), ("n_speed", ctypes.c_int),
                ("n_clusters", ctypes.c_int), ("n_levels", ctypes.c_int), ("n_dictionary", ctypes.c_int),
                ("n_pieces", ctypes.c_int), ("format_major", ctypes.c_int), ("format_minor", ctypes.c_int),
                ("particles_per_cell", ctypes.c_longlong), ("n_max", ctypes.c_longlong),
                ("restitution_k", ctypes.c_double), ("restitution_p", ctypes.c_double),
                ("kernel_bytes", ctypes.c_size_t)]


def _rng(state) -> Rng:
    return Rng((ctypes.c_uint64 * 4)(*[int(x) for x in state]))


def _ptr(a: np.ndarray):
    return a.ctypes.data_as(ctypes.c_void_p)


class NativeTable:
    """An open rbs_table (closed by :meth:`close` or on garbage collection)."""

    def __init__(self, lib: "Native", handle):
        self.lib, self.handle = lib, handle

    def close(self):
        if self.handle:
            self.lib.c.rbs_table_close(self.handle)
            self.handle = None

    def __del__(self):
        self.close()

    @property
    def shapes(self) -> tuple:
        c = self.lib.c
        return tuple(c.rbs_table_shape_name(self.handle, i).decode() for i in range(c.rbs_table_n_shapes(self.handle)))

    def info(self) -> Info:
        info = Info()
        self.lib.c.rbs_table_info_get(self.handle, ctypes.byref(info))
        return info

    def kernel_array(self, name: str) -> np.ndarray:
        data, count, dtype = ctypes.c_void_p(), ctypes.c_size_t(), ctypes.c_int()
        code = self.lib.c.rbs_table_kernel_array(self.handle, name.encode(), ctypes.byref(data), ctypes.byref(count),
                                                 ctypes.byref(dtype))
        if code != OK:
            raise KeyError(name)
        ctype = ctypes.c_double if dtype.value == 0 else ctypes.c_float
        array = np.ctypeslib.as_array(ctypes.cast(data, ctypes.POINTER(ctype)), shape=(count.value,))
        return array.copy()

    def ranges(self):
        lo, hi, vlo, vhi = (ctypes.c_double() for _ in range(4))
        self.lib.c.rbs_table_alpha1_range(self.handle, ctypes.byref(lo), ctypes.byref(hi))
        self.lib.c.rbs_table_speed_range(self.handle, ctypes.byref(vlo), ctypes.byref(vhi))
        return (lo.value, hi.value), (vlo.value, vhi.value)

    # -- mixes
    def mix_equal(self) -> Mix:
        mix = Mix()
        assert self.lib.c.rbs_mix_equal(self.handle, ctypes.byref(mix)) == OK
        return mix

    def mix_from_weights(self, weights: dict):
        mix, message = Mix(), ctypes.create_string_buffer(1024)
        names = (ctypes.c_char_p * max(1, len(weights)))(*[k.encode() for k in weights])
        values = np.ascontiguousarray(list(weights.values()) or [0.0], dtype=np.float64)
        code = self.lib.c.rbs_mix_from_weights(self.handle, len(weights), names, _ptr(values), ctypes.byref(mix),
                                               message, len(message))
        return code, mix, message.value.decode()

    def mix_from_shape(self, name: str):
        mix, message = Mix(), ctypes.create_string_buffer(1024)
        code = self.lib.c.rbs_mix_from_shape(self.handle, name.encode(), ctypes.byref(mix), message, len(message))
        return code, mix, message.value.decode()

    def mix_new(self, shape="mix", weights: dict | None = None):
        """(OwnedMix or None, message): rbs_mix_new_from_weights with ``weights``, else rbs_mix_new_from_shape
        (``"mix"``: rbs_mix_new_equal)."""
        c, message = self.lib.c, ctypes.create_string_buffer(1024)
        if weights is not None:
            names = (ctypes.c_char_p * max(1, len(weights)))(*[k.encode() for k in weights])
            values = np.ascontiguousarray(list(weights.values()) or [0.0], dtype=np.float64)
            pointer = c.rbs_mix_new_from_weights(self.handle, len(weights), names, _ptr(values), message,
                                                 len(message))
        elif shape == "mix":
            pointer = c.rbs_mix_new_equal(self.handle)
        else:
            pointer = c.rbs_mix_new_from_shape(self.handle, shape.encode(), message, len(message))
        return (OwnedMix(self.lib, pointer) if pointer else None), message.value.decode()

    def shape_info(self, i: int) -> dict | None:
        """rbs_table_shape_info of shape i as a dict (vertices copied), or None (RBS_ERR_ARGUMENT)."""
        info = ShapeInfo()
        if self.lib.c.rbs_table_shape_info(self.handle, i, ctypes.byref(info)) != OK:
            return None
        n = info.n_vertices
        vertices = (np.ctypeslib.as_array(info.vertices, shape=(n, 3)).copy() if n else np.zeros((0, 3)))
        return {"name": info.name.decode(), "kind": info.kind, "family": info.family, "vertices": vertices,
                "inertia": np.array(info.inertia[:]), "aspect": np.array(info.aspect[:]),
                "both_hands": info.both_hands, "direct_shape": info.direct_shape}

    # -- draws
    def table_rebound(self, mix, V, n, a, u, interpolation=SCALED):
        V, n, u = (np.ascontiguousarray(x, dtype=np.float64) for x in (V, n, u))
        V_out, W_out = np.empty(3), np.empty(3)
        status = self.lib.c.rbs_table_rebound(self.handle, _mix_ref(mix), _ptr(V), _ptr(n), ctypes.c_double(a),
                                              _ptr(u), interpolation, _ptr(V_out), _ptr(W_out))
        return status, V_out, W_out

    def table_rebound_many(self, mix, V, n, a, u, interpolation=SCALED):
        V, n, a, u = (np.ascontiguousarray(x, dtype=np.float64) for x in (V, n, a, u))
        count = V.shape[0]
        assert n.shape == (count, 3) and a.shape == (count,) and u.shape == (count, U_PER_DRAW)
        V_out, W_out, status = np.empty((count, 3)), np.empty((count, 3)), np.empty(count, dtype=np.int8)
        self.lib.c.rbs_table_rebound_many(self.handle, _mix_ref(mix), ctypes.c_size_t(count), _ptr(V), _ptr(n),
                                          _ptr(a), _ptr(u), interpolation, _ptr(V_out), _ptr(W_out), _ptr(status))
        return status, V_out, W_out

    def table_rebound_many_rng(self, mix, V, n, a, state: np.ndarray, interpolation=SCALED):
        """Returns (status, V_out, W_out, advanced state)."""
        V, n, a = (np.ascontiguousarray(x, dtype=np.float64) for x in (V, n, a))
        count = V.shape[0]
        rng = _rng(state)
        V_out, W_out, status = np.empty((count, 3)), np.empty((count, 3)), np.empty(count, dtype=np.int8)
        self.lib.c.rbs_table_rebound_many_rng(self.handle, _mix_ref(mix), ctypes.c_size_t(count), _ptr(V),
                                              _ptr(n), _ptr(a), ctypes.byref(rng), interpolation, _ptr(V_out),
                                              _ptr(W_out), _ptr(status))
        return status, V_out, W_out, np.array(list(rng.s), dtype=np.uint64)

    def direct_rebound(self, shape: int, V, Omega, n, a: float, u):
        """(status, V⁺ m/s, Ω⁺ rad/s) of rbs_direct_rebound for one particle (shape code, 7 uniforms)."""
        V, Omega, n, u = (np.ascontiguousarray(x, dtype=np.float64) for x in (V, Omega, n, u))
        V_out, W_out = np.empty(3), np.empty(3)
        status = self.lib.c.rbs_direct_rebound(self.handle, shape, _ptr(V), _ptr(Omega), _ptr(n), ctypes.c_double(a),
                                               _ptr(u), _ptr(V_out), _ptr(W_out))
        return status, V_out, W_out

    def rebound(self, mix, V, Omega, n, a, u, method=AUTO, interpolation=SCALED):
        V, Omega, n, u = (np.ascontiguousarray(x, dtype=np.float64) for x in (V, Omega, n, u))
        V_out, W_out = np.empty(3), np.empty(3)
        status = self.lib.c.rbs_rebound(self.handle, _mix_ref(mix), _ptr(V), _ptr(Omega), _ptr(n),
                                        ctypes.c_double(a), _ptr(u), method, interpolation, _ptr(V_out), _ptr(W_out))
        return status, V_out, W_out

    def rebound_rng(self, mix, V, Omega, n, a, state: np.ndarray, method=AUTO, interpolation=SCALED,
                    symbol="rbs_rebound_rng"):
        """Returns (status, V_out, W_out, advanced state); ``symbol`` "rbs_rebound_spin" calls the 0.x name."""
        V, Omega, n = (np.ascontiguousarray(x, dtype=np.float64) for x in (V, Omega, n))
        rng = _rng(state)
        V_out, W_out = np.empty(3), np.empty(3)
        status = getattr(self.lib.c, symbol)(self.handle, _mix_ref(mix), _ptr(V), _ptr(Omega), _ptr(n),
                                             ctypes.c_double(a), ctypes.byref(rng), method, interpolation,
                                             _ptr(V_out), _ptr(W_out))
        return status, V_out, W_out, np.array(list(rng.s), dtype=np.uint64)

    def rebound_grain(self, mix, key: int, V, Omega, n, a, u, method=AUTO, interpolation=SCALED):
        """(status, V⁺ m/s, Ω⁺ rad/s) of rbs_rebound_grain."""
        V, Omega, n, u = (np.ascontiguousarray(x, dtype=np.float64) for x in (V, Omega, n, u))
        V_out, W_out = np.empty(3), np.empty(3)
        status = self.lib.c.rbs_rebound_grain(self.handle, _mix_ref(mix), ctypes.c_int64(key), _ptr(V), _ptr(Omega),
                                              _ptr(n), ctypes.c_double(a), _ptr(u), method, interpolation,
                                              _ptr(V_out), _ptr(W_out))
        return status, V_out, W_out

    def rebound_grain_rng(self, mix, key: int, V, Omega, n, a, state: np.ndarray, method=AUTO, interpolation=SCALED):
        """(status, V⁺, Ω⁺, advanced state) of rbs_rebound_grain_rng."""
        V, Omega, n = (np.ascontiguousarray(x, dtype=np.float64) for x in (V, Omega, n))
        rng = _rng(state)
        V_out, W_out = np.empty(3), np.empty(3)
        status = self.lib.c.rbs_rebound_grain_rng(self.handle, _mix_ref(mix), ctypes.c_int64(key), _ptr(V),
                                                  _ptr(Omega), _ptr(n), ctypes.c_double(a), ctypes.byref(rng), method,
                                                  interpolation, _ptr(V_out), _ptr(W_out))
        return status, V_out, W_out, np.array(list(rng.s), dtype=np.uint64)

    def grain_info(self, mix, key: int):
        """(code, rbs_grain as a dict or None) of rbs_grain_info."""
        grain = Grain()
        code = self.lib.c.rbs_grain_info(self.handle, _mix_ref(mix), ctypes.c_int64(key), ctypes.byref(grain))
        return code, ({name: getattr(grain, name) for name, _ in Grain._fields_} if code == OK else None)

    def rebound_path(self, V, Omega, n, a, method=AUTO):
        V, Omega, n = (np.ascontiguousarray(x, dtype=np.float64) for x in (V, Omega, n))
        return self.lib.c.rbs_rebound_path(self.handle, _ptr(V), _ptr(Omega), _ptr(n), ctypes.c_double(a), method)

    def draw_local(self, mix, alpha1, speed, u, interpolation=SCALED):
        u = np.ascontiguousarray(u, dtype=np.float64)
        out = np.empty(6)
        status = self.lib.c.rbs_draw_local(self.handle, _mix_ref(mix), ctypes.c_double(alpha1),
                                           ctypes.c_double(speed), _ptr(u), interpolation, _ptr(out))
        return status, out


class Native:
    """The shared library of a build folder, its functions typed for ctypes."""

    def __init__(self, build_dir: Path):
        self.build_dir = Path(build_dir)
        candidates = sorted(self.build_dir.glob("librebound_scatter.so*"))
        if not candidates:
            raise BuildError(f"no librebound_scatter.so in {self.build_dir}")
        self.c = c = ctypes.CDLL(str(candidates[0]))
        vp, sz, i, d = ctypes.c_void_p, ctypes.c_size_t, ctypes.c_int, ctypes.c_double
        c.rbs_table_open.argtypes = [ctypes.c_char_p, ctypes.POINTER(vp), ctypes.c_char_p, sz]
        c.rbs_table_open.restype = i
        c.rbs_table_close.argtypes = [vp]
        c.rbs_table_close.restype = None
        c.rbs_table_n_shapes.argtypes = [vp]
        c.rbs_table_n_shapes.restype = i
        c.rbs_table_shape_name.argtypes = [vp, i]
        c.rbs_table_shape_name.restype = ctypes.c_char_p
        c.rbs_table_path.argtypes = [vp]
        c.rbs_table_path.restype = ctypes.c_char_p
        c.rbs_table_alpha1_range.argtypes = [vp, _d, _d]
        c.rbs_table_speed_range.argtypes = [vp, _d, _d]
        c.rbs_table_info_get.argtypes = [vp, ctypes.POINTER(Info)]
        c.rbs_table_kernel_array.argtypes = [vp, ctypes.c_char_p, ctypes.POINTER(vp), ctypes.POINTER(sz),
                                             ctypes.POINTER(i)]
        c.rbs_table_kernel_array.restype = i
        c.rbs_mix_equal.argtypes = [vp, ctypes.POINTER(Mix)]
        c.rbs_mix_equal.restype = i
        c.rbs_mix_from_weights.argtypes = [vp, i, ctypes.POINTER(ctypes.c_char_p), vp, ctypes.POINTER(Mix),
                                           ctypes.c_char_p, sz]
        c.rbs_mix_from_weights.restype = i
        c.rbs_mix_from_shape.argtypes = [vp, ctypes.c_char_p, ctypes.POINTER(Mix), ctypes.c_char_p, sz]
        c.rbs_mix_from_shape.restype = i
        c.rbs_mix_new_equal.argtypes = [vp]
        c.rbs_mix_new_equal.restype = ctypes.POINTER(Mix)
        c.rbs_mix_new_from_shape.argtypes = [vp, ctypes.c_char_p, ctypes.c_char_p, sz]
        c.rbs_mix_new_from_shape.restype = ctypes.POINTER(Mix)
        c.rbs_mix_new_from_weights.argtypes = [vp, i, ctypes.POINTER(ctypes.c_char_p), vp, ctypes.c_char_p, sz]
        c.rbs_mix_new_from_weights.restype = ctypes.POINTER(Mix)
        c.rbs_mix_free.argtypes = [ctypes.POINTER(Mix)]
        c.rbs_mix_free.restype = None
        c.rbs_table_shape_info.argtypes = [vp, i, ctypes.POINTER(ShapeInfo)]
        c.rbs_table_shape_info.restype = i
        c.rbs_table_rebound.argtypes = [vp, ctypes.POINTER(Mix), vp, vp, d, vp, i, vp, vp]
        c.rbs_table_rebound.restype = i
        c.rbs_table_rebound_many.argtypes = [vp, ctypes.POINTER(Mix), sz, vp, vp, vp, vp, i, vp, vp, vp]
        c.rbs_table_rebound_many.restype = None
        c.rbs_table_rebound_many_rng.argtypes = [vp, ctypes.POINTER(Mix), sz, vp, vp, vp, ctypes.POINTER(Rng), i,
                                                 vp, vp, vp]
        c.rbs_table_rebound_many_rng.restype = None
        c.rbs_direct_rebound.argtypes = [vp, i, vp, vp, vp, d, vp, vp, vp]
        c.rbs_direct_rebound.restype = i
        c.rbs_draw_local.argtypes = [vp, ctypes.POINTER(Mix), d, d, vp, i, vp]
        c.rbs_draw_local.restype = i
        c.rbs_rebound.argtypes = [vp, ctypes.POINTER(Mix), vp, vp, vp, d, vp, i, i, vp, vp]
        c.rbs_rebound.restype = i
        for kept in ("rbs_rebound_rng", "rbs_rebound_spin"):     # rbs_rebound_spin: its 0.x name
            getattr(c, kept).argtypes = [vp, ctypes.POINTER(Mix), vp, vp, vp, d, ctypes.POINTER(Rng), i, i, vp, vp]
            getattr(c, kept).restype = i
        c.rbs_rebound_grain.argtypes = [vp, ctypes.POINTER(Mix), ctypes.c_int64, vp, vp, vp, d, vp, i, i, vp, vp]
        c.rbs_rebound_grain.restype = i
        c.rbs_rebound_grain_rng.argtypes = [vp, ctypes.POINTER(Mix), ctypes.c_int64, vp, vp, vp, d, ctypes.POINTER(Rng),
                                            i, i, vp, vp]
        c.rbs_rebound_grain_rng.restype = i
        c.rbs_grain_info.argtypes = [vp, ctypes.POINTER(Mix), ctypes.c_int64, ctypes.POINTER(Grain)]
        c.rbs_grain_info.restype = i
        c.rbs_grain_key.argtypes = [ctypes.c_uint64, ctypes.c_uint64, ctypes.c_uint64]
        c.rbs_grain_key.restype = ctypes.c_int64
        c.rbs_rebound_path.argtypes = [vp, vp, vp, vp, d, i]
        c.rbs_rebound_path.restype = i
        c.rbs_rng_seed.argtypes = [ctypes.POINTER(Rng), ctypes.c_uint64]
        c.rbs_rng_seed_stream.argtypes = [ctypes.POINTER(Rng), ctypes.c_uint64, ctypes.c_uint64]
        c.rbs_rng_uniform.argtypes = [ctypes.POINTER(Rng)]
        c.rbs_rng_uniform.restype = d
        c.rbs_rng_fill.argtypes = [ctypes.POINTER(Rng), vp, sz]
        c.rbs_table_rebound_uniforms.argtypes = [ctypes.POINTER(Rng), sz, vp]
        c.rbs_error_string.argtypes = [i]
        c.rbs_error_string.restype = ctypes.c_char_p
        c.rbs_version.restype = ctypes.c_char_p
        c.rbs_rotation_init.argtypes = [vp, vp, vp, vp]
        c.rbs_rotation_init.restype = None
        c.rbs_rotation_at.argtypes = [vp, d, vp, vp]
        c.rbs_rotation_at.restype = None
        c.rbs_carlson_rf.argtypes = [d, d, d]
        c.rbs_carlson_rf.restype = d
        c.rbs_carlson_rj.argtypes = [d, d, d, d]
        c.rbs_carlson_rj.restype = d

    def open(self, path):
        """(code, NativeTable or None, message)."""
        handle, message = ctypes.c_void_p(), ctypes.create_string_buffer(2048)
        code = self.c.rbs_table_open(str(path).encode(), ctypes.byref(handle), message, len(message))
        return code, (NativeTable(self, handle) if code == OK else None), message.value.decode()

    def table(self, path) -> NativeTable:
        code, table, message = self.open(path)
        if code != OK:
            raise RuntimeError(f"rbs_table_open failed ({code}): {message}")
        return table

    # -- random numbers
    def seed(self, seed: int, stream: int | None = None) -> np.ndarray:
        rng = Rng()
        if stream is None:
            self.c.rbs_rng_seed(ctypes.byref(rng), ctypes.c_uint64(seed))
        else:
            self.c.rbs_rng_seed_stream(ctypes.byref(rng), ctypes.c_uint64(seed), ctypes.c_uint64(stream))
        return np.array(list(rng.s), dtype=np.uint64)

    def fill(self, state: np.ndarray, count: int):
        rng, u = _rng(state), np.empty(count)
        self.c.rbs_rng_fill(ctypes.byref(rng), _ptr(u), ctypes.c_size_t(count))
        return u, np.array(list(rng.s), dtype=np.uint64)

    def uniform(self, state: np.ndarray):
        rng = _rng(state)
        x = self.c.rbs_rng_uniform(ctypes.byref(rng))
        return x, np.array(list(rng.s), dtype=np.uint64)

    def grain_key(self, seed: int, id1: int, id2: int) -> int:
        return self.c.rbs_grain_key(ctypes.c_uint64(seed), ctypes.c_uint64(id1), ctypes.c_uint64(id2))

    def table_rebound_uniforms(self, state: np.ndarray, count: int):
        rng, u = _rng(state), np.empty((count, U_PER_DRAW))
        self.c.rbs_table_rebound_uniforms(ctypes.byref(rng), ctypes.c_size_t(count), _ptr(u))
        return u, np.array(list(rng.s), dtype=np.uint64)

    # -- torque-free flight (rotation.c, internal functions exported by the shared library)
    def rotation_init(self, K, R0, ell, params: np.ndarray) -> None:
        """rbs_rotation_init into ``params`` (float64, C-contiguous, written in place)."""
        K, R0, ell = (np.ascontiguousarray(x, dtype=np.float64) for x in (K, R0, ell))
        assert params.dtype == np.float64 and params.flags.c_contiguous
        self.c.rbs_rotation_init(_ptr(K), _ptr(R0), _ptr(ell), _ptr(params))

    def rotation_at(self, params: np.ndarray, t: float):
        """(R (3x3, body -> lab), omega (lab)) of rbs_rotation_at."""
        params = np.ascontiguousarray(params, dtype=np.float64)
        R, omega = np.empty((3, 3)), np.empty(3)
        self.c.rbs_rotation_at(_ptr(params), ctypes.c_double(t), _ptr(R), _ptr(omega))
        return R, omega


def environment_without_preload() -> dict:
    env = dict(os.environ)
    env.pop("LD_PRELOAD", None)
    return env
