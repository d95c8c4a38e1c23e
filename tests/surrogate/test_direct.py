"""The direct model at run time (surrogate.kernels.direct_path, surrogate.sample_direct): one law in any caller's
frame, with the table's parameters; the model's invariants through it; bad inputs.

The law against `tablegen simulate` at 16 incident states: test_direct_law.py. KS bounds here: those of
tests/helpers/direct_law.py (Bonferroni over the module's comparisons, FAMILY_ALPHA = 1e-3), fixed seeds.
"""

import subprocess
import sys
import threading

import h5py
import numba
import numpy as np
import pytest
from scipy import stats

import surrogate
from data_schema.samples import STATUS_FAILED, STATUS_INVALID, STATUS_REBOUNDED, STATUS_TRAPPED
from direct_model.runtime import U_PER_REBOUND, aspect_ratio, model_parameters
from direct_model.shape_arrays import family_shape_arrays
from direct_model.shapes import SHAPES, AspectRatioLaw, second_moment_factors
from direct_model.simulate import DEFAULT_CONTACT_TOL, DEFAULT_MAX_STEPS, DEFAULT_SET_TOL
from direct_model.wall import CORUNDUM_ON_STEEL, WallMaterial
from surrogate.kernels import direct_rebound

from tests.helpers.direct_law import A, kernel_in_frame, ks_bound, random_frame

ROTATION_COMPARISONS = 6 * len(SHAPES)        # KS comparisons of test_rotating_the_frame_rotates_the_outputs


@pytest.fixture(scope="module")
def params(small_table):
    return small_table.direct_parameters


@pytest.fixture(scope="module")
def shapes(small_table):
    return small_table.shape_arrays


@pytest.mark.parametrize("shape", SHAPES)
def test_rotating_the_frame_rotates_the_outputs(small_table, shape):
    """The same hit in two caller's frames (the model frame and a random one): the outputs, rotated back,
    have one law (KS per component, bound from n), and particles with the same uniforms agree to 1e-9 of
    |V⁻| but for a few (a multi-collision sequence can amplify a last-bit difference of the frame; all 4000
    agree at these seeds)."""
    state = (shape, 55.0, 170.0, (0.2, -0.1, 0.25))
    V0, W0, s0 = kernel_in_frame(small_table, *state, np.eye(3), seed=21)
    V1, W1, s1 = kernel_in_frame(small_table, *state, random_frame(5), seed=21)
    ok0, ok1 = s0 == STATUS_REBOUNDED, s1 == STATUS_REBOUNDED
    bound = ks_bound(ok0.sum(), ok1.sum(), ROTATION_COMPARISONS)
    for k in range(3):
        assert stats.ks_2samp(V0[ok0, k], V1[ok1, k]).statistic < bound
        assert stats.ks_2samp(W0[ok0, k], W1[ok1, k]).statistic < bound
    both = ok0 & ok1
    same = np.all(np.abs(V0[both] - V1[both]) < 1e-9, axis=1)
    assert same.mean() > 0.99 and (s0 == s1).mean() > 0.99


@pytest.mark.parametrize("shape", SHAPES)
def test_a_rebound_never_adds_energy(params, shapes, shape):
    """Through the kernel, in a random frame: ½|V⁺|² + ½ K_min |Ω⁺ a|² ≤ ½|V⁻|² + ½ K_max |Ω⁻ a|² per unit mass
    (lengths in m), K_min, K_max the extreme principal values of J/(m a²) of the particle drawn from the same
    uniforms: the kinetic energy ½|V|² + ½ Ω·JΩ/m lies between these bounds, and collisions never add to it. The
    hit's wall work (m²/s², each part ≥ 0) is the energy lost: within the bounds of E⁻ − E⁺."""
    rng = np.random.default_rng(31)
    code = SHAPES.index(shape)
    kfac, law, cdf = second_moment_factors()[code], shapes.aspect[code], shapes.aspect_cdf[code]
    u = np.empty(U_PER_REBOUND)
    checked = 0
    for i in range(400):
        Q = random_frame(100 + i)
        V = Q @ (rng.normal(size=3) * [100.0, 0.0, 100.0] - [0.0, rng.uniform(30.0, 250.0), 0.0])
        W = rng.normal(size=3) * 150.0 / A * (i % 3) / 2             # |Ω⁻|a/|V⁻| around 0, 1, 2
        u[:] = rng.random(U_PER_REBOUND)
        hit = direct_rebound(params, shapes, code, V, W, Q[:, 1], A, u)
        status, V_out, W_out = hit.status, hit.V, hit.Omega
        if status != STATUS_REBOUNDED:
            continue
        b = aspect_ratio(law, cdf, u[3])
        c = b * aspect_ratio(law, cdf, u[4])
        K = kfac * np.array([b * b + c * c, 1.0 + c * c, 1.0 + b * b])
        before = 0.5 * V @ V + 0.5 * K.max() * (W @ W) * A * A
        after = 0.5 * np.dot(V_out, V_out) + 0.5 * K.min() * np.dot(W_out, W_out) * A * A
        assert after <= before * (1 + 1e-12), i
        lost_most = before - after
        lost_least = 0.5 * V @ V + 0.5 * K.min() * (W @ W) * A * A - (after + 0.5 * (K.max() - K.min()) * np.dot(
            W_out, W_out) * A * A)
        work = hit.wall_work_normal + hit.wall_work_tangential
        assert hit.wall_work_normal > 0.0 and hit.wall_work_tangential >= 0.0, i
        assert lost_least - 1e-12 * before <= work <= lost_most + 1e-12 * before, i
        checked += 1
    assert checked > 350


def test_near_sphere_keeps_angular_momentum_about_the_contact_point():
    """An ellipsoid with b/a, c/b ∈ [0.999999, 1] and Ω⁻ = 0 collides once at the point −a n below its centre:
    (2/5) a² Ω⁺ + a n × V⁺ = a n × V⁻ (per unit mass) in the caller's frame, to the sphere's asphericity."""
    law = AspectRatioLaw(1.0, 1e-3, 0.999999, 1.0)
    near = model_parameters(law, 0.3, 1000, CORUNDUM_ON_STEEL, 1e-10, 1e-9, 100_000, second_moment_factors())
    near_shapes = family_shape_arrays(0.3, law, second_moment_factors())
    rng = np.random.default_rng(41)
    for i in range(200):
        Q = random_frame(300 + i)
        n = Q[:, 1]
        V = Q @ (rng.normal(size=3) * [80.0, 0.0, 80.0] - [0.0, rng.uniform(40.0, 250.0), 0.0])
        hit = direct_rebound(near, near_shapes, 0, V, np.zeros(3), n, A, rng.random(U_PER_REBOUND))
        status, V_out, W_out = hit.status, hit.V, hit.Omega
        assert status == STATUS_REBOUNDED
        before = A * np.cross(n, V)
        after = 0.4 * A * A * np.asarray(W_out) + A * np.cross(n, V_out)
        np.testing.assert_allclose(after, before, rtol=0, atol=1e-5 * A * np.linalg.norm(V))


def test_same_seed_same_bits_whatever_the_threads(small_table):
    rng = np.random.default_rng(51)
    n = 2500                                      # three chunks of CHUNK_ROWS
    V = rng.normal(size=(n, 3)) * [60.0, 0.0, 60.0] - np.c_[np.zeros(n), rng.uniform(30.0, 250.0, n), np.zeros(n)]
    W = rng.normal(size=(n, 3)) * 1e5
    shapes = rng.integers(0, 4, n)
    runs = []
    for threads in (1, numba.config.NUMBA_NUM_THREADS):
        numba.set_num_threads(threads)
        runs.append(surrogate.sample_direct(small_table, V, [0.0, 1.0, 0.0], A, np.array(SHAPES)[shapes],
                                            random_state=3, omega=W))
    numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
    for one, many in zip(*runs):
        np.testing.assert_array_equal(one, many)
    assert set(np.unique(runs[0].status)) <= {STATUS_REBOUNDED, STATUS_TRAPPED, STATUS_FAILED}
    assert np.all(runs[0].wall_work_normal > 0.0) and np.all(runs[0].wall_work_tangential >= 0.0)


def test_the_parameters_are_the_table_s(small_table_path, small_table, tmp_path):
    """A table records the model's parameters (its rows /model/parameters and /wall/parameters, read by name): the
    runtime runs the model with them, bit for bit those of the build (the configuration, the simulate defaults,
    s at its κ); a row of other values gives other parameters."""
    mine = small_table.direct_parameters
    expected = model_parameters(AspectRatioLaw(), 0.3, 1000, CORUNDUM_ON_STEEL, DEFAULT_CONTACT_TOL, DEFAULT_SET_TOL,
                                DEFAULT_MAX_STEPS, second_moment_factors(0.3))
    np.testing.assert_array_equal(mine, expected)
    other = tmp_path / "other.h5"
    other.write_bytes(small_table_path.read_bytes())
    with h5py.File(other, "r+") as f:
        for group, changes in (("model", {"contact_tol": 2e-10, "max_steps": 5000}),
                               ("wall", {"q": 0.5})):
            row = f[group]["parameters"][()]
            for name, value in changes.items():
                row[name] = value
            f[group]["parameters"][...] = row
    table = surrogate.load(other)
    assert table.wall == WallMaterial(0.1, 0.61, 0.5, CORUNDUM_ON_STEEL.name, speed_range_m_s=(50.0, 300.0))
    np.testing.assert_array_equal(table.direct_parameters, model_parameters(
        AspectRatioLaw(), 0.3, 1000, table.wall, 2e-10, DEFAULT_SET_TOL, 5000, second_moment_factors(0.3)))


@pytest.mark.parametrize("change", [
    dict(V=(100.0, 50.0, 0.0)), dict(V=(0.0, 0.0, 0.0)), dict(V=(np.nan, -100.0, 0.0)), dict(n=(0.0, 1.1, 0.0)),
    dict(n=(0.0, np.nan, 0.0)), dict(a=0.0), dict(a=np.inf), dict(omega=(0.0, np.nan, 0.0)), dict(shape=4),
    dict(shape=-1), dict(u=np.full(U_PER_REBOUND, 1.0)), dict(u=np.full(U_PER_REBOUND - 1, 0.5)),
])
def test_bad_kernel_input_is_invalid_with_nan(params, shapes, change):
    args = dict(V=(100.0, -100.0, 0.0), n=(0.0, 1.0, 0.0), a=A, omega=(0.0, 0.0, 0.0), shape=1,
                u=np.full(U_PER_REBOUND, 0.5))
    assert direct_rebound(params, shapes, **args)[0] == STATUS_REBOUNDED
    args.update(change)
    hit = direct_rebound(params, shapes, **args)
    status, V_out, W_out = hit.status, hit.V, hit.Omega
    assert status == STATUS_INVALID and np.isnan(V_out).all() and np.isnan(W_out).all()


def test_a_state_whose_flight_underflows_ends(params, shapes):
    """|V⁻| ~ 1e-160 m/s underflows the free flight's invariants to NaN; the kernel used to loop for ever in
    the AGM of direct_model.rotation. It must end (here: STATUS_FAILED with NaN), as the C twin does. Run
    in a daemon thread so that a regression fails after the timeout instead of hanging the suite."""
    n = np.array([0.34523645, 0.41333518, 0.84259469])
    args = (params, shapes, 0, (-3.77668607e-161, -7.47222348e-161, -5.46831954e-161),
            (-1.50979875e-158, -2.14919893e-158, 1.32388636e-157), tuple(n / np.linalg.norm(n)), 8.635989814806125e-4,
            np.array([0.29739859, 0.48706842, 0.90535956, 0.39282742, 0.62082272, 0.55552379, 0.17284464]))
    result = []
    worker = threading.Thread(target=lambda: result.append(direct_rebound(*args)), daemon=True)
    worker.start()
    worker.join(timeout=120.0)
    assert result, "direct_rebound did not return within 120 s"
    status, V_out, W_out = result[0].status, result[0].V, result[0].Omega
    assert status in (STATUS_REBOUNDED, STATUS_FAILED)
    assert np.isfinite(V_out).all() if status == STATUS_REBOUNDED else np.isnan(V_out).all()


@pytest.mark.parametrize("change, message", [
    (dict(velocity=[[100.0, 50.0, 0.0]]), "The 'velocity' at index 0 does not move into the wall: V.n = 50.0 m/s"),
    (dict(normal=[0.0, 2.0, 0.0]), "The 'normal' at index 0 has length 2.0"),
    (dict(half_size=-1.0), "The 'half_size' at index 0 must be finite and > 0 m, with |V-|/a <= 1e+300 1/s"),
    (dict(omega=[0.0, np.inf, 0.0]), "The 'omega' vector at index 0 is not finite: [0.0, inf, 0.0]."),
    (dict(shape="sphere"), "The 'shape' parameter must name one of the table's shapes (ellipsoid, prism, cut_prism, "
                           "tetrahedron) or a built-in (ellipsoid, prism, cut_prism, tetrahedron); got 'sphere'."),
    (dict(shape=["prism", "sphere"]), "The 'shape' at index 1 must be one of the table's shapes (ellipsoid, prism, "
                                      "cut_prism, tetrahedron) or a built-in (ellipsoid, prism, cut_prism, "
                                      "tetrahedron); got 'sphere'."),
    (dict(shape=["prism"]), "The 'shape' parameter must be one shape name per particle, shape (2,); got (1,)."),
    (dict(velocity=np.zeros((2, 2))), "The 'velocity' parameter must have shape (N, 3); got (2, 2)."),
])
def test_bad_python_input_is_a_one_line_error(small_table, change, message):
    args = dict(velocity=[[100.0, -100.0, 0.0], [10.0, -100.0, 5.0]], normal=[0.0, 1.0, 0.0], half_size=A,
                omega=[0.0, 0.0, 0.0], shape="prism", random_state=1)
    args.update(change)
    with pytest.raises(ValueError) as error:
        surrogate.sample_direct(small_table, **args)
    assert str(error.value).startswith(message) and "\n" not in str(error.value)


def test_runtime_kernel_needs_no_scipy():
    """The run-time path imports and runs with scipy hidden (the plain install has numpy, numba and h5py)."""
    code = ("import sys; sys.modules['scipy'] = None; import numpy as np; "
            "from direct_model.runtime import model_parameters, U_PER_REBOUND; "
            "from direct_model.shapes import AspectRatioLaw; from direct_model.wall import CORUNDUM_ON_STEEL; "
            "from direct_model.shape_arrays import family_shape_arrays; "
            "from surrogate.kernels import direct_rebound; "
            "p = model_parameters(AspectRatioLaw(), 0.3, 1000, CORUNDUM_ON_STEEL, 1e-10, 1e-9, 100000, "
            "(0.2, 1 / 3, 0.33, 0.2)); "
            "shapes = family_shape_arrays(0.3, AspectRatioLaw(), (0.2, 1 / 3, 0.33, 0.2)); "
            "s = direct_rebound(p, shapes, 2, (100.0, -100.0, 0.0), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0), 1e-3, "
            "np.full(U_PER_REBOUND, 0.5))[0]; sys.exit(s)")
    assert subprocess.run([sys.executable, "-c", code]).returncode == STATUS_REBOUNDED
