"""A family entered in direct_model.registry.FAMILIES by the tests alone: the regular octahedron, to show that a
new built-in family is its registry entry and nothing else (tests/tabulation/test_family_entry.py,
tests/native/test_native_family_entry.py)."""

import contextlib

import numpy as np
import pytest

from direct_model.registry import FAMILIES, Family

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
