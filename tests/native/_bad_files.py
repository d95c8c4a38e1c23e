"""The bad table files of the native tests (test_native_files.py, test_native_programs.py)."""

from __future__ import annotations

import shutil

import h5py
import numpy as np

import _python_side as py
from _native import ERR_FORMAT, ERR_IO, ERR_VERSION, OK


def _copy(source, folder, name, edit=None):
    path = folder / name
    shutil.copyfile(source, path)
    if edit is not None:
        with h5py.File(path, "r+") as f:
            edit(f)
    return path


def _replace(f, name, values, **options):
    del f[name]
    f.create_dataset(name, data=values, **options)


def _corrupt_checksummed(path):
    """Rewrite cells/cluster_loc with a Fletcher-32 checksum, then flip a byte of its stored data."""
    with h5py.File(path, "r+") as f:
        values = f["cells/cluster_loc"][()]
        _replace(f, "cells/cluster_loc", values, fletcher32=True, chunks=values.shape)
        offset = f["cells/cluster_loc"].id.get_chunk_info(0).byte_offset
    with open(path, "r+b") as f:
        f.seek(offset + 100)
        byte = f.read(1)
        f.seek(offset + 100)
        f.write(bytes([byte[0] ^ 0xFF]))


def bad_tables(good, folder) -> list:
    """(path, expected code, whether surrogate refuses it too, what the message must name) for every bad file."""
    folder.mkdir(parents=True, exist_ok=True)
    cases = [(folder / "missing.h5", ERR_IO, True, "no such file")]
    truncated = folder / "truncated.h5"
    data = good.read_bytes()
    truncated.write_bytes(data[:len(data) // 2])
    cases.append((truncated, ERR_FORMAT, True, ""))
    garbage = folder / "garbage.h5"
    garbage.write_bytes(np.random.default_rng(0).integers(0, 256, 5000, dtype=np.uint8).tobytes())
    cases.append((garbage, ERR_FORMAT, True, "HDF5"))
    samples = folder / "samples.h5"
    py.write_samples_file(samples)
    cases.append((samples, ERR_FORMAT, True, "rebound_samples"))
    other = folder / "other.h5"
    with h5py.File(other, "w") as f:
        f.create_dataset("x", data=np.arange(10.0))
    cases.append((other, ERR_FORMAT, True, "file_type"))
    directory = folder / "a_folder.h5"
    directory.mkdir(exist_ok=True)
    cases.append((directory, ERR_IO, True, ""))

    def version(major, minor):
        def edit(f):
            f.attrs["format_version"] = np.array([major, minor], dtype=np.int64)
        return edit

    cases.append((_copy(good, folder, "v4.h5", version(4, 0)), ERR_VERSION, True, "4.0"))
    cases.append((_copy(good, folder, "v2.h5", version(2, 1)), ERR_VERSION, True, "2.1"))
    cases.append((_copy(good, folder, "v3_9.h5", version(3, 9)), OK, False, ""))
    cases.append((_copy(good, folder, "no_version.h5", lambda f: f.attrs.__delitem__("format_version")),
                  ERR_FORMAT, True, "format_version"))
    cases.append((_copy(good, folder, "no_mean.h5", lambda f: f["cells"].__delitem__("mean")), ERR_FORMAT, True,
                  "cells/mean"))
    cases.append((_copy(good, folder, "no_shapes.h5", lambda f: f["grid"].__delitem__("shapes")), ERR_FORMAT, True,
                  "grid/shapes"))
    cases.append((_copy(good, folder, "no_resolution.h5", lambda f: f.__delitem__("resolution")), ERR_FORMAT, True,
                  "resolution"))
    cases.append((_copy(good, folder, "wrong_shape.h5",
                        lambda f: _replace(f, "cells/std", f["cells/std"][()][..., :5])), ERR_FORMAT, True,
                  "cells/std"))
    cases.append((_copy(good, folder, "no_wall_law.h5", lambda f: f["grid"].attrs.__delitem__("restitution_k")),
                  ERR_FORMAT, True, "restitution_k"))

    def nan_std(f):
        values = f["cells/std"][()]
        values[0, 0, 0, 2] = np.nan
        f["cells/std"][...] = values

    cases.append((_copy(good, folder, "nan_std.h5", nan_std), ERR_FORMAT, False, "not finite"))

    def shape_index(f):
        values = f["cells/cluster_shape"][()]
        values[0, 0, 0, 0, 0] = 255
        f["cells/cluster_shape"][...] = values

    cases.append((_copy(good, folder, "shape_index.h5", shape_index), ERR_FORMAT, False, "cluster_shape"))
    checksum = _copy(good, folder, "checksum.h5")
    _corrupt_checksummed(checksum)
    cases.append((checksum, ERR_FORMAT, False, "cells/cluster_loc"))
    return cases
