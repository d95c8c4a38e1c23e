"""The offline table build (docs/format.md).

config (TOML configuration and the embedded ``presets``), resolution (default table sizes), cells (one
cell: its seed and its direct-model run), tabulate (a cell's stored representation), driver
(:func:`tablegen.tabulation.driver.build_table`: workers, checkpoints, the HDF5 table) and info
(``tablegen info``).
"""
