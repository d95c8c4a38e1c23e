"""The prose format description stays in step with data_schema."""

import dataclasses
import re
from pathlib import Path

import pytest

from data_schema import samples, table
from direct_model.wall import WALL_FAMILIES
from tablegen.tabulation.config import CONFIG_KEYS

FORMAT_DOC = (Path(__file__).resolve().parents[1] / "docs" / "format.md").read_text()
NAMES = ([samples.SAMPLES_FILE_TYPE, "file_type", "format_version", "samples"]
         + list(samples.REQUIRED_DATASETS) + list(samples.OPTIONAL_DATASETS) + list(samples.REQUIRED_ATTRS)
         + [table.TABLE_FILE_TYPE, "created", "package_version", "config", "config_sha256", "master_seed",
            "grid/alpha1_deg", "grid/speed_m_s", "grid/shapes", "grid/shape_codes", "particles_per_cell",
            "model/parameters", "wall/parameters", "family", "name"]
         + list(table.MODEL_FIELDS) + list(WALL_FAMILIES) + [p.name for f in WALL_FAMILIES.values() for p in f.parameters]
         + [f.name for f in dataclasses.fields(table.TableResolution)]
         + list(table.CELL_DATASETS))


@pytest.mark.parametrize("name", NAMES)
def test_every_schema_name_is_documented(name):
    assert f"`{name}`" in FORMAT_DOC, f"docs/format.md does not describe `{name}`"


@pytest.mark.parametrize("version", [samples.SAMPLES_VERSION, table.TABLE_VERSION])
def test_documented_version_matches_code(version):
    assert f"({version[0]}, {version[1]})" in FORMAT_DOC


def test_config_keys_are_documented():
    for section, keys in CONFIG_KEYS.items():
        for key in keys:
            assert f"`{section}.{key}`" in FORMAT_DOC, f"{section}.{key}"


DOCS = sorted([Path(__file__).resolve().parents[1] / "README.md", Path(__file__).resolve().parents[1] / "examples"
               / "README.md"] + list((Path(__file__).resolve().parents[1] / "docs").rglob("*.md")))


@pytest.mark.parametrize("path", DOCS, ids=lambda p: p.name)
def test_docs_carry_no_dates_or_local_paths(path):
    """Docs are records, not a notebook: no day of a run, no path of one machine."""
    text = path.read_text()
    assert not re.findall(r"\b20\d\d-[01]\d-[0-3]\d\b", text), "a date"
    assert not re.findall(r"(?<![\w.])/(?:tmp|home|work|root|Users)/", text), "a local path"
