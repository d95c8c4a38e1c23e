"""The rebound-scatter Python API as the code_saturne integration uses it.

Every import of the project's packages by integrations/code_saturne and
tests/code_saturne goes through this module, so a refactoring of the packages
re-points these few lines only. Public API only: ``surrogate.load``, ``surrogate.STATUS_*``, the
solver-neutral comparison of a solver's hits with surrogate (``tablegen.study.solver_comparison``, BSD-3:
the statistics live there), the hit records' reader (``tablegen.study.hit_records``, BSD-3: the layout both
adapters write; this integration only finds code_saturne's files) and, to build a table,
``tablegen.build_table(tablegen.parse_config(text), path)``.

Copyright (C) 2026 the rebound-scatter authors. License: GPL-2.0-or-later
(see LICENSE in this folder).
"""

from surrogate import STATUS_FAILED, STATUS_INVALID, STATUS_REBOUNDED, STATUS_TRAPPED, load
from surrogate.kernels import PATH_DIRECT, PATH_TABLE
from tablegen.study.hit_records import grain_mismatches, rank_files, read_hit_files, solver_hits, summary_counts
from tablegen.study.solver_comparison import compare_hits, path_rule

__all__ = ["PATH_DIRECT", "PATH_TABLE", "STATUS_FAILED", "STATUS_INVALID", "STATUS_REBOUNDED", "STATUS_TRAPPED",
           "build_table_from_text", "compare_hits", "grain_mismatches", "load", "path_rule", "rank_files",
           "read_hit_files", "solver_hits", "summary_counts"]


def build_table_from_text(config_text: str, path, **kwargs):
    """Build the table a TOML configuration describes into ``path`` (tablegen's build)."""
    from tablegen import build_table, parse_config
    return build_table(parse_config(config_text), path, **kwargs)
