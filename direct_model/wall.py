"""The wall law of one collision: restitution and friction (docs/model.md §4).

Two empirical coefficients close the impulse model:

* normal restitution of the contact point (Lashkov's corundum/St3 correlation,
  valid for 50–300 m/s)::

      a_nc = 1 − [1 − exp(−k |V_c⁻|^p)] · |v_c⁻| / |V_c⁻|       (|V_c⁻| in m/s)

  where |v_c⁻|/|V_c⁻| is the sine of the contact point's impact angle, so
  a_nc ∈ (0, 1];
* the friction factor (Panfilov & Tsirkunov's heuristic)::

      C_f = exp(q · cos γ),   cos γ = (r_c · V_p⁻) / (|r_c| |V_p⁻|)

  with V_p⁻ the centre-of-mass velocity just before the current collision.

The published law is k = 0.1, p = 0.61, q = 1 (:data:`CORUNDUM_ON_STEEL`).
Another particle/wall pair of the same functional family is another
:class:`WallMaterial`; the kernels receive it as the array :meth:`as_array`.

A wall is a named record of a law *family* (:data:`WALL_FAMILIES`): the
family names the law's form and its parameters, in the order the kernels read
them, with their units and ranges; a record holds the family's name, its
parameters' values, the wall's label and where the law holds: the range of
incident speeds |V⁻| it was measured or fitted over (:data:`SPEED_RANGE_NOT_STATED`
for a law given without one). The model applies the law at any speed; the
runtimes count the hits answered outside that range. The law above is the family
``exponential`` (k, p, q), the only one so far. A table stores the record as
its group ``/wall`` (docs/format.md), read back by field name.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Mapping

import numba
import numpy as np

from direct_model.options import KERNEL


@dataclasses.dataclass(frozen=True)
class WallParameter:
    """One parameter of a wall law family: its name (a field of the table's ``wall/parameters``), units, meaning,
    and its range as words (what an error says) and as a check."""

    name: str
    units: str
    meaning: str
    allowed: str                    # the range in words: "finite and > 0"
    ok: Callable[[float], bool]     # whether a value is in that range

    def check(self, value) -> float:
        """``value`` as a float; ValueError naming the parameter and its range if it is outside."""
        number = float(value)
        if not self.ok(number):
            raise ValueError(f"The wall law parameter '{self.name}' must be {self.allowed}; got {value!r}.")
        return number


@dataclasses.dataclass(frozen=True)
class WallFamily:
    """A wall law family: its name, its law in words and its parameters in the order the kernels read them
    (:meth:`WallMaterial.as_array`)."""

    name: str
    law: str
    parameters: tuple

    @property
    def parameter_names(self) -> tuple:
        return tuple(p.name for p in self.parameters)

    def check(self, values: Mapping) -> tuple:
        """The values of ``values`` (a mapping by parameter name) in the family's order, as floats; ValueError
        naming a parameter that is missing or out of its range (in the family's order)."""
        missing = [name for name in self.parameter_names if name not in values]
        if missing:
            raise ValueError(f"The {self.name} wall law needs the parameters {', '.join(self.parameter_names)}; "
                             f"'{missing[0]}' is missing.")
        return tuple(p.check(values[p.name]) for p in self.parameters)


def _finite_positive(x: float) -> bool:
    return math.isfinite(x) and x > 0.0


EXPONENTIAL = "exponential"
# every wall law family, by name; an entry here (and its twin in native/src/loader.c, WALL_FAMILIES) is a family
WALL_FAMILIES = {
    EXPONENTIAL: WallFamily(
        EXPONENTIAL, "a_nc = 1 − [1 − exp(−k |V_c⁻|^p)] |v_c⁻|/|V_c⁻|, C_f = exp(q cos γ) (docs/model.md §4)",
        (WallParameter("k", "(m/s)^-p", "restitution rate constant", "finite and > 0", _finite_positive),
         WallParameter("p", "1", "restitution speed exponent", "finite and > 0", _finite_positive),
         WallParameter("q", "1", "friction exponent scale in C_f = exp(q cos γ)", "finite", math.isfinite))),
}


def wall_family(name: str) -> WallFamily:
    """The family named ``name``; ValueError naming it and the families known."""
    family = WALL_FAMILIES.get(name) if isinstance(name, str) else None
    if family is None:
        raise ValueError(f"unknown wall law family {name!r}; the families: {', '.join(WALL_FAMILIES)}")
    return family


SPEED_RANGE_NOT_STATED = (0.0, math.inf)      # a law given without the speeds it was measured over


@dataclasses.dataclass(frozen=True)
class WallMaterial:
    """A wall: the record of one wall law (see module doc), here of the ``exponential`` family.

    Attributes
    ----------
    k : float
        Restitution rate constant, (m/s)^(−p); > 0.
    p : float
        Restitution speed exponent; > 0.
    q : float
        Friction exponent scale in C_f = exp(q cos γ); finite.
    name : str
        Label stored with results.
    family : str
        The law family (:data:`WALL_FAMILIES`) whose parameters k, p, q are.
    speed_range_m_s : (float, float)
        The incident speeds |V⁻|, m/s, the law was measured or fitted over, low < high (Lashkov's: 50–300 m/s,
        :data:`CORUNDUM_ON_STEEL`); :data:`SPEED_RANGE_NOT_STATED` (0, inf, the default) for a law given without
        one.
    """

    k: float = 0.1
    p: float = 0.61
    q: float = 1.0
    name: str = "corundum_on_St3_Lashkov1991"
    family: str = EXPONENTIAL
    speed_range_m_s: tuple = SPEED_RANGE_NOT_STATED

    def __post_init__(self):
        if self.family != EXPONENTIAL:      # the record's fields are the exponential family's
            raise ValueError(f"a WallMaterial holds a wall of the {EXPONENTIAL} family (k, p, q); "
                             f"{wall_family(self.family).name!r} has the parameters "
                             f"{', '.join(wall_family(self.family).parameter_names)}")
        wall_family(self.family).check(self.parameters())
        object.__setattr__(self, "speed_range_m_s", check_speed_range(self.speed_range_m_s))

    @property
    def speed_range_stated(self) -> bool:
        """Whether the law states where it holds (a speed range other than :data:`SPEED_RANGE_NOT_STATED`)."""
        return self.speed_range_m_s != SPEED_RANGE_NOT_STATED

    def outside_speed_range(self, speed):
        """Whether each |V⁻| of ``speed`` (m/s; a number or an array) lies outside :attr:`speed_range_m_s`."""
        low, high = self.speed_range_m_s
        return (np.asarray(speed) < low) | (np.asarray(speed) > high)

    def speed_range_text(self) -> str:
        """The range in words: "50-300 m/s", or "not stated"."""
        low, high = self.speed_range_m_s
        return f"{low:g}-{high:g} m/s" if self.speed_range_stated else "not stated"

    def parameters(self) -> dict:
        """The family's parameters by name, in the family's order: {"k": .., "p": .., "q": ..}."""
        return {name: getattr(self, name) for name in wall_family(self.family).parameter_names}

    @classmethod
    def from_parameters(cls, family: str, parameters: Mapping, name: str,
                        speed_range_m_s=None) -> "WallMaterial":
        """The wall of ``family`` with ``parameters`` by name (others ignored), label ``name`` and the speed range
        it holds over (None: :data:`SPEED_RANGE_NOT_STATED`); ValueError naming an unknown family, a missing
        parameter or one out of its range, or a bad range."""
        values = wall_family(family).check(parameters)
        return cls(*values, name=name, family=family,
                   speed_range_m_s=SPEED_RANGE_NOT_STATED if speed_range_m_s is None else speed_range_m_s)

    def as_array(self) -> np.ndarray:
        """The coefficients (k, p, q) as the float64 array the kernels take, read-only as the slice of the model's
        parameters that the runtime passes (a writable one would compile the kernels a second time)."""
        coefficients = np.array(list(self.parameters().values()), dtype=np.float64)
        coefficients.setflags(write=False)
        return coefficients


def check_speed_range(value) -> tuple:
    """``value`` as (low, high) floats, m/s: 0 <= low < high, high finite unless ``value`` is
    SPEED_RANGE_NOT_STATED; ValueError naming it otherwise."""
    try:
        low, high = (float(x) for x in value)
    except (TypeError, ValueError):
        raise ValueError(f"The wall law's 'speed_range_m_s' must be two numbers [low, high] in m/s; got {value!r}.") \
            from None
    if (low, high) == SPEED_RANGE_NOT_STATED:
        return SPEED_RANGE_NOT_STATED
    if not (math.isfinite(low) and math.isfinite(high) and 0.0 <= low < high):
        raise ValueError(f"The wall law's 'speed_range_m_s' must be finite with 0 <= low < high (m/s); got "
                         f"{[low, high]!r}.")
    return low, high


CORUNDUM_ON_STEEL = WallMaterial(speed_range_m_s=(50.0, 300.0))     # Lashkov measured 50–300 m/s


@numba.njit(**KERNEL)
def restitution(wall, contact_speed, sin_impact):
    """Normal restitution a_nc of the contact point; ``contact_speed`` in m/s."""
    return 1.0 - (1.0 - np.exp(-wall[0] * contact_speed ** wall[1])) * sin_impact


@numba.njit(**KERNEL)
def friction_factor(wall, cos_gamma):
    """Friction factor C_f = exp(q cos γ)."""
    return np.exp(wall[2] * cos_gamma)
