"""Every name the native tests take from the Python packages, imported here and nowhere else.

When the packages move (surrogate's kernels into ``surrogate.kernels``, tablegen into subpackages),
only this module is re-pointed. The tests use the public API: ``surrogate.load`` and
``table.kernel_data``, ``surrogate.mix_cdf``, ``surrogate.seed_state``, ``surrogate.fill_uniforms``,
``surrogate.U_PER_DRAW``, the ``STATUS_*`` codes, ``surrogate.sample_local`` and the kernels
``table_rebound``, ``table_rebound_many``, ``table_rebound_many_rng``, ``table_rebound_uniforms``,
``draw_local``; the direct model's free flight from ``direct_model.rotation``, its run-time kernel
``direct_rebound`` and the kernels it calls (``direct_model``: collide, wall_work, body_vertices, the shape arrays and
particle_body, bounding_radius, normal_quantile, aspect_ratio, uniform_quaternion, quaternion_to_matrix,
rebound_model_frame), the wall records (``direct_model.wall``: WallMaterial, TabulatedWall and the node maxima) and
the sampler's restitution factor (``surrogate.kernels.fastmath.restitution_factor``), user grains (tests/helpers/grains.py); those of every
hit (``surrogate.kernels.wall_hit``: ``rebound``, ``rebound_path``, ``SPIN_TOLERANCE``, ``MAX_WALL_HITS``, the
METHOD_* and PATH_* codes), a rough wall's facets (``surrogate.kernels.facet``: ``facet_key``, ``facet_normal``;
``direct_model.wall.MAX_ROUGHNESS_DEG``); the law comparisons of tests/helpers/direct_law.py (its states, ``tablegen simulate`` and the
statistics); tables come from ``tablegen.build_table`` and ``tablegen.parse_config``;
file checks and the samples' angle conversion from ``data_schema``.
"""

import surrogate
from direct_model import runtime as direct_runtime     # the parameter layout (P_*, U_*, N_PARAMS)
from data_schema.samples import STATUS_FAILED, angles_to_velocity
from direct_model.rotation import ROT_PARAMS_SIZE, carlson_rf, carlson_rj, rotation_at, rotation_init
from surrogate import STATUS_INVALID, STATUS_REBOUNDED, STATUS_TRAPPED, U_PER_DRAW, fill_uniforms, grain_key, \
    grain_of, load, mix_cdf, seed_state
from surrogate.kernels import draw_local, table_rebound, table_rebound_many, table_rebound_many_rng, table_rebound_uniforms
from surrogate.kernels.direct_path import direct_rebound
from surrogate.kernels.locate import mix_shape
from data_schema.table import TABLE_VERSION
from direct_model.collision import collide, wall_work
from direct_model.wall import MAX_CONTACT_SINES, MAX_CONTACT_SPEEDS, MAX_ROUGHNESS_DEG, TabulatedWall, WallMaterial
from surrogate.kernels.fastmath import restitution_factor
from direct_model.body_rebound import quaternion_to_matrix
from direct_model.runtime import (SCRATCH_SIZE, U_PER_REBOUND, aspect_ratio, normal_quantile, rebound_model_frame,
                                  uniform_quaternion)
from direct_model.shape_arrays import bounding_radius, particle_body, shape_arrays
from direct_model.shapes import MAX_VERTICES, SHAPES, AspectRatioLaw, body_vertices
from tests.helpers.grains import cloud_grain, hull_grain
from surrogate.kernels.wall_hit import (MAX_WALL_HITS, METHOD_AUTO, METHOD_DIRECT, METHOD_TABLE, PATH_DIRECT,
                                        PATH_TABLE, SPIN_TOLERANCE, rebound, rebound_path)
from surrogate.kernels.facet import facet_key, facet_normal
from tests.helpers.direct_law import (A, N, STATES, assert_one_law, frame_of, incident, one_law, simulated, state_id,
                                      to_model_frame)


def build_table(config_text: str, path) -> None:
    """Build a table from TOML configuration text into ``path`` (tablegen)."""
    from tablegen import build_table as _build, parse_config
    _build(parse_config(config_text), path)


def check_table_file(path) -> None:
    """data_schema's check of a table file (raises for a file the sampler would refuse)."""
    from data_schema.table import read_table
    read_table(path)


def user_grains(count: int, seed: int = 34) -> list:
    """``count`` registry records of user grains: hulls of random point clouds (8 to 40 points, axes 1 : 0.45..1),
    named grain_00, grain_01, ...; every third with an aspect-ratio law, every fifth drawn in both hands."""
    import numpy as np
    from direct_model.shapes import AspectRatioLaw
    from tablegen.tabulation.grain_files import grain_from_points
    rng = np.random.default_rng(seed)
    records = []
    for k in range(count):
        points = rng.normal(size=(int(rng.integers(8, 41)), 3)) * np.sort(rng.uniform(0.45, 1.0, 3))[::-1]
        law = AspectRatioLaw(0.85, 0.1, 0.6, 1.0) if k % 3 == 0 else None
        records.append(grain_from_points(f"grain_{k:02d}", points, "test cloud", aspect=law, both_hands=k % 5 == 0))
    return records


def many_shape_table(source, path, n_shapes: int = 64) -> tuple:
    """A table of ``n_shapes`` shapes written to ``path`` from the table at ``source``: its own shapes
    first, then user grains (:func:`user_grains`) whose cells are copies of the source's, shape k drawing the
    cells of source shape k mod n_source (a synthetic table: the table path draws any cells). Returns the names."""
    import dataclasses
    import numpy as np
    from data_schema.table import read_table, write_table
    table = read_table(source)
    own = table.shape_records()[:n_shapes]
    records = tuple(own) + tuple(user_grains(n_shapes - len(own)))
    rows = np.arange(n_shapes) % len(own)
    cells = {name: np.ascontiguousarray(values[rows]) for name, values in table.cells.items()}
    write_table(path, dataclasses.replace(table, shapes=tuple(r.name for r in records), records=records, cells=cells))
    return tuple(r.name for r in records)


def write_samples_file(path) -> None:
    """A small raw-samples file (another file type) at ``path``."""
    import numpy as np
    from data_schema.samples import SampleSet, write_samples
    n = 4
    write_samples(path, SampleSet(velocity=np.ones((n, 3)), omega=np.zeros((n, 3)),
                                  n_collisions=np.ones(n, dtype=np.int32), status=np.zeros(n, dtype=np.int8),
                                  alpha1=45.0, speed=100.0, shape="prism", seed=1, producer="tests/native"))


__all__ = ["angles_to_velocity", "ROT_PARAMS_SIZE", "carlson_rf", "carlson_rj", "rotation_at", "rotation_init",
           "STATUS_INVALID", "STATUS_REBOUNDED", "STATUS_TRAPPED", "U_PER_DRAW", "build_table", "check_table_file",
           "many_shape_table", "user_grains",
           "draw_local", "fill_uniforms", "load", "mix_cdf", "table_rebound_many", "table_rebound_many_rng",
           "table_rebound", "table_rebound_uniforms", "seed_state", "surrogate", "write_samples_file",
           "MAX_VERTICES", "STATUS_FAILED", "U_PER_REBOUND", "aspect_ratio", "body_vertices", "bounding_radius",
           "SCRATCH_SIZE", "AspectRatioLaw", "cloud_grain", "hull_grain", "particle_body", "rebound_model_frame",
           "shape_arrays",
           "collide", "wall_work", "normal_quantile", "quaternion_to_matrix", "direct_rebound", "uniform_quaternion",
           "A", "N", "SHAPES", "STATES", "assert_one_law", "frame_of", "incident", "one_law", "simulated", "state_id",
           "to_model_frame", "METHOD_AUTO", "METHOD_DIRECT", "METHOD_TABLE", "PATH_DIRECT", "PATH_TABLE",
           "SPIN_TOLERANCE", "rebound_path", "rebound", "mix_shape", "TABLE_VERSION", "MAX_ROUGHNESS_DEG",
           "MAX_WALL_HITS", "facet_key", "facet_normal"]
