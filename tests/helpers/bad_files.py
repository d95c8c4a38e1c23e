"""The corpus of bad table files: one file per way a table can break the written contract (docs/format.md,
"What makes a table valid"), each run through both loaders (test_native_files.py: the same verdict from
surrogate.load and rbs_table_open; test_native_programs.py: the C loader under the sanitizers)."""

from __future__ import annotations

import h5py
import numpy as np

from tests.helpers import python_side as py
from tests.helpers.native_library import ERR_FORMAT, ERR_IO, ERR_VERSION, OK
from tests.helpers.tables import edited_copy


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


def _set(name, index, value):
    """An edit setting element ``index`` of dataset ``name`` to ``value`` (the whole dataset rewritten in place)."""
    def edit(f):
        values = f[name][()]
        values[index] = value
        f[name][...] = values
    return edit


def _attribute(group, name, value):
    def edit(f):
        f[group].attrs[name] = value
    return edit


def _corrupt_chunk(path, name, chunk=0):
    """Flip a byte of the stored data of a chunk of the (Fletcher-32) dataset ``name``."""
    with h5py.File(path, "r") as f:
        info = f[name].id.get_chunk_info(chunk)
        offset = info.byte_offset + info.size // 2
    with open(path, "r+b") as f:
        f.seek(offset)
        byte = f.read(1)
        f.seek(offset)
        f.write(bytes([byte[0] ^ 0xFF]))
    return path


def _flip_bit(value: float, bit: int) -> float:
    return float(np.array([value]).view(np.uint64).__xor__(np.uint64(1 << bit)).view(np.float64)[0])


def bad_tables(good, folder) -> list:
    """(path, expected C code, what the message must name) for every file of the corpus; surrogate.load must
    give the same verdict (refused unless the code is OK)."""
    folder.mkdir(parents=True, exist_ok=True)
    cases = [(folder / "missing.h5", ERR_IO, "no such file")]
    truncated = folder / "truncated.h5"
    data = good.read_bytes()
    truncated.write_bytes(data[:len(data) // 2])
    cases.append((truncated, ERR_FORMAT, ""))
    garbage = folder / "garbage.h5"
    garbage.write_bytes(np.random.default_rng(0).integers(0, 256, 5000, dtype=np.uint8).tobytes())
    cases.append((garbage, ERR_FORMAT, "HDF5"))
    samples = folder / "samples.h5"
    py.write_samples_file(samples)
    cases.append((samples, ERR_FORMAT, "rebound_samples"))
    other = folder / "other.h5"
    with h5py.File(other, "w") as f:
        f.create_dataset("x", data=np.arange(10.0))
    cases.append((other, ERR_FORMAT, "file_type"))
    directory = folder / "a_folder.h5"
    directory.mkdir(exist_ok=True)
    cases.append((directory, ERR_IO, ""))

    def version(major, minor):
        def edit(f):
            f.attrs["format_version"] = np.array([major, minor], dtype=np.int64)
        return edit

    cases.append((edited_copy(good, folder, "v4.h5", version(4, 0)), ERR_VERSION, "4.0"))
    cases.append((edited_copy(good, folder, "v2.h5", version(2, 1)), ERR_VERSION, "2.1"))
    cases.append((edited_copy(good, folder, "v3_9.h5", version(3, 9)), OK, ""))

    def format_3_1(f):      # a table written before 3.2: no checksummed copies of the law's attributes
        version(3, 1)(f)
        del f["grid/law"], f["grid/shape_codes"], f["shapes"]

    cases.append((edited_copy(good, folder, "v3_1.h5", format_3_1), OK, ""))
    cases.append((edited_copy(good, folder, "no_version.h5", lambda f: f.attrs.__delitem__("format_version")),
                  ERR_FORMAT, "format_version"))
    cases.append((edited_copy(good, folder, "no_mean.h5", lambda f: f["cells"].__delitem__("mean")), ERR_FORMAT,
                  "cells/mean"))
    cases.append((edited_copy(good, folder, "no_shapes.h5", lambda f: f["grid"].__delitem__("shapes")), ERR_FORMAT,
                  "grid/shapes"))
    cases.append((edited_copy(good, folder, "no_resolution.h5", lambda f: f.__delitem__("resolution")), ERR_FORMAT,
                  "resolution"))
    cases.append((edited_copy(good, folder, "wrong_shape.h5",
                        lambda f: _replace(f, "cells/std", f["cells/std"][()][..., :5])), ERR_FORMAT, "cells/std"))
    cases.append((edited_copy(good, folder, "no_wall_law.h5", lambda f: f["grid"].attrs.__delitem__("restitution_k")),
                  ERR_FORMAT, "restitution_k"))
    cases.append((edited_copy(good, folder, "no_kappa.h5", lambda f: f["grid"].attrs.__delitem__("kappa")), ERR_FORMAT,
                  "kappa"))
    cases.append((edited_copy(good, folder, "no_config.h5", lambda f: f.attrs.__delitem__("config")), ERR_FORMAT, "config"))
    cases.append((edited_copy(good, folder, "no_law_copy.h5", lambda f: f["grid"].__delitem__("law")), ERR_FORMAT,
                  "grid/law"))
    cases.append((edited_copy(good, folder, "nan_std.h5", _set("cells/std", (0, 0, 0, 2), np.nan)), ERR_FORMAT, "cells/std"))
    cases.append((edited_copy(good, folder, "negative_std.h5", _set("cells/std", (0, 0, 0, 2), -0.01)), ERR_FORMAT,
                  "cells/std"))
    cases.append((edited_copy(good, folder, "shape_index.h5", _set("cells/cluster_shape", (0, 0, 0, 1, 1), 255)), ERR_FORMAT,
                  "cluster_shape"))
    cases.append((edited_copy(good, folder, "shape_index_m.h5", _set("cells/cluster_shape", (0, 0, 0, 0, 0), 16)), ERR_FORMAT,
                  "cluster_shape"))
    cases.append((edited_copy(good, folder, "negative_status.h5", _set("cells/status_counts", (0, 0, 0, 2), -5)), ERR_FORMAT,
                  "status_counts"))
    cases.append((edited_copy(good, folder, "no_draw.h5", _set("cells/status_counts", (0, 0, 0), [0, 0, 10])), ERR_FORMAT,
                  "status_counts"))
    cases.append((edited_copy(good, folder, "negative_collisions.h5", _set("cells/collision_counts", (0, 0, 0, 1), -1)),
                  ERR_FORMAT, "collision_counts"))
    cases.append((edited_copy(good, folder, "negative_scale.h5", _set("cells/cluster_scale", (0, 0, 0, 0, 0), -1.0)),
                  ERR_FORMAT, "cluster_scale"))
    cases.append((edited_copy(good, folder, "regime_2.h5", _set("cells/cluster_regime", (0, 0, 0, 0), 2)), ERR_FORMAT,
                  "cluster_regime"))
    cases.append((edited_copy(good, folder, "weights_sum.h5", _set("cells/cluster_weight", (0, 0, 0, 0), 0.5)), ERR_FORMAT,
                  "cluster_weight"))
    cases.append((edited_copy(good, folder, "negative_indicatrix.h5", _set("cells/indicatrix_3d", (0, 0, 0, 5, 5), -1.0)),
                  ERR_FORMAT, "indicatrix_3d"))
    cases.append((edited_copy(good, folder, "alpha1_grid.h5", lambda f: _replace(f, "grid/alpha1_deg",
                                                                           np.linspace(-30.0, 200.0, f["grid/alpha1_deg"].shape[0]))),
                  ERR_FORMAT, "grid/alpha1_deg"))
    cases.append((edited_copy(good, folder, "speed_ratio.h5", lambda f: _replace(f, "grid/speed_m_s",
                                                                           f["grid/speed_m_s"][()] ** 2)),
                  ERR_FORMAT, "grid/speed_m_s"))

    def banana(f):
        names = [s.decode() if isinstance(s, bytes) else s for s in f["grid/shapes"][()]]
        names[0] = "banana"
        _replace(f, "grid/shapes", np.array(names, dtype=h5py.string_dtype()))

    cases.append((edited_copy(good, folder, "banana.h5", banana), ERR_FORMAT, "grid/shapes"))

    def swapped(f):         # two valid names swapped: only the checksummed copy tells
        names = [s.decode() if isinstance(s, bytes) else s for s in f["grid/shapes"][()]]
        names[0], names[1] = names[1], names[0]
        _replace(f, "grid/shapes", np.array(names, dtype=h5py.string_dtype()))

    cases.append((edited_copy(good, folder, "swapped_shapes.h5", swapped), ERR_FORMAT, "grid/shapes"))
    for name, value in (("restitution_p", 0.0), ("restitution_p", -0.61), ("restitution_k", np.nan)):
        cases.append((edited_copy(good, folder, f"{name}_{value}.h5", _attribute("grid", name, value)), ERR_FORMAT, name))

    def flipped_p(f):       # one flipped bit of restitution_p (0.61 → 1.22) changed the law and loaded
        f["grid"].attrs["restitution_p"] = _flip_bit(float(f["grid"].attrs["restitution_p"]), 52)

    cases.append((edited_copy(good, folder, "flipped_p.h5", flipped_p), ERR_FORMAT, "grid/law"))
    checksum = edited_copy(good, folder, "checksum.h5")
    _corrupt_checksummed(checksum)
    cases.append((checksum, ERR_FORMAT, "cells/cluster_loc"))
    for name in ("cells/indicatrix_2d", "cells/indicatrix_3d", "cells/collision_counts", "grid/law"):
        path = _corrupt_chunk(edited_copy(good, folder, f"checksum_{name.replace('/', '_')}.h5"), name)
        cases.append((path, ERR_FORMAT, name))
    return cases
