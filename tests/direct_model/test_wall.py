"""The wall law families (direct_model.wall.WALL_FAMILIES) and the wall records (WallMaterial, TabulatedWall): a
family is one registry entry, its parameters and arrays named, each with its range; the exponential family (k, p,
q) is the law of docs/model.md §4, the tabulated family a_nc bilinear between nodes of contact speed and sine."""

from __future__ import annotations

import math

import numpy as np
import pytest

from direct_model.runtime import P_WALL, model_parameters
from direct_model.shapes import AspectRatioLaw, second_moment_factors
from direct_model.wall import (CORUNDUM_ON_STEEL, EXPONENTIAL, MAX_CONTACT_SINES, MAX_CONTACT_SPEEDS,
                               SPEED_RANGE_NOT_STATED, TABULATED, WALL_ARRAY_SIZE, WALL_FAMILIES, TabulatedWall,
                               WallMaterial, friction_factor, restitution, wall_family, wall_from_array, wall_record)


@pytest.mark.parametrize("name", list(WALL_FAMILIES))
def test_every_family_names_its_parameters_once_with_units_and_ranges(name):
    family = wall_family(name)
    assert family.name == name and family.law
    names = family.parameter_names
    assert len(set(names)) == len(names) >= 1 and all(n.isidentifier() for n in names)
    for parameter in family.parameters:
        assert parameter.units and parameter.meaning and parameter.allowed
        with pytest.raises(ValueError, match=f"'{parameter.name}' must be {parameter.allowed}"):
            parameter.check(math.nan)


def test_the_exponential_family_is_k_p_q_in_the_kernels_order():
    family = WALL_FAMILIES[EXPONENTIAL]
    assert family.parameter_names == ("k", "p", "q") and family.array_names == ()
    assert [p.allowed for p in family.parameters] == ["finite and > 0", "finite and > 0", "finite"]
    wall = WallMaterial(0.2, 0.5, -0.3, "w")
    assert wall.family == EXPONENTIAL and wall.parameters() == {"k": 0.2, "p": 0.5, "q": -0.3}
    assert wall.as_array().tolist() == [family.code, -0.3, 0.2, 0.5] and not wall.as_array().flags.writeable
    # the kernels read k, p, q at these places
    speed, sin_impact, cos_gamma = 120.0, 0.4, 0.3
    assert restitution(wall.as_array(), speed, sin_impact) == 1.0 - (1.0 - np.exp(-0.2 * speed ** 0.5)) * sin_impact
    assert friction_factor(wall.as_array(), cos_gamma) == np.exp(-0.3 * cos_gamma)
    params = model_parameters(AspectRatioLaw(), 0.3, 1000, wall, 1e-10, 1e-9, 100, second_moment_factors(0.3))
    assert params[P_WALL:P_WALL + 4].tolist() == wall.as_array().tolist() and not params[P_WALL + 4:].any()
    assert wall_from_array(params[P_WALL:], "w") == wall


@pytest.mark.parametrize("values, word", [
    (dict(k=0.0), "'k' must be finite and > 0"), (dict(k=-1.0), "'k' must be finite and > 0"),
    (dict(p=0.0), "'p' must be finite and > 0"), (dict(p=math.inf), "'p' must be finite and > 0"),
    (dict(q=math.nan), "'q' must be finite"), (dict(q=-math.inf), "'q' must be finite"),
])
def test_a_parameter_out_of_range_is_refused_naming_it(values, word):
    with pytest.raises(ValueError, match=word):
        WallMaterial(**values)
    with pytest.raises(ValueError, match=word):
        wall_record(EXPONENTIAL, {**CORUNDUM_ON_STEEL.parameters(), **values}, "w")


def test_a_record_from_its_parameters_by_name():
    wall = wall_record("exponential", {"q": 0.5, "p": 0.7, "k": 0.3, "later": 1.0}, "glass")
    assert wall == WallMaterial(0.3, 0.7, 0.5, "glass")
    assert wall_record(CORUNDUM_ON_STEEL.family, CORUNDUM_ON_STEEL.parameters(),
                       CORUNDUM_ON_STEEL.name, (50, 300)) == CORUNDUM_ON_STEEL
    with pytest.raises(ValueError, match="needs the parameters k, p, q; 'p' is missing"):
        wall_record("exponential", {"k": 0.3, "q": 0.5}, "glass")
    with pytest.raises(ValueError, match="unknown wall law family 'linear'; the families: exponential, tabulated"):
        wall_record("linear", {"k": 0.3}, "glass")
    with pytest.raises(ValueError, match="unknown wall law family 'linear'"):
        WallMaterial(family="linear")


def test_the_speed_range_is_where_the_law_holds():
    """Lashkov's law holds over 50-300 m/s, a law given without a range states none (0, inf: nothing is outside
    it); a range must be 0 <= low < high, finite."""
    assert CORUNDUM_ON_STEEL.speed_range_m_s == (50.0, 300.0) and CORUNDUM_ON_STEEL.speed_range_stated
    assert CORUNDUM_ON_STEEL.outside_speed_range([49.9, 50.0, 300.0, 300.1]).tolist() == [True, False, False, True]
    own = WallMaterial(0.3, 0.7, 0.5, "glass")
    assert own.speed_range_m_s == SPEED_RANGE_NOT_STATED and not own.speed_range_stated
    assert not own.outside_speed_range([1e-9, 1e9]).any() and own.speed_range_text() == "not stated"
    assert WallMaterial(speed_range_m_s=[1, 30]).speed_range_text() == "1-30 m/s"
    for bad in ([30.0, 1.0], [1.0, 1.0], [-1.0, 30.0], [1.0, float("inf")], [float("nan"), 30.0], [1.0], "fast"):
        with pytest.raises(ValueError, match="speed_range_m_s"):
            WallMaterial(speed_range_m_s=bad)


def _sampled(law: WallMaterial, speeds, sines=(0.0, 1.0)) -> TabulatedWall:
    """The tabulated law that samples the exponential ``law`` at the contact speed and sine nodes."""
    a = law.as_array()
    return TabulatedWall(tuple(speeds), tuple(sines),
                         tuple(tuple(float(restitution(a, v, s)) for s in sines) for v in speeds), law.q, name="s")


def test_the_tabulated_law_equals_the_exponential_law_it_samples():
    """The exponential law is linear in the contact sine, so a tabulated copy with sine nodes 0 and 1 equals it at
    every sine of a speed node (to a few ulp: (1 − w)·1 + w·a against 1 − (1 − a)·w) and between speed nodes
    within the linear interpolation bound h²/8 · max|f''| of f(V) = exp(−k V^p); it is constant beyond the end
    nodes, and reads q for the friction factor like the exponential law."""
    law = CORUNDUM_ON_STEEL
    speeds = np.linspace(40.0, 320.0, MAX_CONTACT_SPEEDS)
    table = _sampled(law, speeds)
    a, t = law.as_array(), table.as_array()
    sines = np.linspace(0.0, 1.0, 41)
    for v in speeds:
        for s in sines:
            assert abs(restitution(t, v, s) - restitution(a, v, s)) <= 4 * np.spacing(1.0)
    fine = np.linspace(40.0, 320.0, 2801)
    f = np.exp(-law.k * fine ** law.p)
    curvature = np.max(np.abs(np.gradient(np.gradient(f, fine), fine)))
    bound = (speeds[1] - speeds[0]) ** 2 / 8.0 * curvature * 1.01 + 1e-15
    error = max(abs(restitution(t, v, 1.0) - restitution(a, v, 1.0)) for v in fine)
    assert 0.0 < error <= bound
    assert restitution(t, 1.0, 0.7) == restitution(t, speeds[0], 0.7)
    assert restitution(t, 1e4, 0.7) == restitution(t, speeds[-1], 0.7)
    assert friction_factor(t, 0.3) == friction_factor(a, 0.3)


def test_the_tabulated_law_is_bilinear_between_its_nodes():
    wall = TabulatedWall((50.0, 100.0, 200.0), (0.0, 0.5, 1.0),
                         ((1.0, 0.8, 0.6), (1.0, 0.75, 0.5), (1.0, 0.7, 0.45)), q=0.8, name="t")
    t = wall.as_array()
    assert t.size == 4 + 3 + 3 + 9 <= WALL_ARRAY_SIZE and wall_family(TABULATED).code == t[0]
    assert restitution(t, 75.0, 0.25) == 0.8875             # halfway in both: (0.9 + 0.875) / 2
    assert restitution(t, 200.0, 1.0) == 0.45 and restitution(t, 50.0, 0.5) == 0.8
    assert restitution(t, 150.0, 0.75) == 0.5 * (0.5 * 0.75 + 0.5 * 0.5) + 0.5 * (0.5 * 0.7 + 0.5 * 0.45)
    assert wall_from_array(np.concatenate([t, np.zeros(7)]), "t") == wall
    one = TabulatedWall((100.0,), (0.0, 1.0), ((1.0, 0.6),), name="one")     # one speed node: constant in speed
    assert restitution(one.as_array(), 3.0, 0.5) == restitution(one.as_array(), 3e3, 0.5) == 0.8


@pytest.mark.parametrize("change, word", [
    (dict(contact_speed_m_s=(100.0, 50.0)), "'contact_speed_m_s' must be 1 to 16 finite, strictly increasing"),
    (dict(contact_speed_m_s=(0.0, 50.0)), "'contact_speed_m_s' must be"),
    (dict(contact_speed_m_s=tuple(range(1, 18))), "'contact_speed_m_s' must be 1 to 16"),
    (dict(contact_sine=(0.0, 0.9)), "'contact_sine' must be 2 to 16 finite, strictly increasing numbers from 0 to 1"),
    (dict(contact_sine=(0.1, 1.0)), "'contact_sine' must be"),
    (dict(restitution=((1.0, 0.5),)), "'restitution' must be 2 rows"),
    (dict(restitution=((1.0, 0.5), (1.0, 1.5))), r"in \(0, 1\] at every node; got 1.5 at \[1\]\[1\]"),
    (dict(restitution=((1.0, 0.0), (1.0, 0.5))), r"got 0.0 at \[0\]\[1\]"),
    (dict(q=math.nan), "'q' must be finite"),
])
def test_a_tabulated_law_outside_its_domain_is_refused_naming_the_parameter(change, word):
    """Node values in (0, 1] keep the bilinear a_nc in (0, 1] everywhere; C_f = exp(q cos γ) > 0 for finite q."""
    values = dict(contact_speed_m_s=(50.0, 100.0), contact_sine=(0.0, 1.0), restitution=((1.0, 0.7), (1.0, 0.6)),
                  q=1.0)
    with pytest.raises(ValueError, match=word):
        TabulatedWall(**{**values, **change})
    assert MAX_CONTACT_SPEEDS == MAX_CONTACT_SINES == 16


@pytest.mark.parametrize("shape, alpha1, speed", [("prism", 30.0, 100.0), ("ellipsoid", 80.0, 200.0)])
def test_the_direct_model_with_a_sampled_law_rebounds_as_with_the_law(shape, alpha1, speed):
    """The same particles (seed) with the exponential law and with its tabulated copy on 16 speed nodes from 10 to
    330 m/s: the mean u⁺/|V⁻|, v⁺/|V⁻| differ by less than the copy's largest error in a_nc above 40 m/s (0.0073:
    a collision's v⁺ moves by at most Δa_nc·|v_c⁻|, and every contact here is faster than 40 m/s but for a
    few slow last contacts)."""
    from direct_model.simulate import simulate

    law = CORUNDUM_ON_STEEL
    copy = _sampled(law, np.linspace(10.0, 330.0, 16))
    fine = np.linspace(40.0, 330.0, 2901)
    largest = max(abs(restitution(copy.as_array(), v, 1.0) - restitution(law.as_array(), v, 1.0)) for v in fine)
    assert 0.007 < largest < 0.0074
    own, copied = (simulate(shape, alpha1, speed, 2000, seed=5, wall=w) for w in (law, copy))
    both = (own.status == 0) & (copied.status == 0)
    assert both.sum() > 1900
    difference = (own.velocity[both, :2] - copied.velocity[both, :2]).mean(axis=0) / speed
    assert np.all(np.abs(difference) < largest), difference
    assert not np.array_equal(own.velocity, copied.velocity)     # the copy is another law
