"""Read what a code_saturne run with rebound-scatter walls wrote: the hit records and the log's counts.

The hit records are RUN/hits/hits_<rank>.csv (``hits = hits`` in the settings file), one per rank, in the
layout both adapters write (tablegen.study.hit_records, which reads them): here the boundary zone is the
``patch``, origProc/origId are -1 (6.0's particles carry no persistent id), Ω⁻ is 0 (they carry no spin)
and U_w is 0; ``interaction`` is :data:`HITS_TITLE` where a table or the direct model answered, ``rebound``
for a zone of type rebound, and ``wall`` the wall of the zone's table. The files' second line ends with
what each zone does (:func:`zone_settings`). The counts are the summary rbs_cs_finalize writes to
run_solver.log, in total (:func:`read_summary`) and per zone (:func:`zone_summary`).

Copyright (C) 2026 the rebound-scatter authors. License: GPL-2.0-or-later
(see LICENSE in this folder).
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from saturne_api import rank_files, read_hit_files, summary_counts  # noqa: E402

HITS_TITLE = "code_saturne rebound-scatter"   # the hits files' header: "# code_saturne rebound-scatter hits: ..."
STOCK_TYPES = ("rebound", "deposit", "outlet")   # the zone types that do what the solver's own types do
# the per-zone summary's columns (rbs_cs_finalize), by key
ZONE_SUMMARY = {"hits": "hits", "rebounded": "rebounded", "stuck": "stuck", "removed": "removed",
                "escaped": "escaped", "invalid": "invalid", "trapped": "trapped", "failed": "failed",
                "table": "table", "direct": "direct", "speed_below": "|V|<grid", "speed_above": "|V|>grid",
                "alpha1_outside": "alpha1-out", "outside_law": "out-of-law", "hit_again": "hit-again",
                "at_cap": "at-cap"}
# the counts of a log written before rough walls: neither hit-again nor at-cap, nor the roughness column
_ZONE_SUMMARY_SMOOTH = dict(list(ZONE_SUMMARY.items())[:-2])
_TYPES = "|".join(("rebound-scatter",) + STOCK_TYPES)
# files written before rough walls have no roughness: their walls were smooth
_ZONE = re.compile(rf"(?P<zone>.+?) = (?:(?P<stock>{'|'.join(STOCK_TYPES)})|rebound-scatter, table (?P<table>.+?), "
                   r"mix (?P<mix>.+?), method (?P<method>\w+), interpolation (?P<interpolation>\w+), "
                   r"trapped (?P<trapped>\w+)(?:, roughness (?P<roughness>[-0-9.eE+]+) deg(?: \(the table's\))?)?, "
                   r"wall (?P<wall>.*))$")


def read_hits(run_dir: Path) -> tuple[dict, list]:
    """All ranks' hit records as columns (with V, Win, n, Uw, Vout, Wout as (N, 3) arrays), and each
    file's header settings, in rank order (tablegen.study.hit_records)."""
    return read_hit_files(rank_files(Path(run_dir) / "hits"), HITS_TITLE)


def zone_settings(run_dir: Path) -> dict:
    """What each zone the adapter handles does, from the end of the hits files' second line: zone name ->
    ``{"type": ...}``, one of rebound-scatter and :data:`STOCK_TYPES`, and for rebound-scatter the zone's
    table (absolute path), shape (a name, or a dict of weights, as ``read_hits``'s headers give it), method,
    interpolation, trapped (``deposit`` or ``remove``), roughness (deg; 0 for files written before rough walls)
    and wall. ValueError if the line lists no zones."""
    with rank_files(Path(run_dir) / "hits")[0].open() as fh:
        fh.readline()
        line = fh.readline().rstrip("\n")
    if " Zones: " not in line:
        raise ValueError(f"{run_dir}: the hits files do not say what each zone does (written before zones)")
    out = {}
    for item in re.split(rf"; (?=[^;=]+ = (?:{_TYPES})(?:,|;|$))", line.split(" Zones: ", 1)[1]):
        m = _ZONE.match(item)
        if m is None:
            raise ValueError(f"{run_dir}: not a zone's settings: {item!r}")
        if m["stock"]:
            out[m["zone"]] = {"type": m["stock"]}
            continue
        shape = m["mix"]
        if shape.startswith("weights ("):
            pairs = (pair.split(":") for pair in shape[len("weights ("):-1].split(","))
            shape = {name.strip(): float(weight) for name, weight in pairs}
        out[m["zone"]] = {"type": "rebound-scatter", "table": m["table"], "shape": shape, "method": m["method"],
                          "interpolation": m["interpolation"], "trapped": m["trapped"],
                          "roughness": float(m["roughness"] or 0), "wall": m["wall"]}
    return out


def zone_summary(log_text: str) -> dict:
    """rbs_cs_finalize's per-zone counts (summed over the ranks) in a run_solver.log: zone name -> the counts
    of :data:`ZONE_SUMMARY`'s columns by key, ``roughness``, the zone's wall roughness Δγ in degrees (None for a
    zone of a stock type), and ``interaction``, what the zone does. A log written before rough walls has neither
    ``hit_again``, ``at_cap`` nor ``roughness``."""
    block = log_text[log_text.rindex("    Per zone ("):].splitlines()
    header = block[1].split()
    if header == ["zone", *_ZONE_SUMMARY_SMOOTH.values(), "interaction"]:
        columns, roughness = _ZONE_SUMMARY_SMOOTH, ""
    elif header == ["zone", *ZONE_SUMMARY.values(), "roughness", "interaction"]:
        columns, roughness = ZONE_SUMMARY, r"\s+(\S+)"
    else:
        raise ValueError(f"not the per-zone summary's columns: {block[1]!r}")
    out = {}
    for line in block[2:]:
        m = re.match(rf"\s+(\S+)((?:\s+\d+){{{len(columns)}}}){roughness}  (.*)$", line)
        if m is None:
            break
        counts = dict(zip(columns, map(int, m.group(2).split())))
        if roughness:
            counts["roughness"] = None if m.group(3) == "-" else float(m.group(3))
        out[m.group(1)] = dict(counts, interaction=m.group(m.lastindex))
    return out


def read_summary(log_text: str) -> dict:
    """The counts of rbs_cs_finalize's summary (summed over the ranks) in a run_solver.log: the hits a table
    or the direct model answered, of every zone; and the CPU time spent in the hits (s), of every zone's."""
    block = log_text[log_text.rindex("rebound-scatter ("):]
    return dict(summary_counts(block),
                hits_cpu_s=float(re.search(r"CPU time in the hits\s*=\s*([-0-9.eE+]+) s", block).group(1)))


def read_cpu_seconds(run_dir: Path) -> dict:
    """The solver's CPU and wall seconds (performance.log: all ranks' CPU time, user and system, and rank 0's
    elapsed time)
    and the wall seconds of the particle displacement (timer_stats.csv, summed over the time steps)."""
    perf = (Path(run_dir) / "performance.log").read_text()
    total = re.search(r"Total CPU time:\s*([0-9.eE+-]+) s", perf)   # written by parallel runs only
    cpu = float(total.group(1)) if total else sum(
        float(re.search(rf"{kind} CPU time:\s*([0-9.eE+-]+) s", perf).group(1)) for kind in ("User", "System"))
    wall = float(re.search(r"Elapsed time:\s*([0-9.eE+-]+) s", perf).group(1))
    lines = (Path(run_dir) / "timer_stats.csv").read_text().splitlines()
    names = [c.strip() for c in lines[0].split(",")]
    j = names.index("particle displacement")
    displacement = sum(float(line.split(",")[j]) for line in lines[1:] if line.strip())
    return {"cpu": cpu, "wall": wall, "displacement_wall": displacement}
