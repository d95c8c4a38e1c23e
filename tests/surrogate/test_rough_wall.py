"""Rough walls (docs/model.md §12): the facet law against the shadow-weighted distribution, a sphere against an
independent Sommerfeld–Huber implementation, symmetry, energy, the shadow effect's signature, bits and streams."""

import math

import numba
import numpy as np
import pytest
from scipy import integrate, stats

import surrogate
from data_schema.samples import STATUS_REBOUNDED
from direct_model.collision import COLLISION_OK, collide
from direct_model.runtime import model_parameters
from direct_model.shape_arrays import family_shape_arrays
from direct_model.shapes import AspectRatioLaw, second_moment_factors
from direct_model.wall import CORUNDUM_ON_STEEL
from surrogate.cli import main as surrogate_main
from surrogate.kernels import MAX_WALL_HITS, METHOD_DIRECT, U_PER_DRAW, rebound
from surrogate.kernels.facet import facet_key, facet_normal
from surrogate.kernels.hit import PATH_DIRECT
from surrogate.kernels.layout import frozen
from surrogate.kernels.pipeline import table_rebound_uniforms
from surrogate.kernels.rng import chunk_states

from tests.helpers.cli import run_cli, user_error
from tests.helpers.tables import edited_copy

SPEED = 150.0


def _beam(alpha1_deg, n, speed=SPEED):
    """n copies of V⁻ at α1 on the wall y = 0 (normal +Y), m/s."""
    a1 = math.radians(alpha1_deg)
    return np.tile([speed * math.cos(a1), -speed * math.sin(a1), 0.0], (n, 1))


def _angles(V):
    """(α2, β2) in degrees of rebounds V (N, 3) from the wall y = 0, the impact plane XY."""
    return (np.degrees(np.arctan2(V[:, 1], np.hypot(V[:, 0], V[:, 2]))),
            np.degrees(np.arctan2(V[:, 2], V[:, 0])))


@numba.njit
def _facet_angles(alpha1_deg, roughness_deg, n):
    """(γx, γz) in radians of n facets under V⁻ at α1 on the wall y = 0, from n unrelated facet keys."""
    a1 = math.radians(alpha1_deg)
    V, wall = (math.cos(a1), -math.sin(a1), 0.0), (0.0, 1.0, 0.0)
    u = np.zeros(U_PER_DRAW)
    out = np.empty((n, 2))
    for i in range(n):
        u[0] = (i + 0.5) / n
        found, nf, _ = facet_normal(V, wall, roughness_deg, facet_key(u), 0)
        out[i, 0] = math.asin(-nf[0]) if found else np.nan     # n_f = (−sin γx, cos γx cos γz, cos γx sin γz)
        out[i, 1] = math.atan2(nf[2], nf[1])
    return out


@pytest.mark.parametrize("alpha1_deg", [3.0, 60.0])
def test_facets_follow_the_shadow_weighted_law(alpha1_deg):
    """The facets' γx and γz against their marginals of N(0, Δγ²)² · max(0, cos α1 sin γx + sin α1 cos γx cos γz)
    (on an 801² grid over ±8 Δγ, trapezoid rule); a χ² over 16 equiprobable bins of each (n = 40 000; p > 1e-4)."""
    spread, n = math.radians(10.0), 40_000
    drawn = _facet_angles(alpha1_deg, 10.0, n)
    assert not np.isnan(drawn).any()
    c, s = math.cos(math.radians(alpha1_deg)), math.sin(math.radians(alpha1_deg))
    grid = np.linspace(-8 * spread, 8 * spread, 801)
    gx, gz = np.meshgrid(grid, grid, indexing="ij")
    density = (stats.norm.pdf(gx, 0, spread) * stats.norm.pdf(gz, 0, spread)
               * np.maximum(0.0, c * np.sin(gx) + s * np.cos(gx) * np.cos(gz)))
    for axis in (0, 1):
        marginal = integrate.trapezoid(density, grid, axis=1 - axis)
        cdf = integrate.cumulative_trapezoid(marginal, grid, initial=0.0)
        edges = np.quantile(drawn[:, axis], np.linspace(0, 1, 17))
        edges[0], edges[-1] = grid[0], grid[-1]
        expected = n * np.diff(np.interp(edges, grid, cdf)) / cdf[-1]
        observed = np.histogram(drawn[:, axis], edges)[0]
        assert stats.chisquare(observed, expected, ddof=0).pvalue > 1e-4, (axis, observed, expected)
    if alpha1_deg < 5:      # the shadow: at grazing incidence the facets kept face the particle (γx > 0)
        assert np.mean(drawn[:, 0] > 0) > 0.75


def test_a_smooth_wall_is_today_s_hit(small_table, tmp_path):
    """Δγ = 0 (the default, or given) gives the smooth wall's bits, and a table that stores a roughness gives them
    with roughness_deg=0."""
    V = np.r_[_beam(20.0, 700), _beam(70.0, 700, 240.0)]
    smooth = surrogate.sample_global(small_table, V, [0, 1, 0], 1e-3, "mix", random_state=4)
    assert np.all(smooth.wall_hits == 1)
    given = surrogate.sample_global(small_table, V, [0, 1, 0], 1e-3, "mix", random_state=4, roughness_deg=0.0)
    rough_path = _rough_copy(small_table, tmp_path, 7.5)
    rough_table = surrogate.load(rough_path)
    assert rough_table.wall.roughness_deg == 7.5
    zero = surrogate.sample_global(rough_table, V, [0, 1, 0], 1e-3, "mix", random_state=4, roughness_deg=0)
    for name in smooth._fields:
        np.testing.assert_array_equal(getattr(given, name), getattr(smooth, name))
        np.testing.assert_array_equal(getattr(zero, name), getattr(smooth, name))
    stored = surrogate.sample_global(rough_table, V, [0, 1, 0], 1e-3, "mix", random_state=4)
    assert np.any(stored.V != smooth.V) and np.any(stored.wall_hits > 1)


def _rough_copy(table, folder, roughness_deg):
    """A copy of ``table``'s file whose wall states the roughness ``roughness_deg`` (as the build writes it)."""
    def edit(f):
        old = f["wall/parameters"][()]
        dtype = old.dtype.descr + [("roughness_deg", "<f8")]
        row = np.zeros(1, dtype=dtype)
        for name in old.dtype.names:
            row[name] = old[name]
        row["roughness_deg"] = roughness_deg
        attrs = dict(f["wall/parameters"].attrs)
        del f["wall/parameters"]
        ds = f["wall"].create_dataset("parameters", data=row, chunks=(1,), fletcher32=True)
        ds.attrs.update(attrs)
    return edited_copy(table.path, folder, "rough.h5", edit)


@pytest.mark.parametrize("keyed", [False, True])
def test_rough_rows_are_the_single_hit_kernel_s_and_keep_the_stream(small_table, keyed):
    """Row i of a rough sample_global is rebound() with row i's uniforms (those of a smooth call); the first k rows
    do not depend on the rows after them (a row's redraws take no uniform of the stream); threads change nothing."""
    rng = np.random.default_rng(8)
    n = 1500
    V = _beam(60.0, n) + rng.normal(0, 3.0, (n, 3)) * [1, 0, 1]
    W = rng.normal(0, 2e3, (n, 3)) * (rng.random((n, 1)) < 0.3)
    keys = rng.integers(0, 2 ** 62, n) if keyed else np.full(n, -1)
    kw = dict(shape="mix", omega=W, grain_key=keys if keyed else None, roughness_deg=12.0)
    runs = []
    for threads in (1, numba.config.NUMBA_NUM_THREADS):
        numba.set_num_threads(threads)
        runs.append(surrogate.sample_global(small_table, V, [0, 1, 0], 1e-3, random_state=5, **kw))
    numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
    full = runs[0]
    for name in full._fields:
        np.testing.assert_array_equal(getattr(runs[1], name), getattr(full, name))
    assert np.count_nonzero(full.wall_hits > 1) > 40
    k = 300
    head = surrogate.sample_global(small_table, V[:k], [0, 1, 0], 1e-3, random_state=5, shape="mix", omega=W[:k],
                                   grain_key=keys[:k] if keyed else None, roughness_deg=12.0)
    for name in full._fields:
        np.testing.assert_array_equal(getattr(head, name), getattr(full, name)[:k])
    u = table_rebound_uniforms(chunk_states(np.random.default_rng(5), n)[0].copy(), 40)
    cdf = surrogate.mix_cdf(small_table, "mix")
    for i in range(40):
        one = rebound(small_table.kernel_data, small_table.direct_parameters, small_table.shape_arrays,
                      small_table.model_shapes, cdf, V[i], W[i], (0.0, 1.0, 0.0), 1e-3, u[i], 0, True,
                      int(keys[i]) if keyed else None, 12.0)
        assert (one.status, one.path, one.shape, one.n_collisions, one.wall_hits) == (
            full.status[i], full.path[i], full.shape[i], full.n_collisions[i], full.wall_hits[i])
        np.testing.assert_array_equal(np.array(one.V), full.V[i])
        np.testing.assert_array_equal(np.array(one.Omega), full.Omega[i])
        np.testing.assert_array_equal([one.wall_work_normal, one.wall_work_tangential],
                                      [full.wall_work_normal[i], full.wall_work_tangential[i]])


@pytest.fixture(scope="module")
def rough_beams(small_table):
    """The mix at α1 = 5° and 45°, 150 m/s, on a smooth wall and with Δγ = 10° (table where it holds)."""
    n = 6000
    return {(alpha1, roughness): surrogate.sample_global(small_table, _beam(alpha1, n), [0, 1, 0], 1e-3, "mix",
                                                         random_state=21, clamp=True, roughness_deg=roughness)
            for alpha1 in (5.0, 45.0) for roughness in (0.0, 10.0)}


def test_grazing_hits_rebound_steeper_on_a_rough_wall(rough_beams):
    """The shadow effect's signature: at α1 = 5° the facets hit face the particle, so the mean α2 rises (by several
    of its standard errors: sd/sqrt(n) ≈ 0.1° here; the bound 1°)."""
    smooth, rough = rough_beams[5.0, 0.0], rough_beams[5.0, 10.0]
    a_smooth = _angles(smooth.V[smooth.status == STATUS_REBOUNDED])[0]
    a_rough = _angles(rough.V[rough.status == STATUS_REBOUNDED])[0]
    assert a_rough.mean() > a_smooth.mean() + 1.0, (a_smooth.mean(), a_rough.mean())


@pytest.mark.parametrize("alpha1", [5.0, 45.0])
def test_the_rough_law_is_symmetric_in_beta2(rough_beams, alpha1):
    """Ω⁻ = 0: β2 and −β2 equally likely (a binomial sign test, |z| < 4, and the mean within 4 standard errors);
    the rough wall widens β2's spread."""
    rough, smooth = rough_beams[alpha1, 10.0], rough_beams[alpha1, 0.0]
    beta2 = _angles(rough.V[rough.status == STATUS_REBOUNDED])[1]
    n = beta2.size
    assert abs(np.count_nonzero(beta2 > 0) - n / 2) < 4 * math.sqrt(n) / 2
    assert abs(beta2.mean()) < 4 * beta2.std() / math.sqrt(n)
    assert beta2.std() > _angles(smooth.V[smooth.status == STATUS_REBOUNDED])[1].std()


def test_kinetic_energy_never_grows(small_table):
    """Ω⁻ = 0, the direct model on every facet: |V⁺| ≤ |V⁻| for every rebound (the translational energy is at most
    the total, which no collision raises), re-hits included."""
    n = 1200
    V = np.r_[_beam(2.0, n // 2), _beam(40.0, n // 2, 260.0)]
    hits = surrogate.sample_direct(small_table, V, [0, 1, 0], 1e-3, "mix", random_state=9, roughness_deg=20.0)
    ok = hits.status == STATUS_REBOUNDED
    assert ok.sum() > 0.9 * n and np.any(hits.wall_hits[ok] > 1)
    assert np.all(np.sum(hits.V[ok] ** 2, axis=1) <= np.sum(V[ok] ** 2, axis=1) * (1 + 1e-12))
    assert np.all(hits.path[ok] == PATH_DIRECT)
    assert np.all(hits.V[ok, 1] > 0) and np.all(hits.wall_hits <= MAX_WALL_HITS)


def _sphere_sh(V, roughness_deg, law, rng):
    """The Sommerfeld–Huber rough wall for a sphere of a = 1 m (K = (2/5) I), written apart from the product:
    facet angles from N(0, Δγ²) kept with probability max(0, −V̂·n_f) (plain rejection), one collision per facet
    hit by the wall law (direct_model.collision.collide in the facet's frame), again while V⁺·n ≤ 0."""
    W = np.zeros(3)
    spread = math.radians(roughness_deg)
    Kinv = np.eye(3) / 0.4
    for hits in range(1, MAX_WALL_HITS + 1):
        speed = np.linalg.norm(V)
        t = np.array([V[0], 0.0, V[2]])
        ex = t / np.linalg.norm(t) if np.linalg.norm(t) > 1e-12 * speed else np.array([1.0, 0.0, 0.0])
        ey = np.array([0.0, 1.0, 0.0])
        ez = np.cross(ex, ey)
        while True:
            gx, gz = rng.normal(0, spread, 2)
            nf = -math.sin(gx) * ex + math.cos(gx) * math.cos(gz) * ey + math.cos(gx) * math.sin(gz) * ez
            if rng.random() < max(0.0, -V @ nf / speed):
                break
        e1 = np.cross(nf, ez) if abs(nf @ ez) < 0.9 else np.cross(nf, ex)
        e1 /= np.linalg.norm(e1)
        e3 = np.cross(e1, nf)
        R = np.array([e1, nf, e3])      # rows: the facet's frame, its normal along y
        dV, dW = np.zeros(3), np.zeros(3)
        code = collide(R @ V, R @ W, np.array([0.0, -1.0, 0.0]), Kinv, law, dV, dW)
        assert code == COLLISION_OK
        V, W = V + R.T @ dV, W + R.T @ dW
        if V[1] > 0:
            return V, W, hits
    return None, None, MAX_WALL_HITS


def test_a_sphere_on_a_rough_wall_is_sommerfeld_huber(small_table):
    """A near-sphere (b/a, c/b in [0.999999, 1]) through the product's rough wall against :func:`_sphere_sh`, at
    α1 = 4° and 30°, Δγ = 8°: two-sample KS of α2, β2, |V⁺|/|V⁻| (n = 1500 each; p > 1e-4) and the share of
    re-hits within 5 standard errors. The wall work, summed over a hit's facet hits, is the kinetic energy the
    near-sphere lost, ½|V⁻|² − ½|V⁺|² − ½ (2/5) a²|Ω⁺|² (to its asphericity, 1e-6)."""
    law = AspectRatioLaw(1.0, 1e-3, 0.999999, 1.0)
    params = model_parameters(law, 0.3, 1000, CORUNDUM_ON_STEEL, 1e-10, 1e-9, 100_000, second_moment_factors())
    shapes = family_shape_arrays(0.3, law, second_moment_factors())
    params = frozen(params)        # as a table's: the kernels compiled for the other tests serve
    n, rng = 1500, np.random.default_rng(17)
    wall = CORUNDUM_ON_STEEL.as_array()
    for alpha1 in (4.0, 30.0):
        V0 = _beam(alpha1, 1)[0]
        model, model_hits, sh, sh_hits = [], [], [], []
        for i in range(n):
            one = rebound(small_table.kernel_data, params, shapes, frozen(np.array([0])), np.array([1.0]), V0,
                          np.zeros(3), (0.0, 1.0, 0.0), 1.0, rng.random(U_PER_DRAW), METHOD_DIRECT, True, None, 8.0)
            assert one.status == STATUS_REBOUNDED
            lost = 0.5 * V0 @ V0 - 0.5 * np.dot(one.V, one.V) - 0.2 * np.dot(one.Omega, one.Omega)
            assert one.wall_work_normal > 0.0 and one.wall_work_tangential >= 0.0
            assert one.wall_work_normal + one.wall_work_tangential == pytest.approx(lost, abs=1e-6 * V0 @ V0)
            model.append(one.V)
            model_hits.append(one.wall_hits)
            V, _, hits = _sphere_sh(V0.copy(), 8.0, wall, rng)
            sh.append(V)
            sh_hits.append(hits)
        model, sh = np.array(model), np.array(sh)
        for x, y in zip((*_angles(model), np.linalg.norm(model, axis=1)), (*_angles(sh), np.linalg.norm(sh, axis=1))):
            assert stats.ks_2samp(x, y).pvalue > 1e-4, alpha1
        p1, p2 = np.mean(np.array(model_hits) > 1), np.mean(np.array(sh_hits) > 1)
        se = math.sqrt((p1 * (1 - p1) + p2 * (1 - p2)) / n) + 1 / n
        assert abs(p1 - p2) < 5 * se, (alpha1, p1, p2)


def test_bad_roughness_is_refused_naming_the_range(small_table):
    for bad in (-1.0, 46.0, float("nan"), "5", True):
        with pytest.raises(ValueError, match=r"'roughness_deg' parameter must be None .* \[0, 45\] degrees"):
            surrogate.sample_global(small_table, _beam(30.0, 2), [0, 1, 0], 1e-3, roughness_deg=bad)


def test_cli_sample_on_a_rough_wall(small_table_path, capsys):
    """--roughness-deg: the summary counts the hits that hit again and those at the cap; a smooth wall has no
    such line; a roughness outside [0, 45] is one line, exit 2."""
    argv = ["sample", "--table", str(small_table_path), "--alpha1", "60", "--speed", "150", "-n", "600",
            "--mix", "0.25,0.25,0.25,0.25", "--seed", "2"]
    code, err, out = run_cli(surrogate_main, argv + ["--roughness-deg", "20"], capsys)
    assert code == 0 and not err
    line = next(x for x in out.splitlines() if x.startswith("  rough wall"))
    again = int(line.split(": ")[1].split()[0])
    assert "roughness 20 deg" in line and f"reached the cap of {MAX_WALL_HITS}" in line and 30 < again < 300
    code, err, out = run_cli(surrogate_main, argv, capsys)
    assert code == 0 and "rough wall" not in out
    user_error(surrogate_main, argv + ["--roughness-deg", "46"], capsys, "--roughness-deg", "[0, 45]", "46")
