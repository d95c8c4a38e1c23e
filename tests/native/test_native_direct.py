"""The direct model in C (native/src/direct_path.c and the kernels it calls: shapes.c, collision.c, flight.c,
body_rebound.c, runtime.c) against numba, bit for bit for the same inputs and uniforms: the parameter array the
loader builds, the pieces (shapes, a particle's body, the normal quantile, the uniform quaternion, one
collision), whole rebounds in random caller frames, user grains of 8 to 256 hull vertices, and hostile inputs
(RBS_INVALID with NaN, never a crash)."""

from __future__ import annotations

import ctypes
import re

import h5py
import numpy as np
import pytest

from tests.helpers import python_side as py
from tests.helpers.native_library import ERR_FORMAT, NATIVE, ShapeArrays

SPINS = (0.0, 0.02, 0.3, 1.0)     # |Ω⁻| a / |V⁻| of the whole-rebound comparisons
PER_SHAPE = 2000                  # particles per shape and spin
N_COLLISIONS = 10_000
LAW = py.AspectRatioLaw()
# user grains: hulls of 8 to 256 vertices in both hands, of fixed proportions or stretched by the families' law
GRAINS = [py.hull_grain(f"grain_{n}", n, seed=n, aspect=LAW if n in (24, 256) else None, both_hands=True)
          for n in (8, 24, 64, 256)] + [py.cloud_grain("cloud", 300, seed=3, aspect=LAW)]

_d, _i, _p = ctypes.c_double, ctypes.c_int, ctypes.c_void_p


def _c(native):
    """The library with the model's functions typed (the internal kernels are exported for these tests)."""
    c = native.c
    c.rbs_direct_rebound.argtypes = [_p, _i, _p, _p, _p, _d, _p, _p, _p]
    c.rbs_direct_rebound.restype = _i
    c.rbs_collide.argtypes = [_p] * 7
    c.rbs_collide.restype = _i
    c.rbs_body_vertices.argtypes = [_i, _d, _d, _d, _d, _d, _p]
    c.rbs_body_vertices.restype = _i
    c.rbs_bounding_radius.argtypes = [_i, _p, _p, _i]
    c.rbs_bounding_radius.restype = _d
    c.rbs_particle_body.argtypes = [_p, _i, _d, _d, _d, _p, _p, _p]
    c.rbs_particle_body.restype = _i
    c.rbs_rebound_model_frame.argtypes = [_p, _p, _i, _d, _d, _d, _d, _d, _p, _p, _p]
    c.rbs_rebound_model_frame.restype = _i
    c.rbs_normal_quantile.argtypes = [_d]
    c.rbs_normal_quantile.restype = _d
    c.rbs_aspect_ratio.argtypes = [_p, _p, _d]
    c.rbs_aspect_ratio.restype = _d
    c.rbs_uniform_quaternion.argtypes = [_d, _d, _d, _p]
    c.rbs_uniform_quaternion.restype = None
    c.rbs_quaternion_to_matrix.argtypes = [_p, _p]
    c.rbs_quaternion_to_matrix.restype = None
    return c


def _ptr(x):
    return None if x is None else x.ctypes.data


def _direct_c(c, table, shape, V, omega, n, a, u):
    """(status, V⁺, Ω⁺) of rbs_direct_rebound."""
    V_out, W_out = np.zeros(3), np.zeros(3)
    arrays = [None if x is None else np.ascontiguousarray(x, dtype=np.float64) for x in (V, omega, n, u)]
    status = c.rbs_direct_rebound(table, shape, *(_ptr(x) for x in arrays[:3]), a, _ptr(arrays[3]), _ptr(V_out),
                                  _ptr(W_out))
    return status, V_out, W_out


def _same(a, b):
    """The same float64 bits."""
    bits = (np.asarray(x, dtype=np.float64).view(np.uint64) for x in (a, b))
    return np.array_equal(*bits)


def _old_table(small_table_path, tmp_path, name, **changes):
    """A copy of the small table without the direct model's attributes (a table of 3.0–3.2), with ``changes``
    to its grid attributes (None deletes)."""
    path = tmp_path / name
    path.write_bytes(small_table_path.read_bytes())
    with h5py.File(path, "r+") as f:
        f.attrs["format_version"] = np.array([3, 2], dtype=np.int64)      # its grid/law: restitution_k, _p
        del f["shapes"]                                                    # and no group shapes (3.4)
        law = f["grid/law"][:2]
        del f["grid/law"]
        f["grid"].create_dataset("law", data=law, fletcher32=True)
        for key, value in changes.items():
            if value is None:
                del f["grid"].attrs[key]
            else:
                f["grid"].attrs[key] = value
    return path


OLD = dict.fromkeys(("aspect_ratio_mean", "aspect_ratio_sd", "aspect_ratio_low", "aspect_ratio_high", "contact_tol",
                     "set_tol", "max_steps", "second_moment_factors", "friction_q"))


# -- the parameters -------------------------------------------------------------------------------------

_DEFINE = re.compile(r"^#define (\w+) \(?(\w+(?: \+ \w+)*)\)?(?=\s|$)", flags=re.M)


def _integer_defines(*headers) -> dict:
    """The #defines of the headers whose value is an integer or a sum of integers and earlier such names."""
    values = {}
    for header in headers:
        for name, expression in _DEFINE.findall(header.read_text()):
            terms = expression.split(" + ")
            if all(t.isdigit() or t in values for t in terms):
                values[name] = sum(int(t) if t.isdigit() else values[t] for t in terms)
    return values


def test_the_parameter_layout_is_direct_model_s(table_pair):
    """runtime.h's layout is direct_model.runtime's: every P_* offset, U_* index and N_PARAMS, which both sides
    derive from the shape count (P_KFAC, then one second-moment factor per shape code); the loader's array
    has N_PARAMS elements."""
    c = _integer_defines(NATIVE / "include" / "rebound_scatter.h", NATIVE / "src" / "shapes.h",
                         NATIVE / "src" / "runtime.h")
    c["U_PER_REBOUND"] = c["RBS_U_PER_REBOUND"]
    layout = re.compile(r"P_[A-Z_]+|U_[A-Z_]+|N_PARAMS")
    python = {name: value for name, value in vars(py.direct_runtime).items() if layout.fullmatch(name)}
    assert {"P_KFAC", "N_PARAMS", "U_AXIS"} <= set(python)
    assert {name: value for name, value in c.items() if layout.fullmatch(name)} == python
    assert c["N_PARAMS"] == c["P_KFAC"] + len(py.SHAPES) == c["P_KFAC"] + c["RBS_N_FAMILIES"]
    assert table_pair[1].kernel_array("direct_parameters").size == python["N_PARAMS"]



def test_the_parameter_array_is_surrogate_s(native, table_pair, small_table_path, tmp_path):
    """The loader's "direct_parameters" equal surrogate's table.direct_parameters bit for bit: on a table that
    records them, and on an older one (the configuration's aspect-ratio law, the tolerances and factors every
    build used, q = 1); Φ(low) and Φ(high) from libm's erfc on both sides."""
    python, c_table = table_pair
    assert _same(c_table.kernel_array("direct_parameters"), python.direct_parameters)
    old = _old_table(small_table_path, tmp_path, "old.h5", **OLD)
    expected = py.load(old).direct_parameters
    assert _same(native.table(old).kernel_array("direct_parameters"), expected)
    assert _same(expected, python.direct_parameters)


@pytest.mark.parametrize("law", [
    "aspect_ratio = {mean = 0.75, sd = 0.25, low = 0.4, high = 0.95}",
    "[simulation.aspect_ratio]\nmean = 0.75\nsd = 0.25 # a comment\nlow = 0.4\nhigh = 0.95",
])
def test_an_old_table_takes_the_configuration_s_aspect_law(native, small_table_path, tmp_path, law):
    """Without the aspect_ratio_* attributes the law comes from the build's configuration (TOML): the inline
    table tablegen writes, or a [simulation.aspect_ratio] table; the same bits as surrogate."""
    path = _old_table(small_table_path, tmp_path, "config.h5", **OLD)
    with h5py.File(path, "r+") as f:
        lines = str(f.attrs["config"]).split("\n")
        inline = [k for k, line in enumerate(lines) if line.startswith("aspect_ratio")]
        assert len(inline) == 1
        if law.startswith("["):
            del lines[inline[0]]
            lines += ["", law]
        else:
            lines[inline[0]] = law
        f.attrs["config"] = "\n".join(lines)
    expected = py.load(path).direct_parameters
    assert expected[:4].tolist() == [0.75, 0.25, 0.4, 0.95]
    assert _same(native.table(path).kernel_array("direct_parameters"), expected)


def test_a_table_without_the_factors_has_no_direct_model(native, small_table_path, tmp_path):
    """An old table built at κ ≠ 0.3 does not record its second-moment factors: it loads, has no
    "direct_parameters" (RBS_ERR_ARGUMENT), and rbs_direct_rebound gives RBS_INVALID with NaN."""
    path = _old_table(small_table_path, tmp_path, "kappa.h5", **OLD, kappa=0.25)
    assert py.load(path).direct_parameters is None
    table = native.table(path)
    with pytest.raises(KeyError):
        table.kernel_array("direct_parameters")
    status, V, W = _direct_c(_c(native), table.handle, 1, (100.0, -100.0, 0.0), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0), 1e-3,
                             np.full(7, 0.5))
    assert status == py.STATUS_INVALID and np.isnan(V).all() and np.isnan(W).all()


@pytest.mark.parametrize("changes, message", [
    (dict(contact_tol=-1.0), "The 'contact_tol' parameter must be finite and > 0 (units of a); got -1"),
    (dict(aspect_ratio_low=0.0), "The aspect-ratio bounds must satisfy 0 < low < high <= 1; got low=0"),
    (dict(second_moment_factors=np.array([0.2, 0.3, 1.5, 0.2])), "The 'second_moment_factors' parameter must be 4 "
                                                                  "numbers in (0, 1)"),
    (dict(max_steps=0), "The 'max_steps' parameter must be an integer in [1, 2**53); got 0"),
])
def test_parameters_out_of_range_refuse_the_table(native, small_table_path, tmp_path, changes, message):
    """A parameter out of range: both readers refuse the table, naming the file and the value."""
    path = _old_table(small_table_path, tmp_path, "bad.h5", **changes)
    with pytest.raises(Exception, match="the direct model's parameters are out of range"):
        py.load(path)
    code, table, text = native.open(path)
    assert code == ERR_FORMAT and table is None
    assert text.startswith(f"{path}: the direct model's parameters are out of range: {message}")


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
    half-extents and radius as numba's, for the table's families and the user grains, random ratios and hands."""
    c = _c(native)
    rng = np.random.default_rng(4)
    for arrays in (table_pair[0].shape_arrays, py.shape_arrays(GRAINS)):
        struct = ShapeArrays.of(arrays)
        for trial in range(1000):
            shape = trial % arrays.n_shapes
            ba, cb = rng.uniform(0.5, 1.0, 2)
            hand = (1.0, -1.0)[trial % 8 // 4]
            out = [(np.zeros((256, 3)), np.zeros(3), np.zeros(3)) for _ in range(2)]
            n = c.rbs_particle_body(ctypes.byref(struct), shape, ba, cb, hand, *(x.ctypes.data for x in out[0]))
            assert n == py.particle_body(arrays, shape, ba, cb, hand, *out[1])
            assert all(_same(mine, theirs) for mine, theirs in zip(*out))
            kind = int(arrays.kind[shape])
            assert _same(c.rbs_bounding_radius(kind, out[0][2].ctypes.data, out[0][0].ctypes.data, n),
                         py.bounding_radius(kind, out[1][2], out[1][0], n))


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


def test_one_collision_bit_for_bit(native):
    """rbs_collide against numba's collide on 10⁴ random states (any body, orientation, contact point, spin and
    wall law; a third not approaching): the same outcome and the same bits of ΔV and ΔΩ."""
    c = _c(native)
    rng = np.random.default_rng(7)
    outcomes = {}
    for _ in range(N_COLLISIONS):
        q = rng.normal(size=4)
        R = np.zeros((3, 3))
        py.quaternion_to_matrix(q, R)
        K = rng.uniform(0.05, 0.7, 3)
        Kinv = np.ascontiguousarray((R * (1.0 / K)) @ R.T)
        speed = rng.uniform(1.0, 300.0)
        V, W = speed * rng.uniform(-1, 1, 3), speed * rng.uniform(-1, 1, 3) * rng.choice([0.0, 0.1, 1.0, 5.0])
        r = rng.uniform(-1, 1, 3)
        r[1] = -abs(r[1]) if rng.random() < 0.7 else abs(r[1])
        wall = np.array([rng.uniform(0.02, 0.3), rng.uniform(0.3, 1.0), rng.uniform(-1.0, 2.0)])
        dV_c, dW_c, dV_py, dW_py = (np.full(3, 7.0) for _ in range(4))
        code = c.rbs_collide(*(x.ctypes.data for x in (V, W, r, Kinv, wall, dV_c, dW_c)))
        assert code == py.collide(V, W, r, Kinv, wall, dV_py, dW_py)
        assert _same(dV_c, dV_py) and _same(dW_c, dW_py)
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
    """rbs_direct_rebound against direct_rebound, PER_SHAPE particles of each shape in random caller frames,
    the same uniforms: the same status, and for a rebound the same bits of V⁺ and Ω⁺ — multi-collision sequences
    included, so every operation of the port is numba's (a last-bit difference would grow through them)."""
    python, c_table = table_pair
    c = _c(native)
    params = python.direct_parameters
    rng = np.random.default_rng(int(100 * spin) + 1)
    statuses = {}
    for shape in range(4):
        for V, n, a, omega, u in _particles(rng, PER_SHAPE, spin):
            status, V_py, W_py = py.direct_rebound(params, python.shape_arrays, shape, V, omega, n, a, u)
            mine = _direct_c(c, c_table.handle, shape, V, omega, n, a, u)
            assert mine[0] == status
            if status == py.STATUS_REBOUNDED:
                assert _same(mine[1], V_py) and _same(mine[2], W_py), (shape, V, n, a, omega, u)
            else:
                assert np.isnan(mine[1]).all() and np.isnan(mine[2]).all()
            statuses[status] = statuses.get(status, 0) + 1
    assert statuses.get(py.STATUS_REBOUNDED, 0) > 0.9 * 4 * PER_SHAPE
    print(f"\n|Ω⁻|a/|V⁻| = {spin}: {4 * PER_SHAPE} particles, statuses {statuses}, 0 differing")


@pytest.mark.parametrize("spin", SPINS)
def test_grain_rebounds_bit_for_bit(native, table_pair, spin):
    """A user's grain rebounds in C as in numba: rbs_rebound_model_frame against rebound_model_frame over the
    grains' arrays (hulls of 8 to 256 vertices), 400 particles each at random incidence, the same uniforms:
    the same status and, for a rebound, the same bits of V⁺ and Ω⁺."""
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
        V, W = np.zeros(3), np.zeros(3)
        status = c.rbs_rebound_model_frame(params.ctypes.data, ctypes.byref(struct), shape, *state, u.ctypes.data,
                                           V.ctypes.data, W.ctypes.data)
        assert status == theirs[0]
        if status == py.STATUS_REBOUNDED:
            assert _same(V, theirs[3:6]) and _same(W, theirs[6:9]), (GRAINS[shape].name, state, u)
        statuses[status] = statuses.get(status, 0) + 1
    assert statuses.get(py.STATUS_REBOUNDED, 0) > 0.9 * 400 * len(GRAINS)
    print(f"\n|Ω⁻|a/|V⁻| = {spin}: {400 * len(GRAINS)} grains, statuses {statuses}, 0 differing")


def test_baseline_build_gives_the_same_bits(native_baseline, table_pair, small_table_path):
    """The library built for the x86-64 baseline (the frame's fma() from the C library, not the FMA
    instruction): the same bits as numba on 2000 spinning particles of every shape."""
    python, _ = table_pair
    c, table = _c(native_baseline), native_baseline.table(small_table_path)
    rng = np.random.default_rng(11)
    for k, (V, n, a, omega, u) in enumerate(_particles(rng, 2000, 0.3)):
        status, V_py, W_py = py.direct_rebound(python.direct_parameters, python.shape_arrays, k % 4, V, omega, n, a, u)
        mine = _direct_c(c, table.handle, k % 4, V, omega, n, a, u)
        assert mine[0] == status and (status != py.STATUS_REBOUNDED or (_same(mine[1], V_py) and _same(mine[2], W_py)))


# -- hostile inputs -----------------------------------------------------------------------------------------

GOOD = dict(shape=1, V=(100.0, -100.0, 0.0), omega=(0.0, 0.0, 0.0), n=(0.0, 1.0, 0.0), a=1e-3, u=np.full(7, 0.5))


@pytest.mark.parametrize("change", [
    dict(V=(100.0, 50.0, 0.0)), dict(V=(0.0, 0.0, 0.0)), dict(V=(np.nan, -100.0, 0.0)), dict(V=(np.inf, -100.0, 0.0)),
    dict(n=(0.0, 1.1, 0.0)), dict(n=(0.0, np.nan, 0.0)), dict(a=0.0), dict(a=-1.0), dict(a=np.inf), dict(a=np.nan),
    dict(omega=(0.0, np.nan, 0.0)), dict(omega=(np.inf, 0.0, 0.0)), dict(omega=(1e308, 1e308, 0.0)),
    dict(shape=4), dict(shape=-1), dict(u=np.full(7, 1.0)), dict(u=np.full(7, np.nan)), dict(u=np.full(7, -1e-300)),
    dict(V=None), dict(omega=None), dict(n=None), dict(u=None),
])
def test_bad_input_is_invalid_with_nan(native, table_pair, change):
    """Every input outside its range, or a NULL pointer: RBS_INVALID and NaN outputs (numba agrees where it takes
    the input at all)."""
    c = _c(native)
    args = dict(GOOD, **change)
    status, V, W = _direct_c(c, table_pair[1].handle, args["shape"], args["V"], args["omega"], args["n"], args["a"],
                             args["u"])
    assert status == py.STATUS_INVALID and np.isnan(V).all() and np.isnan(W).all()
    if all(args[k] is not None for k in ("V", "omega", "n", "u")):
        theirs = py.direct_rebound(table_pair[0].direct_parameters, table_pair[0].shape_arrays, args["shape"],
                                   np.asarray(args["V"], float),
                                   np.asarray(args["omega"], float), np.asarray(args["n"], float), args["a"],
                                   args["u"])
        assert theirs[0] == py.STATUS_INVALID


def test_null_table_and_outputs(native, table_pair):
    """A NULL table: RBS_INVALID with NaN; a NULL output: RBS_INVALID, NaN in the other."""
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
    """u = −0 is in [0, 1) for the direct model (numba's 0.0 <= u): a rebound, the same bits."""
    c = _c(native)
    u = np.full(7, 0.5)
    u[3] = -0.0
    status, V, W = _direct_c(c, table_pair[1].handle, 2, GOOD["V"], GOOD["omega"], GOOD["n"], GOOD["a"], u)
    theirs = py.direct_rebound(table_pair[0].direct_parameters, table_pair[0].shape_arrays, 2, np.asarray(GOOD["V"]),
                               np.asarray(GOOD["omega"]),
                               np.asarray(GOOD["n"]), GOOD["a"], u)
    assert status == theirs[0] == py.STATUS_REBOUNDED and _same(V, theirs[1]) and _same(W, theirs[2])
