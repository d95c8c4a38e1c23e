"""tablegen: the offline table build and the study, on the direct rebound model (:mod:`direct_model`).

Subpackages, one per job (the model itself is the top-level package :mod:`direct_model`, which imports
nothing from here, so that :mod:`surrogate` can run it too):

* :mod:`tablegen.tabulation` — the table build (configuration, presets, cells, tabulation, :func:`build_table`);
* :mod:`tablegen.study` — statistics, the paper's study (``tablegen report``) and the validation matrix.

The public API is importable from here::

    from tablegen import simulate, build_table, load_config, parse_config, WallMaterial

(``simulate`` is :func:`direct_model.simulate.simulate` with a progress bar: ``progress=True``.)

It needs the ``build`` extra (``pip install "rebound-scatter[build]"``); the
plain install is the runtime sampler alone (:mod:`surrogate`).
"""

from importlib import import_module
from importlib.util import find_spec

# the distributions of the build extra (pyproject.toml), by the module each installs
BUILD_EXTRA = {"scipy": "scipy", "sklearn": "scikit-learn", "threadpoolctl": "threadpoolctl", "tqdm": "tqdm",
               "trimesh": "trimesh", "fast_simplification": "fast-simplification"}


def _require_build_extra() -> None:
    """ImportError naming what to install when a distribution of the build extra is missing."""
    missing = [name for module, name in BUILD_EXTRA.items() if find_spec(module) is None]
    if missing:
        raise ImportError(f"tablegen needs {', '.join(missing)}, which the plain install of rebound-scatter leaves "
                          f"out (it is the runtime sampler alone); install them with: "
                          f'pip install "rebound-scatter[build]"')


_require_build_extra()

# name: module defining it; imported on first use, so `import tablegen` stays light (no numba, no scikit-learn)
_API = {
    "simulate": "tablegen.progress",
    "SHAPES": "direct_model.shapes",
    "MIX": "direct_model.shapes",
    "AspectRatioLaw": "direct_model.shapes",
    "WallMaterial": "direct_model.wall",
    "CORUNDUM_ON_STEEL": "direct_model.wall",
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
