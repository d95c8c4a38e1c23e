"""One cell of a table: its seed, its direct-model run and its stored representation.

Each cell is an independent task whose seed derives from (master seed, shape,
α1 index, speed index) (:func:`cell_seed`), so a table is bit-identical
whatever the number of workers, the scheduler or the order in which cells
finish. This module and :mod:`tablegen.tabulation.tabulate` decide a cell's content
with the direct model (:data:`tablegen.tabulation.driver.MODEL_SOURCES`).
"""

from __future__ import annotations

import dataclasses
import warnings

import numpy as np

from data_schema.table import CellTable
from tablegen.tabulation.config import BuildConfig
from tablegen.tabulation.resolution import MIN_PARTICLES_PER_CELL
from tablegen.tabulation.tabulate import CellAccumulator
from direct_model.shapes import SHAPES
from direct_model.simulate import simulate

CHUNK_PARTICLES = 1_000_000      # particles simulated at a time within one cell: bounds a worker's memory
REPRESENTATION_KEY = 2 ** 31     # spawn key of the k-means seed (chunks use keys 0, 1, ...)


def derive_seed(seed: int, *key: int) -> int:
    """A 63-bit seed derived from ``seed`` and a spawn key (independent streams per key)."""
    hi, lo = np.random.SeedSequence(seed, spawn_key=key).generate_state(2, np.uint32)
    return (int(hi) << 31) ^ int(lo)


def shape_key(shape: str) -> int:
    """The spawn key of a shape's cells: a family's index in SHAPES (0-3), a user grain's name read as a big-endian
    integer (its UTF-8 bytes: distinct names give distinct keys, each >= 65 as a name starts with a letter), so a
    grain's cells have the same seeds whatever the other shapes of the table."""
    return SHAPES.index(shape) if shape in SHAPES else int.from_bytes(shape.encode(), "big")


def cell_seed(master_seed: int, shape: str, i_alpha: int, i_speed: int) -> int:
    """The seed of one cell, derived from the master seed, the shape (:func:`shape_key`) and the grid indices."""
    return derive_seed(master_seed, shape_key(shape), i_alpha, i_speed)


def cell_label(config: BuildConfig, shape: str, i_alpha: int, i_speed: int) -> str:
    """The cell's name in messages: shape, α1 and speed."""
    return (f"cell (shape={shape}, alpha1={config.alpha1_deg[i_alpha]:g} deg, "
            f"speed={config.speed_m_s[i_speed]:g} m/s)")


def compile_cell_kernels(config: BuildConfig) -> None:
    """Compile a cell's kernels (the model's and the representation's) in this process, on the first cell with the
    fewest particles a cell may have, into numba's on-disk cache: worker processes started afterwards load them
    instead of each compiling them at the same moment."""
    smallest = dataclasses.replace(config, particles_per_cell=MIN_PARTICLES_PER_CELL)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")      # the cell's warnings are the cells' own, given there
        try:
            compute_cell(smallest, config.shapes[0], 0, 0)
        except ValueError:                   # too few rebounds among so few particles: the workers compile the rest
            pass


def compute_cell(config: BuildConfig, shape: str, i_alpha: int, i_speed: int) -> CellTable:
    """Simulate one cell and build its stored representation (runs in a worker): one of the paper's four
    families by its name, a user's grain or a later family by its record (:meth:`BuildConfig.body`; a grain's
    own law of b/a and c/b, if any, instead of the families')."""
    seed = cell_seed(config.seed, shape, i_alpha, i_speed)
    body = config.body(shape)
    acc = CellAccumulator()
    for chunk, start in enumerate(range(0, config.particles_per_cell, CHUNK_PARTICLES)):
        n = min(CHUNK_PARTICLES, config.particles_per_cell - start)
        acc.add(simulate(body, config.alpha1_deg[i_alpha], config.speed_m_s[i_speed], n,
                         seed=derive_seed(seed, chunk), **config.model()))
    return acc.finish(config.resolution, derive_seed(seed, REPRESENTATION_KEY),
                      cell_label(config, shape, i_alpha, i_speed))
