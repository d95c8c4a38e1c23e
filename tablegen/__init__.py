"""tablegen: the direct rebound model and the offline table build.

Subpackages, one per job:

* :mod:`tablegen.model` — the direct model (shapes, wall law, collision, rotation, flight, :func:`simulate`);
* :mod:`tablegen.tabulation` — the table build (configuration, presets, cells, tabulation, :func:`build_table`);
* :mod:`tablegen.study` — statistics, the paper's study (``tablegen report``) and the validation matrix.

The public API is importable from here::

    from tablegen import simulate, build_table, load_config, parse_config, WallMaterial
"""

from importlib import import_module

# name: module defining it; imported on first use, so `import tablegen` stays light (no numba, no scikit-learn)
_API = {
    "simulate": "tablegen.model.simulate",
    "SHAPES": "tablegen.model.shapes",
    "MIX": "tablegen.model.shapes",
    "AspectRatioLaw": "tablegen.model.shapes",
    "WallMaterial": "tablegen.model.wall",
    "CORUNDUM_ON_STEEL": "tablegen.model.wall",
    "BuildConfig": "tablegen.tabulation.config",
    "ConfigError": "tablegen.tabulation.config",
    "load_config": "tablegen.tabulation.config",
    "parse_config": "tablegen.tabulation.config",
    "build_table": "tablegen.tabulation.driver",
    "summarize": "tablegen.study.statistics",
}
__all__ = sorted(_API)


def __getattr__(name):
    if name not in _API:
        raise AttributeError(f"module 'tablegen' has no attribute {name!r}")
    return getattr(import_module(_API[name]), name)


def __dir__():
    return sorted(set(globals()) | set(_API))
