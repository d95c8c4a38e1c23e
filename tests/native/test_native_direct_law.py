"""The C library's direct model (rbs_rebound's direct path, a one-shape mix, in random caller's frames) draws the
law of `tablegen simulate` at the 16 incident states of tests/helpers/direct_law.py (every shape at |Ω⁻|a/|V⁻| ∈ {0, 0.02, 0.3, 1.0},
60–280 m/s): KS over the six components of V⁺/|V⁻| and Ω⁺a/|V⁻|, a classifier two-sample test, the trapped
fractions, with bounds from n and the number of comparisons (tests/helpers/direct_law.py). numba's kernel draws the
same law (tests/surrogate/test_direct_law.py, with the control that shows these tests see a spin of 0.02),
and the same bits as C for the same uniforms (test_native_direct.py). The C side's uniforms come from its
own stream (rbs_rng, seed 13), independent of the reference's."""

import numpy as np
import pytest

from tests.helpers import python_side as py


def _c_in_frame(table, state, seed):
    """rbs_rebound under RBS_METHOD_DIRECT at a state given in the model frame, run in the state's caller's frame;
    outputs rotated back: (V⁺/|V⁻|, Ω⁺a/|V⁻|, status)."""
    shape, alpha1, speed, omega_in = state
    Q = py.frame_of(state)
    V, n, W = py.incident(alpha1, speed, omega_in, Q)
    u, _ = table.lib.fill(table.lib.seed(seed), py.N * py.U_PER_REBOUND)
    V_out, W_out, status = np.empty((py.N, 3)), np.empty((py.N, 3)), np.empty(py.N, dtype=np.int64)
    index = table.shapes.index(shape)
    for i, row in enumerate(u.reshape(py.N, py.U_PER_REBOUND)):
        status[i], V_out[i], W_out[i] = table.direct(index, V, W, n, py.A, row)
    return (*py.to_model_frame(V_out, W_out, Q, speed), status)


@pytest.mark.parametrize("state", py.STATES, ids=py.state_id)
def test_c_and_simulate_draw_one_law(table_pair, state):
    shape, alpha1, speed, omega_in = state
    mine = _c_in_frame(table_pair[1], state, seed=13)
    assert set(np.unique(mine[2])) <= {py.STATUS_REBOUNDED, py.STATUS_TRAPPED, py.STATUS_FAILED}
    py.assert_one_law(py.one_law(mine, py.simulated(shape, alpha1, speed, omega_in, seed=12), len(py.STATES)))
