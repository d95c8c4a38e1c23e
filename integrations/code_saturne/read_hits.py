"""Read what a code_saturne run with rebound-scatter walls wrote: the hit records and the log's counts.

The hit records are RUN/hits/hits_<rank>.csv (``hits = hits`` in the settings file), one per rank, in the
column layout of the OpenFOAM adapter's records (integrations/openfoam): time, rank, boundary zone
(``patch``), origProc/origId (-1: 6.0's particles carry no persistent id), d, a, V⁻ relative to the wall
(at rest), Ω⁻ (0: 6.0's particles carry no spin), n (into the gas), U_w (0), status, path (0 table,
1 direct model, -1 invalid), V⁺, Ω⁺, |Ω⁻|a/|V⁻| and the draw's first uniform. The first line names the
run's settings. The counts are the summary rbs_cs_finalize writes to run_solver.log.

Copyright (C) 2026 the rebound-scatter authors. License: GPL-2.0-or-later
(see LICENSE in this folder).
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

HIT_COLUMNS = ("time,rank,patch,origProc,origId,d,a,Vx,Vy,Vz,Winx,Winy,Winz,nx,ny,nz,Uwx,Uwy,Uwz,status,path,"
               "Voutx,Vouty,Voutz,Wx,Wy,Wz,spin_ratio,u0").split(",")
PATH_TABLE, PATH_DIRECT = 0, 1   # the path column (rbs_rebound_path; -1: invalid)


def parse_header(line: str) -> dict:
    """The run's settings from the first line of a hits file."""
    m = re.match(r"# code_saturne rebound-scatter hits: seed (\d+), stream (\d+), table (.*), mix (.*), "
                 r"halfSizeFactor (\S+), interpolation (\w+), method (\w+), spin tolerance (\S+)$", line.strip())
    if not m:
        raise ValueError(f"not a code_saturne rebound-scatter hits header: {line!r}")
    mix = m.group(4)
    if mix.startswith("weights ("):
        shape = {k.strip(): float(v) for k, v in (item.split(":") for item in mix[len("weights ("):-1].split(","))}
    else:
        shape = mix
    return {"seed": int(m.group(1)), "stream": int(m.group(2)), "table": m.group(3), "shape": shape,
            "half_size_factor": float(m.group(5)), "interpolation": m.group(6), "method": m.group(7),
            "spin_tolerance": float(m.group(8))}


def read_hits(run_dir: Path) -> tuple[dict, list]:
    """All ranks' hit records as columns (with V, Win, n, Uw, Vout, Wout as (N, 3) arrays), and each
    file's header settings, in rank order."""
    files = sorted(Path(run_dir).glob("hits/hits_*.csv"), key=lambda p: int(p.stem.split("_")[1]))
    if not files:
        raise FileNotFoundError(f"{run_dir}: no hits/hits_<rank>.csv (set hits = hits in the settings)")
    headers, rows = [], []
    for f in files:
        with open(f) as fh:
            headers.append(parse_header(fh.readline()))
            fh.readline()
            if fh.readline().strip().split(",") != HIT_COLUMNS:
                raise ValueError(f"{f}: unexpected columns")
            for line_no, line in enumerate(fh, start=4):
                row = line.rstrip("\n").split(",")
                if len(row) != len(HIT_COLUMNS):
                    raise ValueError(f"{f}, line {line_no}: {len(row)} fields, not {len(HIT_COLUMNS)}")
                rows.append(row)
    cols = {}
    for j, name in enumerate(HIT_COLUMNS):
        values = [r[j] for r in rows]
        if name == "patch":
            cols[name] = np.array(values, dtype=object)
        elif name in ("rank", "origProc", "origId", "status", "path"):
            cols[name] = np.array(values, dtype=np.int64)
        else:
            cols[name] = np.array(values, dtype=float)
    for vec, names in (("V", "Vx Vy Vz"), ("Win", "Winx Winy Winz"), ("n", "nx ny nz"), ("Uw", "Uwx Uwy Uwz"),
                       ("Vout", "Voutx Vouty Voutz"), ("Wout", "Wx Wy Wz")):
        cols[vec] = np.column_stack([cols[c] for c in names.split()]).reshape(-1, 3)
    return cols, headers


def read_summary(log_text: str) -> dict:
    """The counts of rbs_cs_finalize's summary (summed over the ranks) in a run_solver.log."""
    block = log_text[log_text.rindex("rebound-scatter ("):]

    def number(label):
        return float(re.search(re.escape(label) + r"[^=]*=\s*([-0-9.eE+]+)", block).group(1))

    cost = re.search(r"answered by the direct model\s*=\s*\d+ \(mean cost\s*([-0-9.eE+]+) us per hit\)", block)
    return {"hits": int(number("- wall hits")), "table": int(number("- answered by the table")),
            "direct": int(number("- answered by the direct model")), "direct_us": float(cost.group(1)),
            "rebounded": int(number("- rebounded")), "trapped": int(number("- trapped")),
            "failed": int(number("- failed (direct model)")), "invalid": int(number("- invalid")),
            "outside": int(number("- outside the table's grid")),
            "hits_cpu_s": float(re.search(r"CPU time in the hits\s*=\s*([-0-9.eE+]+) s", block).group(1))}


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
