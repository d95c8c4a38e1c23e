"""Contact ties (docs/model.md §4.5) in C: the states of tests/direct_model/test_contact_ties.py (a face or an edge
exactly down, Ω⁻ = 0; tests/helpers/ties.py) through rbs_body_rebound (native/src/body_rebound.c, the contact rule
in flight.c) with an explicit orientation, each state and its mirror image: numba's status, collision count and
bits of V⁺ and Ω⁺, and one collision at the face's or edge's centre, V⁺ and Ω⁺ of the closed form to 1e-12 |V⁻|
(derived, and the tolerance argued, in tests/direct_model/test_contact_ties.py)."""

from __future__ import annotations

import ctypes

import numpy as np
import pytest

from tests.helpers import python_side as py
from tests.helpers.ties import (CONTACT_TOL, MAX_STEPS, MIRROR, N_MAX, SET_TOL, WALL, expected, kernel_body, rebound,
                                tie_states)

STATES = tie_states()

_ll = ctypes.c_longlong


def _c(native):
    """The test-only library (``Native.internal``), which exports rbs_body_rebound (native/src/body_rebound.h,
    internal; typed by tests.helpers.native_library.INTERNAL)."""
    return native.internal


def _rebound_c(c, s):
    """rbs_body_rebound of the state: (V⁺ m/s, Ω⁺ (m/s)/a, status, n_collisions)."""
    arrays = [np.ascontiguousarray(x, dtype=np.float64) for x in
              (kernel_body(s), s.body.semi, s.body.K, s.R, s.V, np.zeros(3), WALL.as_array())]
    V, W = np.full(3, np.nan), np.full(3, np.nan)
    n_collisions, n_steps = _ll(-1), _ll(-1)
    status = c.rbs_body_rebound(s.body.kind, arrays[0].ctypes.data, len(s.body.vertices), arrays[1].ctypes.data,
                                arrays[2].ctypes.data, s.body.radius, *(x.ctypes.data for x in arrays[3:]), N_MAX,
                                CONTACT_TOL, SET_TOL, MAX_STEPS, V.ctypes.data, W.ctypes.data,
                                ctypes.byref(n_collisions), ctypes.byref(n_steps), None)
    return V, W, status, n_collisions.value


def _bits(x):
    return np.ascontiguousarray(x, dtype=np.float64).view(np.uint64)


@pytest.mark.parametrize("s", STATES, ids=[s.name for s in STATES])
def test_c_gives_numba_s_bits_and_the_closed_form(native, s):
    """The state and its mirror image: one collision, numba's bits of V⁺ and Ω⁺ (signed zeros included), and the
    collision at the centroid of the tied vertices (the reference; for the mirror image reflected, V⁺ → M V⁺ and
    Ω⁺ → −M Ω⁺)."""
    c = _c(native)
    V_ref, W_ref = expected(s)
    speed = np.linalg.norm(s.V)
    for state, reflect in ((s, np.eye(3)), (s.mirrored(), MIRROR)):
        V, W, status, n_collisions = _rebound_c(c, state)
        assert status == py.STATUS_REBOUNDED and n_collisions == 1
        V_py, W_py, status_py, n_py = rebound(state)
        assert (status_py, n_py) == (status, n_collisions)
        assert np.array_equal(_bits(V), _bits(V_py)) and np.array_equal(_bits(W), _bits(W_py))
        np.testing.assert_allclose(V, reflect @ V_ref, rtol=0.0, atol=1e-12 * speed)
        np.testing.assert_allclose(W, np.linalg.det(reflect) * (reflect @ W_ref), rtol=0.0, atol=1e-12 * speed)
