"""The fingerprint of a table (data_schema.table.table_fingerprint; docs/format.md, "Fingerprint"): it covers
every dataset and every attribute that decides the law, and nothing that says when or where it was built."""


import h5py
import numpy as np
import pytest

from data_schema.table import read_table, table_fingerprint
from tests.helpers.tables import edited_copy


@pytest.fixture(scope="module")
def fingerprint(small_table_path):
    return table_fingerprint(small_table_path)


def test_build_time_host_and_descriptions_do_not_enter(small_table_path, fingerprint, tmp_path):
    def provenance(f):
        f.attrs["created"] = "1999-01-01T00:00:00+00:00"
        f.attrs["package_version"] = "9.9.9"
        f.attrs["model_sha256"] = "0" * 64
        f["cells/mean"].attrs["meaning"] = "another description"

    assert table_fingerprint(edited_copy(small_table_path, tmp_path, "provenance.h5", provenance)) == fingerprint


def test_every_dataset_and_law_attribute_enters(small_table_path, fingerprint, tmp_path):
    """One element of every dataset (the shapes' records too), every field of the parameter rows of groups model
    and wall, one bit of every grid, resolution and wall attribute, the root's recipe: each change gives another
    fingerprint."""
    with h5py.File(small_table_path, "r") as f:
        datasets = [f"{group}/{name}" for group in ("grid", "cells", "shapes") for name in f[group]]
        fields = [(f"{group}/parameters", name) for group in ("model", "wall")
                  for name in f[group]["parameters"].dtype.names]
        attributes = [(group, name) for group in ("grid", "resolution", "wall") for name in f[group].attrs]
    assert len(datasets) == 34 and "shapes/vertices" in datasets and "grid/shape_codes" in datasets
    assert "cells/work_slope" in datasets and "cells/trapped_work" in datasets
    assert len(fields) == 14 and ("model/parameters", "aspect_ratio_sd") in fields and ("wall/parameters", "q") in fields
    assert ("wall/parameters", "speed_range_m_s") in fields
    assert ("wall", "family") in attributes and ("wall", "name") in attributes and ("grid", "particles_per_cell") in attributes
    seen = {fingerprint}

    def change_dataset(name):
        def edit(f):
            values = f[name][()]
            flat = values.reshape(-1)
            flat[-1] = flat[-1] + 1 if values.dtype.kind in "iuf" else b"prism"
            f[name][...] = values
        return edit

    def change_field(name, field):
        def edit(f):
            values = f[name][()]
            values[field] = values[field] * 0.5 + 1
            f[name][...] = values
        return edit

    def change_attribute(group, name):
        def edit(f):
            value = np.asarray(f[group].attrs[name])
            f[group].attrs[name] = "another" if value.dtype.kind in "OSU" else value + 1
        return edit

    edits = [change_dataset(name) for name in datasets] + [change_field(*pair) for pair in fields]
    edits += [change_attribute(*pair) for pair in attributes]
    edits += [lambda f: f.attrs.__setitem__("master_seed", np.uint64(12)),
              lambda f: f.attrs.__setitem__("config", str(f.attrs["config"]) + "\n")]
    for i, edit in enumerate(edits):
        seen.add(table_fingerprint(edited_copy(small_table_path, tmp_path, f"edit_{i}.h5", edit)))
    assert len(seen) == len(edits) + 1


def test_the_fields_order_in_a_parameter_row_does_not_enter(small_table_path, fingerprint, tmp_path):
    """The parameter rows are read by field name: the same values in another field order give the same table and
    the same fingerprint."""
    def reorder(f):
        for group in ("model", "wall"):
            row = f[group]["parameters"][()]
            names = list(reversed(row.dtype.names))
            turned = np.zeros(1, dtype=[(n, row.dtype[n]) for n in names])
            for n in names:
                turned[n] = row[n]
            del f[group]["parameters"]
            f[group].create_dataset("parameters", data=turned, chunks=(1,), fletcher32=True)

    path = edited_copy(small_table_path, tmp_path, "reordered.h5", reorder)
    assert table_fingerprint(path) == fingerprint
    before, after = read_table(small_table_path), read_table(path)
    assert after.wall == before.wall and after.model_parameters() == before.model_parameters()
