"""Figures of ``tablegen report`` (docs/report.md), drawn with matplotlib.

matplotlib is the optional ``plots`` extra; it is imported only here, lazily,
through the object-oriented API (:class:`matplotlib.figure.Figure`, no pyplot,
no display needed). Frames and quantities are those of :mod:`tablegen.study.statistics`:
lab frame of docs/model.md §2, V = |V⁻|, angles in degrees on the axes.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from direct_model.shapes import MIX
from tablegen.study.statistics import (
    NORMAL_IMPACT, QUANTITIES, ReportData, derived, indicatrix_2d, indicatrix_3d, nearest_alpha1,
)
from tablegen.study.wall_work import bitter_deformation, finnie, means, scaled_to_meet

if TYPE_CHECKING:
    from matplotlib.figure import Figure

INSTALL_HINT = 'pip install "rebound-scatter[plots]"'
DPI = 110
PDF_BINS = 60
PROFILE_ALPHA1 = (15.0, 30.0, 45.0, 60.0, 75.0, 90.0)  # deg, wanted α1 of the PDFs and 2-D indicatrices


def require_matplotlib() -> None:
    """ImportError telling what to install if matplotlib is missing."""
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        raise ImportError(f"tablegen report draws its figures with matplotlib, which is not installed; "
                          f"install it with: {INSTALL_HINT}") from None


def _figure(width: float, height: float):
    from matplotlib.figure import Figure
    return Figure(figsize=(width, height), layout="constrained")


def _shape_style(shape: str, i: int) -> dict:
    """Line style of a shape: tab10 colours, the mix thick and black."""
    if shape == MIX:
        return {"color": "black", "lw": 2.2, "marker": "o", "ms": 3.5, "label": shape}
    return {"color": f"C{i}", "lw": 1.2, "marker": "o", "ms": 3.0, "label": shape}


def _alpha1_colours(values) -> list:
    from matplotlib import colormaps
    cmap = colormaps["viridis"]
    return [cmap(0.9 * t) for t in np.linspace(0.0, 1.0, len(values))] if len(values) > 1 else [cmap(0.0)]


def _vs_alpha1(data: ReportData, stats: dict, keys) -> Figure:
    """One row per quantity key, columns mean and most probable, one line per shape, against α1."""
    fig = _figure(9.0, 3.0 * len(keys))
    axes = fig.subplots(len(keys), 2, squeeze=False)
    quantities = {q.key: q for q in QUANTITIES}
    for row, key in zip(axes, keys):
        for ax, kind, name in zip(row, ("mean", "mode"), ("mean", "most probable")):
            for i, shape in enumerate(data.shapes):
                ax.plot(data.alpha1, [stats[shape, a][kind][key] for a in data.alpha1], **_shape_style(shape, i))
            ax.set(xlabel=r"$\alpha_1$ (deg)", ylabel=f"{name} {quantities[key].tex}", xlim=(0, 90))
            ax.grid(alpha=0.3)
    axes[0, 0].legend(fontsize="small")
    return fig


def velocity_figure(data, stats):
    return _vs_alpha1(data, stats, ("u", "v"))


def spin_figure(data, stats):
    return _vs_alpha1(data, stats, ("omega_z",))


def energy_figure(data, stats):
    return _vs_alpha1(data, stats, ("e_trans", "e_rot"))


def _pdf_figure(data: ReportData, key: str) -> Figure:
    """One panel per shape: PDF of quantity ``key`` at several α1 (density over the rebounds)."""
    alphas = nearest_alpha1(data.alpha1, PROFILE_ALPHA1)
    colours = _alpha1_colours(alphas)
    tex = {q.key: q.tex for q in QUANTITIES}[key]
    fig = _figure(3.2 * len(data.shapes), 3.2)
    axes = fig.subplots(1, len(data.shapes), squeeze=False)[0]
    for ax, shape in zip(axes, data.shapes):
        samples = [derived(data.points[shape, a])[key] for a in alphas]
        pooled = np.concatenate(samples)
        lo, hi = np.percentile(pooled, [0.5, 99.5]) if pooled.size else (0.0, 1.0)
        edges = np.linspace(lo, hi if hi > lo else lo + 1.0, PDF_BINS + 1)
        for a, x, colour in zip(alphas, samples, colours):
            counts, _ = np.histogram(x, bins=edges)
            ax.stairs(counts / (max(x.size, 1) * np.diff(edges)), edges, color=colour,
                      label=rf"$\alpha_1$ = {a:g}°")
        ax.set(title=shape, xlabel=tex, ylabel="PDF")
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize="small")
    return fig


def pdf_u_figure(data, stats):
    return _pdf_figure(data, "u")


def pdf_v_figure(data, stats):
    return _pdf_figure(data, "v")


def pdf_omega_figure(data, stats):
    return _pdf_figure(data, "omega_z")


def indicatrix_2d_figure(data: ReportData, stats):
    """Polar I(α2) (1/rad) per shape at several α1; dashed: the sphere's specular direction α2 = α1."""
    from matplotlib.ticker import MaxNLocator

    alphas = nearest_alpha1(data.alpha1, PROFILE_ALPHA1)
    colours = _alpha1_colours(alphas)
    fig = _figure(3.2 * len(data.shapes) + 1.2, 2.8)
    for i, shape in enumerate(data.shapes):
        ax = fig.add_subplot(1, len(data.shapes), i + 1, projection="polar")
        for a, colour in zip(alphas, colours):
            edges, density = indicatrix_2d(data.points[shape, a].alpha2)
            ax.plot(0.5 * (edges[:-1] + edges[1:]), density, color=colour, label=rf"$\alpha_1$ = {a:g}°")
            ax.axvline(np.radians(a), color=colour, ls="--", lw=0.9)
        ax.set_thetamin(0)
        ax.set_thetamax(180)
        ax.yaxis.set_major_locator(MaxNLocator(3))
        ax.tick_params(labelsize="x-small")
        ax.set_title(shape)
    fig.legend(*fig.axes[0].get_legend_handles_labels(), loc="outside right upper", fontsize="small")
    fig.supxlabel(r"angle: $\alpha_2$ from the wall (+X); radius: $I(\alpha_2)$ (1/rad); "
                  r"dashed: specular direction $\alpha_2 = \alpha_1$", fontsize="small")
    return fig


def indicatrix_3d_figure(data: ReportData, stats):
    """Per shape at normal impact: I(α2, β2) as a 3-D polar surface (top) and as a map (bottom)."""
    a1 = nearest_alpha1(data.alpha1, [NORMAL_IMPACT])[0]
    n = len(data.shapes)
    fig = _figure(3.4 * n, 6.4)
    grid = fig.add_gridspec(2, n, height_ratios=(1.0, 1.0))
    for i, shape in enumerate(data.shapes):
        p = data.points[shape, a1]
        a_edges, b_edges, density = indicatrix_3d(p.alpha2, p.beta2)
        _surface(fig.add_subplot(grid[0, i], projection="3d"), a_edges, b_edges, density, a1, shape)
        _map(fig, fig.add_subplot(grid[1, i]), a_edges, b_edges, density, a1)
    fig.suptitle(rf"$\alpha_1$ = {a1:g}°")
    return fig


def _surface(ax, a_edges, b_edges, density, alpha1: float, shape: str) -> None:
    """Surface of radius I(α2, β2) along each rebound direction; plot axes X, Z (lab) horizontal, Y up."""
    from matplotlib import colormaps
    a, b = np.meshgrid(0.5 * (a_edges[:-1] + a_edges[1:]), 0.5 * (b_edges[:-1] + b_edges[1:]), indexing="ij")
    r = density
    top = max(float(r.max()), 1e-12)
    ax.plot_surface(r * np.cos(b) * np.cos(a), r * np.sin(b), r * np.cos(b) * np.sin(a),
                    facecolors=colormaps["viridis"](r / top), linewidth=0, antialiased=False, shade=False)
    s = np.radians(alpha1)
    ax.plot([0, 1.15 * top * np.cos(s)], [0, 0], [0, 1.15 * top * np.sin(s)], color="red", ls="--", lw=1.2)
    ax.set(xlim=(-top, top), ylim=(-top, top), zlim=(0, top), xlabel="X", ylabel="Z", zlabel="Y")
    ax.set_box_aspect((2, 2, 1), zoom=1.1)
    ax.view_init(elev=25, azim=-60)
    ax.tick_params(labelsize="x-small")
    ax.set_title(f"{shape}, max I = {top:.2f} 1/rad²", fontsize="small")


def _map(fig, ax, a_edges, b_edges, density, alpha1: float) -> None:
    """Map of I(α2, β2) (1/rad²) over α2 and β2 in degrees; ×: the sphere's specular direction."""
    mesh = ax.pcolormesh(np.degrees(a_edges), np.degrees(b_edges), density.T, cmap="viridis")
    ax.plot([alpha1], [0.0], marker="x", color="red", ms=8, mew=2)
    ax.set(xlabel=r"$\alpha_2$ (deg)", ylabel=r"$\beta_2$ (deg)", xlim=(0, 180), ylim=(-90, 90))
    fig.colorbar(mesh, ax=ax, label=r"$I(\alpha_2, \beta_2)$ (1/rad²)")


# file, title, caption, drawing function (data, stats) -> Figure
FIGURES = (
    ("velocity_vs_alpha1.png", "Reflected velocity against α1",
     "Mean (left) and most probable (right) u⁺/V (top; tangential, +X) and v⁺/V (bottom; wall-normal, +Y) "
     "against the incidence angle α1, one line per shape, the mix in black.", velocity_figure),
    ("pdf_u.png", "PDF of u⁺/V",
     "Probability density of u⁺/V over the rebounded particles at several α1, one panel per shape.", pdf_u_figure),
    ("pdf_v.png", "PDF of v⁺/V",
     "Probability density of v⁺/V over the rebounded particles at several α1, one panel per shape.", pdf_v_figure),
    ("pdf_omega_z.png", "PDF of Ω_z a/V",
     "Probability density of the spin Ω_z a/V (about +Z, the normal of the impact plane) at several α1, "
     "one panel per shape.", pdf_omega_figure),
    ("spin_vs_alpha1.png", "Spin against α1",
     "Mean (left) and most probable (right) Ω_z a/V against α1.", spin_figure),
    ("energy_vs_alpha1.png", "Energy ratios against α1",
     "Mean (left) and most probable (right) E_V⁺/E_V⁻ (top, translational) and E_Ω⁺/E_V⁻ (bottom, "
     "rotational) against α1; both relative to the incident kinetic energy ½ m V².", energy_figure),
    ("indicatrix_2d.png", "2-D scattering indicatrices",
     "I(α2) in 1/rad (∫ I dα2 = 1 over the rebounds, 2.5° bins) as polar plots: angle α2 from the wall "
     "(+X at 0°, the normal +Y at 90°), radius I. Dashed radial lines: the specular direction of a sphere, "
     "α2 = α1, in the colour of each α1.", indicatrix_2d_figure),
    ("indicatrix_3d.png", "3-D scattering indicatrix at normal impact",
     "I(α2, β2) in 1/rad² (∫∫ I dα2 dβ2 = 1 over the rebounds, 5° × 5° bins) at the α1 nearest 90°. Top: "
     "the surface whose distance from the origin along each rebound direction "
     "(cos β2 cos α2, cos β2 sin α2, sin β2) is I, coloured by I; the wall-normal +Y points up. Bottom: "
     "the same as a map over α2 and β2. Red: the specular direction of a sphere (α2 = α1, β2 = 0).",
     indicatrix_3d_figure),
)


def rough_figure(data: ReportData) -> Figure:
    """Mean α2 (left) and the standard deviation of β2 (right) against α1, one line per roughness Δγ."""
    fig = _figure(11, 4.2)
    left, right = fig.subplots(1, 2)
    for roughness in sorted({g for g, _ in data.rough}):
        points = [(a1, data.rough[roughness, a1]) for a1 in data.alpha1 if (roughness, a1) in data.rough]
        a1 = [a for a, _ in points]
        label = "smooth" if roughness == 0 else f"Δγ = {roughness:g}°"
        left.plot(a1, [np.degrees(r.alpha2).mean() for _, r in points], marker="o", label=label)
        right.plot(a1, [np.degrees(r.beta2).std() for _, r in points], marker="o", label=label)
    left.set(xlabel=r"$\alpha_1$ (deg)", ylabel=r"mean $\alpha_2$ (deg)")
    right.set(xlabel=r"$\alpha_1$ (deg)", ylabel=r"sd of $\beta_2$ (deg)")
    left.legend()
    fig.suptitle(f"{data.rough_shape} on rough walls, |V⁻| = {data.speed:g} m/s")
    return fig


def work_figure(data):
    """Mean W_n/E⁻ (left) and W_t/E⁻ (middle) against α1 per shape at each speed (the second speed dashed), with
    Bitter's and Finnie's angle dependence scaled to meet the mix's at the first speed; right, the mix's median
    and 10–90 % band of each at each speed."""
    fig = _figure(15.0, 4.4)
    left, middle, right = fig.subplots(1, 3)
    alpha1 = np.asarray(data.alpha1)
    speeds = data.work_speeds
    for i, shape in enumerate(data.shapes):
        style = _shape_style(shape, i)
        for k, speed in enumerate(speeds):
            normal, tangential = means(data.work, shape, alpha1, speed)
            kw = dict(style, ls="-" if k == len(speeds) - 1 else "--", label=f"{shape}, {speed:g} m/s")
            left.plot(alpha1, normal, **kw)
            middle.plot(alpha1, tangential, **kw)
    reference = "mix" if "mix" in data.shapes else data.shapes[0]
    normal, tangential = means(data.work, reference, alpha1, speeds[-1])
    fine = np.linspace(max(alpha1.min(), 0.5), 90.0, 200)
    for ax, law, curve, name in ((left, bitter_deformation, normal, "Bitter deformation, sin²α1"),
                                 (middle, finnie, tangential, "Finnie cutting")):
        at, c = scaled_to_meet(law, alpha1, curve)
        ax.plot(fine, c * law(fine), color="grey", lw=1.5, ls=":", label=f"{name} (meets {reference} at {at:g}°)")
    for k, speed in enumerate(speeds):
        points = [data.work[reference, a, speed] for a in alpha1]
        for values, colour in (([p.normal for p in points], "C0"), ([p.tangential for p in points], "C3")):
            q = np.array([np.quantile(v, [0.1, 0.5, 0.9]) if v.size else [np.nan] * 3 for v in values])
            right.plot(alpha1, q[:, 1], color=colour, ls="-" if k == len(speeds) - 1 else "--")
            right.fill_between(alpha1, q[:, 0], q[:, 2], color=colour, alpha=0.15 if k == len(speeds) - 1 else 0.08)
    right.plot([], [], color="C0", label="$W_n/E^-$")
    right.plot([], [], color="C3", label="$W_t/E^-$")
    for ax, label in ((left, r"mean $W_n/E^-$"), (middle, r"mean $W_t/E^-$"),
                      (right, f"{reference}: median, 10–90 %")):
        ax.set(xlabel=r"$\alpha_1$ (deg)", ylabel=label)
        ax.legend(fontsize=6.5)
    return fig


def write_figures(data: ReportData, stats: dict, folder) -> list:
    """Draw and save every figure of :data:`FIGURES` into ``folder``, :func:`rough_figure` as ``rough_wall.png`` if
    the data have rough walls and :func:`work_figure` as ``wall_work.png`` if they have the work on the wall;
    return [(file, title, caption)] of :data:`FIGURES`'."""
    written = []
    for file, title, caption, draw in FIGURES:
        draw(data, stats).savefig(Path(folder) / file, dpi=DPI)
        written.append((file, title, caption))
    if data.rough:
        rough_figure(data).savefig(Path(folder) / "rough_wall.png", dpi=DPI)
    if data.work:
        work_figure(data).savefig(Path(folder) / "wall_work.png", dpi=DPI)
    return written
