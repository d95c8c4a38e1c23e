"""The configurations of the small tables the session builds once (tests/conftest.py): 2e4 particles per cell,
all four shapes, a table of two user grains, one of a grain of 10 000 vertices and one of a family entered by the
tests; and edited copies of a table."""

import json
import shutil

import h5py
import numpy as np

from tests.helpers import REPO


def edited_copy(source, folder, name, edit=None):
    """A copy of the table file ``source`` as ``folder/name``, opened for writing and passed to ``edit(f)``."""
    path = folder / name
    shutil.copyfile(source, path)
    if edit is not None:
        with h5py.File(path, "r+") as f:
            edit(f)
    return path


def _table_config(alpha1_deg, speed_m_s, seed, shapes=None, particles_per_cell=20000):
    grid_shapes = "" if shapes is None else f"shapes = {json.dumps(list(shapes))}\n"
    return (f"[grid]\nalpha1_deg = {list(alpha1_deg)}\nspeed_m_s = {list(speed_m_s)}\n{grid_shapes}"
            f"[simulation]\nparticles_per_cell = {particles_per_cell}\nseed = {seed}\n")


SMALL_TABLE_CONFIG = _table_config([30.0, 60.0, 90.0], [50.0, 150.0, 250.0], seed=11)
# grid points around (1.25°, 175 m/s), (3.5°, 175 m/s) and (42.5°, 175 m/s), with the default preset's
# α1 steps there
OFF_GRID_TABLE_CONFIG = _table_config([1.0, 1.5, 2.0, 3.0, 4.0, 40.0, 45.0], [150.0, 200.0], seed=12)
# the presets' α1 step near grazing before 1.5° was added: (1.5°, 175 m/s) between grid points
WIDE_GRAZING_TABLE_CONFIG = _table_config([1.0, 2.0], [150.0, 200.0], seed=14)
# grid points around NEAR_NORMAL_POINT (α1 deg, |V⁻| m/s): near normal impact at low speed, where
# the law moves fastest with speed (the presets' steps there)
NEAR_NORMAL_POINT = (84.375, 62.5)
NEAR_NORMAL_TABLE_CONFIG = _table_config([83.75, 85.0], [50.0, 75.0], seed=13)
# the prism and a family entered by the tests alone (tests/helpers/families.py) on a 2 × 2 grid
OCTAHEDRON_TABLE_CONFIG = _table_config([30.0, 70.0], [100.0, 200.0], seed=45, shapes=["prism", "octahedron"],
                                        particles_per_cell=3000)
# a tabulated wall law (docs/model.md §4) on a 2 × 2 grid of the prism
TABULATED_WALL = """[wall]
law = "tabulated"
q = 0.8
contact_speed_m_s = [40.0, 120.0, 300.0]
contact_sine = [0.0, 0.5, 1.0]
restitution = [[1.0, 0.8, 0.55], [1.0, 0.75, 0.5], [1.0, 0.7, 0.42]]
name = "test_tabulated"
"""
TABULATED_TABLE_CONFIG = _table_config([30.0, 70.0], [100.0, 200.0], seed=46, shapes=["prism"],
                                       particles_per_cell=1000) + TABULATED_WALL


def written_out_config(alpha1_deg, speed_m_s, shapes, seed) -> str:
    """A configuration with every key written out, so that no preset default enters a known value: the given
    grid and seed, the fewest particles a cell allows and a small resolution (a cell builds in well under a
    second), the paper's shape law and wall."""
    return f"""
[grid]
alpha1_deg = {list(alpha1_deg)}
speed_m_s = {list(speed_m_s)}
shapes = {json.dumps(list(shapes))}
[simulation]
particles_per_cell = 256
seed = {seed}
kappa = 0.3
n_max = 1000
aspect_ratio = {{mean = 0.8, sd = 0.2, low = 0.5, high = 1.0}}
[table]
resolution = {{clusters = 16, dictionary_size = 16, levels = 24}}
[wall]
k = 0.1
p = 0.61
q = 1.0
name = "corundum_on_St3_Lashkov1991"
"""

# a table of two user grains (docs/model.md §9) on a 2 × 2 grid: sand_a the mesh examples/grains/grain_2.obj (17
# hull vertices, fixed proportions), sand_b the hull of seven points with its own b/a, c/b law, in both hands;
# written next to its mesh by write_grain_config (the mesh path is relative to the configuration)
GRAIN_TABLE_CONFIG = """
[grid]
alpha1_deg = [30.0, 70.0]
speed_m_s = [100.0, 200.0]
shapes = ["sand_a", "sand_b"]
[simulation]
particles_per_cell = 3000
seed = 34
[shapes.sand_a]
mesh = "grains/sand_a.obj"
[shapes.sand_b]
vertices = [[0.0, 0.0, 0.0], [1.0, 0.1, 0.0], [0.2, 0.9, 0.1], [0.1, 0.2, 0.7], [0.6, 0.5, 0.5], [0.9, 0.8, 0.3],
            [0.4, -0.2, 0.4]]
aspect_ratio = {mean = 0.8, sd = 0.1}
both_hands = true
"""
GRAIN_MESH = REPO / "examples" / "grains" / "grain_2.obj"


def write_grain_config(folder, text=GRAIN_TABLE_CONFIG, mesh=GRAIN_MESH):
    """``text`` as ``folder/grains.toml`` and the mesh as ``folder/grains/sand_a.obj``; the configuration's path."""
    (folder / "grains").mkdir(exist_ok=True)
    shutil.copyfile(mesh, folder / "grains" / "sand_a.obj")
    path = folder / "grains.toml"
    path.write_text(text)
    return path


# a table of one user grain of BIG_GRAIN_VERTICES hull vertices on one grid point, the fewest particles a cell allows
# (it builds in a few seconds): points on the surface of the ellipsoid of semi-axes (1, 0.7, 0.5), each one a hull
# vertex, given as the configuration's points; numba walks its vertex graph in the contact search, C scans every
# vertex with its work space on the heap
BIG_GRAIN_VERTICES = 10_000


def big_grain_config() -> str:
    """The configuration of the table of one grain of BIG_GRAIN_VERTICES vertices, named "scan"."""
    rng = np.random.default_rng(54)
    points = rng.normal(size=(BIG_GRAIN_VERTICES, 3))
    points /= np.linalg.norm(points, axis=1)[:, None]
    points *= [1.0, 0.7, 0.5]
    return (_table_config([40.0], [150.0], seed=55, shapes=["scan"], particles_per_cell=256)
            + f"[shapes.scan]\nvertices = {json.dumps(points.tolist())}\n")


# the grid attributes a table of format 3.4 held (its wall law and the direct model's parameters), in the order its
# checksummed copy grid/law held them (second_moment_factors: 4 numbers)
FORMAT_3_LAW_ATTRIBUTES = ("restitution_k", "restitution_p", "friction_q", "kappa", "n_max", "aspect_ratio_mean",
                           "aspect_ratio_sd", "aspect_ratio_low", "aspect_ratio_high", "contact_tol", "set_tol",
                           "max_steps", "second_moment_factors")


def format_3_copy(source, folder, name, minor=4):
    """A copy of the table ``source`` (format 4) in the layout of format 3.``minor`` (3.4 by default): the wall law
    and the direct model's parameters as attributes of group grid with their checksummed copy grid/law, no groups
    model and wall; what rebound-scatter before 1.0 wrote (its cells, shapes and configuration unchanged)."""
    def to_format_3(f):
        model, wall = f["model/parameters"][0], f["wall/parameters"][0]
        grid = f["grid"]
        values = {"restitution_k": wall["k"], "restitution_p": wall["p"], "friction_q": wall["q"]}
        values.update({field: model[field] for field in model.dtype.names})
        for attribute in FORMAT_3_LAW_ATTRIBUTES:
            grid.attrs[attribute] = values[attribute]
        grid.attrs["wall_law"] = f["wall"].attrs["name"]
        law = [float(x) for attribute in FORMAT_3_LAW_ATTRIBUTES for x in np.ravel(values[attribute])]
        grid.create_dataset("law", data=np.array(law), fletcher32=True)
        del f["model"], f["wall"]
        f.attrs["format_version"] = np.array([3, minor], dtype=np.int64)

    return edited_copy(source, folder, name, to_format_3)
