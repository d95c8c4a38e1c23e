"""One validation at the NumPy API's boundary (surrogate.validation): the same bad value gets the same one-line
message from every public entry point that takes it (sample_global with each method, sample_local,
sample_direct, the `surrogate sample` command line); one shape contract (a name, a mix, or one shape per
particle) for sample_global and sample_direct, on both paths."""

import numpy as np
import pytest

import surrogate
from data_schema.samples import STATUS_REBOUNDED
from surrogate.cli import main
from surrogate.kernels.locate import mix_shapes
from surrogate.kernels.rng import CHUNK_ROWS

A = 1e-3                                    # half-size, m
NORMAL = [0.0, 1.0, 0.0]
# three hits inside the small table's grid (α1 30–90°, 50–250 m/s)
VELOCITY = [[100.0, -100.0, 0.0], [50.0, -120.0, 30.0], [0.0, -150.0, 0.0]]
GOOD = dict(velocity=VELOCITY, normal=NORMAL, half_size=A, shape="prism", random_state=1)


def _global(method):
    def call(table, **args):
        return surrogate.sample_global(table, **(GOOD | args), method=method)
    return call


def _direct(table, **args):
    args = GOOD | args
    args.pop("interpolation", None)
    return surrogate.sample_direct(table, **args)


def _local(table, **args):
    args = GOOD | args
    return surrogate.sample_local(table, 45.0, 150.0, args["shape"], args["random_state"],
                                  interpolation=args.get("interpolation", "scaled"))


# name -> (call, the arguments it takes)
ENTRY_POINTS = {"sample_global auto": (_global("auto"), "all"), "sample_global table": (_global("table"), "all"),
                "sample_global direct": (_global("direct"), "all"), "sample_direct": (_direct, "all"),
                "sample_local": (_local, {"shape", "random_state", "interpolation"})}


def _cli_argv(change):
    """The `surrogate sample` arguments giving the value of ``change``, or None if the command line does not
    take it (its --omega is Ω⁻a/|V⁻|: a non-finite one is non-finite in both units)."""
    (name, value), = change.items()
    if name == "shape" and isinstance(value, str):
        return ["--shape", value]
    if name == "shape" and isinstance(value, list) and all(isinstance(w, float) for w in value):
        return ["--mix=" + ",".join(repr(w) for w in value)]
    if name == "omega" and np.shape(value) == (3,) and not np.all(np.isfinite(value)):
        return ["--omega", *(repr(w) for w in value)]
    return None


def _message(call, table, change):
    with pytest.raises(ValueError) as info:
        call(table, **change)
    message = str(info.value)
    assert "\n" not in message
    return message


BAD = [
    dict(half_size=1e-3 + 0j), dict(half_size=[A, A]), dict(half_size=np.nan), dict(half_size=-A),
    dict(omega=[np.nan, 0.0, 0.0]), dict(omega=[0.0, np.inf, 0.0]), dict(omega=[1.0, 2.0]),
    dict(omega=np.zeros((2, 3))), dict(omega=[1j, 0.0, 0.0]),
    dict(velocity=[[1.0, 2.0]]), dict(velocity=[[100.0 + 1j, -100.0, 0.0]]), dict(velocity=[[100.0, 50.0, 0.0]]),
    dict(velocity=[[0.0, 0.0, 0.0]]), dict(velocity=[[np.nan, -100.0, 0.0]]), dict(normal=[0.0, 2.0, 0.0]),
    dict(normal=[0.0, np.nan, 0.0]),
    dict(random_state=-1), dict(random_state=1.5), dict(random_state="seed"), dict(random_state=True),
    dict(shape="sphere"), dict(shape=None), dict(shape=[-0.5, 0.5, 0.5, 0.5]), dict(shape=[np.nan, 0.5, 0.25, 0.25]),
    dict(shape=[0.5, 0.6, 0.0, 0.0]), dict(shape=[0.5, 0.5]), dict(shape={"prism": "a"}), dict(shape={1: 1.0}),
    dict(shape=["prism", "sphere", "prism"]), dict(shape=["prism", "prism"]),
    dict(interpolation="linear"), dict(interpolation=None),
    dict(out=(np.empty((3, 3)), np.empty((3, 3)))),
]


@pytest.mark.parametrize("change", BAD, ids=lambda c: repr(c)[:60])
def test_the_same_bad_value_gets_the_same_message_everywhere(small_table, small_table_path, change, capsys):
    (name, _), = change.items()
    messages = {}
    for entry, (call, takes) in ENTRY_POINTS.items():
        if takes == "all" or name in takes:
            if name == "shape" and entry == "sample_local" and isinstance(change["shape"], list) \
                    and all(isinstance(s, str) for s in change["shape"]):
                continue        # one shape per particle is sample_global's and sample_direct's
            if name == "interpolation" and entry == "sample_direct":
                continue
            messages[entry] = _message(call, small_table, change)
    argv = _cli_argv(change)
    if argv is not None:
        code = main(["sample", "--table", str(small_table_path), "--alpha1", "45", "--speed", "150", "-n", "5",
                     "--seed", "1", *argv])
        err = capsys.readouterr().err.strip().splitlines()
        assert code == 2 and len(err) == 1
        messages["surrogate sample"] = err[0].removeprefix("surrogate sample: error: ")
    assert len(messages) >= 2, messages
    assert len(set(messages.values())) == 1, messages


def test_sample_local_takes_one_shape_or_a_mix(small_table):
    with pytest.raises(ValueError, match=r"^The 'shape' parameter must be a shape name or a mix here .* got 2 names"):
        surrogate.sample_local(small_table, [45.0, 50.0], 150.0, ["prism", "ellipsoid"])


def _hits(m, seed):
    """m hits in the small table's grid, with spins that send some to the direct model under "auto"."""
    rng = np.random.default_rng(seed)
    alpha1, speed, phi = np.radians(rng.uniform(30, 90, m)), rng.uniform(50, 250, m), rng.uniform(0, 2 * np.pi, m)
    V = np.column_stack([speed * np.cos(alpha1) * np.cos(phi), -speed * np.sin(alpha1),
                         speed * np.cos(alpha1) * np.sin(phi)])
    W = rng.normal(size=(m, 3)) * (0.2 * speed / A)[:, None]
    W[::2] = 0.0
    return V, W


@pytest.mark.parametrize("method", ["auto", "table", "direct"])
def test_sample_global_with_one_shape_per_particle(small_table, method):
    """Each row given its shape by name gets the bits of the call with that one shape for every row (the
    uniforms of a row do not depend on the shapes); under "auto" both paths answer some rows."""
    m = CHUNK_ROWS + 40
    V, W = _hits(m, 3)
    names = np.array(small_table.shapes)[np.random.default_rng(4).integers(0, len(small_table.shapes), m)]
    got = surrogate.sample_global(small_table, V, NORMAL, A, list(names), random_state=5, omega=W, method=method)
    for name in small_table.shapes:
        rows = names == name
        want = surrogate.sample_global(small_table, V, NORMAL, A, name, random_state=5, omega=W, method=method)
        for g, w in zip(got, want):
            np.testing.assert_array_equal(g[rows], w[rows])
    if method == "auto":
        assert 0 < np.count_nonzero(got.path) < m         # both paths
    assert np.mean(got.status == STATUS_REBOUNDED) > 0.5


def test_sample_direct_with_one_shape_per_particle_and_with_a_mix(small_table):
    """Per-particle names: each row has the bits of the one-shape call. A mix of several shapes: the shapes are
    drawn first, one uniform per particle from random_state (:func:`surrogate.kernels.locate.mix_shapes`),
    then the model's uniforms from the same generator."""
    m = 300
    V, W = _hits(m, 6)
    names = np.array(small_table.shapes)[np.random.default_rng(7).integers(0, len(small_table.shapes), m)]
    got = surrogate.sample_direct(small_table, V, NORMAL, A, names, random_state=8, omega=W)
    for name in small_table.shapes:
        rows = names == name
        want = surrogate.sample_direct(small_table, V, NORMAL, A, name, random_state=8, omega=W)
        for g, w in zip(got, want):
            np.testing.assert_array_equal(g[rows], w[rows])
    mix = {"prism": 0.25, "tetrahedron": 0.75}
    generator = np.random.default_rng(9)
    drawn = mix_shapes(surrogate.mix_cdf(small_table, mix), generator.random(m))
    want = surrogate.sample_direct(small_table, V, NORMAL, A, list(np.array(small_table.shapes)[drawn]),
                                   random_state=generator, omega=W)
    for g, w in zip(surrogate.sample_direct(small_table, V, NORMAL, A, mix, random_state=9, omega=W), want):
        np.testing.assert_array_equal(g, w)
    assert set(np.array(small_table.shapes)[drawn]) == {"prism", "tetrahedron"}


def test_omega_is_taken_alike(small_table):
    """omega (3,) for every hit, or (N, 3), or None (no spin, as zeros), the same in sample_global and
    sample_direct."""
    V, _ = _hits(5, 10)
    spin = np.array([0.0, 0.0, 2e4])
    for sample in (lambda **k: surrogate.sample_global(small_table, V, NORMAL, A, "prism", 1, method="direct", **k),
                   lambda **k: surrogate.sample_direct(small_table, V, NORMAL, A, "prism", 1, **k)):
        for one, other in ((dict(omega=spin), dict(omega=np.tile(spin, (5, 1)))),
                           (dict(omega=None), dict(omega=np.zeros(3)))):
            for x, y in zip(sample(**one), sample(**other)):
                np.testing.assert_array_equal(x, y)
