"""Human-readable description of a rebound table (``tablegen info``)."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np

from data_schema.samples import STATUS_NAMES
from data_schema.table import ReboundTable, table_fingerprint
from direct_model.registry import FAMILIES, ConvexPolyhedron

STEP_DECIMALS = 9       # grid steps equal to this many decimals count as one step (round-off of {start, stop, step})


def _grid(values) -> str:
    v = np.asarray(values)
    steps = np.unique(np.round(np.diff(v), STEP_DECIMALS)) if len(v) > 1 else []
    step = f", step {steps[0]:g}" if len(steps) == 1 else ""
    return f"{len(v)} values, {v[0]:g} to {v[-1]:g}{step}"


def _shape(record, width: int) -> str:
    """One shape of a table: name (in a column ``width`` wide), kind, vertex count, its aspect-ratio law and
    hands."""
    if isinstance(record, ConvexPolyhedron):
        kind = f"convex polyhedron, {len(record.vertices)} vertices"
    else:
        kind = "smooth body (ellipsoid)"
    law = record.aspect
    scaled = (f"b/a, c/b ~ N({law.mean:g}, {law.sd:g}) in [{law.low:g}, {law.high:g}]" if law is not None
              else "fixed proportions")
    built_in = "built-in" if record.name in FAMILIES else "user grain"
    return f"{record.name:<{width}} {built_in}, {kind}; {scaled}{'; both hands' if record.both_hands else ''}"


def describe_table(table: ReboundTable, path: Path | None = None) -> str:
    """Format version, fingerprint (with ``path``), grids, shapes (one line each: name, kind, vertex count, law),
    counts per cell (summarised), size, config hash."""
    counts = table.cells["status_counts"]            # (shape, alpha, speed, status)
    total = counts.sum(axis=-1)
    lines = []
    if path is not None:
        lines += [f"{path}: rebound table, {path.stat().st_size / 1e6:.1f} MB",
                  f"fingerprint sha256 {table_fingerprint(path)} (its content: docs/format.md, 'Fingerprint')"]
    lines += [
        f"format version {table.format_version[0]}.{table.format_version[1]}, made {table.created} by package "
        f"version {table.package_version}",
        "the work on the wall: " + ("W_n, W_t drawn with each rebound" if table.has_work else
                                    "not held (format 4.0: rebuild the table for W_n, W_t)"),
        f"config sha256 {table.config_sha256}, master seed {table.master_seed}",
        f"alpha1 (deg): {_grid(table.alpha1_deg)}",
        f"speed (m/s):  {_grid(table.speed_m_s)}",
        f"shapes: {len(table.shapes)} (cut_prism kappa = {table.kappa:g}); n_max = {table.n_max}",
        *(f"  {_shape(record, max(16, *(len(r.name) for r in table.shape_records())))}"
          for record in table.shape_records()),
        f"wall: {table.wall.name} ({table.wall.family} law: "
        + ", ".join(f"{name} = {value:g}" for name, value in table.wall.parameters().items())
        + f"; holds for |V-| {table.wall.speed_range_text()})",
        f"cells: {total.size}, {table.particles_per_cell} particles each",
        "resolution: " + ", ".join(f"{f.name} {getattr(table.resolution, f.name)}"
                                   for f in dataclasses.fields(table.resolution)),
    ]
    rows = []
    for s, shape in enumerate(table.shapes):
        frac = 100.0 * counts[s] / total[s][..., None]
        rows.append([shape] + [f"{f.min():6.2f}..{f.max():6.2f} (mean {f.mean():6.2f})"
                               for f in (frac[..., k] for k in range(len(STATUS_NAMES)))])
    header = ["shape"] + [f"{name} %" for name in STATUS_NAMES.values()]
    # each column as wide as its longest entry, two spaces apart: a long shape name never runs into a number
    widths = [max(len(row[c]) for row in rows + [header]) for c in range(len(header))]
    for row in [header] + rows:
        lines.append(f"{row[0]:<{widths[0]}}" + "".join(f"  {x:>{w}}" for x, w in zip(row[1:], widths[1:])))
    return "\n".join(lines)
