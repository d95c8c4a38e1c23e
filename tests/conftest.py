"""Shared fixtures: small tables built once per test session (2e4 particles per cell, all four shapes)."""

import pytest

from tablegen import build_table, parse_config
from tests.helpers.tables import (NEAR_NORMAL_TABLE_CONFIG, OFF_GRID_TABLE_CONFIG, SMALL_TABLE_CONFIG,
                                  WIDE_GRAZING_TABLE_CONFIG)


def _build(tmp_path_factory, name, config_text):
    path = tmp_path_factory.mktemp("tables") / f"{name}.h5"
    build_table(parse_config(config_text), path)
    return path


@pytest.fixture(scope="session")
def small_table_path(tmp_path_factory):
    """A table on a 3 × 3 grid."""
    return _build(tmp_path_factory, "small", SMALL_TABLE_CONFIG)


@pytest.fixture(scope="session")
def small_table(small_table_path):
    import surrogate
    return surrogate.load(small_table_path)


@pytest.fixture(scope="session")
def off_grid_table(tmp_path_factory):
    """A table for comparisons between grid points (see OFF_GRID_TABLE_CONFIG)."""
    import surrogate
    return surrogate.load(_build(tmp_path_factory, "off_grid", OFF_GRID_TABLE_CONFIG))


@pytest.fixture(scope="session")
def wide_grazing_table(tmp_path_factory):
    """A table with 1–2° as one α1 interval (see WIDE_GRAZING_TABLE_CONFIG)."""
    import surrogate
    return surrogate.load(_build(tmp_path_factory, "wide_grazing", WIDE_GRAZING_TABLE_CONFIG))


@pytest.fixture(scope="session")
def near_normal_table(tmp_path_factory):
    """A table for comparisons between grid speeds near normal impact (see NEAR_NORMAL_TABLE_CONFIG)."""
    import surrogate
    return surrogate.load(_build(tmp_path_factory, "near_normal", NEAR_NORMAL_TABLE_CONFIG))
