"""Compare the rebounds a code_saturne run applied with surrogate's on the same incident states.

    python compare_saturne_rebounds.py RUN [--zone NAME ...] [--table T.h5] [--seed S] [--json FILE.json]
                                       [--no-classifier] [--check]

RUN is the run folder (the case's RESU/) holding hits/hits_<rank>.csv (read_hits.py reads them). This file
only turns those records into the solver-neutral record of the BSD module tablegen.study.solver_comparison
(``SolverHits``, through saturne_api) and calls it; the statistics and their bounds are that module's (its
docstring states them). It takes the hits a table or the direct model answered on the zones given (--zone,
all by default), which must draw from one table with one mix, method and interpolation (each zone's, as the
hits files list them; --table replaces the table), on a smooth wall (a rough zone, roughness_deg > 0, is
refused):

1. the path of every hit against the zones' method (``path_rule`` for auto: code_saturne 6.0's particles
   carry no spin (Ω⁻ = 0), so the direct model answers exactly the hits outside the table's grid; every hit
   by the table under method table, by the direct model under direct);
2. each path's answers against surrogate's at the same incident states (``compare_hits``: the table's hits
   with ``surrogate.sample_global`` method "table", the direct model's with method "direct"; KS per
   variable, a classifier two-sample test, the fractions not rebounded, all bounds of one law shared over
   the run at family α = 1e-3).

--check exits with status 1 if a bound is not met or a hit took the wrong path; a run folder without hit
records, zones of several tables or settings, a missing table or an existing --json file: one line on
stderr, status 2.

Copyright (C) 2026 the rebound-scatter authors. License: GPL-2.0-or-later
(see LICENSE in this folder).
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from saturne_api import (PATH_DIRECT, PATH_TABLE, STATUS_INVALID, compare_hits, load, path_rule,  # noqa: E402
                         solver_hits)
from read_hits import HITS_TITLE, read_hits, zone_settings  # noqa: E402

METHOD_PATH = {"table": PATH_TABLE, "direct": PATH_DIRECT}   # the one path of every hit under these methods


def drawn_hits(run_dir: Path, zones=None) -> tuple[dict, dict]:
    """The hits a table or the direct model answered on ``zones`` (names; all if None), and their settings:
    the run's header with the zones' table, shape, method and interpolation. ValueError if no hit is left,
    if the zones differ in any of these (a comparison draws from one law), or if one is rough (surrogate answers
    the hits here on the smooth wall)."""
    hits, headers = read_hits(run_dir)
    keep = hits["interaction"] == HITS_TITLE
    if zones is not None:
        keep &= np.isin(hits["patch"], list(zones))
    if not keep.any():
        raise ValueError(f"no hit a table or the direct model answered on {', '.join(zones or ['any zone'])}")
    described = zone_settings(run_dir)
    used = sorted(set(hits["patch"][keep].tolist()))
    rough = [f"{z} (roughness_deg {described[z]['roughness']:g})" for z in used if described[z]["roughness"] > 0]
    if rough:
        raise ValueError(f"the zones {', '.join(rough)} are rough: the comparison with surrogate is of smooth walls; "
                         "compare the smooth zones (--zone)")
    laws = {(described[z]["table"], str(described[z]["shape"]), described[z]["method"],
             described[z]["interpolation"]) for z in used}
    if len(laws) > 1:
        raise ValueError(f"the zones {', '.join(used)} draw with {len(laws)} tables or settings: compare the "
                         "zones of one table and one mix, method and interpolation at a time (--zone)")
    zone = described[used[0]]
    settings = dict(headers[0], **{k: zone[k] for k in ("table", "shape", "method", "interpolation")})
    return {name: column[keep] for name, column in hits.items()}, settings


def compare(run_dir: Path, table_path: Path | None = None, seed: int = 1, classifier: bool = True,
            zones=None) -> dict:
    """A run's hits (:func:`drawn_hits` of ``zones``) against surrogate: ``res["paths"]`` the path rule
    (``path_rule``) and ``res["wrong_path"]`` the hits the zones' method would not have sent where they went,
    ``res["comparison"]`` the solver against surrogate per path (a ``ComparisonReport``),
    ``res["checks_passed"]`` both met. ``table_path``: default the zones' table; ``seed``: surrogate's
    draws; ``classifier=False``: KS and the fractions not rebounded only."""
    hits, settings = drawn_hits(run_dir, zones)
    table_path = Path(table_path or settings["table"])
    table = load(table_path)
    record = solver_hits(hits, settings)
    paths = path_rule(record, table, settings["spin_tolerance"])
    if settings["method"] == "auto":
        wrong = paths["spinning_not_direct"] + paths["outside_not_direct"] + paths["still_inside_not_table"]
    else:
        wrong = int(np.sum((record.path != STATUS_INVALID) & (record.path != METHOD_PATH[settings["method"]])))
    comparison = compare_hits(record, table, seed, settings["interpolation"], classifier)
    return {"run": str(run_dir), "zones": sorted(set(hits["patch"].tolist())), "table": str(table_path),
            "settings": settings, "ranks": sorted(int(r) for r in set(hits["rank"].tolist())), "paths": paths,
            "wrong_path": wrong, "comparison": comparison, "checks_passed": bool(comparison.ok and wrong == 0)}


def report(res: dict) -> str:
    """The figures of :func:`compare` as lines of text."""
    pa = res["paths"]
    return "\n".join([
        f"run {res['run']}, zones {', '.join(res['zones'])} on {len(res['ranks'])} rank(s), table "
        f"{res['table']}, method {res['settings']['method']}: hits outside the grid {pa['outside']} "
        f"({pa['outside_not_direct']} not direct), spinning {pa['spinning']} ({pa['spinning_not_direct']} not "
        f"direct), non-spinning inside the grid {pa['still_inside']} ({pa['still_inside_not_table']} not "
        f"table); on a path the method does not take: {res['wrong_path']}",
        res["comparison"].lines()])


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run", type=Path, help="the run folder (the case's RESU/)")
    parser.add_argument("--zone", action="append", metavar="NAME",
                        help="compare the hits of this zone only (repeat for several zones of one table)")
    parser.add_argument("--table", type=Path, help="the table (default: the zones' table, as the run recorded)")
    parser.add_argument("--seed", type=int, default=1, help="seed of surrogate's draws")
    parser.add_argument("--json", type=Path, help="write the figures here")
    parser.add_argument("--no-classifier", action="store_true", help="KS and fractions not rebounded only")
    parser.add_argument("--check", action="store_true", help="exit 1 if a bound is not met")
    args = parser.parse_args(argv)
    if args.json and args.json.exists():
        print(f"compare_saturne_rebounds.py: --json {args.json} exists; give a new file", file=sys.stderr)
        return 2
    try:
        res = compare(args.run, args.table, args.seed, classifier=not args.no_classifier, zones=args.zone)
    except (FileNotFoundError, ValueError) as error:   # no hits in RUN, a file not ours, zones of two laws
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
