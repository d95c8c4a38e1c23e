"""The rebound-scatter Python API as the code_saturne integration uses it.

Every import of the project's packages by integrations/code_saturne and
tests/code_saturne goes through this module, so a refactoring of the packages
re-points these few lines only. Public API only: ``surrogate.load``,
``surrogate.sample_global``, ``surrogate.STATUS_*`` and, to build a table,
``tablegen.build_table(tablegen.parse_config(text), path)``.

Copyright (C) 2026 the rebound-scatter authors. License: GPL-2.0-or-later
(see LICENSE in this folder).
"""

from surrogate import STATUS_FAILED, STATUS_INVALID, STATUS_REBOUNDED, STATUS_TRAPPED, load, sample_global

__all__ = ["STATUS_FAILED", "STATUS_INVALID", "STATUS_REBOUNDED", "STATUS_TRAPPED", "build_table_from_text", "load",
           "sample_global"]


def build_table_from_text(config_text: str, path, **kwargs):
    """Build the table a TOML configuration describes into ``path`` (tablegen's build)."""
    from tablegen import build_table, parse_config
    return build_table(parse_config(config_text), path, **kwargs)
