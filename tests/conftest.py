"""Shared fixtures: small tables built once per test session (2e4 particles per cell, all four shapes)."""

import pytest

from tablegen import build_table, parse_config


def _table_config(alpha1_deg, speed_m_s, seed):
    return (f"[grid]\nalpha1_deg = {list(alpha1_deg)}\nspeed_m_s = {list(speed_m_s)}\n"
            f"[simulation]\nparticles_per_cell = 20000\nseed = {seed}\n")


def _build(tmp_path_factory, name, config_text):
    path = tmp_path_factory.mktemp("tables") / f"{name}.h5"
    build_table(parse_config(config_text), path)
    return path


SMALL_TABLE_CONFIG = _table_config([30.0, 60.0, 90.0], [50.0, 150.0, 250.0], seed=11)
# grid points around (1.25°, 175 m/s), (3.5°, 175 m/s) and (42.5°, 175 m/s), with the default preset's
# α1 steps there
OFF_GRID_TABLE_CONFIG = _table_config([1.0, 1.5, 2.0, 3.0, 4.0, 40.0, 45.0], [150.0, 200.0], seed=12)
# the presets' α1 step near grazing before 1.5° was added: (1.5°, 175 m/s) between grid points
WIDE_GRAZING_TABLE_CONFIG = _table_config([1.0, 2.0], [150.0, 200.0], seed=14)
# grid points around NEAR_NORMAL_POINT (α1 deg, |V⁻| m/s): near normal impact at low speed, where
# the law moves fastest with speed (the presets' steps there)
NEAR_NORMAL_POINT = (84.375, 62.5)
NEAR_NORMAL_TABLE_CONFIG = _table_config([83.75, 85.0], [50.0, 75.0], seed=13)


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
