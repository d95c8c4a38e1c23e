"""The offline table build (docs/format.md).

config (TOML configuration and the embedded ``presets``), resolution (default table sizes), cells (one
cell: its seed and its direct-model run), tabulate (a cell's stored representation), driver
(:func:`tablegen.build.driver.build_table`: workers, checkpoints, the HDF5 table) and info
(``tablegen info``).
"""

from importlib import import_module

# name: module defining it; imported on first use, so reading a configuration needs no scikit-learn
_API = {
    "BuildConfig": "tablegen.build.config",
    "ConfigError": "tablegen.build.config",
    "load_config": "tablegen.build.config",
    "parse_config": "tablegen.build.config",
    "build_table": "tablegen.build.driver",
    "BuildError": "tablegen.build.driver",
    "CheckpointError": "tablegen.build.driver",
    "compute_cell": "tablegen.build.cells",
}
__all__ = sorted(_API)


def __getattr__(name):
    if name not in _API:
        raise AttributeError(f"module 'tablegen.build' has no attribute {name!r}")
    return getattr(import_module(_API[name]), name)
