"""Table-build configuration: TOML files and the embedded presets.

A configuration has four sections (every key optional; defaults are those of
the ``default`` preset, and the published corundum-on-steel wall law)::

    [grid]
    alpha1_deg = [1, 2, 3, ...] or {start = 5, stop = 90, step = 5}    # degrees, in (0, 90]
    speed_m_s  = [50, 100, ...]  or {start = 50, stop = 300, step = 50}  # m/s, in [1e-3, 1e4], neighbours ≤ 16× apart
    shapes     = ["ellipsoid", "prism", "cut_prism", "tetrahedron"]

    [simulation]
    particles_per_cell = 20000        # direct-model particles per (shape, α1, |V⁻|) cell
    seed = 20261121                   # master seed; each cell's seed derives from it
    kappa = 0.3                       # cut-prism corner truncation
    n_max = 1000                      # collisions before a particle counts as trapped
    aspect_ratio = {mean = 0.8, sd = 0.2, low = 0.5, high = 1.0}   # b/a and c/b

    [table]
    resolution = "auto"               # or {clusters = .., dictionary_size = .., levels = ..}

    [wall]                            # the wall law of docs/model.md §4 (law = "exponential", the default)
    k = 0.1                           # restitution rate constant, (m/s)^-p, > 0
    p = 0.61                          # restitution speed exponent, > 0
    q = 1.0                           # friction factor exp(q cos gamma), finite
    name = "corundum_on_St3_Lashkov1991"
    speed_range_m_s = [50.0, 300.0]   # the |V⁻| the law was measured over (not stated for your own k, p, q
                                      # unless given): the runtimes count the hits answered outside it
    roughness_deg = 0.0               # the wall's roughness Δγ, degrees, in [0, 45]: 0 smooth (docs/model.md §12)
    # or law = "tabulated": q, contact_speed_m_s = [...], contact_sine = [0.0, ..., 1.0], and
    # restitution = [[a_nc per sine node], one row per speed node] (docs/model.md §4)
    # or preset = "NAME": a wall preset (tablegen/tabulation/walls; docs/model.md §4.8) for every key above but
    # roughness_deg

    [shapes.sand_a]                   # a user's grain, named in grid.shapes (tablegen.tabulation.shape_config)
    mesh = "grains/sand_a.stl"        # relative to the configuration file; or vertices = [[x, y, z], ...]

``grid.shapes`` names built-in families and user grains; each user grain has its ``[shapes.NAME]`` section and
each section is named in ``grid.shapes``. Unknown keys and invalid values raise :class:`ConfigError` naming the
key.
Presets: ``default`` (the README's main job, a few minutes on 2 cores),
``production`` (the table users should run with) and ``paper`` (the study of
Panfilov & Tsirkunov 2022 at 10⁸ particles per cell; for a cluster).
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import math
import tomllib
from importlib import resources
from pathlib import Path

import numpy as np

from data_schema.samples import ALPHA1_RANGE_TEXT, alpha1_is_physical
from data_schema.table import MAX_SPEED_RATIO, SPEED_GRID_RANGE, TableResolution
from tablegen.tabulation.resolution import MIN_PARTICLES_PER_CELL, resolution_for
from direct_model.registry import FAMILIES, ConvexPolyhedron, built_in_shape
from direct_model.shapes import SHAPES, AspectRatioLaw, check_kappa
from direct_model.wall import (CORUNDUM_ON_STEEL, EXPONENTIAL, MAX_ROUGHNESS_DEG, WALL_FAMILIES, Wall,
                               check_roughness, check_speed_range, wall_family, wall_record)
from tablegen.tabulation.config_error import ConfigError
from tablegen.tabulation.shape_config import parse_shape_sections

PRESETS = ("default", "production", "paper")
MAX_GRID_POINTS = 1000      # per axis: far beyond any useful table, small enough to check before allocating
MAX_SEED = 2 ** 63          # seeds are 63-bit (numpy SeedSequence entropy, HDF5 uint64 attribute)
GRID_ROUNDING = 1e-9        # a {start, stop, step} grid keeps a stop that round-off puts just past it


@dataclasses.dataclass(frozen=True, eq=False)
class BuildConfig:
    """A fully resolved build configuration (every value explicit).

    ``grains``: the records (:mod:`direct_model.registry`) of the user's grains of ``shapes``, in their order;
    ``families``: the records of its families after the paper's four (:data:`direct_model.registry.FAMILIES`),
    made when the text was parsed, so that every cell simulates the record its table stores. Two configurations
    are equal when their :meth:`to_toml` texts are: the text decides the table.
    """

    alpha1_deg: tuple
    speed_m_s: tuple
    shapes: tuple
    particles_per_cell: int
    seed: int
    kappa: float
    n_max: int
    aspect: AspectRatioLaw
    resolution: TableResolution
    wall: Wall = CORUNDUM_ON_STEEL
    grains: tuple = ()
    families: tuple = ()

    def __eq__(self, other) -> bool:
        return isinstance(other, BuildConfig) and self.to_toml() == other.to_toml()

    def __hash__(self) -> int:
        return hash(self.to_toml())

    @property
    def n_cells(self) -> int:
        return len(self.shapes) * len(self.alpha1_deg) * len(self.speed_m_s)

    def grain(self, name: str) -> ConvexPolyhedron | None:
        """The record of the user's grain ``name``; None for a built-in family."""
        return next((g for g in self.grains if g.name == name), None)

    def body(self, name: str):
        """What a cell of shape ``name`` simulates (``direct_model.simulate.simulate``'s ``shape``): the record
        of a user grain or of a later family, the name of one of the paper's four (their bits come from
        :mod:`direct_model.shapes`)."""
        return self.grain(name) or next((f for f in self.families if f.name == name), name)

    def model(self) -> dict:
        """The direct model's settings a cell runs with, as keywords of ``direct_model.simulate.simulate``."""
        return {"kappa": self.kappa, "aspect": self.aspect, "n_max": self.n_max, "wall": self.wall}

    def shape_records(self) -> tuple:
        """The record of each shape, in the order of ``shapes``: a family's at ``kappa`` and ``aspect``, or the
        user's grain."""
        bodies = [self.body(s) for s in self.shapes]
        return tuple(built_in_shape(b, self.kappa, self.aspect) if isinstance(b, str) else b for b in bodies)

    def to_toml(self) -> str:
        """The resolved configuration as TOML text (reads back to an equal config)."""
        def fmt(values):
            return "[" + ", ".join(repr(float(v)) for v in values) + "]"
        res = ", ".join(f"{f.name} = {getattr(self.resolution, f.name)}"
                        for f in dataclasses.fields(self.resolution))
        a = self.aspect
        w = self.wall
        return "\n".join([
            "[grid]",
            f"alpha1_deg = {fmt(self.alpha1_deg)}",
            f"speed_m_s = {fmt(self.speed_m_s)}",
            "shapes = [" + ", ".join(f'"{s}"' for s in self.shapes) + "]",
            "",
            "[simulation]",
            f"particles_per_cell = {self.particles_per_cell}",
            f"seed = {self.seed}",
            f"kappa = {self.kappa!r}",
            f"n_max = {self.n_max}",
            f"aspect_ratio = {{mean = {a.mean!r}, sd = {a.sd!r}, low = {a.low!r}, high = {a.high!r}}}",
            "",
            "[table]",
            f"resolution = {{{res}}}",
            "",
            "[wall]",
            *wall_values_toml(w),
            f"name = {json.dumps(w.name)}",
            *([f"speed_range_m_s = [{w.speed_range_m_s[0]!r}, {w.speed_range_m_s[1]!r}]"]
              if w.speed_range_stated else []),
            *([f"roughness_deg = {w.roughness_deg!r}"] if w.roughness_deg != 0.0 else []),
            "",
            *(_grain_toml(g) for g in self.grains),
        ])

    def sha256(self) -> str:
        """Hash of :meth:`to_toml`: identifies the configuration in files and checkpoints."""
        return hashlib.sha256(self.to_toml().encode()).hexdigest()


def wall_values_toml(wall: Wall) -> list:
    """The ``[wall]`` lines of a law's family and values (exact float reprs): an exponential law's k, p, q as
    they always were (so a default table's configuration text, hash and fingerprint stay the same), another
    family's ``law`` line first."""
    def number(x):
        return repr(float(x))
    lines = [] if wall.family == EXPONENTIAL else [f"law = {json.dumps(wall.family)}"]
    lines += [f"{name} = {number(value)}" for name, value in wall.parameters().items()]
    for name, array in wall.arrays().items():
        rows = ["[" + ", ".join(map(number, row)) + "]" for row in np.atleast_2d(array)]
        lines.append(f"{name} = " + ("[" + ", ".join(rows) + "]" if array.ndim == 2 else rows[0]))
    return lines


def _grain_toml(record: ConvexPolyhedron) -> str:
    """The ``[shapes.NAME]`` section of a user's grain as its canonical hull (vertices and triangles), not as its
    mesh file or points.

    The text is what the table stores as its configuration (and hashes, and fingerprints), so it must rebuild
    the table from the table alone: a mesh path would name a file that the table does not hold and that may
    change, and a rotated, moved or rescaled copy of the file, which gives the same grain and the same cells,
    would give another text. The canonical hull (exact float reprs), what /shapes holds, reads back as it is
    (:func:`tablegen.tabulation.grain_files.canonical_grain`): the same record bit for bit, where taking its
    frame again would move it by round-off.
    """
    lines = [f"[shapes.{record.name}]",
             "vertices = [" + ", ".join("[" + ", ".join(repr(float(x)) for x in v) + "]"
                                        for v in record.vertices) + "]",
             "triangles = [" + ", ".join("[" + ", ".join(str(int(i)) for i in t) + "]" for t in record.triangles) + "]"]
    law = record.aspect
    if law is not None:
        lines.append(f"aspect_ratio = {{mean = {law.mean!r}, sd = {law.sd!r}, low = {law.low!r}, high = {law.high!r}}}")
    if record.both_hands:
        lines.append("both_hands = true")
    return "\n".join(lines) + "\n"


# every family's parameters and arrays: a [wall] key of another family than its law is named as such
WALL_VALUE_KEYS = {key for family in WALL_FAMILIES.values() for key in (*family.parameter_names, *family.array_names)}
CONFIG_KEYS = {
    "grid": {"alpha1_deg", "speed_m_s", "shapes"},
    "simulation": {"particles_per_cell", "seed", "kappa", "n_max", "aspect_ratio"},
    "table": {"resolution"},
    "wall": {"preset", "law", *WALL_VALUE_KEYS, "name", "speed_range_m_s", "roughness_deg"},
}
WALL_PRESETS = "tablegen.tabulation.walls"      # the package of the wall presets' files
PRESET_ADDS = ("roughness_deg",)    # what a [wall] section may add to a preset: its surface, not the pair's law
GRAINS_SECTION = "shapes"      # [shapes.NAME]: the user's grains; their keys are shape_config's


def preset_text(name: str) -> str:
    """The TOML text of an embedded preset."""
    if name not in PRESETS:
        raise ConfigError(f"unknown preset {name!r}; presets: {', '.join(PRESETS)}")
    return resources.files("tablegen.tabulation.presets").joinpath(f"{name}.toml").read_text()


def wall_presets() -> tuple:
    """The names of the wall presets (``tablegen/tabulation/walls/NAME.toml``), sorted."""
    files = resources.files(WALL_PRESETS).iterdir()
    return tuple(sorted(f.name.removesuffix(".toml") for f in files if f.name.endswith(".toml")))


def wall_preset_text(name: str) -> str:
    """The TOML text of the wall preset ``name``: its source in comment lines, then its ``[wall]`` section."""
    if name not in wall_presets():
        raise ConfigError(f"unknown wall preset {name!r}; wall presets: {', '.join(wall_presets())}")
    return resources.files(WALL_PRESETS).joinpath(f"{name}.toml").read_text()


def load_config(path=None, preset: str = "default", log=None) -> BuildConfig:
    """Read a configuration file (or the named preset when ``path`` is None); mesh paths are relative to the
    file's folder. ``log``: called with a warning line (a grain's mesh that is not convex)."""
    if path is None:
        return parse_config(preset_text(preset), f"preset '{preset}'")
    try:
        with open(path, "rb") as f:
            text = f.read().decode("utf-8")
    except OSError as exc:
        raise ConfigError(f"{path}: cannot read the configuration: {exc.strerror}") from None
    except UnicodeDecodeError as exc:
        raise ConfigError(f"{path}: the configuration is not UTF-8 text (byte {exc.start}); TOML files are "
                          f"UTF-8") from None
    return parse_config(text, str(path), Path(path).parent, log)


def parse_config(text: str, source: str = "<config>", base_dir=None, log=None) -> BuildConfig:
    """Parse and validate TOML text; defaults come from the ``default`` preset.

    ``base_dir``: the folder relative mesh paths of ``[shapes.NAME]`` start from (default: the current
    directory); ``log``: called with a warning line (a grain's mesh that is not convex, grid speeds outside the
    wall law's speed range).
    """
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"{source}: not valid TOML: {exc}") from exc
    _check_keys(data, source)
    base = {} if source == "preset 'default'" else tomllib.loads(preset_text("default"))
    merged = {section: {**base.get(section, {}), **data.get(section, {})} for section in CONFIG_KEYS}
    grid, sim, table, wall = merged["grid"], merged["simulation"], merged["table"], merged["wall"]

    alpha1 = _grid_values(grid.get("alpha1_deg"), "grid.alpha1_deg", source)
    bad = [a for a in alpha1 if not alpha1_is_physical(a)]
    if bad:
        raise ConfigError(f"{source}: 'grid.alpha1_deg' values must be in {ALPHA1_RANGE_TEXT} degrees; got {bad[0]!r}")
    speeds = _grid_values(grid.get("speed_m_s"), "grid.speed_m_s", source)
    low, high = SPEED_GRID_RANGE
    bad = [v for v in speeds if not low <= v <= high]
    if bad:
        raise ConfigError(f"{source}: 'grid.speed_m_s' values must be in [{low:g}, {high:g}] m/s (what the model "
                          f"and the runtime serve); got {bad[0]!r}")
    wide = [(a, b) for a, b in zip(speeds, speeds[1:]) if b > MAX_SPEED_RATIO * a]
    if wide:
        raise ConfigError(f"{source}: 'grid.speed_m_s' has consecutive speeds {wide[0][0]!r} and {wide[0][1]!r} m/s, a "
                          f"factor {wide[0][1] / wide[0][0]:.3g} apart; allowed: at most {MAX_SPEED_RATIO:g} (the "
                          f"runtime's restitution pieces between grid speeds); add speeds between them")
    shapes = grid.get("shapes")
    sections = data.get(GRAINS_SECTION, {})
    if not isinstance(shapes, list) or not shapes:
        raise ConfigError(f"{source}: 'grid.shapes' must be a non-empty list of {', '.join(FAMILIES)} or the "
                          f"names of [shapes.NAME] sections; got {shapes!r}")
    for s in shapes:
        if not isinstance(s, str) or (s not in FAMILIES and s not in sections):
            raise ConfigError(f"{source}: 'grid.shapes' entries must be one of {', '.join(FAMILIES)} or a user grain "
                              f"with its [shapes.NAME] section; got {s!r}, which has no section")
    if len(set(shapes)) != len(shapes):
        raise ConfigError(f"{source}: 'grid.shapes' has duplicates: {shapes!r}")
    grains = {}
    if sections:
        grains = parse_shape_sections(sections, Path.cwd() if base_dir is None else base_dir, source, log,
                                      used=shapes)

    n = _integer(sim.get("particles_per_cell"), "simulation.particles_per_cell", MIN_PARTICLES_PER_CELL, source)
    seed = _integer(sim.get("seed"), "simulation.seed", 0, source)
    if seed >= MAX_SEED:
        raise ConfigError(f"{source}: 'simulation.seed' must be < 2**63; got {seed!r}")
    n_max = _integer(sim.get("n_max"), "simulation.n_max", 1, source)
    try:
        kappa = check_kappa(sim.get("kappa"))
    except (TypeError, ValueError):
        raise ConfigError(f"{source}: 'simulation.kappa' must be in [0, 1); got {sim.get('kappa')!r}") from None
    aspect_raw = sim.get("aspect_ratio")
    if not isinstance(aspect_raw, dict) or set(aspect_raw) - {"mean", "sd", "low", "high"}:
        raise ConfigError(f"{source}: 'simulation.aspect_ratio' must be a table with keys mean, sd, low, "
                          f"high; got {aspect_raw!r}")
    try:
        aspect = AspectRatioLaw(**{k: float(v) for k, v in aspect_raw.items()})
    except (TypeError, ValueError) as exc:
        raise ConfigError(f"{source}: 'simulation.aspect_ratio': {exc}") from None

    res_raw = table.get("resolution")
    if res_raw == "auto":
        resolution = resolution_for(n)
    elif isinstance(res_raw, dict):
        allowed = {f.name for f in dataclasses.fields(TableResolution)}
        unknown = set(res_raw) - allowed
        if unknown:
            raise ConfigError(f"{source}: unknown key 'table.resolution.{sorted(unknown)[0]}'; "
                              f"allowed: {', '.join(sorted(allowed))}")
        try:
            resolution = TableResolution(**res_raw)
        except (TypeError, ValueError) as exc:
            raise ConfigError(f"{source}: 'table.resolution': {exc}") from None
    else:
        raise ConfigError(f"{source}: 'table.resolution' must be \"auto\" or a table of sizes; got {res_raw!r}")

    wall = _wall(wall, source)
    outside = [v for v in speeds if wall.outside_speed_range(v)]
    if outside and log is not None:
        log(f"warning: {source}: the grid's speeds {', '.join(f'{v:g}' for v in outside)} m/s lie outside "
            f"{wall.speed_range_text()}, where the wall law {wall.name!r} holds (wall.speed_range_m_s); its cells "
            f"apply the law there all the same")
    return BuildConfig(alpha1_deg=tuple(alpha1), speed_m_s=tuple(speeds), shapes=tuple(shapes),
                       particles_per_cell=n, seed=seed, kappa=kappa, n_max=n_max, aspect=aspect,
                       resolution=resolution, wall=wall,
                       grains=tuple(grains[s] for s in shapes if s in grains),
                       families=tuple(built_in_shape(s, kappa, aspect) for s in shapes
                                      if s in FAMILIES and s not in SHAPES))


def _wall(raw: dict, source: str) -> Wall:
    """The wall law of the ``[wall]`` section: its family ``law`` (:data:`direct_model.wall.WALL_FAMILIES`;
    default exponential) and that family's parameters and arrays by name, each checked against its range;
    missing scalar parameters take the corundum-on-steel law's values (its q for the tabulated family), a
    tabulated law's arrays must be given. Its speed range ``speed_range_m_s`` = [low, high] m/s: the default
    law's when no law value is given, else not stated unless given. ``preset`` names a wall preset
    (:func:`wall_presets`), whose section stands for the law, its name and its speed range; ``roughness_deg`` may
    be added to it."""
    if "preset" in raw:
        raw = _preset_section(raw, source)
    law = raw.get("law", EXPONENTIAL)
    if law not in WALL_FAMILIES:
        raise ConfigError(f"{source}: 'wall.law' must be one of {', '.join(WALL_FAMILIES)}; got {law!r}")
    family = wall_family(law)
    own_keys = {*family.parameter_names, *family.array_names}
    foreign = sorted(k for k in raw if k in WALL_VALUE_KEYS and k not in own_keys)
    if foreign:
        raise ConfigError(f"{source}: 'wall.{foreign[0]}' is not a parameter of the {law} wall law (its "
                          f"parameters: {', '.join((*family.parameter_names, *family.array_names))})")
    values = {}
    for parameter in family.parameters:
        value = raw.get(parameter.name, CORUNDUM_ON_STEEL.parameters()[parameter.name])
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not parameter.ok(float(value)):
            raise ConfigError(f"{source}: 'wall.{parameter.name}' must be a number, {parameter.allowed}; got {value!r}")
        values[parameter.name] = float(value)
    for array in family.arrays:
        if array.name not in raw:
            raise ConfigError(f"{source}: the {law} wall law needs 'wall.{array.name}': {array.meaning}")
        value = raw[array.name]
        rows = value if len(array.dims) == 2 and isinstance(value, list) else [value]
        if not isinstance(value, list) or any(not isinstance(row, list) or any(
                isinstance(x, bool) or not isinstance(x, (int, float)) for x in row) for row in rows):
            raise ConfigError(f"{source}: 'wall.{array.name}' must be "
                              f"{'a list of lists' if len(array.dims) == 2 else 'a list'} of numbers "
                              f"({array.meaning}); got {value!r}")
        values[array.name] = value
    name = raw.get("name", CORUNDUM_ON_STEEL.name)
    if not isinstance(name, str) or not name.strip():
        raise ConfigError(f"{source}: 'wall.name' must be a non-empty string; got {name!r}")
    own_law = any(k in raw for k in (*own_keys, "law"))
    speed_range = raw.get("speed_range_m_s", None if own_law else CORUNDUM_ON_STEEL.speed_range_m_s)
    if speed_range is not None:
        if (not isinstance(speed_range, (list, tuple)) or len(speed_range) != 2
                or any(isinstance(x, bool) or not isinstance(x, (int, float)) for x in speed_range)):
            raise ConfigError(f"{source}: 'wall.speed_range_m_s' must be two numbers [low, high] in m/s, "
                              f"0 <= low < high; got {speed_range!r}")
        try:
            speed_range = check_speed_range(speed_range)
        except ValueError:
            raise ConfigError(f"{source}: 'wall.speed_range_m_s' must be finite with 0 <= low < high (m/s); "
                              f"got {speed_range!r}") from None
    roughness = raw.get("roughness_deg", 0.0)
    try:
        roughness = check_roughness(roughness)
    except ValueError:
        raise ConfigError(f"{source}: 'wall.roughness_deg' must be a number in [0, {MAX_ROUGHNESS_DEG:g}] degrees "
                          f"(0: a smooth wall); got {roughness!r}") from None
    try:
        return wall_record(family.name, values, name, speed_range, roughness)
    except ValueError as exc:       # a tabulated law's nodes or values: the message names the parameter
        raise ConfigError(f"{source}: [wall]: {exc}") from None


def _preset_section(raw: dict, source: str) -> dict:
    """The ``[wall]`` section of the preset ``raw["preset"]``, with the keys of :data:`PRESET_ADDS` that ``raw``
    gives; ConfigError for an unknown preset or a key the preset sets."""
    preset, presets = raw["preset"], wall_presets()
    if not isinstance(preset, str) or preset not in presets:
        raise ConfigError(f"{source}: 'wall.preset' must be one of {', '.join(presets)}; got {preset!r}")
    extra = sorted(k for k in raw if k not in ("preset", *PRESET_ADDS))
    if extra:
        raise ConfigError(f"{source}: 'wall.{extra[0]}' cannot be given with 'wall.preset' (the preset {preset!r} "
                          f"sets the law, its name and speed range; only {', '.join(PRESET_ADDS)} may be added)")
    section = tomllib.loads(wall_preset_text(preset))["wall"]
    return {**section, **{key: raw[key] for key in PRESET_ADDS if key in raw}}


def _check_keys(data: dict, source: str) -> None:
    for section, value in data.items():
        if section not in CONFIG_KEYS and section != GRAINS_SECTION:
            raise ConfigError(f"{source}: unknown section '[{section}]'; sections: {', '.join(CONFIG_KEYS)}, "
                              f"{GRAINS_SECTION}.NAME")
        if not isinstance(value, dict):
            raise ConfigError(f"{source}: '{section}' must be a table ([{section}])")
        if section == GRAINS_SECTION:
            continue                  # its sections' keys: shape_config.parse_shape_sections
        for key in value:
            if key not in CONFIG_KEYS[section]:
                raise ConfigError(f"{source}: unknown key '{section}.{key}'; allowed in [{section}]: "
                                  f"{', '.join(sorted(CONFIG_KEYS[section]))}")


def _integer(value, key, minimum, source) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < minimum:
        raise ConfigError(f"{source}: '{key}' must be an integer >= {minimum}; got {value!r}")
    return value


def _grid_values(spec, key, source) -> list:
    """A grid from a list of numbers or {start, stop, step} (stop included)."""
    if isinstance(spec, dict):
        if set(spec) != {"start", "stop", "step"}:
            raise ConfigError(f"{source}: '{key}' as a table needs exactly start, stop, step; got {spec!r}")
        try:
            start, stop, step = (float(spec[k]) for k in ("start", "stop", "step"))
        except (TypeError, ValueError):
            raise ConfigError(f"{source}: '{key}' start, stop, step must be numbers; got {spec!r}") from None
        if not (all(map(math.isfinite, (start, stop, step))) and step > 0 and stop >= start):
            raise ConfigError(f"{source}: '{key}' needs finite numbers with step > 0 and stop >= start; "
                              f"got {spec!r}")
        span = (stop - start) / step
        if not span < MAX_GRID_POINTS:
            raise ConfigError(f"{source}: '{key}' = {spec!r} gives {span + 1:.3g} grid points; allowed: at most "
                              f"{MAX_GRID_POINTS} (a larger step)")
        count = math.floor(span + GRID_ROUNDING) + 1
        values = [start + k * step for k in range(count)]
    elif isinstance(spec, list):
        values = spec
    else:
        raise ConfigError(f"{source}: '{key}' must be a list of numbers or {{start, stop, step}}; got {spec!r}")
    if not values:
        raise ConfigError(f"{source}: '{key}' is empty; give at least one value")
    if len(values) > MAX_GRID_POINTS:
        raise ConfigError(f"{source}: '{key}' has {len(values)} values; allowed: at most {MAX_GRID_POINTS}")
    if any(isinstance(v, bool) or not isinstance(v, (int, float)) for v in values):
        raise ConfigError(f"{source}: '{key}' values must be numbers; got {values!r}")
    values = [float(v) for v in values]
    if any(b <= a for a, b in zip(values, values[1:])):
        raise ConfigError(f"{source}: '{key}' values must be strictly increasing; got {values!r}")
    return values
