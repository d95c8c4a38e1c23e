"""The direct model in C (native/src/direct_path.c and the kernels it calls: shapes.c, collision.c, flight.c,
body_rebound.c, runtime.c) against numba, bit for bit for the same inputs and uniforms: the parameter array the
loader builds, the pieces (shapes, a particle's body, the normal quantile, the uniform quaternion, one
collision: internal functions, bound in the test-only library), whole rebounds in random caller frames (rbs_rebound
under RBS_METHOD_DIRECT with a one-shape mix, the public way to the direct path), user grains of 8 to 1000 hull
vertices, and hostile inputs (RBS_INVALID with NaN, never a crash)."""

from __future__ import annotations

import ctypes
import re

import h5py
import numpy as np
import pytest

from direct_model.shape_arrays import particle_hull     # not yet re-exported by tests/helpers/python_side.py
from tests.helpers import python_side as py
from tests.helpers.native_library import (ERR_FORMAT, INVALID, METHOD_DIRECT, NATIVE, PATH_DIRECT, PATH_NONE,
                                          ShapeArrays, direct_uniforms)

SPINS = (0.0, 0.02, 0.3, 1.0)     # |Ω⁻| a / |V⁻| of the whole-rebound comparisons
PER_SHAPE = 2000                  # particles per shape and spin
N_COLLISIONS = 10_000
LAW = py.AspectRatioLaw()
# user grains: hulls of 8 to 1000 vertices in both hands, of fixed proportions or stretched by the families' law (above
# 64 vertices numba walks the hull's vertex graph, C scans; above 256 C's work space is on the heap)
GRAINS = [py.hull_grain(f"grain_{n}", n, seed=n, aspect=LAW if n in (24, 256, 1000) else None, both_hands=True)
          for n in (8, 24, 64, 256, 1000)] + [py.cloud_grain("cloud", 300, seed=3, aspect=LAW)]

def _c(native):
    """The test-only library, its internal functions typed (tests.helpers.native_library.INTERNAL)."""
    return native.internal


def _ptr(x):
    return None if x is None else x.ctypes.data


def _direct_c(c, table, shape, V, omega, n, a, u):
    """(status, V⁺, Ω⁺) of the test-only library's rbs_direct_rebound (the direct path alone, a shape code)."""
    V_out, W_out = np.zeros(3), np.zeros(3)
    arrays = [None if x is None else np.ascontiguousarray(x, dtype=np.float64) for x in (V, omega, n, u)]
    status = c.rbs_direct_rebound(table, shape, *(_ptr(x) for x in arrays[:3]), a, _ptr(arrays[3]), _ptr(V_out),
                                  _ptr(W_out))
    return status, V_out, W_out


def _same(a, b):
    """The same float64 bits."""
    bits = (np.asarray(x, dtype=np.float64).view(np.uint64) for x in (a, b))
    return np.array_equal(*bits)


# the direct model's parameters of another table: its rows model/parameters and wall/parameters edited (their fields
# in reverse order, one more field: both loaders read them by name)
OTHER_MODEL = dict(contact_tol=2e-10, set_tol=3e-9, max_steps=7000, n_max=500)
OTHER_WALL = dict(q=0.4)


def _other_table(small_table_path, tmp_path, name, model=None, wall=None):
    """A copy of the small table whose parameter rows hold ``model`` and ``wall`` (field: value), written in the
    reverse field order with one more field, chunked (1,) under Fletcher-32."""
    path = tmp_path / name
    path.write_bytes(small_table_path.read_bytes())
    with h5py.File(path, "r+") as f:
        for group, changes in (("model", model or {}), ("wall", wall or {})):
            row = f[group]["parameters"][()]
            names = list(reversed(row.dtype.names))
            turned = np.zeros(1, dtype=[("later", "<f8")] + [(n, row.dtype[n]) for n in names])
            for n in names:
                turned[n] = changes.get(n, row[n])
            del f[group]["parameters"]
            f[group].create_dataset("parameters", data=turned, chunks=(1,), fletcher32=True)
    return path


# -- the parameters -------------------------------------------------------------------------------------

_DEFINE = re.compile(r"^#define (\w+) \(?(\w+(?: \+ \w+)*)\)?(?=\s|$)", flags=re.M)


def _integer_defines(*headers) -> dict:
    """The #defines of the headers whose value is an integer or a sum of integers and such names (of any of the
    headers; the first definition of a name kept)."""
    found = [(name, expression.split(" + ")) for header in headers
             for name, expression in _DEFINE.findall(header.read_text())]
    values, changed = {}, True
    while changed:
        changed = False
        for name, terms in found:
            if name not in values and all(t.isdigit() or t in values for t in terms):
                values[name] = sum(int(t) if t.isdigit() else values[t] for t in terms)
                changed = True
    return values


def test_the_parameter_layout_is_direct_model_s(table_pair):
    """runtime.h's layout is direct_model.runtime's: every P_* offset, U_* index and N_PARAMS, which both sides
    derive from the shape count and the wall array's size (P_KFAC, then one second-moment factor per shape code,
    then the wall's array of WALL_ARRAY_SIZE); the loader's array has N_PARAMS elements."""
    c = _integer_defines(NATIVE / "include" / "rebound_scatter.h", *sorted((NATIVE / "src").glob("*.h")))
    c.setdefault("U_PER_REBOUND", c.get("RBS_U_PER_REBOUND"))
    layout = re.compile(r"P_[A-Z_]+|U_[A-Z_]+|N_PARAMS")
    python = {name: value for name, value in vars(py.direct_runtime).items() if layout.fullmatch(name)}
    assert {"P_KFAC", "N_PARAMS", "U_AXIS"} <= set(python)
    assert {name: value for name, value in c.items() if layout.fullmatch(name)} == python
    assert c["P_WALL"] == c["P_KFAC"] + len(py.SHAPES) == c["P_KFAC"] + c["RBS_N_FAMILIES"]
    assert c["N_PARAMS"] == c["P_WALL"] + c["WALL_ARRAY_SIZE"]
    assert table_pair[1].kernel_array("direct_parameters").size == python["N_PARAMS"]



def test_the_parameter_array_is_surrogate_s(native, table_pair, small_table_path, tmp_path):
    """The loader's "direct_parameters" equal surrogate's table.direct_parameters bit for bit: on the table, and on
    one whose rows model/parameters and wall/parameters hold other values in another field order (read by name);
    Φ(low) and Φ(high) from libm's erfc on both sides."""
    python, c_table = table_pair
    assert _same(c_table.kernel_array("direct_parameters"), python.direct_parameters)
    other = _other_table(small_table_path, tmp_path, "other.h5", OTHER_MODEL, OTHER_WALL)
    expected = py.load(other).direct_parameters
    table = native.table(other)
    try:
        assert _same(table.kernel_array("direct_parameters"), expected)
        assert table.wall()["parameters"] == {"k": 0.1, "p": 0.61, "q": 0.4}
    finally:
        table.close()
    assert expected[py.direct_runtime.P_WALL + 1] == 0.4 and expected[py.direct_runtime.P_N_MAX] == 500   # W_Q
    assert not _same(expected, python.direct_parameters)


@pytest.mark.parametrize("changes, message", [
    (dict(contact_tol=-1.0), "field 'contact_tol' of dataset 'model/parameters' must be finite and > 0; got -1"),
    (dict(aspect_ratio_low=0.0), "field 'aspect_ratio_low' of dataset 'model/parameters' must be in (0, 1); got 0"),
    (dict(second_moment_factors=np.array([0.2, 0.3, 1.5, 0.2])), "field 'second_moment_factors' of dataset "
                                                                  "'model/parameters' must be 4 numbers in (0, 1), one "
                                                                  "per shape code; got 1.5 at index 2"),
    (dict(max_steps=0), "field 'max_steps' of dataset 'model/parameters' must be an integer in [1, 2**53); got 0"),
])
def test_parameters_out_of_range_refuse_the_table(native, small_table_path, tmp_path, changes, message):
    """A parameter out of range: both readers refuse the table with one message naming the file, the field and
    its range."""
    path = _other_table(small_table_path, tmp_path, "bad.h5", changes)
    with pytest.raises(ValueError) as info:
        py.load(path)
    code, table, text = native.open(path)
    assert code == ERR_FORMAT and table is None
    assert text == str(info.value) == f"{path}: {message}"


# -- the pieces ---------------------------------------------------------------------------------------------


def test_shapes_bit_for_bit(native):
    """The families' vertices at random half-extents, κ and hand."""
    c = _c(native)
    rng = np.random.default_rng(5)
    for trial in range(2000):
        shape = trial % 4
        a, b, c_ = 1.0, rng.uniform(0.3, 1.0), rng.uniform(0.1, 1.0)
        kappa, hand = rng.uniform(0.0, 1.0), (1.0, -1.0)[trial % 8 // 4]
        mine, theirs = np.zeros((py.MAX_VERTICES, 3)), np.zeros((py.MAX_VERTICES, 3))
        n = c.rbs_body_vertices(shape, a, b, c_, kappa, hand, mine.ctypes.data)
        assert n == py.body_vertices(shape, a, b, c_, kappa, hand, theirs)
        assert _same(mine[:n], theirs[:n])


def test_particle_bodies_bit_for_bit(native, table_pair):
    """One particle's body from the shape arrays (rbs_particle_body, rbs_bounding_radius): vertices, J/m,
    half-extents and radius as numba's, for the table's families and the user grains (hulls of more than
    direct_model.hull_walk.WALK_ABOVE vertices: numba's radius from the hull's farthest candidates, C's from every
    vertex),
    random ratios and hands. C computes the half-extents from the vertices, numba reads them precomputed; numba's
    vertices (room for 256 here) are unit[i] · scale."""
    c = _c(native)
    rng = np.random.default_rng(4)
    for arrays in (table_pair[0].shape_arrays, py.shape_arrays(GRAINS)):
        struct = ShapeArrays.of(arrays)
        for trial in range(1000):
            shape = trial % arrays.n_shapes
            ba, cb = rng.uniform(0.5, 1.0, 2)
            hand = (1.0, -1.0)[trial % 8 // 4]
            # C's vertices: room for the shape's rows; numba's: room for 256 (it copies them only where they fit)
            mine = (np.zeros((int(np.diff(arrays.vertex_start).max()), 3)), np.zeros(3), np.zeros(3))
            theirs, scale = (np.zeros((256, 3)), np.zeros(3), np.zeros(3)), np.zeros(3)
            c_scale = np.zeros(3)
            n = c.rbs_particle_body(ctypes.byref(struct), shape, ba, cb, hand, *(x.ctypes.data for x in mine),
                                    c_scale.ctypes.data)
            assert n == py.particle_body(arrays, shape, ba, cb, hand, *theirs, scale)
            assert _same(c_scale, scale)
            assert _same(mine[1], theirs[1]) and _same(mine[2], theirs[2])
            unit = arrays.vertices[arrays.vertex_start[shape]:arrays.vertex_start[shape] + n]
            assert _same(mine[0][:n], unit * scale) and (n > 256 or _same(mine[0][:n], theirs[0][:n]))
            kind = int(arrays.kind[shape])
            # its Python form: a view numba returns to Python is boxed as the array it was sliced from
            hull = particle_hull.py_func(arrays, shape, scale)
            assert _same(c.rbs_bounding_radius(kind, mine[2].ctypes.data, mine[0].ctypes.data, n),
                         py.bounding_radius(kind, theirs[2], theirs[0], n, hull))


def test_random_inputs_bit_for_bit(native, table_pair):
    """Φ⁻¹ (both tails and the centre, AS 241's three branches), the aspect-ratio law, Shoemake's quaternion and
    its matrix: the same bits as numba."""
    c = _c(native)
    params = table_pair[0].direct_parameters
    rng = np.random.default_rng(6)
    p = np.concatenate([rng.random(20000), 10.0 ** -rng.uniform(1, 300, 2000), 1.0 - 10.0 ** -rng.uniform(1, 16, 2000),
                        [0.075, 0.925, 0.5, 5e-324]])
    assert _same([c.rbs_normal_quantile(x) for x in p], [py.normal_quantile(x) for x in p])
    arrays = table_pair[0].shape_arrays
    law, cdf = arrays.aspect[0], arrays.aspect_cdf[0]
    u = np.concatenate([rng.random(5000), [0.0, np.nextafter(1.0, 0.0)]])
    assert _same([c.rbs_aspect_ratio(law.ctypes.data, cdf.ctypes.data, x) for x in u],
                 [py.aspect_ratio(law, cdf, x) for x in u])
    for u0, u1, u2 in rng.random((5000, 3)):
        mine, theirs = np.zeros(4), np.zeros(4)
        c.rbs_uniform_quaternion(u0, u1, u2, mine.ctypes.data)
        py.uniform_quaternion(u0, u1, u2, theirs)
        assert _same(mine, theirs)
        R_c, R_py = np.zeros(9), np.zeros((3, 3))
        c.rbs_quaternion_to_matrix(mine.ctypes.data, R_c.ctypes.data)
        py.quaternion_to_matrix(theirs, R_py)
        assert _same(R_c, R_py.ravel())


def _random_tabulated_wall(rng, ns=None, nz=None):
    """A wall of ``ns`` speed nodes in 1 to 400 m/s and ``nz`` sine nodes (random counts where None: 1 to 16 and 2 to
    16), a_nc in (0, 1], q in [-1, 2]."""
    ns = int(rng.integers(1, py.MAX_CONTACT_SPEEDS + 1)) if ns is None else ns
    nz = int(rng.integers(2, py.MAX_CONTACT_SINES + 1)) if nz is None else nz
    speeds = np.unique(rng.uniform(1.0, 400.0, ns))
    sines = np.concatenate([[0.0], np.unique(rng.uniform(0.0, 1.0, nz - 2)), [1.0]])
    values = 1.0 - rng.uniform(0.0, 1.0, (len(speeds), len(sines)))     # (0, 1]
    return py.TabulatedWall(tuple(speeds), tuple(sines), tuple(map(tuple, values)), q=rng.uniform(-1.0, 2.0))


def test_one_collision_bit_for_bit(native):
    """rbs_collide against numba's collide on 10⁴ random states (any body, orientation, contact point, spin and
    wall law: every other state an exponential law, the others a tabulated one, its node counts from the fewest
    to the most; a third not approaching): the same outcome and the same bits of ΔV and ΔΩ, and of the collision's
    work on the wall (rbs_wall_work, numba's wall_work)."""
    c = _c(native)
    rng = np.random.default_rng(7)
    counts = [(1, 2), (1, 16), (16, 2), (py.MAX_CONTACT_SPEEDS, py.MAX_CONTACT_SINES)] + [(None, None)] * 60
    # writable, as the kernels' arrays elsewhere
    tabulated = [np.array(_random_tabulated_wall(rng, *count).as_array()) for count in counts]
    outcomes = {}
    for i in range(N_COLLISIONS):
        q = rng.normal(size=4)
        R = np.zeros((3, 3))
        py.quaternion_to_matrix(q, R)
        K = rng.uniform(0.05, 0.7, 3)
        Kinv = np.ascontiguousarray((R * (1.0 / K)) @ R.T)
        speed = rng.uniform(1.0, 300.0)
        V, W = speed * rng.uniform(-1, 1, 3), speed * rng.uniform(-1, 1, 3) * rng.choice([0.0, 0.1, 1.0, 5.0])
        r = rng.uniform(-1, 1, 3)
        r[1] = -abs(r[1]) if rng.random() < 0.7 else abs(r[1])
        k, p, q = rng.uniform(0.02, 0.3), rng.uniform(0.3, 1.0), rng.uniform(-1.0, 2.0)
        wall = np.array(py.WallMaterial(k, p, q).as_array()) if i % 2 else tabulated[(i // 2) % len(tabulated)]
        dV_c, dW_c, dV_py, dW_py = (np.full(3, 7.0) for _ in range(4))
        code = c.rbs_collide(*(x.ctypes.data for x in (V, W, r, Kinv, wall, dV_c, dW_c)))
        assert code == py.collide(V, W, r, Kinv, wall, dV_py, dW_py)
        assert _same(dV_c, dV_py) and _same(dW_c, dW_py)
        if code in (0, 1):
            work = ctypes.c_double(), ctypes.c_double()
            c.rbs_wall_work(*(x.ctypes.data for x in (V, W, r, dV_c, dW_c)), *map(ctypes.byref, work))
            assert _same([w.value for w in work], py.wall_work(V, W, r, dV_py, dW_py))
        outcomes[code] = outcomes.get(code, 0) + 1
    assert outcomes.get(0, 0) > N_COLLISIONS // 3 and outcomes.get(2, 0) > N_COLLISIONS // 10
    print(f"\none collision: {N_COLLISIONS} states, outcomes {outcomes}, 0 ulp")


# -- whole rebounds -----------------------------------------------------------------------------------------


def _particles(rng, count, spin):
    """Random caller frames: unit normals, V⁻ into the wall at α1 in (0, 90] deg (every 50th exactly normal),
    |V⁻| 10–300 m/s, a 10 µm–10 mm, Ω⁻ of random direction with |Ω⁻|a/|V⁻| = spin, uniforms."""
    for i in range(count):
        n = rng.normal(size=3)
        n /= np.linalg.norm(n)
        t = rng.normal(size=3)
        t -= t.dot(n) * n
        t /= np.linalg.norm(t)
        alpha1 = np.pi / 2 if i % 50 == 0 else rng.uniform(0.01, np.pi / 2)
        speed, a = rng.uniform(10.0, 300.0), 10.0 ** rng.uniform(-5.0, -2.0)
        V = speed * (np.cos(alpha1) * t - np.sin(alpha1) * n) if i % 50 else -speed * n
        omega = rng.normal(size=3)
        omega *= spin * speed / a / np.linalg.norm(omega)
        yield V, n, a, omega, rng.random(py.U_PER_REBOUND)


@pytest.mark.parametrize("spin", SPINS)
def test_whole_rebounds_bit_for_bit(native, table_pair, spin):
    """The direct path of rbs_rebound (RBS_METHOD_DIRECT, the mix of one shape, the model's uniforms as u[1..7])
    against direct_rebound, PER_SHAPE particles of each shape in random caller frames, the same uniforms: the same
    status, and for a rebound the same bits of V⁺ and Ω⁺ — multi-collision sequences included, so every operation
    of the port is numba's (a last-bit difference would grow through them); the result names the direct path
    and the shape; the same bits of the wall work whatever the status (NaN for an invalid hit). Every tenth
    particle also through the direct path alone (the test-only library's rbs_direct_rebound): the same bits."""
    python, c_table = table_pair
    c = _c(native)
    params = python.direct_parameters
    assert python.shapes == tuple(py.SHAPES)       # the small table's shape i is the family of code i
    rng = np.random.default_rng(int(100 * spin) + 1)
    statuses = {}
    for shape in range(4):
        for k, (V, n, a, omega, u) in enumerate(_particles(rng, PER_SHAPE, spin)):
            hit = py.direct_rebound(params, python.shape_arrays, shape, V, omega, n, a, u)
            status, V_py, W_py = hit.status, hit.V, hit.Omega
            result, _ = c_table.hit(c_table.single(shape), V, omega, n, a, direct_uniforms(u), method=METHOD_DIRECT)
            mine = result.status, np.array(result.V[:]), np.array(result.Omega[:])
            assert mine[0] == status
            assert (result.path, result.shape) == ((PATH_DIRECT, shape) if status != INVALID else (PATH_NONE, -1))
            assert _same([result.wall_work_normal, result.wall_work_tangential],
                         [hit.wall_work_normal, hit.wall_work_tangential]), (shape, V, n, a, omega, u)
            if status == py.STATUS_REBOUNDED:
                assert _same(mine[1], V_py) and _same(mine[2], W_py), (shape, V, n, a, omega, u)
                assert result.n_collisions >= 1
            else:
                assert np.isnan(mine[1]).all() and np.isnan(mine[2]).all()
            if k % 10 == 0:
                alone = _direct_c(c, c_table.handle, shape, V, omega, n, a, u)
                assert alone[0] == status and _same(alone[1], mine[1]) and _same(alone[2], mine[2])
            statuses[status] = statuses.get(status, 0) + 1
    assert statuses.get(py.STATUS_REBOUNDED, 0) > 0.9 * 4 * PER_SHAPE
    print(f"\n|Ω⁻|a/|V⁻| = {spin}: {4 * PER_SHAPE} particles, statuses {statuses}, 0 differing")


@pytest.mark.parametrize("spin", SPINS)
def test_grain_rebounds_bit_for_bit(native, table_pair, spin):
    """A user's grain rebounds in C as in numba: rbs_rebound_model_frame_counted against rebound_model_frame over the
    grains' arrays (hulls of 8 to 1000 vertices), 400 particles each at random incidence, the same uniforms:
    the same status, collisions and bits of the wall work and, for a rebound, the same bits of V⁺ and Ω⁺."""
    c = _c(native)
    params = table_pair[0].direct_parameters
    arrays = py.shape_arrays(GRAINS)
    struct = ShapeArrays.of(arrays)
    rng = np.random.default_rng(int(100 * spin) + 21)
    scratch = np.empty(py.SCRATCH_SIZE)
    statuses = {}
    for k in range(400 * len(GRAINS)):
        shape = k % len(GRAINS)
        alpha1, speed = rng.uniform(0.02, np.pi / 2), rng.uniform(20.0, 300.0)
        omega = rng.normal(size=3)
        omega *= spin * speed / np.linalg.norm(omega)
        u = rng.random(py.U_PER_REBOUND)
        state = (speed * np.cos(alpha1), -speed * np.sin(alpha1), *omega)
        theirs = py.rebound_model_frame(params, arrays, shape, *state, u, scratch)
        V, W, work, collisions = np.zeros(3), np.zeros(3), np.zeros(2), ctypes.c_longlong(-1)
        status = c.rbs_rebound_model_frame_counted(params.ctypes.data, ctypes.byref(struct), shape, *state,
                                                   u.ctypes.data, V.ctypes.data, W.ctypes.data,
                                                   ctypes.byref(collisions), work.ctypes.data)
        assert (status, collisions.value) == (theirs.status, theirs.n_collisions)
        assert _same(work, [theirs.wall_work_normal, theirs.wall_work_tangential]), (GRAINS[shape].name, state, u)
        if status == py.STATUS_REBOUNDED:
            assert _same(V, theirs.V) and _same(W, theirs.Omega), (GRAINS[shape].name, state, u)
        statuses[status] = statuses.get(status, 0) + 1
    assert statuses.get(py.STATUS_REBOUNDED, 0) > 0.9 * 400 * len(GRAINS)
    print(f"\n|Ω⁻|a/|V⁻| = {spin}: {400 * len(GRAINS)} grains, statuses {statuses}, 0 differing")


def test_collision_counts_are_numba_s(native, table_pair):
    """rbs_result.n_collisions of the direct path is rebound_model_frame's count: hits in the model frame itself
    (n = +Y, V⁻ in the XY plane with V⁻_x > 0 a power of 2, so the impact frame is the caller's exactly), spinning
    and not."""
    python, c_table = table_pair
    params = python.direct_parameters
    rng = np.random.default_rng(12)
    scratch = np.empty(py.SCRATCH_SIZE)
    counts = set()
    for k in range(400):
        shape, a = k % 4, 1e-3
        V = np.array([2.0 ** rng.integers(3, 9), -rng.uniform(5.0, 300.0), 0.0])
        speed = np.linalg.norm(V)
        omega = rng.normal(size=3) * (speed / a) * (0.0 if k % 3 == 0 else 0.3)
        u = rng.random(py.U_PER_REBOUND)
        result, _ = c_table.hit(c_table.single(shape), V, omega, (0.0, 1.0, 0.0), a, direct_uniforms(u),
                                method=METHOD_DIRECT)
        theirs = py.rebound_model_frame(params, python.shape_arrays, shape, V[0], V[1], *(a * omega), u, scratch)
        assert result.status == theirs.status, k
        if result.status == py.STATUS_REBOUNDED:
            assert result.n_collisions == theirs.n_collisions, (k, result.n_collisions, theirs.n_collisions)
            counts.add(result.n_collisions)
    assert len(counts) > 2, counts


def test_baseline_build_gives_the_same_bits(native_baseline, table_pair, small_table_path):
    """The library built for the x86-64 baseline (the frame's fma() from the C library, not the FMA
    instruction): the same bits as numba on 2000 spinning particles of every shape (rbs_rebound, direct path)."""
    python, _ = table_pair
    table = native_baseline.table(small_table_path)
    rng = np.random.default_rng(11)
    for k, (V, n, a, omega, u) in enumerate(_particles(rng, 2000, 0.3)):
        hit = py.direct_rebound(python.direct_parameters, python.shape_arrays, k % 4, V, omega, n, a, u)
        status, V_py, W_py = hit.status, hit.V, hit.Omega
        mine = table.direct(k % 4, V, omega, n, a, u)
        assert mine[0] == status and (status != py.STATUS_REBOUNDED or (_same(mine[1], V_py) and _same(mine[2], W_py)))


# -- hostile inputs -----------------------------------------------------------------------------------------

GOOD = dict(shape=1, V=(100.0, -100.0, 0.0), omega=(0.0, 0.0, 0.0), n=(0.0, 1.0, 0.0), a=1e-3, u=np.full(7, 0.5))
CHANGES = [
    dict(V=(100.0, 50.0, 0.0)), dict(V=(0.0, 0.0, 0.0)), dict(V=(np.nan, -100.0, 0.0)), dict(V=(np.inf, -100.0, 0.0)),
    dict(n=(0.0, 1.1, 0.0)), dict(n=(0.0, np.nan, 0.0)), dict(a=0.0), dict(a=-1.0), dict(a=np.inf), dict(a=np.nan),
    dict(omega=(0.0, np.nan, 0.0)), dict(omega=(np.inf, 0.0, 0.0)), dict(omega=(1e308, 1e308, 0.0)),
    dict(u=np.full(7, 1.0)), dict(u=np.full(7, np.nan)), dict(u=np.full(7, -1e-300)),
]


@pytest.mark.parametrize("change", CHANGES)
def test_bad_input_is_invalid_with_nan(native, table_pair, change):
    """Every input outside its range: RBS_INVALID and NaN outputs, from rbs_rebound's direct path (the mix of one
    shape) and from the direct path alone; numba agrees."""
    c = _c(native)
    args = dict(GOOD, **change)
    mine = table_pair[1].direct(args["shape"], args["V"], args["omega"], args["n"], args["a"], args["u"])
    alone = _direct_c(c, table_pair[1].handle, args["shape"], args["V"], args["omega"], args["n"], args["a"],
                      args["u"])
    for status, V, W in (mine, alone):
        assert status == py.STATUS_INVALID and np.isnan(V).all() and np.isnan(W).all()
    theirs = py.direct_rebound(table_pair[0].direct_parameters, table_pair[0].shape_arrays, args["shape"],
                               np.asarray(args["V"], float), np.asarray(args["omega"], float),
                               np.asarray(args["n"], float), args["a"], args["u"])
    assert theirs[0] == py.STATUS_INVALID


@pytest.mark.parametrize("change", [dict(shape=4), dict(shape=-1), dict(V=None), dict(omega=None), dict(n=None),
                                    dict(u=None)])
def test_bad_arguments_of_the_direct_path_alone(native, table_pair, change):
    """The direct path alone (rbs_direct_rebound, internal) given a shape code outside the table's or a NULL
    pointer: RBS_INVALID and NaN outputs (numba agrees on the shape codes)."""
    args = dict(GOOD, **change)
    status, V, W = _direct_c(_c(native), table_pair[1].handle, args["shape"], args["V"], args["omega"], args["n"],
                             args["a"], args["u"])
    assert status == py.STATUS_INVALID and np.isnan(V).all() and np.isnan(W).all()
    if all(args[k] is not None for k in ("V", "omega", "n", "u")):
        theirs = py.direct_rebound(table_pair[0].direct_parameters, table_pair[0].shape_arrays, args["shape"],
                                   np.asarray(args["V"], float), np.asarray(args["omega"], float),
                                   np.asarray(args["n"], float), args["a"], args["u"])
        assert theirs[0] == py.STATUS_INVALID


def test_null_table_and_outputs(native, table_pair):
    """The direct path alone: a NULL table: RBS_INVALID with NaN; a NULL output: RBS_INVALID, NaN in the other
    (rbs_rebound's NULL arguments: test_native_spin)."""
    c = _c(native)
    status, V, W = _direct_c(c, None, GOOD["shape"], GOOD["V"], GOOD["omega"], GOOD["n"], GOOD["a"], GOOD["u"])
    assert status == py.STATUS_INVALID and np.isnan(V).all() and np.isnan(W).all()
    args = [np.asarray(GOOD[k], dtype=np.float64) for k in ("V", "omega", "n")]
    out = np.zeros(3)
    for outputs in ((None, out), (out, None)):
        out[:] = 0.0
        status = c.rbs_direct_rebound(table_pair[1].handle, 1, *(x.ctypes.data for x in args), 1e-3,
                                      GOOD["u"].ctypes.data, *(_ptr(x) for x in outputs))
        assert status == py.STATUS_INVALID
        assert np.isnan(out).all()


def test_minus_zero_uniform_is_taken_as_numba_takes_it(native, table_pair):
    """u = −0 is in [0, 1) for the direct model alone (numba's direct_rebound: 0.0 <= u): a rebound, the same bits;
    a hit's 13 uniforms must be in [+0, 1) on every path (numba's rebound, rbs_rebound): −0 there is refused."""
    python, c_table = table_pair
    u = np.full(7, 0.5)
    u[3] = -0.0
    theirs = py.direct_rebound(python.direct_parameters, python.shape_arrays, 2, np.asarray(GOOD["V"]),
                               np.asarray(GOOD["omega"]), np.asarray(GOOD["n"]), GOOD["a"], u)
    status, V, W = _direct_c(_c(native), c_table.handle, 2, GOOD["V"], GOOD["omega"], GOOD["n"], GOOD["a"], u)
    assert status == theirs.status == py.STATUS_REBOUNDED and _same(V, theirs.V) and _same(W, theirs.Omega)
    hit = py.rebound(python.kernel_data, python.direct_parameters, python.shape_arrays, python.model_shapes,
                     py.mix_cdf(python, "cut_prism"), GOOD["V"], GOOD["omega"], GOOD["n"], GOOD["a"],
                     direct_uniforms(u), py.METHOD_DIRECT)
    status, V, W = c_table.direct(2, GOOD["V"], GOOD["omega"], GOOD["n"], GOOD["a"], u)
    assert status == hit.status == py.STATUS_INVALID and np.isnan(V).all() and np.isnan(W).all()
