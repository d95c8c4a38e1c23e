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
