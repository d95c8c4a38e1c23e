"""The fingerprint of a table (data_schema.table.table_fingerprint; docs/format.md, "Fingerprint"): it covers
every dataset and every attribute that decides the law, and nothing that says when or where it was built."""


import h5py
import numpy as np
import pytest

from data_schema.table import table_fingerprint
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
    """One element of every dataset (the shapes' records of format 3.4 too), one bit of every grid and resolution
    attribute, the root's recipe: each change gives another fingerprint."""
    with h5py.File(small_table_path, "r") as f:
        datasets = [f"{group}/{name}" for group in ("grid", "cells", "shapes") for name in f[group]]
        attributes = [(group, name) for group in ("grid", "resolution") for name in f[group].attrs]
    assert len(datasets) == 27 and "shapes/vertices" in datasets and ("grid", "kappa") in attributes and ("grid", "aspect_ratio_sd") in attributes
    seen = {fingerprint}

    def change_dataset(name):
        def edit(f):
            values = f[name][()]
            flat = values.reshape(-1)
            flat[-1] = flat[-1] + 1 if values.dtype.kind in "iuf" else b"prism"
            f[name][...] = values
        return edit

    def change_attribute(group, name):
        def edit(f):
            value = np.asarray(f[group].attrs[name])
            f[group].attrs[name] = "another" if value.dtype.kind in "OSU" else value + 1
        return edit

    edits = [change_dataset(name) for name in datasets] + [change_attribute(*pair) for pair in attributes]
    edits += [lambda f: f.attrs.__setitem__("master_seed", np.uint64(12)),
              lambda f: f.attrs.__setitem__("config", str(f.attrs["config"]) + "\n")]
    for i, edit in enumerate(edits):
        seen.add(table_fingerprint(edited_copy(small_table_path, tmp_path, f"edit_{i}.h5", edit)))
    assert len(seen) == len(edits) + 1
