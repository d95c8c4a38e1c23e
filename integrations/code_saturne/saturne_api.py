"""The rebound-scatter Python API as the code_saturne integration uses it.

Every import of the project's packages by integrations/code_saturne and
tests/code_saturne goes through this module, so a refactoring of the packages
re-points these few lines only. Public API only: ``surrogate.load``, ``surrogate.STATUS_*``, the
solver-neutral comparison of a solver's hits with surrogate (``tablegen.study.solver_comparison``, BSD-3:
the statistics live there), the hit records' reader (``tablegen.study.hit_records``, BSD-3: the layout both
adapters write; this integration only finds code_saturne's files) and, to build a table,
``tablegen.build_table(tablegen.parse_config(text), path)``, and the names of a table's work datasets
(``data_schema.table.WORK_DATASETS``) to write a table as format 4.0 did.

Copyright (C) 2026 the rebound-scatter authors. License: GPL-2.0-or-later
(see LICENSE in this folder).
"""

import shutil

import h5py
import numpy as np

from data_schema.table import WORK_DATASETS
from surrogate import STATUS_FAILED, STATUS_INVALID, STATUS_REBOUNDED, STATUS_TRAPPED, load
from surrogate.kernels import PATH_DIRECT, PATH_TABLE
from tablegen.study.hit_records import grain_mismatches, rank_files, read_hit_files, solver_hits, summary_counts
from tablegen.study.solver_comparison import compare_hits, path_rule

__all__ = ["PATH_DIRECT", "PATH_TABLE", "STATUS_FAILED", "STATUS_INVALID", "STATUS_REBOUNDED", "STATUS_TRAPPED",
           "build_table_from_text", "compare_hits", "grain_mismatches", "load", "path_rule", "rank_files",
           "read_hit_files", "solver_hits", "summary_counts", "table_without_work"]


def build_table_from_text(config_text: str, path, **kwargs):
    """Build the table a TOML configuration describes into ``path`` (tablegen's build)."""
    from tablegen import build_table, parse_config
    return build_table(parse_config(config_text), path, **kwargs)


def table_without_work(table, path):
    """A copy of the table file ``table`` at ``path`` as format 4.0 wrote it: no work datasets, format_version
    (4, 0) (its table path's draws carry no work on the wall: NaN)."""
    shutil.copyfile(table, path)
    with h5py.File(path, "r+") as f:
        for name in WORK_DATASETS:
            del f["cells"][name]
        f.attrs["format_version"] = np.array((4, 0), dtype=np.int64)
    return path
