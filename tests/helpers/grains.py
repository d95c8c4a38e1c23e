"""User grains for the tests, made reproducibly: hulls of random point clouds (tablegen's hull, the registry's
canonical frame)."""

import numpy as np

from direct_model.registry import grain
from tablegen.tabulation.grain_files import convex_hull

PROPORTIONS = (1.0, 0.7, 0.5)      # the clouds' spread along three axes: an irregular, flattened grain
# the hull limit the tests of a refusal lower direct_model.registry.MAX_HULL_VERTICES to: small hulls, quick (the
# real limit, 65536, is checked in tests/native/test_native_shapes.py, where both loaders refuse one vertex more)
LOWERED_HULL_LIMIT = 300


def cloud_grain(name, n_points, seed, aspect=None, both_hands=False):
    """The canonical record of the hull of a Gaussian cloud of ``n_points`` (spread :data:`PROPORTIONS`)."""
    rng = np.random.default_rng(seed)
    vertices, triangles, _ = convex_hull(rng.normal(size=(n_points, 3)) * PROPORTIONS, name)
    return grain(name, vertices, triangles, aspect=aspect, both_hands=both_hands)


def hull_grain(name, n_vertices, seed, aspect=None, both_hands=False):
    """A grain of exactly ``n_vertices`` hull vertices: random points on the ellipsoid of semi-axes
    :data:`PROPORTIONS`, every one a vertex."""
    rng = np.random.default_rng(seed)
    points = rng.normal(size=(n_vertices, 3))
    points /= np.linalg.norm(points, axis=1)[:, None]
    vertices, triangles, _ = convex_hull(points * PROPORTIONS, name)
    assert len(vertices) == n_vertices
    return grain(name, vertices, triangles, aspect=aspect, both_hands=both_hands)
