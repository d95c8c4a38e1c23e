"""The plain install is the runtime alone: a fresh virtual environment with ``pip install .`` draws from a table
and runs the direct model, the same draws as the development install, without the build extra."""

import json
import re
from pathlib import Path

import numpy as np

import surrogate
from tablegen import BUILD_EXTRA
from tests.helpers.plain_install import PYPROJECT, RUNTIME_ONLY


def _requirement_name(requirement: str) -> str:
    return re.split(r"[\[<>=!~; ]", requirement, maxsplit=1)[0]


def test_build_extra_is_what_tablegen_checks():
    assert sorted(BUILD_EXTRA.values()) == sorted(map(_requirement_name, PYPROJECT["project"]["optional-dependencies"]
                                                      ["build"]))


def test_plain_install_draws_from_a_table(small_table_path, plain_install):
    install, run, env = plain_install.result()      # tests.helpers.plain_install, started with the session
    assert install.returncode == 0, install.stderr
    assert run.returncode == 0, run.stderr
    fresh = json.loads(run.stdout)
    assert Path(fresh["where"]).is_relative_to(env), "surrogate did not come from the fresh install"
    assert fresh["missing"] == list(RUNTIME_ONLY), "the plain install brought more than the runtime"
    assert 'pip install "rebound-scatter[build]"' in fresh["refused"]
    table = surrogate.load(small_table_path)
    local = surrogate.sample_local(table, np.full(200, 33.7), np.full(200, 144.6), "mix", random_state=7)
    hits = surrogate.sample_direct(table, np.tile([120.0, -80.0, 10.0], (50, 1)),
                                   [0.0, 1.0, 0.0], 5e-5, "prism", random_state=7,
                                   omega=[0.0, 0.0, 2e5])
    V_out, Omega_out, status = hits.V, hits.Omega, hits.status
    assert (local.status == 0).sum() > 150 and (status == 0).sum() > 40
    np.testing.assert_array_equal(np.array(fresh["local"], dtype=float),
                                  np.column_stack([local.alpha2, local.beta2, local.speed_ratio, local.omega,
                                                   local.status]))
    np.testing.assert_array_equal(np.array(fresh["status"]), status)
    np.testing.assert_array_equal(np.array(fresh["V"], dtype=float), V_out)
    np.testing.assert_array_equal(np.array(fresh["Omega"], dtype=float), Omega_out)
