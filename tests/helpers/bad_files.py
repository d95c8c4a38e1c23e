"""The corpus of bad table files: one file per way a table can break the written contract (docs/format.md,
"What makes a table valid"), each run through both loaders (test_native_files.py: the same verdict from
surrogate.load and rbs_table_open; test_native_programs.py: the C loader under the sanitizers)."""

from __future__ import annotations

import h5py
import numpy as np

from tests.helpers import python_side as py
from tests.helpers.native_library import ERR_FORMAT, ERR_IO, ERR_VERSION, OK
from tests.helpers.tables import edited_copy, format_3_copy


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


# the datasets of the work on the wall (data_schema.table.WORK_DATASETS)
WORK_DATASETS = ("work_loc", "work_scale", "work_shape", "work_slope", "work_dictionary", "work_mean", "work_std",
                 "trapped_work")


def _drop_cells(*names, version=None):
    """An edit removing the datasets cells/<name>, and with ``version`` setting the root's format_version."""
    def edit(f):
        for name in names:
            del f["cells"][name]
        if version is not None:
            f.attrs["format_version"] = np.array(version, dtype=np.int64)
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

    cases.append((edited_copy(good, folder, "v5.h5", version(5, 0)), ERR_VERSION, "5.0"))
    cases.append((edited_copy(good, folder, "v2.h5", version(2, 1)), ERR_VERSION, "2.1"))
    cases.append((edited_copy(good, folder, "v4_9.h5", version(4, 9)), OK, ""))
    # a table of format 3 (before rebound-scatter 1.0): refused, saying how to rebuild it
    old = format_3_copy(good, folder, "v3_4.h5")
    cases.append((old, ERR_VERSION, f"table format 3.4 was written before rebound-scatter 1.0, which reads format 4; "
                                    f"rebuild it from the configuration it stores: tablegen info --config {old} > "
                                    f"TABLE.toml && tablegen build --config TABLE.toml -o NEW.h5"))
    cases.append((edited_copy(good, folder, "v3_1.h5", version(3, 1)), ERR_VERSION, "table format 3.1 was written"))
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
    cases.append((edited_copy(good, folder, "no_wall_row.h5", lambda f: f["wall"].__delitem__("parameters")),
                  ERR_FORMAT, "wall/parameters"))
    cases.append((edited_copy(good, folder, "no_kappa.h5", _row_edit("model", drop="kappa")), ERR_FORMAT, "kappa"))
    cases.append((edited_copy(good, folder, "no_config.h5", lambda f: f.attrs.__delitem__("config")), ERR_FORMAT, "config"))
    cases.append((edited_copy(good, folder, "no_codes.h5", lambda f: f["grid"].__delitem__("shape_codes")), ERR_FORMAT,
                  "grid/shape_codes"))
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
    # the work on the wall (format 4.1): all of its datasets or none, each within its rules
    cases.append((edited_copy(good, folder, "partial_work.h5", _drop_cells("trapped_work", "work_std")), ERR_FORMAT,
                  "inconsistent table: ReboundTable has the work datasets ['work_dictionary', 'work_loc', 'work_mean', "
                  "'work_scale', 'work_shape', 'work_slope'] but not ['trapped_work', 'work_std']: all or none"))
    cases.append((edited_copy(good, folder, "no_work.h5", _drop_cells(*WORK_DATASETS, version=(4, 0))), OK, ""))
    cases.append((edited_copy(good, folder, "work_shape_m.h5", _set("cells/work_shape", (0, 0, 0, 0, 1), 16)), ERR_FORMAT,
                  "cells/work_shape"))
    cases.append((edited_copy(good, folder, "negative_work_scale.h5", _set("cells/work_scale", (0, 0, 0, 0, 0), -0.5)),
                  ERR_FORMAT, "cells/work_scale"))
    cases.append((edited_copy(good, folder, "trapped_work_above_1.h5", _set("cells/trapped_work", (0, 0, 0, 1), 1.5)),
                  ERR_FORMAT, "cells/trapped_work"))
    cases.append((edited_copy(good, folder, "decreasing_work_dictionary.h5",
                              _set("cells/work_dictionary", (0, 0, 0, 1, 3), np.linspace(1.0, -1.0, 25))),
                  ERR_FORMAT, "dataset 'cells/work_dictionary' row 19 decreases"))
    cases.append((edited_copy(good, folder, "work_slope_shape.h5",
                              lambda f: _replace(f, "cells/work_slope", f["cells/work_slope"][()][..., :12])),
                  ERR_FORMAT, "cells/work_slope"))
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
    for name, value in (("p", 0.0), ("p", -0.61), ("k", np.nan)):
        cases.append((edited_copy(good, folder, f"wall_{name}_{value}.h5", _row_edit("wall", **{name: value})),
                      ERR_FORMAT, f"field '{name}' of dataset 'wall/parameters'"))
    checksum = edited_copy(good, folder, "checksum.h5")
    _corrupt_checksummed(checksum)
    cases.append((checksum, ERR_FORMAT, "cells/cluster_loc"))
    # a flipped bit of a parameter row (of p: 0.61 → 1.22 would change the law) fails its checksum
    for name in ("cells/indicatrix_2d", "cells/indicatrix_3d", "cells/collision_counts", "grid/shape_codes",
                 "wall/parameters", "model/parameters"):
        path = _corrupt_chunk(edited_copy(good, folder, f"checksum_{name.replace('/', '_')}.h5"), name)
        cases.append((path, ERR_FORMAT, name))
    return cases


def _row_edit(group, drop=None, dtype=None, **values):
    """An edit of ``group/parameters`` (one compound row): field ``drop`` left out, fields of ``dtype`` (a
    {name: dtype}) stored as that type (a new field appended), the fields of ``values`` set; rewritten chunked (1,)
    under Fletcher-32."""
    def edit(f):
        row = f[group]["parameters"][()]
        types = {name: row.dtype[name] for name in row.dtype.names if name != drop}
        types.update(dtype or {})
        new = np.zeros(1, dtype=[(name, t) for name, t in types.items()])
        for name in types:
            new[name] = (values[name] if name in values else row[name]) if np.dtype(types[name]).kind not in "OSU" \
                else b"0.61"
        del f[group]["parameters"]
        f[group].create_dataset("parameters", data=new, chunks=(1,), fletcher32=True)
    return edit


def _replace_row(group, data):
    def edit(f):
        del f[group]["parameters"]
        f[group].create_dataset("parameters", data=data)
    return edit


def parameter_row_cases(good, folder) -> list:
    """(path, expected C code, the message after "PATH: ") for each fault of the rows /wall/parameters and
    /model/parameters and of the wall's attributes: the two loaders give the same message, word for word."""
    folder.mkdir(parents=True, exist_ok=True)
    wall, model = "dataset 'wall/parameters'", "dataset 'model/parameters'"
    model_fields = ("kappa, n_max, aspect_ratio_mean, aspect_ratio_sd, aspect_ratio_low, aspect_ratio_high, "
                    "contact_tol, set_tol, max_steps, second_moment_factors")
    specs = [
        ("no_wall", lambda f: f.__delitem__("wall"), "missing group 'wall'"),
        ("no_model", lambda f: f.__delitem__("model"), "missing group 'model'"),
        ("no_wall_row", lambda f: f["wall"].__delitem__("parameters"), f"missing {wall}"),
        ("no_family", lambda f: f["wall"].attrs.__delitem__("family"), "missing attribute 'family' of group 'wall'"),
        ("no_wall_name", lambda f: f["wall"].attrs.__delitem__("name"), "missing attribute 'name' of group 'wall'"),
        ("numeric_family", _attribute("wall", "family", 3.0),
         "cannot read the attribute 'family' of group 'wall' as a string"),
        ("unknown_family", _attribute("wall", "family", "linear"),
         "the attribute 'family' of group 'wall' names an unknown wall law family 'linear' (this version knows: "
         "exponential, tabulated)"),
        ("no_q", _row_edit("wall", drop="q"), f"{wall} has no field 'q'; the fields read: k, p, q (the exponential "
                                              f"wall law) and speed_range_m_s"),
        ("no_speed_range", _row_edit("wall", drop="speed_range_m_s"),
         f"{wall} has no field 'speed_range_m_s'; the fields read: k, p, q (the exponential wall law) and "
         f"speed_range_m_s"),
        ("speed_range_reversed", _row_edit("wall", speed_range_m_s=[300.0, 50.0]),
         f"field 'speed_range_m_s' of {wall} must be [low, high] m/s with 0 <= low < high finite, or [0, inf] (not "
         f"stated); got [300, 50]"),
        ("speed_range_half_open", _row_edit("wall", speed_range_m_s=[50.0, np.inf]),
         f"field 'speed_range_m_s' of {wall} must be [low, high] m/s with 0 <= low < high finite, or [0, inf] (not "
         f"stated); got [50, inf]"),
        ("speed_range_one", _row_edit("wall", dtype={"speed_range_m_s": "<f8"}, speed_range_m_s=50.0),
         f"field 'speed_range_m_s' of {wall} must be stored as 2 numbers"),
        ("p_zero", _row_edit("wall", p=0.0), f"field 'p' of {wall} must be finite and > 0; got 0"),
        ("p_negative", _row_edit("wall", p=-0.61),
         f"field 'p' of {wall} must be finite and > 0; got -0.60999999999999999"),
        ("k_nan", _row_edit("wall", k=np.nan), f"field 'k' of {wall} must be finite and > 0; got nan"),
        ("q_inf", _row_edit("wall", q=np.inf), f"field 'q' of {wall} must be finite; got inf"),
        ("p_string", _row_edit("wall", dtype={"p": "S8"}), f"field 'p' of {wall} must be stored as one number"),
        ("roughness_above_45", _row_edit("wall", dtype={"roughness_deg": "<f8"}, roughness_deg=46.0),
         f"field 'roughness_deg' of {wall} must be in [0, 45] degrees; got 46"),
        ("roughness_negative", _row_edit("wall", dtype={"roughness_deg": "<f8"}, roughness_deg=-0.5),
         f"field 'roughness_deg' of {wall} must be in [0, 45] degrees; got -0.5"),
        ("roughness_nan", _row_edit("wall", dtype={"roughness_deg": "<f8"}, roughness_deg=np.nan),
         f"field 'roughness_deg' of {wall} must be in [0, 45] degrees; got nan"),
        ("roughness_pair", _row_edit("wall", dtype={"roughness_deg": ("<f8", (2,))}, roughness_deg=[5.0, 5.0]),
         f"field 'roughness_deg' of {wall} must be stored as one number"),
        ("wall_not_compound", _replace_row("wall", np.array([0.1, 0.61, 1.0])),
         f"{wall} must hold one row of a compound type, one field per parameter"),
        ("wall_two_rows", _replace_row("wall", np.zeros(2, dtype=[("k", "<f8"), ("p", "<f8"), ("q", "<f8")])),
         f"{wall} must hold one row of a compound type, one field per parameter"),
        ("no_kappa", _row_edit("model", drop="kappa"), f"{model} has no field 'kappa'; the fields read: {model_fields}"),
        ("kappa_one", _row_edit("model", kappa=1.0), f"field 'kappa' of {model} must be in [0, 1); got 1"),
        ("n_max_real", _row_edit("model", dtype={"n_max": "<f8"}), f"field 'n_max' of {model} must be stored as one "
                                                                   f"integer"),
        ("n_max_zero", _row_edit("model", n_max=0), f"field 'n_max' of {model} must be an integer in [1, 2**53); got 0"),
        ("sd_zero", _row_edit("model", aspect_ratio_sd=0.0), f"field 'aspect_ratio_sd' of {model} must be finite and "
                                                             f"> 0; got 0"),
        ("high_below_low", _row_edit("model", aspect_ratio_high=0.4),
         f"field 'aspect_ratio_high' of {model} must be in (aspect_ratio_low, 1]; got 0.40000000000000002"),
        ("contact_tol_zero", _row_edit("model", contact_tol=0.0), f"field 'contact_tol' of {model} must be finite and "
                                                                  f"> 0; got 0"),
        ("max_steps_zero", _row_edit("model", max_steps=0), f"field 'max_steps' of {model} must be an integer in "
                                                            f"[1, 2**53); got 0"),
        ("kfac_three", _row_edit("model", dtype={"second_moment_factors": ("<f8", (3,))},
                                 second_moment_factors=[0.2, 0.3, 0.3]),
         f"field 'second_moment_factors' of {model} must be stored as 4 numbers"),
        ("kfac_out", _row_edit("model", second_moment_factors=[0.2, 0.33, 1.5, 0.2]),
         f"field 'second_moment_factors' of {model} must be 4 numbers in (0, 1), one per shape code; got 1.5 at "
         f"index 2"),
    ]
    return [(edited_copy(good, folder, f"row_{name}.h5", edit), ERR_FORMAT, message) for name, edit, message in specs]


def _wall_dataset(name, values=None):
    """An edit of the wall's dataset ``name``: rewritten with ``values`` (float64, under Fletcher-32), or removed."""
    def edit(f):
        del f["wall"][name]
        if values is not None:
            f["wall"].create_dataset(name, data=np.asarray(values, dtype=np.float64), fletcher32=True)
    return edit


def tabulated_wall_cases(good, folder) -> list:
    """(path, expected C code, the message after "PATH: ", Python's and C's) for faults of a tabulated wall law's
    arrays in the table ``good`` (of TABULATED_TABLE_CONFIG's wall: speed nodes 40, 120, 300 m/s, sine nodes 0,
    0.5, 1). Both loaders quote values as a Python list of floats."""
    folder.mkdir(parents=True, exist_ok=True)
    rule = "group 'wall': The wall law parameter"
    specs = [
        ("restitution_above_1", _set("wall/restitution", (1, 1), 1.5),
         f"{rule} 'restitution' must be in (0, 1] at every node; got 1.5 at [1][1] (|V_c| = 120 m/s, sine 0.5)."),
        ("restitution_zero", _set("wall/restitution", (2, 0), 0.0),
         f"{rule} 'restitution' must be in (0, 1] at every node; got 0.0 at [2][0] (|V_c| = 300 m/s, sine 0)."),
        ("sine_not_to_1", _wall_dataset("contact_sine", [0.0, 0.5, 0.9]),
         f"{rule} 'contact_sine' must be 2 to 16 finite, strictly increasing numbers from 0 to 1; got [0.0, 0.5, 0.9]."),
        ("speeds_not_increasing", _wall_dataset("contact_speed_m_s", [40.0, 300.0, 120.0]),
         f"{rule} 'contact_speed_m_s' must be 1 to 16 finite, strictly increasing numbers > 0; got [40.0, 300.0, "
         f"120.0]."),
        ("restitution_columns", _wall_dataset("restitution", [[1.0, 0.8], [1.0, 0.75], [1.0, 0.7]]),
         f"{rule} 'restitution' must be 3 rows (one per speed node) of 3 numbers (one per sine node); got [[1.0, 0.8], "
         f"[1.0, 0.75], [1.0, 0.7]]."),
        ("restitution_flat", _wall_dataset("restitution", [1.0, 0.8, 0.55, 1.0, 0.75, 0.5, 1.0, 0.7, 0.42]),
         "dataset 'wall/restitution' must hold 2-dimensional numbers; got float64 of shape (9,)"),
        ("no_sines", _wall_dataset("contact_sine"),
         "missing dataset 'wall/contact_sine' (an array of the tabulated wall law: the sine nodes |v_c⁻|/|V_c⁻|)"),
        ("q_nan", _row_edit("wall", q=np.nan), "field 'q' of dataset 'wall/parameters' must be finite; got nan"),
    ]
    return [(edited_copy(good, folder, f"tabulated_{name}.h5", edit), ERR_FORMAT, message)
            for name, edit, message in specs]
