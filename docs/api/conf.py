"""Sphinx configuration of the API reference, built from the docstrings of the public Python API.

    python -m sphinx -W -b html docs/api docs/api/_build     (tests/test_api_docs.py runs it)

Each page documents a package by its ``__all__`` (automodule), so a function renamed or added there is
documented without editing these pages.
"""

import re

project = "rebound-scatter"
author = "the rebound-scatter authors"
copyright = "2026, the rebound-scatter authors"
extensions = ["sphinx.ext.autodoc", "numpydoc"]
exclude_patterns = ["_build"]
html_theme = "alabaster"
autodoc_default_options = {"members": True, "undoc-members": True, "member-order": "bysource"}
autodoc_typehints = "none"           # the docstrings state types with their units and frames
numpydoc_show_class_members = False  # autodoc lists the members already
numpydoc_validation_checks = set()   # the docstrings are prose in numpydoc sections, not a checklist
suppress_warnings = ["ref.python"]   # the same name exported by two packages (surrogate.U_PER_DRAW and its kernels')

_LITERAL = re.compile(r"(``.*?``)")


def _bars_as_text(app, what, name, obj, options, lines):
    """The docstrings write magnitudes as |V⁻|, which reStructuredText reads as a substitution: escape the
    bars outside inline literals."""
    for i, line in enumerate(lines):
        lines[i] = "".join(part if part.startswith("``") else part.replace("|", r"\|")
                           for part in _LITERAL.split(line))


def setup(app):
    app.connect("autodoc-process-docstring", _bars_as_text, priority=400)
