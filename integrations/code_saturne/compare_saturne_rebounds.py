"""Compare the rebounds a code_saturne run applied with surrogate's on the same incident states.

    python compare_saturne_rebounds.py RUN [--table T.h5] [--seed S] [--json FILE.json] [--no-classifier] [--check]

RUN is the run folder (the case's RESU/) holding hits/hits_<rank>.csv (read_hits.py reads them). This file
only turns those records into the solver-neutral record of the BSD module tablegen.study.solver_comparison
(``SolverHits``, through saturne_api) and calls it; the statistics and their bounds are that module's (its
docstring states them):

1. the path of every hit against the rule of method auto (``path_rule``): code_saturne 6.0's particles
   carry no spin (Ω⁻ = 0), so the direct model answers exactly the hits outside the table's grid;
2. each path's answers against surrogate's at the same incident states (``compare_hits``: the table's hits
   with ``surrogate.sample_global`` method "table", the direct model's with method "direct"; KS per
   variable, a classifier two-sample test, the fractions not rebounded, all bounds of one law shared over
   the run at family α = 1e-3).

--check exits with status 1 if a bound is not met or a hit took the wrong path; a run folder without hit
records, a missing table or an existing --json file: one line on stderr, status 2.

Copyright (C) 2026 the rebound-scatter authors. License: GPL-2.0-or-later
(see LICENSE in this folder).
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from saturne_api import compare_hits, load, path_rule, solver_hits  # noqa: E402
from read_hits import read_hits  # noqa: E402


def compare(run_dir: Path, table_path: Path | None = None, seed: int = 1, classifier: bool = True) -> dict:
    """A run's hits against surrogate: ``res["paths"]`` the path rule (``path_rule``), ``res["comparison"]``
    the solver against surrogate per path (a ``ComparisonReport``), ``res["checks_passed"]`` both met.
    ``table_path``: default the table the run recorded; ``seed``: surrogate's draws; ``classifier=False``:
    KS and the fractions not rebounded only."""
    hits, headers = read_hits(run_dir)
    settings = headers[0]
    table_path = Path(table_path or settings["table"])
    table = load(table_path)
    record = solver_hits(hits, settings)
    paths = path_rule(record, table, settings["spin_tolerance"])
    comparison = compare_hits(record, table, seed, settings["interpolation"], classifier)
    wrong = paths["spinning_not_direct"] + paths["outside_not_direct"] + paths["still_inside_not_table"]
    return {"run": str(run_dir), "table": str(table_path), "settings": settings,
            "ranks": sorted(int(h["stream"]) for h in headers), "paths": paths, "comparison": comparison,
            "checks_passed": bool(comparison.ok and wrong == 0)}


def report(res: dict) -> str:
    """The figures of :func:`compare` as lines of text."""
    pa = res["paths"]
    return "\n".join([
        f"run {res['run']} on {len(res['ranks'])} rank(s), method {res['settings']['method']}: hits outside the "
        f"grid {pa['outside']} ({pa['outside_not_direct']} not direct), spinning {pa['spinning']} "
        f"({pa['spinning_not_direct']} not direct), non-spinning inside the grid {pa['still_inside']} "
        f"({pa['still_inside_not_table']} not table)",
        res["comparison"].lines()])


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run", type=Path, help="the run folder (the case's RESU/)")
    parser.add_argument("--table", type=Path, help="the table (default: the path the run recorded)")
    parser.add_argument("--seed", type=int, default=1, help="seed of surrogate's draws")
    parser.add_argument("--json", type=Path, help="write the figures here")
    parser.add_argument("--no-classifier", action="store_true", help="KS and fractions not rebounded only")
    parser.add_argument("--check", action="store_true", help="exit 1 if a bound is not met")
    args = parser.parse_args(argv)
    if args.json and args.json.exists():
        print(f"compare_saturne_rebounds.py: --json {args.json} exists; give a new file", file=sys.stderr)
        return 2
    try:
        res = compare(args.run, args.table, args.seed, classifier=not args.no_classifier)
    except (FileNotFoundError, ValueError) as error:   # no hits in RUN, a file not ours, no table
        print(f"compare_saturne_rebounds.py: {error}", file=sys.stderr)
        return 2
    print(report(res))
    if args.json:
        plain = {k: v.as_dict() if hasattr(v, "as_dict") else v for k, v in res.items()}
        args.json.write_text(json.dumps(plain, indent=2))
    if args.check and not res["checks_passed"]:
        print("comparison bounds NOT met", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
