"""Read what a code_saturne run with rebound-scatter walls wrote: the hit records and the log's counts.

The hit records are RUN/hits/hits_<rank>.csv (``hits = hits`` in the settings file), one per rank, in the
layout both adapters write (tablegen.study.hit_records, which reads them): here the boundary zone is the
``patch``, origProc/origId are -1 (6.0's particles carry no persistent id), Ω⁻ is 0 (they carry no spin)
and U_w is 0; ``interaction`` is :data:`HITS_TITLE` where a table or the direct model answered, ``rebound``
for a zone of type rebound, and ``wall`` the wall of the zone's table. The files' second line ends with
what each zone does (:func:`zone_settings`). The counts are the summary rbs_cs_finalize writes to
run_solver.log, in total (:func:`read_summary`) and per zone (:func:`zone_summary`). The adapter's boundary
statistics (rbs_cs_define_statistics: the work on the walls) are in the run's postprocessing output, EnSight Gold
(:func:`boundary_statistics`).

Copyright (C) 2026 the rebound-scatter authors. License: GPL-2.0-or-later
(see LICENSE in this folder).
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from saturne_api import rank_files, read_hit_files, summary_counts  # noqa: E402

HITS_TITLE = "code_saturne rebound-scatter"   # the hits files' header: "# code_saturne rebound-scatter hits: ..."
STOCK_TYPES = ("rebound", "deposit", "outlet")   # the zone types that do what the solver's own types do
# the per-zone summary's columns of counts (rbs_cs_finalize), by key
ZONE_SUMMARY = {"hits": "hits", "rebounded": "rebounded", "stuck": "stuck", "removed": "removed",
                "escaped": "escaped", "invalid": "invalid", "trapped": "trapped", "failed": "failed",
                "table": "table", "direct": "direct", "speed_below": "|V|<grid", "speed_above": "|V|>grid",
                "alpha1_outside": "alpha1-out", "outside_law": "out-of-law", "hit_again": "hit-again",
                "at_cap": "at-cap", "no_work": "no-work"}
# the counts of a log written before the work on the wall: no no-work, nor the work columns
_ZONE_SUMMARY_ROUGH = dict(list(ZONE_SUMMARY.items())[:-1])
# the counts of a log written before rough walls: neither hit-again nor at-cap, nor the roughness column
_ZONE_SUMMARY_SMOOTH = dict(list(ZONE_SUMMARY.items())[:-3])
# the work columns after the roughness: the mean W_n and W_t, J/kg
_WORK_COLUMNS = ["Wn(J/kg)", "Wt(J/kg)"]
# the adapter's boundary statistics (rbs_cs_define_statistics): weight x mass x W_n and W_t (J), weight x mass (kg),
# weight (the hits)
BOUNDARY_STATISTICS = ("rbs_wall_work_normal", "rbs_wall_work_tangential", "rbs_wall_hit_mass", "rbs_wall_hits")
# EnSight Gold's element types of fixed node counts that a boundary mesh may hold
_ENSIGHT_NODES = {"point": 1, "bar2": 2, "bar3": 3, "tria3": 3, "tria6": 6, "quad4": 4, "quad8": 8}
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
    zone of a stock type), ``work_normal`` and ``work_tangential``, the mean W_n and W_t of its hits with work in
    J/kg, weighted by statistical weight × mass (None for a stock type or no such hit), and ``interaction``, what
    the zone does. A log written before the work on the wall has no ``no_work`` nor work; one written before
    rough walls neither ``hit_again``, ``at_cap`` nor ``roughness``."""
    block = log_text[log_text.rindex("    Per zone ("):].splitlines()
    header = block[1].split()
    layouts = ((_ZONE_SUMMARY_SMOOTH, []), (_ZONE_SUMMARY_ROUGH, ["roughness"]),
               (ZONE_SUMMARY, ["roughness", *_WORK_COLUMNS]))
    for columns, extra in layouts:
        if header == ["zone", *columns.values(), *extra, "interaction"]:
            break
    else:
        raise ValueError(f"not the per-zone summary's columns: {block[1]!r}")
    out = {}
    for line in block[2:]:
        m = re.match(rf"\s+(\S+)((?:\s+\d+){{{len(columns)}}})((?:\s+\S+){{{len(extra)}}})  (.*)$", line)
        if m is None:
            break
        row = dict(zip(columns, map(int, m.group(2).split())))
        values = [None if v == "-" else float(v) for v in m.group(3).split()]
        row.update(zip(("roughness", "work_normal", "work_tangential"), values))
        out[m.group(1)] = dict(row, interaction=m.group(4))
    return out


def boundary_statistics(run_dir: Path) -> dict:
    """The adapter's boundary statistics (:data:`BOUNDARY_STATISTICS`) at the last output of the run's
    postprocessing (RUN/postprocessing/RESULTS_BOUNDARY.case, EnSight Gold binary, as 6.0's default writer
    writes it): name -> one float64 per boundary face in the output's order (the writer's float32 values), and
    ``zone``, each face's boundary zone name (the output's boundary_zone_id, named by setup.log). ValueError
    if the output lacks them."""
    post = Path(run_dir) / "postprocessing"
    case = (post / "RESULTS_BOUNDARY.case").read_text()
    blocks = _ensight_blocks(post / re.search(r"model:\s*(\S+)", case).group(1))
    files = dict(re.findall(r"scalar per element:(?:\s+\d+)?\s+(\S+)\s+(\S+)", case))
    missing = [name for name in (*BOUNDARY_STATISTICS, "boundary_zone_id") if name not in files]
    if missing:
        raise ValueError(f"{post}: RESULTS_BOUNDARY.case has no {', '.join(missing)} (rbs_cs_define_statistics "
                         "not called?)")
    # the last output's file number: start + (steps - 1) x increment
    steps, start, increment = (int(re.search(rf"{key}:\s*(\d+)", case).group(1)) for key in (
        "number of steps", "filename start number", "filename increment"))
    out = {}
    for name in (*BOUNDARY_STATISTICS, "boundary_zone_id"):
        pattern = files[name]
        stars = pattern.count("*")
        if stars:
            pattern = pattern.replace("*" * stars, f"{start + (steps - 1) * increment:0{stars}d}")
        out[name] = _ensight_element_values(post / pattern, blocks)
    zones = _boundary_zone_names((Path(run_dir) / "setup.log").read_text())
    out["zone"] = np.array([zones[int(z)] for z in out.pop("boundary_zone_id")], dtype=object)
    return out


def _ensight_blocks(geo: Path) -> list:
    """(part number, element type, element count) of each element block of an EnSight Gold binary geometry
    file, in the file's order."""
    data = geo.read_bytes()
    pos = 0

    def text():
        nonlocal pos
        pos += 80
        return data[pos - 80:pos].split(b"\0")[0].decode().strip()

    def ints(n):
        nonlocal pos
        pos += 4 * n
        return np.frombuffer(data, dtype="<i4", count=n, offset=pos - 4 * n)

    if text() != "C Binary":
        raise ValueError(f"{geo}: not an EnSight Gold C Binary geometry file")
    text(), text()                                      # the two lines of description
    # ids written in the file ("given", or "ignore": written, not used), or not ("off", "assign")
    node_ids, element_ids = (text().split()[-1] in ("given", "ignore") for _ in range(2))
    blocks, part = [], None
    while pos < len(data):
        word = text()
        if word == "extents":
            pos += 6 * 4
        elif word == "part":
            part = int(ints(1)[0])
            text()                                      # the part's description
            if text() != "coordinates":
                raise ValueError(f"{geo}: part {part} is not unstructured")
            n = int(ints(1)[0])
            pos += 4 * n * (3 + node_ids)
        elif word == "nsided":
            n = int(ints(1)[0])
            pos += 4 * n * element_ids
            pos += 4 * int(ints(n).sum())
            blocks.append((part, word, n))
        elif word in _ENSIGHT_NODES:
            n = int(ints(1)[0])
            pos += 4 * n * (element_ids + _ENSIGHT_NODES[word])
            blocks.append((part, word, n))
        else:
            raise ValueError(f"{geo}: element type {word!r} is not read here")
    return blocks


def _ensight_element_values(path: Path, blocks: list) -> np.ndarray:
    """A per-element scalar variable file of EnSight Gold binary, on the geometry's ``blocks``."""
    data = path.read_bytes()
    pos, values, part = 80, [], None
    for block_part, kind, n in blocks:
        if block_part != part:
            if data[pos:pos + 4] != b"part" or int(np.frombuffer(data, "<i4", 1, pos + 80)[0]) != block_part:
                raise ValueError(f"{path}: not part {block_part} where the geometry has it")
            pos, part = pos + 84, block_part
        if data[pos:pos + 80].split(b"\0")[0].decode().strip() != kind:
            raise ValueError(f"{path}: not the element type {kind} where the geometry has it")
        values.append(np.frombuffer(data, "<f4", n, pos + 80).astype(np.float64))
        pos += 80 + 4 * n
    if pos != len(data):
        raise ValueError(f"{path}: {len(data) - pos} bytes after the geometry's elements")
    return np.concatenate(values)


def _boundary_zone_names(setup_log: str) -> dict:
    """Boundary zone id -> name, from setup.log's list of the boundary zones."""
    section = setup_log[setup_log.index("Boundary zones\n"):]
    # up to the next section's title, a line underlined with dashes
    end = re.search(r"\n\n[^\n]+\n-{3,}\n", section[1:])
    section = section[:end.start() + 1] if end else section
    return {int(zone_id): name for name, zone_id in re.findall(r'Zone: "([^"]+)"\s*\n\s*id:\s*(\d+)', section)}


def read_summary(log_text: str) -> dict:
    """The counts of rbs_cs_finalize's summary (summed over the ranks) in a run_solver.log: the hits a table
    or the direct model answered, of every zone; the CPU time spent in the hits (s), of every zone's; and,
    in a log written since the work on the wall, that work summed over those hits, ``work_normal_J`` and
    ``work_tangential_J`` (statistical weight × mass × W_n, W_t), and ``no_work``, the hits without it."""
    block = log_text[log_text.rindex("rebound-scatter ("):]
    out = dict(summary_counts(block),
               hits_cpu_s=float(re.search(r"CPU time in the hits\s*=\s*([-0-9.eE+]+) s", block).group(1)))
    work = re.search(r"work on the walls, normal and tangential = (\S+) J, (\S+) J \((\d+) hits without work",
                     block)
    if work:
        out.update(work_normal_J=float(work.group(1)), work_tangential_J=float(work.group(2)),
                   no_work=int(work.group(3)))
    return out


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
