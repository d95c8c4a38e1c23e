"""Read what a code_saturne run with rebound-scatter walls wrote: the hit records and the log's counts.

The hit records are RUN/hits/hits_<rank>.csv (``hits = hits`` in the settings file), one per rank, in the
layout both adapters write (tablegen.study.hit_records, which reads them): here the boundary zone is the
``patch``, origProc/origId are -1 (6.0's particles carry no persistent id), Ω⁻ is 0 (they carry no spin)
and U_w is 0. The counts are the summary rbs_cs_finalize writes to run_solver.log.

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


def read_hits(run_dir: Path) -> tuple[dict, list]:
    """All ranks' hit records as columns (with V, Win, n, Uw, Vout, Wout as (N, 3) arrays), and each
    file's header settings, in rank order (tablegen.study.hit_records)."""
    return read_hit_files(rank_files(Path(run_dir) / "hits"), HITS_TITLE)


def read_summary(log_text: str) -> dict:
    """The counts of rbs_cs_finalize's summary (summed over the ranks) in a run_solver.log, and the CPU time
    spent in the hits (s)."""
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
