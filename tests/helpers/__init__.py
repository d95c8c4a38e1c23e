"""Helpers shared by the tests, imported the same way everywhere: ``from tests.helpers.<module> import ...``.

pytest puts the repository's root on ``sys.path`` (``pythonpath`` in pyproject's ``[tool.pytest.ini_options]``),
so ``tests`` is this checkout's package from any folder and without PYTHONPATH. A subprocess that needs a
helper runs it as a module from the root, ``[sys.executable, "-m", "tests.helpers.<module>", ...]`` with
``cwd=REPO``: ``-m`` puts the working folder first on the child's path, and nothing else is needed.
"""

from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
"""The repository's root: the working folder of every subprocess that imports ``tests``."""
