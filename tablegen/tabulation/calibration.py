"""Calibration of the wall law to measured rebounds: ``tablegen calibrate`` (docs/model.md §4.6).

The data: per incident state (α1 in degrees from the wall, |V⁻| in m/s, Ω⁻ = 0) the measured means, over the
particles that rebounded, of either the coefficients e_n = −v⁺/v⁻ and e_t = u⁺/u⁻ or the ratios u⁺/|V⁻| and
v⁺/|V⁻| of the centre-of-mass velocity (lab frame of docs/model.md §2: u along the wall in the impact plane, v along
the wall normal), and optionally their standard deviations over the particles and the particle counts.

The model: the same means from the direct model for a mix of grains; every row's particles (orientations,
proportions, hands) come from seeds fixed for the whole fit (common random numbers), so the objective is a
deterministic function of the law's parameters. The fit: weighted least squares over the free parameters of a
family of :data:`direct_model.wall.WALL_FAMILIES` (its fit values, :func:`fit_form`), each in the coordinate that
keeps it in its range.

The kernels (:func:`model_means`, :func:`in_form`, :func:`residual_variance`, :func:`estimated_sd`,
:func:`jacobian`, :func:`covariance`) are plain functions over arrays; :func:`measurements`,
:func:`read_measurements` and :func:`calibrate` validate what they are given.
"""

from __future__ import annotations

import csv
import dataclasses
import io
import json
import math
import warnings
from collections.abc import Callable, Mapping
from pathlib import Path

import numpy as np

from data_schema.output import PNG_KEY, TOML_MARKER
from data_schema.samples import ALPHA1_RANGE_TEXT, alpha1_is_physical
from direct_model.registry import FAMILIES
from direct_model.shapes import SHAPES
from direct_model.wall import (CORUNDUM_ON_STEEL, EXPONENTIAL, MAX_CONTACT_SPEEDS, TABULATED, TabulatedWall, Wall,
                               wall_family, wall_record)
from tablegen.tabulation.config import wall_values_toml

COEFFICIENTS = ("e_n", "e_t")           # e_n = −v⁺/v⁻, e_t = u⁺/u⁻
RATIOS = ("u_ratio", "v_ratio")         # u⁺/|V⁻|, v⁺/|V⁻|
STATE_COLUMNS = ("alpha1_deg", "speed_m_s")
SD_SUFFIX = "_sd"
COUNT_COLUMN = "n"
DEFAULT_MIX = {name: 1.0 / len(SHAPES) for name in SHAPES}      # the paper's four families in equal parts
DEFAULT_PARTICLES = 8000        # per row: a mean's model standard error ~0.002 (docs/model.md §4.6)
DEFAULT_SEED = 1
# finite-difference step in the fit coordinates: steps well below 1e-2 see the jumps of collision counts, steps of
# 0.1 the curvature (docs/model.md §4.6)
STEP = 0.05
XTOL = 2e-3                     # a step this small relative to the fit coordinates ends the fit: below the model noise
FTOL = 1e-4                     # a step that lowers the cost by less than this fraction of it ends the fit too
MAX_STEPS = 40                  # trial points per stage (least_squares_fit); each accepted one adds a Jacobian
WALL_FILE_KIND = "wall_law"
FIGURE_KIND = "wall_law_figure"
INSTALL_HINT = 'pip install "rebound-scatter[plots]"'


@dataclasses.dataclass(frozen=True)
class Transform:
    """A fit coordinate t of a parameter θ: ``forward`` θ → t, ``inverse`` t → θ, ``slope`` dθ/dt at t."""

    forward: Callable
    inverse: Callable
    slope: Callable


LOG = Transform(math.log, math.exp, math.exp)
LINEAR = Transform(float, float, lambda t: 1.0)
# a value in (0, 1): its logit; smooth, and every t gives a value inside
LOGIT = Transform(lambda x: math.log(x / (1.0 - x)), lambda t: 1.0 / (1.0 + math.exp(-t)),
                  lambda t: math.exp(-t) / (1.0 + math.exp(-t)) ** 2)
DEFAULT_LAW = CORUNDUM_ON_STEEL      # the published law: the fit's start and the comparison printed


@dataclasses.dataclass(frozen=True)
class FitForm:
    """How a family's law is fitted: the names of its fit values (what --fix names), each one's fit coordinate
    (:class:`Transform`), their values at the published law (the start), the wall they make
    (``make(values, name)``) and the pair that data at one speed cannot tell apart (if any)."""

    family: str
    names: tuple
    transforms: dict
    start: dict
    make: Callable
    trade_off: tuple = ()
    allowed: dict = dataclasses.field(default_factory=dict)     # name → (check, range in words)


def node_name(speed: float) -> str:
    """The fit value of a tabulated law's a_nc at normal contact at the speed node ``speed`` (m/s): a_nc_100."""
    return f"a_nc_{speed:g}"


def fit_form(family: str, speeds) -> FitForm:
    """The :class:`FitForm` of ``family`` for data at the incident speeds ``speeds`` (m/s).

    exponential: k, p (log coordinates: > 0) and q, from the published law; k and p trade off at one speed.
    tabulated: q and, at each distinct speed of the data as a contact-speed node, a_nc at normal contact
    (``a_nc_<speed>``, logit coordinate: in (0, 1)); the law is linear in the contact sine from a_nc = 1 at
    sine 0, like the exponential law, so that its values stay in (0, 1] and it is smooth in them; it starts from
    the published law's a_nc at those speeds.
    """
    q = wall_family(EXPONENTIAL).parameters[-1]
    if family == EXPONENTIAL:
        law = wall_family(EXPONENTIAL)
        return FitForm(family, law.parameter_names, {"k": LOG, "p": LOG, "q": LINEAR}, DEFAULT_LAW.parameters(),
                       lambda values, name: wall_record(EXPONENTIAL, values, name), ("k", "p"),
                       {p.name: (p.ok, p.allowed) for p in law.parameters})
    nodes = tuple(float(v) for v in np.unique(np.asarray(speeds, dtype=np.float64)))
    if len(nodes) > MAX_CONTACT_SPEEDS:
        raise ValueError(f"the tabulated wall law holds at most {MAX_CONTACT_SPEEDS} speed nodes and the data have "
                         f"{len(nodes)} speeds; allowed: at most {MAX_CONTACT_SPEEDS} (fit the exponential law)")
    names = (*(node_name(v) for v in nodes), "q")
    start = {**{node_name(v): math.exp(-DEFAULT_LAW.k * v ** DEFAULT_LAW.p) for v in nodes}, "q": DEFAULT_LAW.q}

    def make(values, name):
        return TabulatedWall(nodes, (0.0, 1.0), tuple((1.0, values[node_name(v)]) for v in nodes), values["q"],
                             name=name)
    in_unit = (lambda x: 0.0 < x < 1.0, "in (0, 1)")
    return FitForm(TABULATED, names, {**{node_name(v): LOGIT for v in nodes}, "q": LINEAR}, start, make, (),
                   {**{node_name(v): in_unit for v in nodes}, "q": (q.ok, q.allowed)})


# ------------------------------------------------------------------------------------------------ the data

@dataclasses.dataclass(frozen=True, eq=False)
class Measurements:
    """Measured mean rebounds, one row per incident state (Ω⁻ = 0).

    Attributes
    ----------
    source : what the data came from (its file), for messages.
    names : the two quantities, :data:`COEFFICIENTS` (e_n, e_t) or :data:`RATIOS` (u⁺/|V⁻|, v⁺/|V⁻|).
    alpha1 : (m,) incidence angles from the wall, degrees.
    speed : (m,) incident speeds |V⁻|, m/s.
    mean : (m, 2) the measured means of ``names`` over the rebounded particles, dimensionless.
    sd : (m, 2) their standard deviations over the particles; a column is NaN where it was not given.
    count : (m,) particles per row (1 where not given).
    rows : each row's label in messages ("line 5 (data row 4)").
    ignored : the columns of the source that were not read.
    """

    source: str
    names: tuple
    alpha1: np.ndarray
    speed: np.ndarray
    mean: np.ndarray
    sd: np.ndarray
    count: np.ndarray
    rows: tuple
    ignored: tuple = ()

    @property
    def sd_given(self) -> np.ndarray:
        """(2,) bool: whether each quantity's standard deviations were given."""
        return ~np.isnan(self.sd[0])


def _positive(x):
    return np.isfinite(x) & (x > 0)


# per column: (allowed in words, check of an array)
_COLUMN_RANGES = {
    "alpha1_deg": (f"in {ALPHA1_RANGE_TEXT} degrees", alpha1_is_physical),
    "speed_m_s": ("finite and > 0 m/s", _positive),
    "e_n": ("finite and > 0 (e_n = -v+/v- of a rebound)", _positive),
    "e_t": ("finite", np.isfinite),
    "u_ratio": ("finite", np.isfinite),
    "v_ratio": ("finite and > 0 (v+/|V-| of a rebound)", _positive),
    SD_SUFFIX: ("finite and > 0", _positive),
    COUNT_COLUMN: ("an integer >= 1", lambda x: np.isfinite(x) & (x >= 1) & (np.mod(x, 1) == 0)),
}


def _range_of(column: str):
    return _COLUMN_RANGES[SD_SUFFIX if column.endswith(SD_SUFFIX) else column]


def _check_column(source, rows, column, values) -> None:
    allowed, ok = _range_of(column)
    bad = np.flatnonzero(~ok(values))
    if bad.size:
        raise ValueError(f"{source} {rows[bad[0]]}, column '{column}': must be {allowed}; "
                         f"got {float(values[bad[0]])!r}")


def measurements(alpha1, speed, names, mean, sd=None, count=None, source: str = "<data>", rows=None) -> Measurements:
    """Measured mean rebounds (:class:`Measurements`), checked: α1 (deg) in (0, 90] ((0, 90) with e_t, which
    u⁻ = 0 leaves undefined at 90°), |V⁻| (m/s) finite and > 0, e_n and v⁺/|V⁻| > 0, e_t and u⁺/|V⁻| finite, each
    sd given (m, 2) finite and > 0, each count an integer ≥ 1, one row per (α1, |V⁻|); ValueError naming the row,
    the column and the allowed range. ``rows``: the rows' labels in messages (default "data row i", from 1)."""
    names = tuple(names)
    if names not in (COEFFICIENTS, RATIOS):
        raise ValueError(f"the measured quantities must be {', '.join(COEFFICIENTS)} or {', '.join(RATIOS)}; "
                         f"got {', '.join(map(str, names))}")
    alpha1 = np.asarray(alpha1, dtype=float).reshape(-1)
    m = len(alpha1)
    if m == 0:
        raise ValueError(f"{source}: no data rows; give one row per (alpha1_deg, speed_m_s)")
    rows = tuple(rows) if rows is not None else tuple(f"data row {i + 1}" for i in range(m))

    def column(values, name, shape):
        array = np.asarray(values, dtype=float)
        if array.shape != shape:
            raise ValueError(f"{source}: '{name}' has shape {array.shape}; the data has {m} rows: {shape}")
        return array

    speed = column(speed, "speed_m_s", (m,))
    mean = column(mean, "mean", (m, 2))
    sd = np.full((m, 2), np.nan) if sd is None else column(sd, "sd", (m, 2)).copy()
    count = np.ones(m) if count is None else column(count, COUNT_COLUMN, (m,))
    _check_column(source, rows, "alpha1_deg", alpha1)
    _check_column(source, rows, "speed_m_s", speed)
    for q, name in enumerate(names):
        _check_column(source, rows, name, mean[:, q])
        if not np.all(np.isnan(sd[:, q])):
            _check_column(source, rows, name + SD_SUFFIX, sd[:, q])
    _check_column(source, rows, COUNT_COLUMN, count)
    if names == COEFFICIENTS and np.any(alpha1 == 90.0):
        i = int(np.flatnonzero(alpha1 == 90.0)[0])
        raise ValueError(f"{source} {rows[i]}, column 'alpha1_deg': must be in (0, 90) degrees with e_t (u- = 0 at "
                         f"90 degrees leaves e_t = u+/u- undefined; give u_ratio, v_ratio instead); got 90.0")
    seen = {}
    for i, state in enumerate(zip(alpha1, speed)):
        if state in seen:
            raise ValueError(f"{source} {rows[i]}, columns 'alpha1_deg', 'speed_m_s': "
                             f"({float(state[0])!r}, {float(state[1])!r}) "
                             f"repeats {rows[seen[state]]}; allowed: one row per (alpha1, speed) (merge them)")
        seen[state] = i
    return Measurements(source, names, alpha1, speed, mean, sd, count, rows)


def known_columns(names) -> tuple:
    """The columns a file of the quantities ``names`` may have: α1, |V⁻|, the quantities, their sd, the count."""
    return (*STATE_COLUMNS, *names, *(name + SD_SUFFIX for name in names), COUNT_COLUMN)


def read_measurements(path) -> Measurements:
    """The measurements of a CSV file (UTF-8, comma-separated; blank lines and lines starting with # skipped).

    The header names the columns: ``alpha1_deg`` (deg), ``speed_m_s`` (m/s), then ``e_n, e_t`` or
    ``u_ratio, v_ratio``, optionally the standard deviations ``<quantity>_sd`` and the particle count ``n``.
    Checked as :func:`measurements`, each message naming the file's line, its data row and the column. Other
    columns are ignored (``Measurements.ignored``; :func:`calibrate` says so).
    """
    try:
        with open(path, encoding="utf-8-sig", newline="") as f:
            text = f.read()
    except OSError as exc:
        raise ValueError(f"{path}: cannot read the measurements: {exc.strerror}") from None
    except UnicodeDecodeError as exc:
        raise ValueError(f"{path}: the measurements are not UTF-8 text (byte {exc.start})") from None
    lines = [(number, line) for number, line in enumerate(text.splitlines(), 1)
             if line.strip() and not line.lstrip().startswith("#")]
    if not lines:
        raise ValueError(f"{path}: no header line; the first line names the columns: alpha1_deg, speed_m_s, then "
                         f"e_n, e_t or u_ratio, v_ratio")
    table = list(csv.reader(line for _, line in lines))
    header_line, header = lines[0][0], [name.strip() for name in table[0]]
    repeated = sorted({name for name in header if header.count(name) > 1})
    if repeated:
        raise ValueError(f"{path} line {header_line}: the column '{repeated[0]}' is named twice")
    forms = [names for names in (COEFFICIENTS, RATIOS) if set(names) & set(header)]
    if len(forms) == 2:
        raise ValueError(f"{path} line {header_line}: the header has columns of both e_n, e_t and u_ratio, v_ratio; "
                         f"give one pair")
    names = forms[0] if forms else COEFFICIENTS
    for name in (*STATE_COLUMNS, *names):
        if name not in header:
            raise ValueError(f"{path} line {header_line}: column '{name}' is missing; the columns: alpha1_deg, "
                             f"speed_m_s, then e_n, e_t or u_ratio, v_ratio (optional: their _sd and n); "
                             f"the header has: {', '.join(header)}")
    known = known_columns(names)
    used = [name for name in header if name in known]
    rows = tuple(f"line {number} (data row {i + 1})" for i, (number, _) in enumerate(lines[1:]))
    values = {name: np.empty(len(rows)) for name in used}
    for i, fields in enumerate(table[1:]):
        if len(fields) != len(header):
            raise ValueError(f"{path} {rows[i]}: has {len(fields)} values; the header has {len(header)} columns")
        for name in used:
            text = fields[header.index(name)].strip()
            if not text:
                raise ValueError(f"{path} {rows[i]}, column '{name}': empty; must be {_range_of(name)[0]}")
            try:
                values[name][i] = float(text)
            except ValueError:
                raise ValueError(f"{path} {rows[i]}, column '{name}': must be a number, {_range_of(name)[0]}; "
                                 f"got {text!r}") from None
    for name in used:       # a column given is checked whole (measurements() takes an all-NaN sd for none)
        if name.endswith(SD_SUFFIX):
            _check_column(str(path), rows, name, values[name])
    sd = np.column_stack([values.get(name + SD_SUFFIX, np.full(len(rows), np.nan)) for name in names])
    data = measurements(values["alpha1_deg"], values["speed_m_s"], names,
                        np.column_stack([values[name] for name in names]), sd, values.get(COUNT_COLUMN),
                        str(path), rows)
    return dataclasses.replace(data, ignored=tuple(name for name in header if name not in known))


# ------------------------------------------------------------------------------------------------ the model

def particle_seeds(seed: int, rows: int, constituents: int) -> np.ndarray:
    """(rows, constituents) seeds of ``direct_model.simulate.simulate``, one per row and constituent of the mix,
    derived from ``seed``: the same at every evaluation of a fit, independent across rows and constituents."""
    return np.array([[int(np.random.SeedSequence(seed, spawn_key=(i, j)).generate_state(1, np.uint64)[0] >> 1)
                      for j in range(constituents)] for i in range(rows)], dtype=np.int64)


def model_means(wall: Wall, alpha1, speed, bodies, weights, counts, seeds, model: Mapping):
    """The direct model's mean u⁺/|V⁻| and v⁺/|V⁻| (columns 0, 1) over the rebounded particles of a mix, per row
    (α1 in degrees, |V⁻| in m/s, Ω⁻ = 0; lab frame of docs/model.md §2), and the variances of those means:
    two (m, 2) arrays.

    ``bodies[j]`` (what ``simulate`` takes as ``shape``) is run with ``counts[j]`` particles from ``seeds[i, j]``
    at row i; the mix weighs it by ``weights[j]`` (sum 1) times its share of rebounds, as a mix drawn at random
    would. A row where no particle rebounded is NaN.
    """
    from direct_model.simulate import simulate

    weights = np.asarray(weights, dtype=float)
    means, variances = np.full((len(alpha1), 2), np.nan), np.full((len(alpha1), 2), np.nan)
    with warnings.catch_warnings():
        # the warning is about the default law's measured range; a calibrated law is the answer to it
        warnings.filterwarnings("ignore", message="speed .* is outside")
        for i, (a, v) in enumerate(zip(alpha1, speed)):
            part_mean, part_var, share = np.zeros((len(bodies), 2)), np.zeros((len(bodies), 2)), np.zeros(len(bodies))
            for j, body in enumerate(bodies):
                result = simulate(body, a, v, int(counts[j]), seed=int(seeds[i, j]), wall=wall, **model)
                rebounded = result.velocity[result.status == 0, :2] / v
                if len(rebounded):
                    share[j] = weights[j] * len(rebounded) / counts[j]
                    for k in range(2):
                        mean = math.fsum(rebounded[:, k]) / len(rebounded)
                        part_mean[j, k] = mean
                        part_var[j, k] = math.fsum((rebounded[:, k] - mean) ** 2) / len(rebounded) ** 2
            total = math.fsum(share)
            if total > 0:
                c = share / total
                for k in range(2):
                    means[i, k] = _dot(c, part_mean[:, k])
                    variances[i, k] = _dot(c ** 2, part_var[:, k])
    return means, variances


def in_form(names, alpha1, values, variances=False) -> np.ndarray:
    """(m, 2) u⁺/|V⁻|, v⁺/|V⁻| means (or their variances, ``variances=True``) as the quantities ``names``:
    (e_n, e_t) = (v⁺/(|V⁻| sin α1), u⁺/(|V⁻| cos α1)), or (u_ratio, v_ratio) as they are; α1 in degrees."""
    if tuple(names) == RATIOS:
        return values
    a = np.radians(alpha1)
    scale = np.column_stack((1.0 / np.sin(a), 1.0 / np.cos(a))) ** (2 if variances else 1)
    return values[:, ::-1] * scale


# ------------------------------------------------------------------------------------------------ the fit

def residual_variance(sd, count, model_variance, sd_estimate) -> np.ndarray:
    """(m, 2) variance of each residual (model mean − measured mean): sd² / n plus the model's variance of its
    mean where the sd is given; ``sd_estimate[q]``² / n where quantity q's sd is not (NaN in ``sd``)."""
    given = ~np.isnan(sd)
    return np.where(given, np.where(given, sd, 0.0) ** 2 / count[:, None] + model_variance,
                    np.asarray(sd_estimate) ** 2 / count[:, None])


def estimated_sd(residual, count, n_free: int) -> np.ndarray:
    """(2,) each quantity's sd over the particles, the same in every row, from the residuals (m, 2) of the fit:
    sqrt(Σ n r² / (m − n_free / 2)), each quantity carrying half the free parameters."""
    return np.array([math.sqrt(math.fsum(count * residual[:, k] ** 2) / (len(residual) - n_free / 2.0))
                     for k in range(residual.shape[1])])


def jacobian(residuals: Callable, t, step: float = STEP, central: bool = False, at=None) -> np.ndarray:
    """(N, P) finite-difference Jacobian of ``residuals`` (a function of the P fit coordinates) at ``t``: forward
    differences of ``step`` (reusing ``at``, the residuals at ``t``, if given), or central ones."""
    t = np.asarray(t, dtype=float)
    base = None if central else (residuals(t) if at is None else at)
    columns = []
    for j in range(len(t)):
        shift = np.zeros_like(t)
        shift[j] = step
        if central:
            columns.append((residuals(t + shift) - residuals(t - shift)) / (2.0 * step))
        else:
            columns.append((residuals(t + shift) - base) / step)
    return np.column_stack(columns)


def covariance(jac, scale: float = 1.0) -> np.ndarray:
    """(P, P) covariance of the fit coordinates from the Jacobian of the weighted residuals, (JᵀJ)⁻¹ × ``scale``
    (a pseudo-inverse: parameters the data cannot tell apart get a large, not a failing, variance)."""
    return _pseudo_inverse(_normal_matrix(jac)) * scale


# Deterministic linear algebra for the few fit coordinates: exactly rounded sums (math.fsum) and plain loops, no
# BLAS or SIMD reduction: numpy's and OpenBLAS's kernels differ by CPU, and a fit must give the same bits on any.

def _dot(a, b) -> float:
    """a · b, exactly rounded."""
    return math.fsum(np.asarray(a, dtype=float) * np.asarray(b, dtype=float))


def _normal_matrix(jac) -> np.ndarray:
    """JᵀJ of the (N, P) Jacobian, each entry exactly rounded."""
    p = jac.shape[1]
    return np.array([[_dot(jac[:, i], jac[:, j]) for j in range(p)] for i in range(p)])


def _solve(a, b) -> np.ndarray:
    """x with a x = b for a small (P, P) matrix: Gaussian elimination with partial pivoting, in Python floats."""
    m = [list(map(float, row)) + [float(v)] for row, v in zip(a, b)]
    p = len(m)
    for col in range(p):
        pivot = max(range(col, p), key=lambda r: abs(m[r][col]))
        m[col], m[pivot] = m[pivot], m[col]
        if m[col][col] == 0.0:
            raise ZeroDivisionError("singular")
        for r in range(col + 1, p):
            f = m[r][col] / m[col][col]
            m[r] = [x - f * y for x, y in zip(m[r], m[col])]
    x = [0.0] * p
    for r in range(p - 1, -1, -1):
        x[r] = (m[r][p] - math.fsum(m[r][c] * x[c] for c in range(r + 1, p))) / m[r][r]
    return np.array(x)


def _pseudo_inverse(a) -> np.ndarray:
    """The pseudo-inverse of a small symmetric positive semi-definite matrix: cyclic Jacobi eigenvalues, the
    eigenvalues below 1e-12 of the largest taken as zero."""
    p = len(a)
    a = [list(map(float, row)) for row in a]
    v = [[float(i == j) for j in range(p)] for i in range(p)]
    for _ in range(100):
        off = math.fsum(a[i][j] ** 2 for i in range(p) for j in range(p) if i != j)
        if off <= 1e-30 * math.fsum(a[i][i] ** 2 for i in range(p)):
            break
        for i in range(p - 1):
            for j in range(i + 1, p):
                if a[i][j] == 0.0:
                    continue
                theta = (a[j][j] - a[i][i]) / (2.0 * a[i][j])
                t = math.copysign(1.0, theta) / (abs(theta) + math.sqrt(theta * theta + 1.0))
                c = 1.0 / math.sqrt(t * t + 1.0)
                s = t * c
                for k in range(p):          # a := a R, then a := Rᵀ a, R the rotation in the (i, j) plane
                    aki, akj = a[k][i], a[k][j]
                    a[k][i], a[k][j] = c * aki - s * akj, s * aki + c * akj
                for k in range(p):
                    aik, ajk = a[i][k], a[j][k]
                    a[i][k], a[j][k] = c * aik - s * ajk, s * aik + c * ajk
                for k in range(p):
                    vki, vkj = v[k][i], v[k][j]
                    v[k][i], v[k][j] = c * vki - s * vkj, s * vki + c * vkj
    eig = [a[i][i] for i in range(p)]
    top = max(eig, default=0.0)
    inv = [1.0 / e if e > 1e-12 * top else 0.0 for e in eig]
    return np.array([[math.fsum(v[i][k] * inv[k] * v[j][k] for k in range(p)) for j in range(p)] for i in range(p)])


def least_squares_fit(residuals: Callable, t0, xtol: float = XTOL, ftol: float = FTOL,
                      max_steps: int = MAX_STEPS) -> np.ndarray:
    """The coordinates minimising ½|residuals(t)|² from ``t0``: Levenberg–Marquardt with forward-difference
    Jacobians (:func:`jacobian`) and the deterministic arithmetic above. Ends when a step is below ``xtol``
    relative to t, when it lowers the cost by less than ``ftol`` of it, or after ``max_steps`` trial points."""
    t = np.asarray(t0, dtype=float)
    r = residuals(t)
    cost = 0.5 * _dot(r, r)
    damping, trials = 1e-3, 0
    while trials < max_steps:
        jac = jacobian(residuals, t, at=r)
        a, g = _normal_matrix(jac), np.array([_dot(jac[:, i], r) for i in range(jac.shape[1])])
        while trials < max_steps:
            damped = a + np.diag([damping * (d if d > 0.0 else 1.0) for d in np.diag(a)])
            try:
                step = _solve(damped, -g)
            except ZeroDivisionError:
                return t
            trial = t + step
            r_trial = residuals(trial)
            trials += 1
            cost_trial = 0.5 * _dot(r_trial, r_trial)
            if cost_trial < cost:
                done = (math.sqrt(_dot(step, step)) <= xtol * (xtol + math.sqrt(_dot(t, t)))
                        or cost - cost_trial <= ftol * cost)
                t, r, cost, damping = trial, r_trial, cost_trial, max(damping / 10.0, 1e-12)
                if done:
                    return t
                break
            damping *= 10.0
            if damping > 1e12:
                return t
    return t


@dataclasses.dataclass(frozen=True, eq=False)
class Calibration:
    """A fitted wall law and what it was fitted to.

    ``values``: every fit value of the family by name (:func:`fit_form`: the fitted and the fixed, units of
    :data:`direct_model.wall.WALL_FAMILIES`); ``wall``: the law they make; ``free``: those fitted; ``standard_error``: theirs (delta method from
    the fit coordinates); ``correlation``: (P, P) of the free ones. ``chi2`` over ``dof`` = 2m − P degrees of
    freedom; ``scaled``: the covariance is scaled by χ²/dof (an sd was estimated). ``sd_estimate``: (2,) the sd per
    particle estimated for a quantity given without one (NaN where given). ``fitted``, ``default``: (m, 2) the
    model's means in the data's quantities at the fit and at the published law (``default_law``);
    ``fitted_se``: the model's Monte Carlo standard errors of ``fitted``. ``mix``: weight by constituent.
    """

    family: str
    values: dict
    wall: Wall
    free: tuple
    standard_error: dict
    correlation: np.ndarray
    chi2: float
    dof: int
    scaled: bool
    sd_estimate: np.ndarray
    data: Measurements
    fitted: np.ndarray
    fitted_se: np.ndarray
    default: np.ndarray
    default_law: Wall
    mix: dict
    particles: int
    seed: int
    evaluations: int

    @property
    def chi2_dof(self) -> float:
        return self.chi2 / self.dof


def _mix(mix, config) -> dict:
    """``mix`` (None: :data:`DEFAULT_MIX`; a mapping name → weight, or names in equal parts) checked and
    normalised; names are built-in families or the grid shapes of ``config``."""
    if mix is None:
        return dict(DEFAULT_MIX)
    weights = dict(mix) if isinstance(mix, Mapping) else {name: 1.0 for name in mix}
    available = (*FAMILIES, *(config.shapes if config is not None else ()))
    for name, weight in weights.items():
        if name not in available:
            hint = "" if config is not None else " (a user grain: name it in the grid of a --config FILE)"
            raise ValueError(f"the grain {name!r} is not one of {', '.join(dict.fromkeys(available))}{hint}")
        if not (math.isfinite(weight) and weight >= 0):
            raise ValueError(f"the weight of {name!r} in the mix must be finite and >= 0; got {weight!r}")
    total = sum(weights.values())
    if not total > 0:
        raise ValueError(f"the weights of the mix must have a sum > 0; got {weights!r}")
    return {name: weight / total for name, weight in weights.items() if weight > 0}


def calibrate(data: Measurements, family: str = EXPONENTIAL, fixed: Mapping | None = None, mix=None,
              particles: int = DEFAULT_PARTICLES, seed: int = DEFAULT_SEED, config=None, progress=None,
              log=None) -> Calibration:
    """Fit the wall law ``family``'s parameters, but the ``fixed`` ones (name → value), to ``data``.

    The model's means are those of :func:`model_means` over ``mix`` (None: the paper's four families in equal
    parts; names, or name → weight), ``particles`` per row shared by the constituents by weight, from seeds
    derived from ``seed`` (:func:`particle_seeds`). ``config`` (a :class:`tablegen.tabulation.config.BuildConfig`
    or None): its grid's user grains may be named in ``mix`` and its kappa, b/a and c/b law and n_max are run (its
    wall is not: it is what is fitted). ``progress``: None, or called with 1 after each evaluation of the model;
    ``log``: None, or called with one warning line naming the data's columns that the fit ignores, once the
    arguments are checked (so that a refusal is the only line).

    The fit is weighted least squares (:func:`least_squares_fit`, the same bits on any CPU) in the coordinates of
    :func:`fit_form`, from the published law; a residual's variance is :func:`residual_variance`, the model's
    variance taken at the stage's start. Where an sd is missing, a first stage takes it as the model's own scatter
    among particles at the published law and a second refits from the first's optimum with it estimated from the
    residuals there (:func:`estimated_sd`). ValueError if the data cannot
    determine the free parameters (fewer rows than them; one speed with both of the form's trade-off pair
    free), a parameter to fix is unknown or out of its range, or the model leaves a row without rebounds.
    """
    form = fit_form(wall_family(family).name, data.speed)
    fixed = dict(fixed or {})
    unknown = [name for name in fixed if name not in form.names]
    if unknown:
        raise ValueError(f"cannot fix '{unknown[0]}': the {family} wall law's fit values are "
                         f"{', '.join(form.names)}")
    for name, value in fixed.items():
        ok, allowed = form.allowed[name]
        if not ok(float(value)):
            raise ValueError(f"cannot fix '{name}' at {value!r}: the {family} wall law's '{name}' must be {allowed}")
    fixed = {name: float(fixed[name]) for name in form.names if name in fixed}
    free = tuple(name for name in form.names if name not in fixed)
    m = len(data.alpha1)
    if not free:
        raise ValueError(f"every parameter of the {family} wall law is fixed ({', '.join(form.names)}); "
                         f"leave at least one free")
    if m < len(free):
        raise ValueError(f"{data.source}: {m} data row{'s' * (m != 1)} and {len(free)} free parameters "
                         f"({', '.join(free)}); allowed: at least as many rows as free parameters (add rows or fix "
                         f"parameters, e.g. --fix {free[-1]}={form.start[free[-1]]:g})")
    pair = form.trade_off
    if pair and all(name in free for name in pair) and len(np.unique(data.speed)) == 1:
        raise ValueError(f"{data.source}, column 'speed_m_s': every row has the speed {data.speed[0]:g} m/s; "
                         f"{pair[0]} and {pair[1]} trade off at one speed; fix one, e.g. --fix "
                         f"{pair[1]}={form.start[pair[1]]:g} (or give two speeds or more)")
    weights = _mix(mix, config)
    if not (isinstance(particles, (int, np.integer)) and not isinstance(particles, bool) and particles >= 1):
        raise ValueError(f"the particles per row must be an integer >= 1; got {particles!r}")
    names = tuple(weights)
    bodies = [name if config is None else config.body(name) for name in names]
    counts = [max(1, round(particles * weights[name])) for name in names]
    seeds = particle_seeds(seed, m, len(names))
    model = {} if config is None else {key: value for key, value in config.model().items() if key != "wall"}
    transforms = [form.transforms[name] for name in free]
    if data.ignored and log is not None:
        log(f"{data.source}: warning: columns ignored: {', '.join(data.ignored)} (the columns read: "
            f"{', '.join(known_columns(data.names))})")

    cache = {}

    def evaluate(values: dict, wall: Wall | None = None):
        """The model's means and their variances in the data's quantities at the fit values ``values`` (or at
        ``wall``, the published law)."""
        # 12 digits: exp(log x) may miss x by an ulp, and is the same law
        key = (wall,) if wall is not None else tuple(float(f"{values[name]:.12g}") for name in form.names)
        if key not in cache:
            wall = wall if wall is not None else form.make(values, "calibration")
            means, variances = model_means(wall, data.alpha1, data.speed, bodies, [weights[n] for n in names],
                                           counts, seeds, model)
            empty = np.flatnonzero(np.isnan(means[:, 0]))
            if empty.size:
                raise ValueError(f"{data.source} {data.rows[empty[0]]}: no particle of the mix rebounded with "
                                 f"{wall.law_text()}; the data are far from this law (check the columns)")
            cache[key] = (in_form(data.names, data.alpha1, means), in_form(data.names, data.alpha1, variances, True))
            if progress is not None:
                progress(1)
        return cache[key]

    def values_at(t) -> dict:
        return {**fixed, **{name: tr.inverse(float(x)) for name, tr, x in zip(free, transforms, t)}}

    def weighted(t, variance):
        return ((evaluate(values_at(t))[0] - data.mean) / np.sqrt(variance)).ravel()

    def stage_variance(t, sd_estimate):
        return residual_variance(data.sd, data.count, evaluate(values_at(t))[1], sd_estimate)

    def fit(t0, variance):
        return least_squares_fit(lambda t: weighted(t, variance), t0)

    start = {**form.start, **fixed}
    t = np.array([tr.forward(start[name]) for name, tr in zip(free, transforms)])
    # stage 1: a missing sd starts as the model's own scatter among particles at the published law
    model_variance = evaluate(start)[1]
    sd_estimate = np.where(data.sd_given, np.nan, [math.sqrt(math.fsum(model_variance[:, k] * particles) / m)
                                                   for k in range(2)])
    variance = stage_variance(t, sd_estimate)
    t = fit(t, variance)
    if not np.all(data.sd_given):
        # stage 2: a missing sd from the residuals of the first optimum
        sd_estimate = np.where(data.sd_given, np.nan, estimated_sd(evaluate(values_at(t))[0] - data.mean,
                                                                   data.count, len(free)))
        variance = stage_variance(t, sd_estimate)
        t = fit(t, variance)
    fitted, fitted_variance = evaluate(values_at(t))
    chi2 = math.fsum(((fitted - data.mean) ** 2 / variance).ravel())
    dof = 2 * m - len(free)
    scaled = not bool(np.all(data.sd_given))
    cov = covariance(jacobian(lambda x: weighted(x, variance), t, central=True), chi2 / dof if scaled else 1.0)
    se_t = np.sqrt(np.diag(cov))
    values = values_at(t)
    return Calibration(
        family=form.family, values={name: values[name] for name in form.names}, wall=form.make(values, "calibrated"),
        free=free,
        standard_error={name: float(tr.slope(x) * s) for name, tr, x, s in zip(free, transforms, t, se_t)},
        correlation=cov / np.outer(se_t, se_t), chi2=chi2, dof=dof, scaled=scaled, sd_estimate=sd_estimate,
        data=data, fitted=fitted, fitted_se=np.sqrt(fitted_variance), default=evaluate({}, DEFAULT_LAW)[0],
        default_law=DEFAULT_LAW, mix=weights, particles=particles, seed=seed, evaluations=len(cache))


# ------------------------------------------------------------------------------------------------ the outputs

def _law_text(values: Mapping) -> str:
    return ", ".join(f"{name} = {value:.6g}" for name, value in values.items())


def format_calibration(cal: Calibration) -> str:
    """The fit as text: values with standard errors, correlations, χ²/dof, and each row's measured, fitted and
    published-law means."""
    data, names = cal.data, cal.data.names
    lines = [f"{cal.family} wall law fitted to {data.source}: {len(data.alpha1)} rows of {', '.join(names)}, "
             f"speeds {data.speed.min():g}-{data.speed.max():g} m/s, alpha1 {data.alpha1.min():g}-"
             f"{data.alpha1.max():g} deg",
             "grains: " + ", ".join(f"{name} {w:.3g}" for name, w in cal.mix.items())
             + f"; {cal.particles} particles per row, seed {cal.seed} (the same particles at every evaluation); "
               f"{cal.evaluations} evaluations of the model"]
    for q, name in enumerate(names):
        lines.append(f"sd of {name}: " + ("given (weights n/sd^2)" if data.sd_given[q] else
                                         f"not given; estimated from the residuals: {cal.sd_estimate[q]:.4g} per "
                                         f"particle, the same in every row"))
    lines += ["", f"{'parameter':<10} {'value':>12} {'std. error':>12}"]
    for name, value in cal.values.items():
        se = f"{cal.standard_error[name]:12.4g}" if name in cal.free else f"{'(fixed)':>12}"
        lines.append(f"{name:<10} {value:12.6g} {se}")
    lines += ["", "correlation: " + "  ".join(f"{name:>6}" for name in cal.free)]
    for name, row in zip(cal.free, cal.correlation):
        lines.append(f"{name:>11}  " + "  ".join(f"{c:6.3f}" for c in row))
    lines += ["", f"chi2/dof = {cal.chi2_dof:.3g} (chi2 {cal.chi2:.4g}, dof {cal.dof}); standard errors from the "
                  f"Jacobian at the optimum" + (", scaled by chi2/dof (an sd was estimated)" if cal.scaled else ""),
              "", f"means: measured, fitted (model s.e.), default law ({cal.default_law.law_text()})",
              f"{'row':<26} {'alpha1':>7} {'speed':>7}"
              + "".join(f" {name + ' data':>11} {'fit':>16} {'default':>8}" for name in names)]
    for i, row in enumerate(data.rows):
        lines.append(f"{row:<26} {data.alpha1[i]:7.3g} {data.speed[i]:7.4g}" + "".join(
            f" {data.mean[i, q]:11.4f} {cal.fitted[i, q]:8.4f} ({cal.fitted_se[i, q]:.4f}) {cal.default[i, q]:8.4f}"
            for q in range(2)))
    return "\n".join(lines)


def wall_toml(cal: Calibration, name: str) -> str:
    """The fitted law as the ``[wall]`` section of a build configuration (tablegen.tabulation.config), named
    ``name``, after comment lines on the fit; the file alone is a configuration too (the default grid)."""
    data = cal.data
    errors = ", ".join(f"{p} = {cal.values[p]:.6g} +- {cal.standard_error[p]:.2g}" for p in cal.free)
    fixed = ", ".join(f"{p} = {cal.values[p]:.6g}" for p in cal.values if p not in cal.free)
    return "\n".join([
        TOML_MARKER.format(kind=WALL_FILE_KIND) + "generated by tablegen calibrate",
        f"# data: {data.source} ({len(data.alpha1)} rows of {', '.join(data.names)}; speeds "
        f"{data.speed.min():g} to {data.speed.max():g} m/s, alpha1 {data.alpha1.min():g} to {data.alpha1.max():g} deg)",
        f"# fit: chi2/dof = {cal.chi2_dof:.3g} (dof {cal.dof}); {errors}" + (f"; fixed {fixed}" if fixed else ""),
        "# grains: " + ", ".join(f"{n} {w:.3g}" for n, w in cal.mix.items())
        + f"; {cal.particles} particles per row, seed {cal.seed}",
        "# paste the [wall] section into a build configuration (or build with this file as --config)",
        "[wall]",
        *wall_values_toml(cal.wall),
        f"name = {json.dumps(name)}",
        f"speed_range_m_s = [{float(data.speed.min())!r}, {float(data.speed.max())!r}]   # the data's: where the "
        "law holds",
        ""])


def figure_png(cal: Calibration) -> bytes:
    """A PNG of the measured means (± their standard errors sd/√n where sd is given), the fit and the published
    law against α1 (deg): one panel per quantity, one colour per speed."""
    from matplotlib.figure import Figure
    from matplotlib.lines import Line2D

    data = cal.data
    fig = Figure(figsize=(11.0, 4.4), layout="constrained")
    axes = fig.subplots(1, 2)
    speeds = np.unique(data.speed)
    for q, ax in enumerate(axes):
        for colour, speed in enumerate(speeds):
            rows = np.flatnonzero(data.speed == speed)
            rows = rows[np.argsort(data.alpha1[rows])]
            a = data.alpha1[rows]
            error = data.sd[rows, q] / np.sqrt(data.count[rows]) if data.sd_given[q] else None
            ax.errorbar(a, data.mean[rows, q], yerr=error, fmt="o", color=f"C{colour}", capsize=3)
            ax.plot(a, cal.fitted[rows, q], "-", color=f"C{colour}")
            ax.plot(a, cal.default[rows, q], "--", color=f"C{colour}", alpha=0.6)
        ax.set_xlabel("α1, deg")
        ax.set_ylabel(data.names[q])
        ax.grid(alpha=0.3)
    handles = ([Line2D([], [], color=f"C{c}", lw=6, label=f"{s:g} m/s") for c, s in enumerate(speeds)]
               + [Line2D([], [], color="grey", marker="o", ls="", label="data" + (" (± sd/√n)" if any(
                   data.sd_given) else "")),
                  Line2D([], [], color="grey", ls="-", label="fit"),
                  Line2D([], [], color="grey", ls="--", label="default law")])
    axes[1].legend(handles=handles, fontsize=8)
    fig.suptitle(f"{cal.family} wall law fitted to {Path(data.source).name}: {_law_text(cal.values)} "
                 f"(chi2/dof {cal.chi2_dof:.3g})", fontsize=10)
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=110, metadata={PNG_KEY: FIGURE_KIND})
    return buffer.getvalue()


def require_matplotlib() -> None:
    """ImportError telling what to install if matplotlib (for ``--figure``) is missing."""
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        raise ImportError(f"tablegen calibrate --figure draws with matplotlib, which is not installed; install it "
                          f"with: {INSTALL_HINT}") from None
