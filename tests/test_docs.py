"""The prose format description stays in step with data_schema."""

from pathlib import Path

import pytest

from data_schema import samples

FORMAT_DOC = (Path(__file__).resolve().parents[1] / "docs" / "format.md").read_text()
NAMES = ([samples.SAMPLES_FILE_TYPE, "file_type", "format_version", "samples"]
         + list(samples.REQUIRED_DATASETS) + list(samples.OPTIONAL_DATASETS) + list(samples.REQUIRED_ATTRS))


@pytest.mark.parametrize("name", NAMES)
def test_every_schema_name_is_documented(name):
    assert f"`{name}`" in FORMAT_DOC, f"docs/format.md does not describe `{name}`"


def test_documented_version_matches_code():
    major, minor = samples.SAMPLES_VERSION
    assert f"({major}, {minor})" in FORMAT_DOC
