"""The example scripts (examples/) as modules, for their tests: loaded from their file as when run as a script."""

import importlib.util
import sys
from pathlib import Path

from tests.helpers import REPO

EXAMPLES = REPO / "examples"


def example_module(path: Path):
    """The module of the script ``path``, its folder first on ``sys.path`` while it loads (as when run: a helper
    module beside it imports)."""
    sys.path.insert(0, str(path.parent))
    try:
        spec = importlib.util.spec_from_file_location(path.stem, path)
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
    finally:
        sys.path.remove(str(path.parent))
    return module
