"""The spread of the rebound angles per patch of finished runs, beside their hits that hit the wall again.

    python integrations/openfoam/rebound_spread.py CASE [CASE ...] [--patch NAME ...]

Each CASE is a run written with ``writeHits true`` (every hit: ``hitsEvery 1``). Per patch that draws
(interaction stochasticRebound; ``--patch``: those only) the script prints, from the solver log's last per-patch
summary, the wall's roughness, the hits and those that hit the wall again or reached the cap of wall hits; and
from the hits files, over the rebounded hits, the mean and sd of α2, the rebound's angle from the wall
(asin(V⁺·n/|V⁺|), whatever the incidence), and the sd of β2, its angle out of the impact plane (the impact frame
of tablegen.study.solver_comparison.impact_states), in degrees: for all hits, and for the hits that arrived
without spin (Ω⁻ = 0: in a colliding cloud, each parcel's first hit, whose incident states two runs of one
case share, whatever their walls do afterwards). Two runs of one case, one with a rough patch, show what the
roughness does to that patch's scatter (docs/openfoam.md, "A rough wall").

Copyright (C) 2026 the rebound-scatter authors. License: GPL-3.0-or-later
(see LICENSE in this folder).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from compare_rebounds import HITS_TITLE, patch_summary, read_hits  # noqa: E402
from rbs_api import STATUS_REBOUNDED, impact_states  # noqa: E402


def solver_log(case: Path) -> str:
    """The text of the case's solver log: the log.* file holding the adapter's per-patch summary."""
    for log in sorted(case.glob("log.*")):
        text = log.read_text(errors="replace")
        if "    Per patch (" in text:
            return text
    raise FileNotFoundError(f"{case}: no log.* with the stochasticRebound per-patch summary")


def angles(hits: dict, rows) -> dict:
    """n, the mean and sd of α2 and the sd of β2 (deg) of the hits at ``rows`` (a boolean mask)."""
    V, n, V_out = hits["V"][rows], hits["n"][rows], hits["Vout"][rows]
    alpha2 = np.degrees(np.arcsin(np.clip(np.einsum("ij,ij->i", V_out, n) / np.linalg.norm(V_out, axis=1), -1, 1)))
    beta2 = np.degrees(impact_states(V, n, hits["a"][rows], V_out, hits["Wout"][rows])[:, 1])
    return {"n": int(rows.sum()), "alpha2_mean": float(alpha2.mean()) if len(alpha2) else np.nan,
            "alpha2_sd": float(alpha2.std()) if len(alpha2) else np.nan,
            "beta2_sd": float(beta2.std()) if len(beta2) else np.nan}


def spread(case: Path, patches=None) -> dict:
    """Patch name -> roughness, hits, hit_again, at_cap (the log's summary) and ``all``, ``first``: the
    :func:`angles` of its rebounded hits, all of them and those without Ω⁻, for each patch that draws."""
    rows = patch_summary(solver_log(case))
    hits, _ = read_hits(case)
    out = {}
    for patch, counts in rows.items():
        if counts.get("roughness") is None or (patches and patch not in patches):
            continue
        on = (hits["patch"] == patch) & (hits["interaction"] == HITS_TITLE) & (hits["status"] == STATUS_REBOUNDED)
        first = on & ~hits["Win"].any(axis=1)
        out[patch] = {"roughness": counts["roughness"], "hits": counts["hits"], "hit_again": counts["hit_again"],
                      "at_cap": counts["at_cap"], "all": angles(hits, on), "first": angles(hits, first)}
    return out


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("cases", type=Path, nargs="+", help="finished runs (with their hits files)")
    parser.add_argument("--patch", action="append", metavar="NAME", help="this patch only (repeat for several)")
    args = parser.parse_args(argv)
    header = (f"  {'patch':<14} {'rough':>5} {'hits':>6} {'hit again':>13} {'cap':>4}   {'rebounded: n':>12} "
              f"{'a2 mean':>7} {'a2 sd':>6} {'b2 sd':>6}   {'without spin: n':>15} {'a2 mean':>7} {'a2 sd':>6} "
              f"{'b2 sd':>6}")
    for case in args.cases:
        try:
            patches = spread(case, args.patch)
        except (FileNotFoundError, ValueError) as error:
            print(f"rebound_spread.py: {error}", file=sys.stderr)
            return 2
        print(f"{case} (angles in degrees)\n{header}")
        for patch, p in patches.items():
            again = f"{p['hit_again']} ({p['hit_again'] / max(p['hits'], 1):.1%})"
            cells = [f"{a['alpha2_mean']:7.1f} {a['alpha2_sd']:6.2f} {a['beta2_sd']:6.2f}"
                     for a in (p["all"], p["first"])]
            print(f"  {patch:<14} {p['roughness']:5g} {p['hits']:6d} {again:>13} {p['at_cap']:4d}   "
                  f"{p['all']['n']:12d} {cells[0]}   {p['first']['n']:15d} {cells[1]}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
