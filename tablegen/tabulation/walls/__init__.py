"""The wall presets: each ``NAME.toml`` is a ``[wall]`` section that a build configuration names with
``[wall] preset = "NAME"`` (tablegen.tabulation.config), with its source in its comment lines; a preset fitted by
``tablegen calibrate`` has the data it was fitted to beside it as ``NAME.csv`` (docs/model.md §4.8)."""
