"""The paper's study as a report folder (``tablegen report``; docs/report.md).

Panfilov & Tsirkunov (2022) study the rebound at |V⁻| = 200 m/s with no
incident spin (Ω⁻ = 0) as a function of the incidence angle α1, for each shape
and for the equal-weight mix. This module

1. gathers, per (shape, α1), the reflected states of the rebounded particles
   (α2, β2, s = |V⁺|/|V⁻|, Ω⁺a/|V⁻|, E_Ω⁺/E_V⁻) and the counts by status and by
   number of collisions, from the direct model (:func:`direct_data`) or from a
   table (:func:`table_data`);
2. derives u⁺/|V⁻|, v⁺/|V⁻|, Ω_z a/|V⁻|, E_V⁺/E_V⁻ and E_Ω⁺/E_V⁻ (docs/model.md
   §6), their means and most probable values, and the scattering indicatrices
   (:mod:`tablegen.study.statistics`);
3. writes the figures (:mod:`tablegen.study.figures`) and an ``index.md`` with
   the numbers into a new folder (:func:`write_report`).

Frame: the lab frame of docs/model.md §2 (wall y = 0, normal +Y into the gas,
impact plane XY, V⁻ = |V⁻|(cos α1, −sin α1, 0)). Angles are in degrees at the
interface and in radians inside the samples. V stands for |V⁻|.
"""

from __future__ import annotations

import dataclasses
import datetime
import math
import tomllib
from pathlib import Path

import numpy as np

from data_schema.common import package_version
from data_schema.output import atomic_folder
from data_schema.samples import STATUS_REBOUNDED
from direct_model.registry import FAMILIES
from direct_model.shapes import MIX, SHAPES, AspectRatioLaw, second_moment_factor
from tablegen.progress import progress_bar
from tablegen.study.figures import require_matplotlib, write_figures
from tablegen.study.statistics import (
    COLLISION_CLASSES, NORMAL_IMPACT, QUANTITIES, PointSamples, ReportData, RoughSamples, from_sample_set,
    nearest_alpha1, point_statistics,
)
from tablegen.study.wall_work import means, pooled, work_samples

PAPER_SPEED = 200.0                                    # m/s, incident speed of the paper's study
WORK_SPEEDS = (100.0, PAPER_SPEED)                     # m/s, of the work on the wall: also at half the speed
DEFAULT_ALPHA1 = tuple(float(a) for a in range(5, 91, 5))   # deg
DEFAULT_N = 20_000
INERTIA_QUADRATURE_POINTS = 4096                       # midpoint rule of ⟨r²⟩ over the aspect-ratio law


# -- derived quantities -------------------------------------------------------

def isotropic_inertia(shape: str, kappa: float, aspect: AspectRatioLaw) -> float:
    """Mean of tr J/(3 m a²) over the aspect-ratio law: the isotropic inertia per unit mass, units of a².

    J/m = s (b² + c², a² + c², a² + b²) in the body frame (docs/model.md §3), so
    tr J/(3 m a²) = (2/3) s (1 + (b/a)² + (c/a)²). With b/a and c/b independent
    and alike, ⟨(c/a)²⟩ = ⟨r²⟩² where ⟨r²⟩ = ∫₀¹ ppf(u)² du (midpoint rule,
    :data:`INERTIA_QUADRATURE_POINTS` points).
    """
    u = (np.arange(INERTIA_QUADRATURE_POINTS) + 0.5) / INERTIA_QUADRATURE_POINTS
    r2 = float(np.mean(aspect.ppf(u) ** 2))
    return 2.0 / 3.0 * second_moment_factor(shape, kappa) * (1.0 + r2 + r2 * r2)


def grain_isotropic_inertia(record) -> float:
    """tr J/(3 m a²) of a user's grain (a registry record), units of a²: of its body if it keeps its proportions,
    else the mean over its own b/a, c/b law, on a midpoint grid of √INERTIA_QUADRATURE_POINTS quantiles each
    (the stretched body's a moves with the ratios, so no closed form)."""
    if record.aspect is None:
        return float(record.inertia.sum()) / 3.0
    side = math.isqrt(INERTIA_QUADRATURE_POINTS)
    ratios = record.aspect.ppf((np.arange(side) + 0.5) / side)
    return float(np.mean([record.stretched(r1, r2).inertia.sum() for r1 in ratios for r2 in ratios])) / 3.0


# -- data stage -------------------------------------------------------------

def _constituents(shapes, available) -> tuple:
    """Shapes to sample: the pure shapes asked for, and every available shape if the mix is."""
    return tuple(s for s in available if s in shapes or MIX in shapes)


def pool(parts) -> PointSamples:
    """Union of several shapes' samples; the equal-weight mix when each part has as many particles."""
    counts = ("status_counts", "collision_counts")
    merged = {name: sum(getattr(p, name) for p in parts) for name in counts}
    for f in dataclasses.fields(PointSamples):
        if f.name not in counts:
            merged[f.name] = np.concatenate([getattr(p, f.name) for p in parts])
    return PointSamples(**merged)


def _with_mix(parts: dict, shapes, mix_of, merge=pool) -> dict:
    """The reported samples of ``parts`` (keyed (shape, α1, ...)): the pure shapes asked for, and the mix, ``merge``
    of ``mix_of``'s at the same α1 (and speed)."""
    rests = dict.fromkeys(key[1:] for key in parts)
    return {(shape, *rest): merge([parts[(s, *rest)] for s in mix_of]) if shape == MIX else parts[(shape, *rest)]
            for shape in shapes for rest in rests}


def direct_data(shapes, alpha1=DEFAULT_ALPHA1, n: int = DEFAULT_N, seed: int = 0,
                progress: bool = False, config=None) -> ReportData:
    """Run the direct model at 200 m/s, Ω⁻ = 0, for each shape and α1 (deg); ``n`` particles each; and at each
    speed of :data:`WORK_SPEEDS` for the work on the wall.

    Every run uses the same ``seed`` (common random numbers: the same
    orientations and aspect ratios at every point). The mix pools the
    available shapes' runs; it has no run of its own. ``config`` (a
    :class:`tablegen.tabulation.config.BuildConfig`, or None): the shapes of its grid, its user grains among them,
    are the available ones and its model (kappa, the b/a and c/b law, n_max, the wall law) is run, as its table's
    cells are; None: the built-in families with the model's defaults.
    """
    from direct_model.simulate import simulate

    available = tuple(FAMILIES) if config is None else config.shapes
    model = {} if config is None else config.model()
    alpha1 = tuple(sorted(set(float(a) for a in alpha1)))
    mix_of = _constituents(shapes, available)
    bar = progress_bar(progress, len(mix_of) * len(alpha1) * len(WORK_SPEEDS) * n, "particle", "report runs")
    parts, work = {}, {}
    for shape in mix_of:
        body = shape if config is None else config.body(shape)
        for a in alpha1:
            for speed in WORK_SPEEDS:
                run = simulate(body, a, speed, n, seed=seed, **model)
                work[shape, a, speed] = work_samples(run.status, run.extra["wall_work_normal"],
                                                     run.extra["wall_work_tangential"], speed)
                if speed == PAPER_SPEED:
                    parts[shape, a] = from_sample_set(run)
                if bar is not None:
                    bar.update(n)
    if bar is not None:
        bar.close()
    source = "direct model (`direct_model.simulate.simulate`)"
    if config is not None:
        source += f" with the model of a build configuration (grid shapes {', '.join(available)})"
    return ReportData(
        source=source, speed=PAPER_SPEED, alpha1=alpha1,
        shapes=_ordered(shapes, available), mix_of=tuple(available), n=n, seed=seed,
        counts_note=f"Counted over the {n} simulated particles per shape.",
        e_rot_method="exact: E_Ω⁺ = ½ Ω⁺·JΩ⁺ with each particle's own inertia tensor and orientation "
                     "(docs/model.md §5.4).",
        points=_with_mix(parts, shapes, available), work=_with_mix(work, shapes, available, pooled),
        work_speeds=WORK_SPEEDS, work_source="the direct model, the same seed at every point")


def table_data(path, shapes=None, alpha1=None, n: int = DEFAULT_N, seed: int = 0, roughness=()) -> ReportData:
    """Draw ``n`` reflected states per shape and α1 from a table, at its grid speed nearest 200 m/s.

    The work on the wall (a table of format 4.1): ``n`` hits per (shape, α1) at the grid speeds nearest
    :data:`WORK_SPEEDS` by :func:`surrogate.sample_global`.

    ``roughness``: roughness values Δγ (degrees, in [0, 45]) at which to draw, besides, the law of the mix (or of
    the first reported shape without it) on rough walls: ``n`` hits per (Δγ, α1) by :func:`surrogate.sample_global`
    (docs/model.md §12), in :attr:`ReportData.rough`.

    ``shapes``: names of the table's shapes (families or user grains) and ``"mix"``; None: all and the mix.

    ``alpha1`` (deg) must be grid points of the table (default: all of them),
    so every draw comes from one cell. The statuses and collision counts are
    those the table stores per cell (its build's particles). E_Ω⁺/E_V⁻ uses
    :func:`isotropic_inertia`: a table holds Ω⁺ but not the particle's
    orientation or aspect ratio (:func:`grain_isotropic_inertia` for a user's grain). The mix pools the table's
    shapes.
    """
    import surrogate
    from data_schema.table import read_table

    table = read_table(path)
    sampler = surrogate.load(path)
    grid = np.asarray(table.alpha1_deg, dtype=float)
    alpha1 = tuple(float(a) for a in grid) if alpha1 is None else _grid_points(alpha1, grid)
    shapes = tuple(table.shapes) + (MIX,) if shapes is None else shapes
    missing = [s for s in shapes if s != MIX and s not in table.shapes]
    if missing:
        raise ValueError(f"The 'shapes' {', '.join(missing)} are not in the table {path} "
                         f"(it holds {', '.join(table.shapes)}).")
    i_speed = int(np.argmin(np.abs(np.asarray(table.speed_m_s) - PAPER_SPEED)))
    speed = float(table.speed_m_s[i_speed])
    mix_of = _constituents(shapes, tuple(table.shapes))
    aspect = _aspect_law(table.config_text)
    records = dict(zip(table.shapes, table.shape_records()))
    inertias = {s: isotropic_inertia(s, table.kappa, aspect) if s in SHAPES else grain_isotropic_inertia(records[s])
                for s in mix_of}
    parts = {}
    for shape in mix_of:
        inertia = inertias[shape]
        for a in alpha1:
            cell = (table.shapes.index(shape), int(np.argmin(np.abs(grid - a))), i_speed)
            d = surrogate.sample_local(sampler, np.full(n, a), speed, shape, random_state=seed)
            ok = d.status == STATUS_REBOUNDED
            collisions = table.cells["collision_counts"][cell]
            parts[shape, a] = PointSamples(
                alpha2=d.alpha2[ok], beta2=d.beta2[ok], speed_ratio=d.speed_ratio[ok], omega=d.omega[ok],
                e_rot_ratio=inertia * np.sum(d.omega[ok] ** 2, axis=1),
                status_counts=np.asarray(table.cells["status_counts"][cell], dtype=np.int64),
                collision_counts=np.r_[collisions[:5], collisions[5:].sum()].astype(np.int64))
    work = {}
    if sampler.kernel_data.has_work:
        grid_speeds = [float(table.speed_m_s[int(np.argmin(np.abs(np.asarray(table.speed_m_s) - v)))])
                       for v in WORK_SPEEDS]
        work = {(shape, a, v): _table_work(sampler, shape, a, v, n, seed) for shape in mix_of for a in alpha1
                for v in dict.fromkeys(grid_speeds)}
    inertias = ", ".join(f"{s} {value:.4f}" for s, value in inertias.items())
    rough_shape = MIX if MIX in shapes else shapes[0]
    rough = {(float(g), a): _rough_samples(sampler, rough_shape, a, speed, g, n, seed) for g in roughness
             for a in alpha1}
    return ReportData(
        source=f"table `{path}` (made {table.created}, config sha256 {table.config_sha256[:12]}…), "
               f"drawn with `surrogate.sample_local`",
        speed=speed, alpha1=alpha1, shapes=_ordered(shapes, tuple(table.shapes)), mix_of=tuple(table.shapes), n=n,
        seed=seed,
        counts_note=f"From the table's cells: {table.particles_per_cell} direct-model particles per shape.",
        e_rot_method="approximate: a table stores Ω⁺ but not the particle's orientation or aspect ratio, so "
                     "E_Ω⁺/E_V⁻ = k̄ |Ω⁺a/V|² with k̄ the isotropic inertia ⟨tr J⟩/(3 m a²) averaged over the "
                     f"aspect-ratio law of the table ({inertias}). Against the direct model at 200 m/s this "
                     "overestimates the mean E_Ω⁺/E_V⁻ by 4–11 %, and by up to 21 % for ellipsoids near "
                     "normal impact (docs/report.md).",
        points=_with_mix(parts, shapes, tuple(table.shapes)), rough=rough,
        rough_shape=rough_shape if rough else "", work=_with_mix(work, shapes, tuple(table.shapes), pooled),
        work_speeds=tuple(sorted({v for _, _, v in work})),
        work_source="drawn from the table with `surrogate.sample_global`, at its grid speeds nearest "
                    + " and ".join(f"{v:g}" for v in WORK_SPEEDS) + " m/s")


def _table_work(sampler, shape: str, alpha1: float, speed: float, n: int, seed: int):
    """The work on the wall of ``n`` table hits of ``shape`` at (α1 deg, |V⁻| m/s) on the lab wall
    (:func:`surrogate.sample_global`, the table path; half-size 1 m: the work does not depend on it)."""
    import surrogate

    a1 = math.radians(alpha1)
    V = np.tile([speed * math.cos(a1), -speed * math.sin(a1), 0.0], (n, 1))
    # clamp: α1 recomputed from V may fall a rounding error outside the grid
    hits = surrogate.sample_global(sampler, V, [0.0, 1.0, 0.0], 1.0, shape, random_state=seed, method="table",
                                   clamp=True)
    return work_samples(hits.status, hits.wall_work_normal, hits.wall_work_tangential, speed)


def _rough_samples(sampler, shape: str, alpha1: float, speed: float, roughness: float, n: int,
                   seed: int) -> RoughSamples:
    """``n`` hits of ``shape`` (the table's mix for ``"mix"``) at (α1 deg, |V⁻| m/s) on the lab wall of
    roughness ``roughness`` degrees, by :func:`surrogate.sample_global` (half-size 1 m: the angles do not
    depend on it)."""
    import surrogate

    a1 = math.radians(alpha1)
    V = np.tile([speed * math.cos(a1), -speed * math.sin(a1), 0.0], (n, 1))
    hits = surrogate.sample_global(sampler, V, [0.0, 1.0, 0.0], 1.0, shape, random_state=seed,
                                   roughness_deg=roughness)
    ok = hits.status == STATUS_REBOUNDED
    Vp = hits.V[ok]
    return RoughSamples(alpha2=np.arctan2(Vp[:, 1], np.hypot(Vp[:, 0], Vp[:, 2])),
                        beta2=np.arctan2(Vp[:, 2], Vp[:, 0]), again=float(np.mean(hits.wall_hits > 1)),
                        trapped=float(np.mean(hits.status == surrogate.STATUS_TRAPPED)))


def _ordered(shapes, available) -> tuple:
    """The reported shapes in the order of the available ones (the families', or the table's), then the mix."""
    return tuple(s for s in tuple(available) + (MIX,) if s in shapes)


def _grid_points(alpha1, grid) -> tuple:
    """``alpha1`` (deg) as grid points; ValueError naming the grid if one is not on it."""
    values = sorted(set(float(a) for a in alpha1))
    off = [a for a in values if not np.any(np.isclose(grid, a, rtol=0.0, atol=1e-9))]
    if off:
        raise ValueError(f"The 'alpha1' values must be grid points of the table "
                         f"({', '.join(f'{g:g}' for g in grid)} deg); got {', '.join(f'{a:g}' for a in off)}.")
    return tuple(values)


def _aspect_law(config_text: str) -> AspectRatioLaw:
    """The aspect-ratio law recorded in a table's build configuration (default law if absent)."""
    raw = tomllib.loads(config_text).get("simulation", {}).get("aspect_ratio")
    return AspectRatioLaw(**{k: float(v) for k, v in raw.items()}) if raw else AspectRatioLaw()


# -- output -----------------------------------------------------------------

REPORT_KIND = "study_report"      # the kind a report folder's marker names (data_schema.output)


def study_statistics(data: ReportData) -> dict:
    """{(shape, α1): :func:`point_statistics`} over every reported point."""
    return {key: point_statistics(p) for key, p in data.points.items()}


def write_report(data: ReportData, out, overwrite: bool = False) -> Path:
    """Write the figures and ``index.md`` into the new folder ``out``; return its path.

    The folder is written under a temporary name next to ``out`` and swapped
    into place when complete, so ``out`` never holds a half-written report.
    An existing ``out`` is replaced only with ``overwrite`` and only if it is a
    report folder this function wrote (its marker file); anything else is
    refused with :class:`data_schema.output.OutputError`.
    Raises ImportError naming the ``plots`` extra if matplotlib is missing.
    """
    require_matplotlib()
    stats = study_statistics(data)
    with atomic_folder(out, REPORT_KIND, overwrite) as tmp:
        figures = write_figures(data, stats, tmp)
        (tmp / "index.md").write_text(render_index(data, stats, figures), encoding="utf-8")
    return Path(out)


def _fmt(x: float) -> str:
    return "–" if not np.isfinite(x) else f"{x:.4f}"


def markdown_table(header, rows) -> str:
    """A markdown table from a header and rows of cells (strings)."""
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(row) + " |" for row in rows]
    return "\n".join(lines)


def render_index(data: ReportData, stats: dict, figures) -> str:
    """The text of ``index.md``: conditions, frames, every figure (``figures``: (file, title, caption)), numbers."""
    parts = [_conditions(data)]
    for file, title, caption in figures:
        parts.append(f"## {title}\n\n{caption}\n\n![{title}]({file})")
    parts.append(_collision_section(data, stats))
    if data.work:
        parts.append(_work_section(data))
    if data.rough:
        parts.append(_rough_section(data))
    parts.append("## Numbers\n\nMeans and most probable (m.p.) values over the rebounded particles; "
                 "\"rebounds\" is the number of rebounded samples, \"trapped %\" is of all particles.")
    for shape in data.shapes:
        parts.append(f"### {shape}\n\n" + _numbers_table(data, stats, shape))
    return "\n\n".join(parts) + "\n"


def _rough_section(data: ReportData) -> str:
    """The rough walls' numbers: per (Δγ, α1) the mean and sd of α2 and β2 (deg) and the shares that hit again
    and were trapped."""
    rows = []
    for (roughness, a1), r in data.rough.items():
        alpha2, beta2 = np.degrees(r.alpha2), np.degrees(r.beta2)
        rows.append([f"{roughness:g}", f"{a1:g}", f"{alpha2.mean():.2f}", f"{alpha2.std():.2f}",
                     f"{beta2.mean():.2f}", f"{beta2.std():.2f}", f"{100 * r.again:.2f}", f"{100 * r.trapped:.2f}"])
    return ("## Rough walls\n\n"
            f"{data.rough_shape} on walls of roughness Δγ (docs/model.md §12) at |V⁻| = {data.speed:g} m/s, "
            f"{data.n} hits of `surrogate.sample_global` per row (the table where it holds, the direct model for "
            "the other facet hits); \"hit again\": a rebound off a facet into the mean wall, hitting another facet."
            "\n\n![Rough walls](rough_wall.png)\n\n"
            + markdown_table(["Δγ (deg)", "α1 (deg)", "α2 mean", "α2 sd", "β2 mean", "β2 sd", "hit again %",
                              "trapped %"], rows))


def _work_section(data: ReportData) -> str:
    """The report's section: the figure and, per shape, the mean W_n/E⁻ and W_t/E⁻ against α1 at each speed."""
    header = ["α1 (deg)"] + [f"{name} {speed:g} m/s" for speed in data.work_speeds
                             for name in ("W_n/E⁻", "W_t/E⁻")]
    tables = []
    for shape in data.shapes:
        columns = [means(data.work, shape, data.alpha1, speed) for speed in data.work_speeds]
        rows = [[f"{a:g}"] + [f"{values[k]:.4f}" for pair in columns for values in pair]
                for k, a in enumerate(data.alpha1)]
        tables.append(f"### {shape}\n\n" + markdown_table(header, rows))
    return ("## Work on the wall\n\n"
            f"The work of each hit on the wall per unit mass (docs/model.md §4.7) in units of E⁻ = ½|V⁻|²: W_n of "
            f"the normal impulses (indentation), W_t of the tangential ones (cutting), over the hits that "
            f"rebounded or were trapped, at |V⁻| = {', '.join(f'{v:g}' for v in data.work_speeds)} m/s "
            f"({data.work_source}). Grey: Bitter's (1963) deformation wear, sin²α1, beside W_n, and Finnie's "
            f"(1960) ductile cutting beside W_t, each scaled to meet the mix's mean curve at the speed "
            f"{data.work_speeds[-1]:g} m/s where that curve peaks: shapes of curves, not magnitudes (those models "
            f"give the volume a sphere's hit removes).\n\n![Work on the wall](wall_work.png)\n\n"
            + "\n\n".join(tables))


def _conditions(data: ReportData) -> str:
    mix = (f"; mix = the equal-weight union of {', '.join(data.mix_of)} (as many particles of each)"
           if MIX in data.shapes else "")
    rows = [("source", data.source),
            ("incident speed \\|V⁻\\|", f"{data.speed:g} m/s" + ("" if data.speed == PAPER_SPEED else
                                                               " (the table's grid speed nearest 200 m/s)")),
            ("incident spin Ω⁻", "0"),
            ("α1 (deg)", ", ".join(f"{a:g}" for a in data.alpha1)),
            ("shapes", ", ".join(data.shapes) + mix),
            ("samples per (shape, α1)", f"{data.n}"),
            ("seed", f"{data.seed} (the same for every (shape, α1))"),
            ("made", f"{datetime.datetime.now(datetime.timezone.utc).isoformat(timespec='seconds')} by "
                     f"`tablegen report`, package version {package_version()}")]
    widths = markdown_table(["quantity", "bin width"], [(q.text, f"{q.mode_bin:g}") for q in QUANTITIES])
    return "\n\n".join([
        "# Rebound study at the conditions of Panfilov & Tsirkunov (2022)",
        markdown_table(["", ""], rows),
        "**Frame** (docs/model.md §2): lab frame, wall y = 0 with normal +Y into the gas, impact plane XY, "
        "V⁻ = V (cos α1, −sin α1, 0) with V = |V⁻|. α1 is measured from the wall (90° is a normal impact); "
        "α2 = atan2(v⁺, u⁺) is the in-plane rebound angle from +X and β2 = asin(w⁺/|V⁺|) the out-of-plane "
        "angle. u⁺ and v⁺ are the tangential and wall-normal components of V⁺, Ω_z a/V the spin about the "
        "normal of the impact plane. E_V⁺/E_V⁻ = (|V⁺|/V)² and E_Ω⁺/E_V⁻ are the translational and "
        "rotational kinetic energies after the rebound over the incident kinetic energy ½ m V². All "
        "statistics are over the rebounded particles; trapped and failed particles are only counted.",
        f"**E_Ω⁺/E_V⁻** is {data.e_rot_method}",
        "**Most probable value**: the centre of the fullest bin of a histogram with bins "
        "[k·w, (k+1)·w) of fixed width w (the lowest bin on a tie). Modes are fragile where a "
        "distribution has two near-equal peaks or a sharp edge (docs/model.md §6).\n\n" + widths,
    ])


def _collision_section(data: ReportData, stats: dict) -> str:
    a = nearest_alpha1(data.alpha1, [NORMAL_IMPACT])[0]
    header = ["shape"] + list(COLLISION_CLASSES) + ["trapped %", "failed %"]
    rows = [[shape] + [f"{c:.1f} %" for c in stats[shape, a]["collision_percent"]]
            + [f"{stats[shape, a]['trapped_percent']:.2f}", f"{stats[shape, a]['failed_percent']:.2f}"]
            for shape in data.shapes]
    return (f"## Collisions per rebound at α1 = {a:g}°\n\nPercentages of the rebounds with 1, 2, 3, 4, 5 and "
            f"more than 5 collisions; trapped and failed are percentages of all particles. "
            f"{data.counts_note}\n\n" + markdown_table(header, rows))


def _numbers_table(data: ReportData, stats: dict, shape: str) -> str:
    header = ["α1 (deg)", "rebounds", "trapped %"] + [f"{kind} {q.text}" for q in QUANTITIES
                                                      for kind in ("mean", "m.p.")]
    rows = []
    for a in data.alpha1:
        st = stats[shape, a]
        rows.append([f"{a:g}", f"{st['rebounds']}", f"{st['trapped_percent']:.2f}"]
                    + [_fmt(st[kind][q.key]) for q in QUANTITIES for kind in ("mean", "mode")])
    return markdown_table(header, rows)
