"""Table format 4 (docs/format.md, "Table files"): the wall as the named record /wall and the direct model's
parameters as /model, each one checksummed row read by field name; a table of format 3 (before rebound-scatter
1.0) refused with one message saying how to rebuild it from the configuration it stores, which
``tablegen info --config`` prints and from which ``tablegen build`` makes the same cells, bit for bit."""

from __future__ import annotations

import h5py
import numpy as np
import pytest

import surrogate
from data_schema.common import DataFormatError
from data_schema.table import (CELL_DATASETS, MODEL_FIELDS, TABLE_VERSION, WORK_DATASETS, read_table, stored_config,
                               table_fingerprint)
from direct_model.wall import WALL_FAMILIES
from surrogate.cli import main as surrogate_main
from tablegen import build_table, parse_config
from tablegen.cli import main as tablegen_main
from tests.helpers.bad_files import parameter_row_cases
from tests.helpers.cli import run_cli, user_error
from tests.helpers.tables import edited_copy, format_3_copy

# two cells of the fewest particles a cell allows: a family and a user grain given by its points (the stored
# configuration holds its hull)
REBUILD_CONFIG = """
[grid]
alpha1_deg = [45.0]
speed_m_s = [100.0]
shapes = ["prism", "sand_b"]
[simulation]
particles_per_cell = 256
seed = 7
[wall]
k = 0.12
p = 0.58
q = 0.9
name = "glass_on_steel"
[shapes.sand_b]
vertices = [[0.0, 0.0, 0.0], [1.0, 0.1, 0.0], [0.2, 0.9, 0.1], [0.1, 0.2, 0.7], [0.6, 0.5, 0.5], [0.9, 0.8, 0.3],
            [0.4, -0.2, 0.4]]
both_hands = true
"""


def older_message(path, minor=4) -> str:
    return (f"{path}: table format 3.{minor} was written before rebound-scatter 1.0, which reads format "
            f"{TABLE_VERSION[0]}; rebuild it from the configuration it stores: tablegen info --config {path} > "
            f"TABLE.toml && tablegen build --config TABLE.toml -o NEW.h5")


@pytest.fixture(scope="module")
def rebuild_table(tmp_path_factory):
    path = tmp_path_factory.mktemp("format") / "table.h5"
    build_table(parse_config(REBUILD_CONFIG), path, workers=1)
    return path


def test_the_layout_of_format_4(small_table_path):
    """/model and /wall hold one compound row each, chunked (1,) under Fletcher-32; grid keeps the grids, the names,
    their checksummed codes and particles_per_cell, and no law attribute; the cells hold the work datasets of
    format 4.1."""
    with h5py.File(small_table_path, "r") as f:
        assert tuple(f.attrs["format_version"]) == TABLE_VERSION == (4, 1)
        assert set(WORK_DATASETS) <= set(f["cells"]) and set(f["cells"]) == set(CELL_DATASETS) | set(WORK_DATASETS)
        assert set(f) == {"grid", "model", "wall", "shapes", "resolution", "cells"}
        assert set(f["grid"]) == {"alpha1_deg", "speed_m_s", "shapes", "shape_codes"}
        assert set(f["grid"].attrs) == {"particles_per_cell"}
        for group, names in (("model", tuple(MODEL_FIELDS)),
                             ("wall", (*WALL_FAMILIES["exponential"].parameter_names, "speed_range_m_s"))):
            row = f[group]["parameters"]
            assert row.shape == (1,) and row.chunks == (1,) and row.fletcher32 and row.dtype.names == names
        assert f["model/parameters"].dtype["second_moment_factors"].subdtype[1] == (4,)
        assert f["wall/parameters"].dtype["speed_range_m_s"].subdtype[1] == (2,)
        assert tuple(f["wall/parameters"][0]["speed_range_m_s"]) == (50.0, 300.0)
        assert f["model/parameters"].dtype["n_max"].kind == f["model/parameters"].dtype["max_steps"].kind == "i"
        assert dict(f["wall"].attrs) == {"family": "exponential", "name": "corundum_on_St3_Lashkov1991"}


@pytest.mark.parametrize("minor", [4, 0])
def test_a_format_3_table_is_refused_with_how_to_rebuild_it(small_table_path, tmp_path, minor):
    """A table in the layout rebound-scatter 0.x wrote (3.4), or any 3.x: one error, naming its format and the two
    commands that rebuild it."""
    path = format_3_copy(small_table_path, tmp_path, f"old_{minor}.h5", minor)
    for load in (read_table, surrogate.load, table_fingerprint):
        with pytest.raises(DataFormatError) as info:
            load(path)
        assert str(info.value) == older_message(path, minor)


def test_command_lines_refuse_a_format_3_table_in_one_line(small_table_path, tmp_path, capsys):
    path = format_3_copy(small_table_path, tmp_path, "old.h5")
    for main, argv in ((tablegen_main, ["info", str(path)]),
                       (surrogate_main, ["sample", "--table", str(path), "--alpha1", "45", "--speed", "100",
                                         "--shape", "prism", "-n", "10", "--out", str(tmp_path / "s.h5")])):
        line, out = user_error(main, argv, capsys)
        assert line.endswith(": error: " + older_message(path)), line
    another = edited_copy(small_table_path, tmp_path, "v5.h5",
                          lambda f: f.attrs.__setitem__("format_version", np.array([5, 0])))
    user_error(tablegen_main, ["info", str(another)], capsys, "format version 5.0 is not readable",
               "reads major version 4")


def test_info_config_rebuilds_a_format_3_table_bit_for_bit(rebuild_table, tmp_path, capsys):
    """tablegen info --config prints the stored configuration of a 3.x or 4.x table (reading nothing else: the
    cells may be gone); building it gives the same cells and the same table (fingerprint) as the original build."""
    old = format_3_copy(rebuild_table, tmp_path, "old.h5")

    def without_cells(f):
        del f["cells"]

    stripped = edited_copy(old, tmp_path, "no_cells.h5", without_cells)
    texts = []
    for path in (old, stripped, rebuild_table):
        code, err, out = run_cli(tablegen_main, ["info", "--config", str(path)], capsys)
        assert code == 0 and err == [], err
        texts.append(out)
    assert texts[0] == texts[1] == texts[2] == stored_config(rebuild_table)
    assert "[shapes.sand_b]" in texts[0] and "triangles = " in texts[0] and "mesh" not in texts[0]
    config = tmp_path / "TABLE.toml"
    config.write_text(texts[0])
    new = tmp_path / "NEW.h5"
    code, err, _ = run_cli(tablegen_main, ["build", "--config", str(config), "-o", str(new), "--workers", "1",
                                           "--no-progress"], capsys)
    assert code == 0, err
    with h5py.File(rebuild_table, "r") as a, h5py.File(new, "r") as b:
        for name in CELL_DATASETS:
            assert a["cells"][name][()].tobytes() == b["cells"][name][()].tobytes(), name
    assert table_fingerprint(new) == table_fingerprint(rebuild_table)
    assert read_table(new).wall == read_table(rebuild_table).wall == parse_config(REBUILD_CONFIG).wall


def test_info_config_refuses_what_is_not_a_table_of_format_3_or_4(small_table_path, tmp_path, capsys):
    v2 = edited_copy(small_table_path, tmp_path, "v2.h5", lambda f: f.attrs.__setitem__("format_version",
                                                                                       np.array([2, 1])))
    user_error(tablegen_main, ["info", "--config", str(v2)], capsys, "v2.h5", "reads major version 3 or 4")
    no_config = edited_copy(small_table_path, tmp_path, "no_config.h5", lambda f: f.attrs.__delitem__("config"))
    user_error(tablegen_main, ["info", "--config", str(no_config)], capsys, "no_config.h5",
               "stores no build configuration")


def test_the_wall_and_the_model_are_read_by_field_name(small_table_path, tmp_path):
    """The fields in another order and with a field this version does not know: the same table."""
    def reorder(f):
        for group in ("model", "wall"):
            row = f[group]["parameters"][()]
            names = list(reversed(row.dtype.names))
            turned = np.zeros(1, dtype=[("later", "<f8")] + [(n, row.dtype[n]) for n in names])
            for n in names:
                turned[n] = row[n]
            del f[group]["parameters"]
            f[group].create_dataset("parameters", data=turned, chunks=(1,), fletcher32=True)

    before = read_table(small_table_path)
    after = read_table(edited_copy(small_table_path, tmp_path, "reordered.h5", reorder))
    assert after.wall == before.wall and after.model_parameters() == before.model_parameters()


def test_a_bad_parameter_row_is_refused_naming_the_field_and_its_range(small_table_path, tmp_path):
    """Each fault of the rows (tests/helpers/bad_files.parameter_row_cases): DataFormatError naming the file, the
    dataset or attribute, the field and what is allowed; the C loader gives the same message
    (tests/native/test_native_format.py)."""
    for path, _, message in parameter_row_cases(small_table_path, tmp_path):
        with pytest.raises(DataFormatError) as info:
            read_table(path)
        assert str(info.value) == f"{path}: {message}", path.name
