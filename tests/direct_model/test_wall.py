"""The wall law families (direct_model.wall.WALL_FAMILIES) and the wall record (WallMaterial): a family is one
registry entry, its parameters named in the order the kernels read them, each with its range; the exponential
family (k, p, q) is the law of docs/model.md §4."""

from __future__ import annotations

import math

import numpy as np
import pytest

from direct_model.runtime import P_WALL, model_parameters
from direct_model.shapes import AspectRatioLaw, second_moment_factors
from direct_model.wall import (CORUNDUM_ON_STEEL, EXPONENTIAL, SPEED_RANGE_NOT_STATED, WALL_FAMILIES, WallMaterial,
                               friction_factor, restitution, wall_family)


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
    assert family.parameter_names == ("k", "p", "q")
    assert [p.allowed for p in family.parameters] == ["finite and > 0", "finite and > 0", "finite"]
    wall = WallMaterial(0.2, 0.5, -0.3, "w")
    assert wall.family == EXPONENTIAL and wall.parameters() == {"k": 0.2, "p": 0.5, "q": -0.3}
    assert wall.as_array().tolist() == [0.2, 0.5, -0.3] and not wall.as_array().flags.writeable
    # the kernels read k, p, q at these places
    speed, sin_impact, cos_gamma = 120.0, 0.4, 0.3
    assert restitution(wall.as_array(), speed, sin_impact) == 1.0 - (1.0 - np.exp(-0.2 * speed ** 0.5)) * sin_impact
    assert friction_factor(wall.as_array(), cos_gamma) == np.exp(-0.3 * cos_gamma)
    params = model_parameters(AspectRatioLaw(), 0.3, 1000, wall, 1e-10, 1e-9, 100, second_moment_factors(0.3))
    assert params[P_WALL:P_WALL + len(family.parameters)].tolist() == wall.as_array().tolist()


@pytest.mark.parametrize("values, word", [
    (dict(k=0.0), "'k' must be finite and > 0"), (dict(k=-1.0), "'k' must be finite and > 0"),
    (dict(p=0.0), "'p' must be finite and > 0"), (dict(p=math.inf), "'p' must be finite and > 0"),
    (dict(q=math.nan), "'q' must be finite"), (dict(q=-math.inf), "'q' must be finite"),
])
def test_a_parameter_out_of_range_is_refused_naming_it(values, word):
    with pytest.raises(ValueError, match=word):
        WallMaterial(**values)
    with pytest.raises(ValueError, match=word):
        WallMaterial.from_parameters(EXPONENTIAL, {**CORUNDUM_ON_STEEL.parameters(), **values}, "w")


def test_a_record_from_its_parameters_by_name():
    wall = WallMaterial.from_parameters("exponential", {"q": 0.5, "p": 0.7, "k": 0.3, "later": 1.0}, "glass")
    assert wall == WallMaterial(0.3, 0.7, 0.5, "glass")
    assert WallMaterial.from_parameters(CORUNDUM_ON_STEEL.family, CORUNDUM_ON_STEEL.parameters(),
                                        CORUNDUM_ON_STEEL.name, (50, 300)) == CORUNDUM_ON_STEEL
    with pytest.raises(ValueError, match="needs the parameters k, p, q; 'p' is missing"):
        WallMaterial.from_parameters("exponential", {"k": 0.3, "q": 0.5}, "glass")
    with pytest.raises(ValueError, match="unknown wall law family 'linear'; the families: exponential"):
        WallMaterial.from_parameters("linear", {"k": 0.3}, "glass")
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
