"""The full validation matrix (slow: run with ``pytest -m slow``).

Each comparison draws n = 2·10⁴ states from a table and 2·10⁴ from the direct
model (independent seed) at the on-grid and off-grid points of
:func:`tablegen.study.validation.matrix_points` (off grid: every α1 interval), for the four shapes and the mix.

Targets (the validation plan): the ``default`` preset table, every marginal's
KS ≤ 0.03 on and off grid; the ``production`` table, classifier accuracy
≤ 0.55 on grid and ≤ 0.58 off grid, and KS ≤ 0.03 off grid. Noise at these
sizes: the classifier's chance-level SE is √(0.25/2·10⁴) = 0.0035, so 0.55
is 14 SE above chance; the 95 % point of KS for two samples of one law is
1.358 √(2/2·10⁴) = 0.0136 (0.0155 with the noise of a default cell's 2·10⁴
build particles), leaving ~0.015 for the representation and interpolation.

The production table takes about an hour to build on 2 cores, so its test
reads it from the path in the environment variable REBOUND_PRODUCTION_TABLE
(``tablegen build --preset production -o production.h5``) and is skipped
without it. The default table is built by the test (about 4 minutes on 2 cores).
"""

import os

import pytest

from tablegen.tabulation.driver import build_table
from tablegen.tabulation.config import load_config
from tablegen.study.validation_report import TARGETS, run_matrix

pytestmark = pytest.mark.slow
N = 20_000


def _check(rows, targets):
    acc_on, acc_off, ks_on, ks_off = targets
    failures = []
    for r in rows:
        acc_target = acc_on if r["where"] == "on grid" else acc_off
        ks_target = ks_on if r["where"] == "on grid" else ks_off
        where = f"{r['where']} {r['shape']} at {r['alpha1']:g} deg, {r['speed']:g} m/s"
        if acc_target is not None and r["classifier_accuracy"] > acc_target:
            failures.append(f"{where}: classifier {r['classifier_accuracy']:.3f} > {acc_target}")
        worst = max(r["ks"], key=r["ks"].get)
        if ks_target is not None and r["ks"][worst] > ks_target:
            failures.append(f"{where}: KS({worst}) {r['ks'][worst]:.4f} > {ks_target}")
    assert not failures, "\n".join(failures)


def test_default_table_meets_its_targets(tmp_path):
    path = build_table(load_config(preset="default"), tmp_path / "default.h5")
    _check(run_matrix({"default": path}, N, os.cpu_count() or 1), TARGETS["default"])


def test_production_table_meets_its_targets():
    path = os.environ.get("REBOUND_PRODUCTION_TABLE")
    if not path:
        pytest.skip("set REBOUND_PRODUCTION_TABLE to a table built with `tablegen build --preset production`")
    _check(run_matrix({"production": path}, N, os.cpu_count() or 1), TARGETS["production"])
