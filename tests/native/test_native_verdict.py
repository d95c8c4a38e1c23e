"""One verdict from both loaders on the shapes' records (docs/format.md, "Shapes"). Each edit rewrites a dataset of
group /shapes whole, so HDF5 writes it with a fresh Fletcher-32 checksum: the files are checksum-valid, and only
the records' contract can refuse them.

- A built-in family's row is the family's record at the table's κ and law, bit for bit: one entry of its vertices,
  triangles, inertia, aspect law, hands or kind changed, in each family of the small table (ellipsoid, prism,
  cut_prism, tetrahedron), and surrogate.load and rbs_table_open both refuse the file, naming the dataset and the
  shape (the kind through the vertex count it contradicts).
- A user grain's record has no reference but itself: both loaders rebuild its mass properties from its vertices and
  triangles (registry.polyhedron), so an inertia that is not its hull's, a moved vertex or a turned triangle is
  refused by both, while what the record alone decides (its law, its hands, the order of its triangles, which
  fsum's exact rounding makes no matter) loads in both.
- Unaltered copies, rewritten the same way, load in both.
"""

from __future__ import annotations

import h5py
import numpy as np
import pytest

from tests.helpers import python_side as py
from tests.helpers.native_library import ERR_FORMAT, OK
from tests.helpers.tables import edited_copy

SHAPE_DATASETS = ("name", "kind", "vertex_start", "vertices", "triangle_start", "triangles", "inertia", "aspect",
                  "both_hands")
FAMILIES = ("ellipsoid", "prism", "cut_prism", "tetrahedron")


def _rewrite(dataset, change=None):
    """An edit rewriting /shapes/``dataset`` whole (a fresh checksum), after ``change(values, starts)`` (in place;
    starts: the vertex and triangle starts)."""
    def edit(f):
        values = f[f"shapes/{dataset}"][()]
        if change is not None:
            before = values.copy()
            change(values, (f["shapes/vertex_start"][()], f["shapes/triangle_start"][()]))
            assert values.tobytes() != before.tobytes(), dataset
        f[f"shapes/{dataset}"][...] = values
    return edit


def _one_entry(dataset, i):
    """One entry of shape i's part of ``dataset`` changed so that the file stays within every bound: a vertex
    coordinate or a law's mean by one ulp, an inertia by one ulp, a triangle turned (two indices swapped), the
    hands or the kind flipped."""
    def change(values, starts):
        vertex_start, triangle_start = starts
        if dataset == "vertices":
            values[vertex_start[i], 1] = np.nextafter(values[vertex_start[i], 1], 0.0)
        elif dataset == "triangles":
            values[triangle_start[i], [1, 2]] = values[triangle_start[i], [2, 1]]
        elif dataset in ("inertia", "aspect"):
            values[i, 0] = np.nextafter(values[i, 0], np.inf)
        elif dataset in ("both_hands", "kind"):
            values[i] = 1 - values[i]
    return _rewrite(dataset, change)


def _checksum_valid(path):
    with h5py.File(path, "r") as f:
        for name in SHAPE_DATASETS:
            assert f[f"shapes/{name}"].fletcher32, name
            f[f"shapes/{name}"][()]                  # reads: its checksum holds


def _loads_in_both(native, path):
    code, table, message = native.open(path)
    assert code == OK, (path.name, message)
    table.close()
    py.load(path)


def _refused_by_both(native, path, names):
    """Both loaders refuse the file with a message naming the file and each of ``names``."""
    _checksum_valid(path)
    code, table, message = native.open(path)
    assert code != OK and table is None, (path.name, code)
    assert code == ERR_FORMAT and message.startswith(str(path)), (path.name, code, message)
    assert all(name in message for name in names), (path.name, names, message)
    with pytest.raises(ValueError) as info:
        py.load(path)
    assert str(path) in str(info.value) and all(name in str(info.value) for name in names), (path.name, str(info.value))


def _names(path):
    with h5py.File(path, "r") as f:
        return [s.decode() for s in f["shapes/name"][()]]


def test_unaltered_copies_load_in_both(native, small_table_path, grain_table_path, tmp_path):
    for source in (small_table_path, grain_table_path):
        for dataset in SHAPE_DATASETS:
            path = edited_copy(source, tmp_path, f"same_{source.stem}_{dataset}.h5", _rewrite(dataset))
            _checksum_valid(path)
            _loads_in_both(native, path)


# (family, dataset) of every entry the test alters: each per-shape dataset of each family's row (the ellipsoid has
# no vertex or triangle rows; its count rule is test_native_shapes.py's)
FAMILY_CASES = [(family, dataset) for family in FAMILIES
                for dataset in ("kind", "vertices", "triangles", "inertia", "aspect", "both_hands")
                if family != "ellipsoid" or dataset not in ("vertices", "triangles")]


@pytest.mark.parametrize("family, dataset", FAMILY_CASES)
def test_an_altered_family_record_is_refused_by_both(native, small_table_path, tmp_path, family, dataset):
    names = _names(small_table_path)
    assert tuple(names) == FAMILIES
    path = edited_copy(small_table_path, tmp_path, f"{family}_{dataset}.h5", _one_entry(dataset, names.index(family)))
    # a kind that is not the family's contradicts its vertex count, which is checked first
    named = "shapes/vertex_start" if dataset == "kind" else f"shapes/{dataset}"
    _refused_by_both(native, path, (named, f"'{family}'"))


def _moved_vertex(i):
    """Shape i's vertex of median ξ moved by 1e-6 a along ξ: its half-extents stay, its centre of mass leaves the
    origin."""
    def change(values, starts):
        rows = np.arange(starts[0][i], starts[0][i + 1])
        values[rows[np.argsort(values[rows, 0])[len(rows) // 2]], 0] += 1e-6
    return _rewrite("vertices", change)


def _inside_out(i):
    """Every triangle of shape i turned: a surface facing inwards (no volume)."""
    def change(values, starts):
        rows = slice(starts[1][i], starts[1][i + 1])
        values[rows] = values[rows][:, ::-1]
    return _rewrite("triangles", change)


# what is altered: (the edit of shape i, the dataset the messages name)
GRAIN_EDITS = {"inertia": (lambda i: _one_entry("inertia", i), "shapes/inertia"),
               "vertex": (_moved_vertex, "shapes/vertices"),
               "triangle": (lambda i: _one_entry("triangles", i), "shapes/triangles"),
               "surface": (_inside_out, "shapes/triangles")}


@pytest.mark.parametrize("grain", ("sand_a", "sand_b"))
@pytest.mark.parametrize("what", GRAIN_EDITS)
def test_an_inconsistent_user_grain_is_refused_by_both(native, grain_table_path, tmp_path, grain, what):
    """A grain of the grain table (sand_a from a mesh, sand_b from points) with its inertia one ulp off, a vertex
    moved, one triangle turned inside out or the whole surface turned."""
    names = _names(grain_table_path)
    assert names == ["sand_a", "sand_b"]
    edit, named = GRAIN_EDITS[what]
    path = edited_copy(grain_table_path, tmp_path, f"{grain}_{what}.h5", edit(names.index(grain)))
    _refused_by_both(native, path, (named, f"'{grain}'"))


def test_what_a_user_grain_record_alone_decides_loads_in_both(native, grain_table_path, tmp_path):
    """A grain's hands, its law (sand_a gets one, sand_b loses its own) and the order of its triangles are its
    own: both loaders take them."""
    def reversed_triangles(values, starts):
        rows = slice(starts[1][1], starts[1][2])
        values[rows] = values[rows][::-1]

    def laws(values, starts):
        values[0] = [0.9, 0.05, 0.7, 1.0]
        values[1] = np.nan

    edits = {"hands": _rewrite("both_hands", lambda values, starts: values.__setitem__(slice(None), 1 - values)),
             "laws": _rewrite("aspect", laws), "order": _rewrite("triangles", reversed_triangles)}
    for what, edit in edits.items():
        path = edited_copy(grain_table_path, tmp_path, f"own_{what}.h5", edit)
        _checksum_valid(path)
        _loads_in_both(native, path)
