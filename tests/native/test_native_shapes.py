"""Tables store their shapes (group /shapes; docs/format.md, "Shapes"), and both runtimes read them
from there: registry records round trip through the file bit for bit; a table of 64 shapes (the families and
60 user grains) loads in Python and C with the same records, its mix draws each shape with its weight, and the
C and numba kernels draw the same bits from it; a flipped bit or an out-of-range value in any /shapes dataset
fails to load in both loaders with a message naming the dataset, and so does a table without the group."""

from __future__ import annotations

import re

import h5py
import numpy as np
import pytest

from tests.helpers import python_side as py
from tests.helpers.tables import edited_copy
from tests.helpers.bad_files import _corrupt_chunk, _flip_bit, _set
from tests.helpers.native_library import ERR_FORMAT, FAMILY_NONE, METHOD_DIRECT, NATIVE

SHAPE_DATASETS = ("name", "kind", "vertex_start", "vertices", "triangle_start", "triangles", "inertia", "aspect",
                  "both_hands")


@pytest.fixture(scope="module")
def many_shapes(small_table_path, tmp_path_factory):
    path = tmp_path_factory.mktemp("many") / "many_shapes.h5"
    return path, py.many_shape_table(small_table_path, path, 64)


def _refused_alike(native, path, names):
    code, table, message = native.open(path)
    assert code == ERR_FORMAT and table is None and names in message, (path.name, code, message)
    with pytest.raises(ValueError) as info:
        py.load(path)
    assert str(path) in str(info.value) and names in str(info.value), (path.name, str(info.value))


def _same_arrays(a, b):
    return a.shape == b.shape and a.tobytes() == b.tobytes()


def test_records_round_trip_through_the_file(small_table_path, tmp_path):
    """The families at the table's κ and law and a user grain (direct_model.registry.grain) come back from the
    file as the same records: names, kinds, vertices, triangles, inertia, laws and hands, bit for bit."""
    from data_schema.shape_records import shape_datasets
    from data_schema.table import read_table
    path = tmp_path / "round_trip.h5"
    py.many_shape_table(small_table_path, path, 5)
    written = read_table(small_table_path).shape_records() + tuple(py.user_grains(1))
    read = read_table(path).records
    assert [r.name for r in read] == [r.name for r in written] == ["ellipsoid", "prism", "cut_prism", "tetrahedron",
                                                                   "grain_00"]
    assert [type(r) for r in read] == [type(r) for r in written]
    for key, values in shape_datasets(written).items():
        assert _same_arrays(shape_datasets(read)[key], values), key
    grain = read[-1]
    assert grain.aspect == written[-1].aspect and grain.both_hands and len(grain.triangles) == 2 * len(grain.vertices) - 4


def test_a_table_of_64_shapes_loads_alike_in_python_and_c(native, many_shapes):
    path, names = many_shapes
    table = py.load(path)
    assert table.shapes == names and len(names) == 64
    # the direct model's shapes: the four families by code, then the table's 60 grains in table order
    assert table.model_shapes.tolist() == list(range(64)) and table.shape_arrays.n_shapes == 64
    arrays = table.shape_datasets
    c_table = native.table(path)
    try:
        assert c_table.shapes == names
        for i, name in enumerate(names):
            info = c_table.shape_info(i)
            start, stop = arrays["vertex_start"][i], arrays["vertex_start"][i + 1]
            assert info["name"] == name and info["kind"] == arrays["kind"][i]
            assert info["family"] == (i if i < 4 else FAMILY_NONE) and info["both_hands"] == arrays["both_hands"][i]
            assert _same_arrays(info["vertices"], arrays["vertices"][start:stop])
            assert _same_arrays(info["inertia"], arrays["inertia"][i]) and _same_arrays(info["aspect"], arrays["aspect"][i])
        assert c_table.shape_info(64) is None
    finally:
        c_table.close()


def _distinct_cells(source, folder):
    """The 64-shape table with the α2 location of every cluster of shape k moved by k · 1e-6 rad, so that a draw
    tells which shape the mix gave it."""
    def edit(f):
        loc = f["cells/cluster_loc"][()]
        loc[..., 0] += (np.arange(loc.shape[0]) * 1e-6).reshape(-1, 1, 1, 1).astype(np.float32)
        f["cells/cluster_loc"][...] = loc
    return edited_copy(source, folder, "distinct.h5", edit)


def test_the_mix_draws_each_of_64_shapes_with_its_weight_in_c_and_python_alike(native, many_shapes, tmp_path):
    """Weights w_k ∝ k + 1 over the 64 shapes; n = 64 000 draws in C (rbs_draw_many, a mix of
    rbs_mix_new_from_weights) and numba (the same uniforms, surrogate.mix_cdf): the same bits. Each draw's shape
    is found as the one whose single-shape mix gives the same bits; the counts' chi-square over 63 degrees of
    freedom stays below its 1 - 1e-6 quantile, 131.4 (fixed seed: the test is deterministic; a correct mix fails
    it for one seed in a million)."""
    from scipy.stats import chi2
    path = _distinct_cells(many_shapes[0], tmp_path)
    names = many_shapes[1]
    n, k = 64_000, len(names)
    weights = np.arange(1, k + 1, dtype=np.float64)
    weights /= weights.sum()
    rng = np.random.default_rng(64)
    u = rng.random((n, py.U_PER_DRAW))
    u[:, 3] = 0.999999                       # never trapped: every draw is a rebound that names its shape
    V = np.tile([150.0 * np.cos(np.radians(30.0)), -150.0 * np.sin(np.radians(30.0)), 0.0], (n, 1))
    normal, a = np.tile([0.0, 1.0, 0.0], (n, 1)), np.full(n, 1e-4)
    c_table, table = native.table(path), py.load(path)
    try:
        mix, message = c_table.mix_new(weights=dict(zip(names, weights)))
        assert mix is not None, message
        status, c_V, _ = c_table.draw_many(mix, V, normal, a, u)
        V_out, W_out, py_status = np.empty((n, 3)), np.empty((n, 3)), np.empty(n, dtype=np.int8)
        py.table_rebound_many(table.kernel_data, py.mix_cdf(table, dict(zip(names, weights))), V, normal, a, u, V_out,
                              W_out, py_status)
        assert np.array_equal(status, py_status) and c_V.tobytes() == V_out.tobytes()
        assert np.all(status == py.STATUS_REBOUNDED)
        shape = np.full(n, -1)
        for j, name in enumerate(names):
            single, _ = c_table.mix_new(name)
            _, V_j, _ = c_table.draw_many(single, V, normal, a, u)
            same = np.all(V_j == c_V, axis=1)
            assert np.all(shape[same] == -1)         # one shape only gives a draw's bits
            shape[same] = j
    finally:
        c_table.close()
    assert np.all(shape >= 0)
    counts = np.bincount(shape, minlength=k)
    expected = n * weights
    statistic = float(((counts - expected) ** 2 / expected).sum())
    assert statistic < chi2.ppf(1.0 - 1e-6, k - 1), (statistic, counts)


def test_a_flipped_bit_in_any_shapes_dataset_fails_to_load_in_both(native, small_table_path, tmp_path):
    for name in SHAPE_DATASETS:
        path = _corrupt_chunk(edited_copy(small_table_path, tmp_path, f"flip_{name}.h5"), f"shapes/{name}")
        _refused_alike(native, path, f"shapes/{name}")


def _off_surface(vertex, instead):
    """An edit giving the prism's (rows 0-11 of shapes/triangles) every corner ``vertex`` as ``instead``: the same
    number of triangles, every index in range, ``vertex`` on no triangle."""
    def edit(f):
        values = f["shapes/triangles"][()]
        prism = values[:12]
        prism[prism == vertex] = instead
        f["shapes/triangles"][...] = values
    return edit


# dataset: edits (HDF5 rewrites the chunk with a fresh Fletcher-32) that break what /shapes may hold, one per rule (the small table: rows
# ellipsoid, prism (vertices 0-7), cut_prism (8-31), tetrahedron (32-35))
BAD_VALUES = {
    "name": [_set("shapes/name", 1, b"prisma"), _set("shapes/name", 0, b"mix")],
    "kind": [_set("shapes/kind", 1, 2), _set("shapes/kind", 1, -1)],
    "vertex_start": [_set("shapes/vertex_start", 4, 35), _set("shapes/vertex_start", 2, 3)],
    "vertices": [_set("shapes/vertices", (3, 1), np.nan), _set("shapes/vertices", (3, 1), 1.6),
                 _set("shapes/vertices", (3, 1), 0.5)],
    "triangle_start": [_set("shapes/triangle_start", 2, 11)],
    "triangles": [_set("shapes/triangles", (0, 0), 8), _set("shapes/triangles", (0, 0), -1), _off_surface(7, 6)],
    "inertia": [_set("shapes/inertia", (1, 0), -0.5), _set("shapes/inertia", (1, 0), np.inf),
                _set("shapes/inertia", (1, 0), 1.5)],
    "aspect": [_set("shapes/aspect", (1, 2), 1.0), _set("shapes/aspect", (1, 1), 0.0),
               _set("shapes/aspect", (1, 0), np.nan)],
    "both_hands": [_set("shapes/both_hands", 1, 2), _set("shapes/both_hands", 3, 0)],
}


def test_a_bad_value_in_any_shapes_dataset_is_refused_by_both(native, small_table_path, tmp_path):
    for name, edits in BAD_VALUES.items():
        for k, edit in enumerate(edits):
            _refused_alike(native, edited_copy(small_table_path, tmp_path, f"bad_{name}_{k}.h5", edit), f"shapes/{name}")


def test_a_bad_value_in_a_user_grain_is_refused_by_both(native, many_shapes, tmp_path):
    """A user grain's row (shape 4): a name outside NAME_PATTERN, a vertex count under 4, a vertex outside the
    unit box's bound, a law with low >= high, and the group missing."""
    path = many_shapes[0]
    with h5py.File(path, "r") as f:
        start = f["shapes/vertex_start"][()]
    edits = {"name": _set("shapes/name", 4, b"4grain"), "vertex_start": _set("shapes/vertex_start", 5, start[4] + 3),
             "vertices": _set("shapes/vertices", (start[4], 2), -1.7), "aspect": _set("shapes/aspect", (4, 2), 1.0)}
    for name, edit in edits.items():
        _refused_alike(native, edited_copy(path, tmp_path, f"grain_{name}.h5", edit), f"shapes/{name}")
    _refused_alike(native, edited_copy(path, tmp_path, "no_group.h5", lambda f: f.__delitem__("shapes")), "'shapes'")


def test_a_hull_over_the_vertex_limit_is_refused_alike(native, small_table_path, tmp_path):
    """The last shape's row given MAX_HULL_VERTICES + 1 vertices (shapes.h's limit; rows of zeros appended to
    shapes/vertices): both loaders refuse it in the same words, which state the limit, so C's is Python's."""
    limit = int(re.search(r"#define MAX_HULL_VERTICES (\d+)", (NATIVE / "src" / "shapes.h").read_text()).group(1))

    def too_many(f):
        start, vertices = f["shapes/vertex_start"][()], f["shapes/vertices"][()]
        extra = limit + 1 - int(start[-1] - start[-2])
        start[-1] += extra
        f["shapes/vertex_start"][...] = start
        del f["shapes/vertices"]
        f["shapes"].create_dataset("vertices", data=np.concatenate([vertices, np.zeros((extra, 3))]), fletcher32=True)

    path = edited_copy(small_table_path, tmp_path, "too_many_vertices.h5", too_many)
    with h5py.File(path, "r") as f:
        name = f["shapes/name"][-1].decode()
    words = f"dataset 'shapes/vertex_start' gives shape '{name}' {limit + 1} vertices; allowed: 4 to {limit} for a convex"
    _refused_alike(native, path, words)


def test_a_flipped_kappa_bit_changes_the_families_and_is_refused(native, small_table_path, tmp_path):
    """κ decides the cut prism's record: a flipped bit of the field kappa of model/parameters (its checksum
    rewritten) no longer gives the stored record and is refused, and so is a table whose cut prism's vertices
    were made at another κ (their checksums rewritten)."""
    def other_kappa(f):
        from direct_model.registry import built_in_shape
        from direct_model.shapes import AspectRatioLaw
        row = f["model/parameters"][0]
        law = AspectRatioLaw(*(float(row[k]) for k in ("aspect_ratio_mean", "aspect_ratio_sd", "aspect_ratio_low",
                                                        "aspect_ratio_high")))
        start = f["shapes/vertex_start"][()]
        vertices = f["shapes/vertices"][()]
        vertices[start[2]:start[3]] = built_in_shape("cut_prism", 0.25, law).vertices
        f["shapes/vertices"][...] = vertices

    _refused_alike(native, edited_copy(small_table_path, tmp_path, "kappa_vertices.h5", other_kappa), "shapes/vertices")
    def flip_kappa(f):
        row = f["model/parameters"][()]
        row["kappa"] = _flip_bit(float(row["kappa"][0]), 40)
        f["model/parameters"][...] = row

    _refused_alike(native, edited_copy(small_table_path, tmp_path, "kappa_bit.h5", flip_kappa), "kappa")


def test_user_grains_of_a_table_rebound_alike_in_c_and_numba(native, many_shapes):
    """The direct path of every user grain of the 64-shape table, reached through the mix (rbs_rebound, method
    direct: one shape per mix, u[0] drawing it), gives the same bits in C and numba, spinning or not, at three
    incidences; and at least 9 in 10 of those hits rebound (the grains are compact: a trapped or failed
    rebound is rare)."""
    path, names = many_shapes
    table, c_table = py.load(path), native.table(path)
    rng = np.random.default_rng(34)
    rebounded = total = 0
    try:
        for k in range(4, 64, 3):
            mix, message = c_table.mix_new(shape=names[k])
            assert mix is not None, message
            cdf = py.mix_cdf(table, names[k])
            for alpha1, omega in ((20.0, (0.0, 0.0, 0.0)), (55.0, (0.0, 0.0, 3e5)), (85.0, (2e5, -1e5, 0.0))):
                V = np.array([120.0 * np.cos(np.radians(alpha1)), -120.0 * np.sin(np.radians(alpha1)), 0.0])
                u = rng.random(py.U_PER_DRAW)
                c = c_table.rebound(mix, V, np.array(omega), np.array([0.0, 1.0, 0.0]), 1e-4, u,
                                    method=METHOD_DIRECT)
                p = py.rebound(table.kernel_data, table.direct_parameters, table.shape_arrays, table.model_shapes,
                               cdf, tuple(V), omega, (0.0, 1.0, 0.0), 1e-4, u, py.METHOD_DIRECT)
                assert c[0] == p.status, (names[k], alpha1, c[0], p.status)
                assert np.array_equal(c[1], np.array(p.V), equal_nan=True) and \
                    np.array_equal(c[2], np.array(p.Omega), equal_nan=True), (names[k], alpha1)
                rebounded += c[0] == py.STATUS_REBOUNDED
                total += 1
    finally:
        c_table.close()
    assert rebounded >= 0.9 * total, (rebounded, total)
