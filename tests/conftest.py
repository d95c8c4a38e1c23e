"""Shared fixtures: a small table built once per test session."""

import pytest

from tablegen.build import build_table
from tablegen.config import parse_config

SMALL_TABLE_CONFIG = """
[grid]
alpha1_deg = [30.0, 60.0, 90.0]
speed_m_s = [50.0, 150.0, 250.0]
[simulation]
particles_per_cell = 20000
seed = 11
"""


@pytest.fixture(scope="session")
def small_table_path(tmp_path_factory):
    """A table of all four shapes on a 3 × 3 grid, 2e4 particles per cell."""
    path = tmp_path_factory.mktemp("tables") / "small.h5"
    build_table(parse_config(SMALL_TABLE_CONFIG), path)
    return path


@pytest.fixture(scope="session")
def small_table(small_table_path):
    import surrogate
    return surrogate.load(small_table_path)


OFF_GRID_TABLE_CONFIG = """
[grid]
alpha1_deg = [3.0, 4.0, 40.0, 45.0]
speed_m_s = [150.0, 200.0]
[simulation]
particles_per_cell = 20000
seed = 12
"""


@pytest.fixture(scope="session")
def off_grid_table(tmp_path_factory):
    """Grid points around (3.5°, 175 m/s) and (42.5°, 175 m/s), with the default preset's α1 steps there."""
    import surrogate
    path = tmp_path_factory.mktemp("tables") / "off_grid.h5"
    build_table(parse_config(OFF_GRID_TABLE_CONFIG), path)
    return surrogate.load(path)
