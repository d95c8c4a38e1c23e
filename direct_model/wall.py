"""The wall law of one collision: restitution and friction (docs/model.md §4).

Two empirical coefficients close the impulse model:

* normal restitution a_nc ∈ (0, 1] of the contact point, a function of its speed |V_c⁻| (m/s) and of the sine
  |v_c⁻|/|V_c⁻| of its impact angle. The law *family* gives its form:

  - ``exponential`` (Lashkov's corundum/St3 correlation, valid for 50–300 m/s)::

        a_nc = 1 − [1 − exp(−k |V_c⁻|^p)] · |v_c⁻| / |V_c⁻|

  - ``tabulated``: a_nc given at nodes of contact speed and contact sine, bilinear between them and constant
    beyond the first and last speed node (the sine nodes run from 0 to 1, so a_nc is defined everywhere; node
    values in (0, 1] keep it there, as a bilinear blend of them);

* the friction factor (Panfilov & Tsirkunov's heuristic), the same in every family::

      C_f = exp(q · cos γ),   cos γ = (r_c · V_p⁻) / (|r_c| |V_p⁻|)

  with V_p⁻ the centre-of-mass velocity just before the current collision.

The published law is the exponential one with k = 0.1, p = 0.61, q = 1 (:data:`CORUNDUM_ON_STEEL`).

A wall is a named record (:class:`Wall`) of a law family (:data:`WALL_FAMILIES`): the family names the law's
form, its scalar parameters with their units and ranges, and its arrays; a record holds the family's name, its
values, the wall's label and where the law holds: the range of incident speeds |V⁻| it was measured or fitted
over (:data:`SPEED_RANGE_NOT_STATED` for a law given without one). The model applies the law at any speed; the
runtimes count the hits answered outside that range. :class:`WallMaterial` is a wall of the exponential family,
:class:`TabulatedWall` one of the tabulated family; :func:`wall_record` makes either by family name. A table
stores the record as its group ``/wall`` (docs/format.md), read back by name. The kernels receive a wall as one
float64 array (:meth:`Wall.as_array`, layout W_*): the family's code, q, then the family's own values.
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
    """One scalar parameter of a wall law family: its name (a field of the table's ``wall/parameters``), units,
    meaning, and its range as words (what an error says) and as a check."""

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
class WallArray:
    """One array of a wall law family (a dataset of the table's group ``wall``): its name, units, dimensions (by
    the names of the arrays that give their lengths) and meaning."""

    name: str
    units: str
    dims: tuple
    meaning: str


@dataclasses.dataclass(frozen=True)
class WallFamily:
    """A wall law family: its name, its code in the kernels' wall array (W_FAMILY), its law in words, its scalar
    parameters and its arrays."""

    name: str
    code: int
    law: str
    parameters: tuple
    arrays: tuple = ()

    @property
    def parameter_names(self) -> tuple:
        return tuple(p.name for p in self.parameters)

    @property
    def array_names(self) -> tuple:
        return tuple(a.name for a in self.arrays)

    def check(self, values: Mapping) -> tuple:
        """The scalar parameters of ``values`` (a mapping by name) in the family's order, as floats; ValueError
        naming a parameter that is missing or out of its range (in the family's order)."""
        missing = [name for name in (*self.parameter_names, *self.array_names) if name not in values]
        if missing:
            raise ValueError(f"The {self.name} wall law needs the parameters "
                             f"{', '.join((*self.parameter_names, *self.array_names))}; '{missing[0]}' is missing.")
        return tuple(p.check(values[p.name]) for p in self.parameters)


def _finite_positive(x: float) -> bool:
    return math.isfinite(x) and x > 0.0


_Q = WallParameter("q", "1", "friction exponent scale in C_f = exp(q cos γ)", "finite", math.isfinite)
EXPONENTIAL, TABULATED = "exponential", "tabulated"
MAX_CONTACT_SPEEDS, MAX_CONTACT_SINES = 16, 16      # nodes of a tabulated law: what the C runtime's record holds
# every wall law family, by name; an entry here (and its twin in native/src/loader.c, WALL_FAMILIES) is a family
WALL_FAMILIES = {
    EXPONENTIAL: WallFamily(
        EXPONENTIAL, 0,
        "a_nc = 1 − [1 − exp(−k |V_c⁻|^p)] |v_c⁻|/|V_c⁻|, C_f = exp(q cos γ) (docs/model.md §4)",
        (WallParameter("k", "(m/s)^-p", "restitution rate constant", "finite and > 0", _finite_positive),
         WallParameter("p", "1", "restitution speed exponent", "finite and > 0", _finite_positive), _Q)),
    TABULATED: WallFamily(
        TABULATED, 1,
        "a_nc bilinear in |V_c⁻| and |v_c⁻|/|V_c⁻| between nodes (constant beyond the speed nodes), "
        "C_f = exp(q cos γ) (docs/model.md §4)",
        (_Q,),
        (WallArray("contact_speed_m_s", "m/s", ("contact_speed_m_s",),
                   f"the speed nodes |V_c⁻|: 1 to {MAX_CONTACT_SPEEDS}, finite, > 0 and increasing"),
         WallArray("contact_sine", "1", ("contact_sine",),
                   f"the sine nodes |v_c⁻|/|V_c⁻|: 2 to {MAX_CONTACT_SINES}, increasing from 0 to 1"),
         WallArray("restitution", "1", ("contact_speed_m_s", "contact_sine"),
                   "a_nc at the nodes, one row per speed node, each value in (0, 1]"))),
}

# the kernels' wall array: the family's code and q, then the exponential family's k, p, or the tabulated family's
# node counts, speed nodes, sine nodes and a_nc (row-major: speed, then sine)
W_FAMILY, W_Q = 0, 1
W_K, W_P = 2, 3
W_N_SPEEDS, W_N_SINES, W_NODES = 2, 3, 4
WALL_ARRAY_SIZE = W_NODES + MAX_CONTACT_SPEEDS + MAX_CONTACT_SINES + MAX_CONTACT_SPEEDS * MAX_CONTACT_SINES
EXPONENTIAL_CODE = WALL_FAMILIES[EXPONENTIAL].code


def wall_family(name: str) -> WallFamily:
    """The family named ``name``; ValueError naming it and the families known."""
    family = WALL_FAMILIES.get(name) if isinstance(name, str) else None
    if family is None:
        raise ValueError(f"unknown wall law family {name!r}; the families: {', '.join(WALL_FAMILIES)}")
    return family


SPEED_RANGE_NOT_STATED = (0.0, math.inf)      # a law given without the speeds it was measured over
MAX_ROUGHNESS_DEG = 45.0    # the largest roughness Δγ, degrees: the facet law's rejection keeps ≥ 0.38 of draws


class Wall:
    """What every wall record has beside its family's values (``family``, ``name``, ``speed_range_m_s``,
    ``roughness_deg``): where the law holds, its values by name and the kernels' array.

    ``roughness_deg`` is the wall's roughness Δγ in degrees, in [0, MAX_ROUGHNESS_DEG] (0, a smooth wall: the
    default): the spread of the facets a rough wall puts under each hit (docs/model.md §12). The law holds on
    each facet as on a smooth wall, so the runtimes apply it at run time (a call may override it) and the
    table's cells do not depend on it."""

    family: str
    name: str
    speed_range_m_s: tuple
    roughness_deg: float

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
        """The family's scalar parameters by name, in the family's order (exponential: k, p, q)."""
        return {name: getattr(self, name) for name in wall_family(self.family).parameter_names}

    def arrays(self) -> dict:
        """The family's arrays by name, as float64 numpy arrays ({} for the exponential family)."""
        return {name: np.array(getattr(self, name), dtype=np.float64) for name in wall_family(self.family).array_names}

    def law_text(self) -> str:
        """The law's values in words: "k=0.1, p=0.61, q=1", with a tabulated law's node counts."""
        text = ", ".join(f"{name}={value:.4g}" for name, value in self.parameters().items())
        shapes = [f"{name} {'x'.join(map(str, array.shape))}" for name, array in self.arrays().items()]
        return ", ".join([text, *shapes]) if shapes else text

    def as_array(self) -> np.ndarray:
        """The kernels' wall array (layout W_*), read-only as the slice of the model's parameters that the runtime
        passes (a writable one would compile the kernels a second time)."""
        family = wall_family(self.family)
        values = [float(family.code), float(self.q)]
        if family.name == EXPONENTIAL:
            values += [self.k, self.p]
        else:
            arrays = self.arrays()
            speeds, sines = arrays["contact_speed_m_s"], arrays["contact_sine"]
            values += [len(speeds), len(sines), *speeds, *sines, *arrays["restitution"].ravel()]
        array = np.array(values, dtype=np.float64)
        array.setflags(write=False)
        return array


def _record_fields(record) -> None:
    """Check ``record``'s family, its scalar parameters, speed range and roughness (ValueError naming them)."""
    wall_family(record.family).check({**record.parameters(), **{a: 0 for a in wall_family(record.family).array_names}})
    object.__setattr__(record, "speed_range_m_s", check_speed_range(record.speed_range_m_s))
    object.__setattr__(record, "roughness_deg", check_roughness(record.roughness_deg))


@dataclasses.dataclass(frozen=True)
class WallMaterial(Wall):
    """A wall of the ``exponential`` family (see module doc).

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
        The law family (:data:`WALL_FAMILIES`): ``exponential``.
    speed_range_m_s : (float, float)
        The incident speeds |V⁻|, m/s, the law was measured or fitted over, low < high (Lashkov's: 50–300 m/s,
        :data:`CORUNDUM_ON_STEEL`); :data:`SPEED_RANGE_NOT_STATED` (0, inf, the default) for a law given without
        one.
    roughness_deg : float
        The wall's roughness Δγ, degrees, in [0, MAX_ROUGHNESS_DEG]; 0 (the default): smooth (:class:`Wall`).
    """

    k: float = 0.1
    p: float = 0.61
    q: float = 1.0
    name: str = "corundum_on_St3_Lashkov1991"
    family: str = EXPONENTIAL
    speed_range_m_s: tuple = SPEED_RANGE_NOT_STATED
    roughness_deg: float = 0.0

    def __post_init__(self):
        if self.family != EXPONENTIAL:      # the record's fields are the exponential family's
            other = wall_family(self.family)
            raise ValueError(f"a WallMaterial holds a wall of the {EXPONENTIAL} family (k, p, q); {other.name!r} has "
                             f"the parameters {', '.join((*other.parameter_names, *other.array_names))}")
        _record_fields(self)


def _nodes(name: str, values, count: tuple, first_last=None) -> tuple:
    """``values`` as a tuple of floats: ``count`` = (least, most) of them, finite, strictly increasing, all > 0
    or (``first_last``) from first_last[0] to first_last[1]; ValueError naming ``name`` otherwise."""
    array = np.asarray(values, dtype=np.float64) if np.ndim(values) == 1 else None
    allowed = (f"{count[0]} to {count[1]} finite, strictly increasing numbers "
               + (f"from {first_last[0]:g} to {first_last[1]:g}" if first_last else "> 0"))
    if (array is None or not count[0] <= array.size <= count[1] or not np.all(np.isfinite(array))
            or not np.all(np.diff(array) > 0.0)
            or (first_last is None and not np.all(array > 0.0))
            or (first_last is not None and (array[0], array[-1]) != first_last)):
        raise ValueError(f"The wall law parameter '{name}' must be {allowed}; got {values!r}.")
    return tuple(float(x) for x in array)


@dataclasses.dataclass(frozen=True)
class TabulatedWall(Wall):
    """A wall of the ``tabulated`` family (see module doc): a_nc at nodes of contact speed and contact sine.

    Attributes
    ----------
    contact_speed_m_s : tuple of float
        The speed nodes |V_c⁻|, m/s: 1 to MAX_CONTACT_SPEEDS, > 0 and increasing; a_nc is constant beyond the
        first and the last.
    contact_sine : tuple of float
        The sine nodes |v_c⁻|/|V_c⁻|: 2 to MAX_CONTACT_SINES, increasing from 0 to 1.
    restitution : tuple of tuples of float
        a_nc at the nodes, one row per speed node, one value per sine node, each in (0, 1].
    q : float
        Friction exponent scale in C_f = exp(q cos γ); finite.
    name, family, speed_range_m_s, roughness_deg
        As :class:`WallMaterial`'s; ``family`` is ``tabulated``.
    """

    contact_speed_m_s: tuple
    contact_sine: tuple
    restitution: tuple
    q: float = 1.0
    name: str = "tabulated"
    family: str = TABULATED
    speed_range_m_s: tuple = SPEED_RANGE_NOT_STATED
    roughness_deg: float = 0.0

    def __post_init__(self):
        if self.family != TABULATED:
            raise ValueError(f"a TabulatedWall holds a wall of the {TABULATED} family; got {self.family!r}")
        _record_fields(self)
        speeds = _nodes("contact_speed_m_s", self.contact_speed_m_s, (1, MAX_CONTACT_SPEEDS))
        sines = _nodes("contact_sine", self.contact_sine, (2, MAX_CONTACT_SINES), (0.0, 1.0))
        values = np.asarray(self.restitution, dtype=np.float64) if np.ndim(self.restitution) == 2 else None
        if values is None or values.shape != (len(speeds), len(sines)):
            raise ValueError(f"The wall law parameter 'restitution' must be {len(speeds)} rows (one per speed node) "
                             f"of {len(sines)} numbers (one per sine node); got {self.restitution!r}.")
        bad = np.argwhere(~((values > 0.0) & (values <= 1.0)))
        if bad.size:
            i, j = bad[0]
            raise ValueError(f"The wall law parameter 'restitution' must be in (0, 1] at every node; got "
                             f"{float(values[i, j])!r} at [{i}][{j}] (|V_c| = {speeds[i]:g} m/s, sine {sines[j]:g}).")
        object.__setattr__(self, "contact_speed_m_s", speeds)
        object.__setattr__(self, "contact_sine", sines)
        object.__setattr__(self, "restitution", tuple(tuple(float(x) for x in row) for row in values))
        object.__setattr__(self, "q", float(self.q))


_RECORDS = {EXPONENTIAL: WallMaterial, TABULATED: TabulatedWall}


def wall_record(family: str, values: Mapping, name: str, speed_range_m_s=None, roughness_deg=0.0) -> Wall:
    """The wall of ``family`` with ``values`` by name (scalar parameters and arrays; others ignored), label
    ``name``, the speed range it holds over (None: :data:`SPEED_RANGE_NOT_STATED`) and its roughness (degrees);
    ValueError naming an unknown family, a missing value or one out of its range, a bad range or roughness."""
    law = wall_family(family)
    law.check(values)
    fields = {n: values[n] for n in (*law.parameter_names, *law.array_names)}
    return _RECORDS[law.name](**fields, name=name, family=law.name,
                              speed_range_m_s=SPEED_RANGE_NOT_STATED if speed_range_m_s is None else speed_range_m_s,
                              roughness_deg=roughness_deg)


def wall_from_array(array, name: str) -> Wall:
    """The wall whose kernels' array (:meth:`Wall.as_array`, or the model's parameters from P_WALL on) is
    ``array``, labelled ``name``, its speed range not stated."""
    array = np.asarray(array, dtype=np.float64)
    code = int(array[W_FAMILY])
    family = next(f for f in WALL_FAMILIES.values() if f.code == code)
    if family.name == EXPONENTIAL:
        return WallMaterial(float(array[W_K]), float(array[W_P]), float(array[W_Q]), name=name)
    ns, nz = int(array[W_N_SPEEDS]), int(array[W_N_SINES])
    speeds = array[W_NODES:W_NODES + ns]
    sines = array[W_NODES + ns:W_NODES + ns + nz]
    values = array[W_NODES + ns + nz:W_NODES + ns + nz + ns * nz].reshape(ns, nz)
    return TabulatedWall(tuple(speeds), tuple(sines), tuple(map(tuple, values)), float(array[W_Q]), name=name)


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


def check_roughness(value) -> float:
    """``value`` as a roughness Δγ in degrees, a float in [0, MAX_ROUGHNESS_DEG]; ValueError naming it otherwise."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)) \
            or not 0.0 <= value <= MAX_ROUGHNESS_DEG:
        raise ValueError(f"The wall's 'roughness_deg' must be a number in [0, {MAX_ROUGHNESS_DEG:g}] degrees; got "
                         f"{value!r}.")
    return float(value)


CORUNDUM_ON_STEEL = WallMaterial(speed_range_m_s=(50.0, 300.0))     # Lashkov measured 50–300 m/s


@numba.njit(**KERNEL)
def node_weight(wall, first, count, x):
    """Of the ``count`` increasing nodes wall[first:first + count]: the index (from ``first``) of the node at or
    below ``x`` and of the next, and the weight of the next, 0 below the first node and 1 above the last."""
    if count == 1:
        return 0, 0, 0.0
    i = 0
    while i < count - 2 and wall[first + i + 1] <= x:
        i += 1
    w = (x - wall[first + i]) / (wall[first + i + 1] - wall[first + i])
    if w < 0.0:
        w = 0.0
    elif w > 1.0:
        w = 1.0
    return i, i + 1, w


@numba.njit(**KERNEL)
def tabulated_restitution(wall, contact_speed, sin_impact):
    """a_nc of the tabulated family: bilinear between the nodes (module doc); ``contact_speed`` in m/s."""
    ns, nz = int(wall[W_N_SPEEDS]), int(wall[W_N_SINES])
    sines, values = W_NODES + ns, W_NODES + ns + nz
    i0, i1, ws = node_weight(wall, W_NODES, ns, contact_speed)
    j0, j1, wz = node_weight(wall, sines, nz, sin_impact)
    low = (1.0 - wz) * wall[values + i0 * nz + j0] + wz * wall[values + i0 * nz + j1]
    high = (1.0 - wz) * wall[values + i1 * nz + j0] + wz * wall[values + i1 * nz + j1]
    return (1.0 - ws) * low + ws * high


@numba.njit(**KERNEL)
def restitution(wall, contact_speed, sin_impact):
    """Normal restitution a_nc of the contact point; ``contact_speed`` in m/s."""
    if wall[W_FAMILY] == EXPONENTIAL_CODE:
        return 1.0 - (1.0 - np.exp(-wall[W_K] * contact_speed ** wall[W_P])) * sin_impact
    return tabulated_restitution(wall, contact_speed, sin_impact)


@numba.njit(**KERNEL)
def friction_factor(wall, cos_gamma):
    """Friction factor C_f = exp(q cos γ)."""
    return np.exp(wall[W_Q] * cos_gamma)
