"""Table format 4 in the C loader as in data_schema (docs/format.md, "Identification and versions", "The
parameter rows"): a table of format 3 refused with RBS_ERR_VERSION and Python's message, word for word; the rows
/wall/parameters and /model/parameters read by field name, every fault of them (a field missing, an unknown wall
law family, a parameter out of its range, ...) refused with RBS_ERR_FORMAT and Python's message, word for word;
rbs_table_wall reporting the wall as read."""

from __future__ import annotations

import h5py
import numpy as np
import pytest

from tests.helpers import python_side as py
from tests.helpers.bad_files import parameter_row_cases
from tests.helpers.native_library import ERR_FORMAT, ERR_VERSION, OK
from tests.helpers.tables import edited_copy, format_3_copy


def _python_message(path) -> str:
    with pytest.raises(ValueError) as info:
        py.load(path)
    return str(info.value)


def _one_verdict(native, path, expected):
    """The C code ``expected`` and Python's message, word for word; the message."""
    code, table, message = native.open(path)
    assert code == expected and table is None, (path.name, code, message)
    assert message == _python_message(path), path.name
    return message


@pytest.mark.parametrize("minor", [4, 3, 0])
def test_a_format_3_table_is_refused_by_both_with_how_to_rebuild_it(native, small_table_path, tmp_path, minor):
    """The 3.4 layout (what rebound-scatter before 1.0 wrote), and any 3.x: RBS_ERR_VERSION, one message."""
    old = format_3_copy(small_table_path, tmp_path, f"old_3_{minor}.h5", minor)
    message = _one_verdict(native, old, ERR_VERSION)
    assert message == (f"{old}: table format 3.{minor} was written before rebound-scatter 1.0, which reads format 4; "
                       f"rebuild it from the configuration it stores: tablegen info --config {old} > TABLE.toml && "
                       f"tablegen build --config TABLE.toml -o NEW.h5")


def test_another_major_version_is_refused_by_both(native, small_table_path, tmp_path):
    for major in (2, 5):
        path = edited_copy(small_table_path, tmp_path, f"v{major}.h5",
                           lambda f: f.attrs.__setitem__("format_version", np.array([major, 0])))
        code, table, message = native.open(path)
        assert code == ERR_VERSION and table is None and f"format version {major}.0" in message, message
        assert f"format version {major}.0 is not readable" in _python_message(path)


def test_a_bad_parameter_row_gets_one_verdict_word_for_word(native, small_table_path, tmp_path):
    """A field of the wall's row missing, an unknown family, p <= 0 (and the other faults of
    tests/helpers/bad_files.parameter_row_cases): RBS_ERR_FORMAT and the same message from both loaders."""
    cases = parameter_row_cases(small_table_path, tmp_path)
    names = {path.stem for path, _, _ in cases}
    assert {"row_no_q", "row_unknown_family", "row_p_zero", "row_p_negative", "row_no_kappa"} <= names
    for path, expected, message in cases:
        assert expected == ERR_FORMAT
        assert _one_verdict(native, path, ERR_FORMAT) == f"{path}: {message}"


def test_rbs_table_wall_reports_the_wall_as_read(native, small_table_path, tmp_path):
    """Another wall (name, q) in a row of another field order with a field this version does not know: both loaders
    read it by name; rbs_table_wall gives the family, the name and the parameters in the family's order, the bits
    Python read; the derived restitution arrays and direct parameters are Python's, bit for bit."""
    def other_wall(f):
        row = f["wall/parameters"][()]
        turned = np.zeros(1, dtype=[("q", "<f8"), ("later", "<i4"), ("speed_range_m_s", "<i4", (2,)), ("p", "<f4"),
                                    ("k", "<f8")])
        turned["q"], turned["p"], turned["k"], turned["speed_range_m_s"] = 0.45, 0.5, row["k"], (2, 30)
        del f["wall/parameters"]
        f["wall"].create_dataset("parameters", data=turned, chunks=(1,), fletcher32=True)
        f["wall"].attrs["name"] = "glass_on_steel"

    path = edited_copy(small_table_path, tmp_path, "other_wall.h5", other_wall)
    python = py.load(path)
    assert python.wall.name == "glass_on_steel" and python.wall.parameters() == {"k": 0.1, "p": 0.5, "q": 0.45}
    assert python.wall.speed_range_m_s == (2.0, 30.0)
    code, table, message = native.open(path)
    assert code == OK, message
    try:
        wall = table.wall()
        assert (wall["family"], wall["name"], wall["n_parameters"]) == ("exponential", "glass_on_steel", 3)
        assert list(wall["parameters"]) == ["k", "p", "q"] and wall["speed_range_m_s"] == (2.0, 30.0)
        assert np.array(list(wall["parameters"].values())).tobytes() == \
            np.array(list(python.wall.parameters().values())).tobytes()
        for name in ("speed_restitution", "restitution_pieces"):
            assert table.kernel_array(name).tobytes() == getattr(python.kernel_data, name).tobytes(), name
        assert table.kernel_array("direct_parameters").tobytes() == python.direct_parameters.tobytes()
    finally:
        table.close()


def test_a_corrupt_parameter_row_fails_its_checksum_in_both(native, small_table_path, tmp_path):
    """A flipped byte of a row's stored chunk: its Fletcher-32 fails, both loaders name the dataset."""
    for name in ("wall/parameters", "model/parameters"):
        path = edited_copy(small_table_path, tmp_path, f"corrupt_{name.replace('/', '_')}.h5")
        with h5py.File(path, "r") as f:
            info = f[name].id.get_chunk_info(0)
        with open(path, "r+b") as f:
            f.seek(info.byte_offset + 2)
            byte = f.read(1)
            f.seek(info.byte_offset + 2)
            f.write(bytes([byte[0] ^ 0x10]))
        code, table, message = native.open(path)
        assert code == ERR_FORMAT and table is None and name in message, message
        assert name in _python_message(path)
