"""A family entered in direct_model.registry.FAMILIES by the tests alone: the regular octahedron, to show that a
new built-in family is its registry entry and nothing else (tests/tabulation/test_family_entry.py,
tests/native/test_native_family_entry.py)."""

import contextlib

import numpy as np
import pytest

from direct_model.registry import FAMILIES, Family

# a table of the prism and the octahedron on a 2 × 2 grid, built in the test process (where the entry is)
OCTAHEDRON_TABLE_CONFIG = """
[grid]
alpha1_deg = [30.0, 70.0]
speed_m_s = [100.0, 200.0]
shapes = ["prism", "octahedron"]
[simulation]
particles_per_cell = 3000
seed = 45
"""


def _octahedron_body(kappa):
    """|ξ| + |η| + |ζ| ≤ 1: its six corners on the axes, its eight faces facing the cube's corners."""
    corners = np.array([[x, y, z] for x in (-1.0, 1.0) for y in (-1.0, 1.0) for z in (-1.0, 1.0)])
    return np.vstack([np.eye(3), -np.eye(3)]), corners


@contextlib.contextmanager
def octahedron_entered():
    """FAMILIES with the entry "octahedron" inside the block, as it was after."""
    with pytest.MonkeyPatch.context() as patch:
        patch.setitem(FAMILIES, "octahedron", Family(_octahedron_body))
        yield
