"""The configurations of the small tables the session builds once (tests/conftest.py): 2e4 particles per cell,
all four shapes; and edited copies of a table."""

import shutil

import h5py


def edited_copy(source, folder, name, edit=None):
    """A copy of the table file ``source`` as ``folder/name``, opened for writing and passed to ``edit(f)``."""
    path = folder / name
    shutil.copyfile(source, path)
    if edit is not None:
        with h5py.File(path, "r+") as f:
            edit(f)
    return path


def _table_config(alpha1_deg, speed_m_s, seed):
    return (f"[grid]\nalpha1_deg = {list(alpha1_deg)}\nspeed_m_s = {list(speed_m_s)}\n"
            f"[simulation]\nparticles_per_cell = 20000\nseed = {seed}\n")


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
