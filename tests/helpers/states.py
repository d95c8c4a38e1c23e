"""Random incident states for the bit-identity tests, and the ulp distance of two float64 arrays."""

from __future__ import annotations

import numpy as np


def unit_vectors(rng, count):
    v = rng.standard_normal((count, 3))
    return v / np.linalg.norm(v, axis=1)[:, None]


def incident_states(rng, count, alpha1_range=(0.0, 90.0), speed_range=(5.0, 400.0)):
    """(V, n, a): random unit normals, α1 and |V⁻| uniform over the ranges (deg, m/s), with the special
    cases mixed in: exact normal impact, grazing, invalid (V·n ≥ 0, zero, NaN, inf), grid speeds, and the
    hostile ones the draws refuse or guard: normals that are not unit vectors, half-sizes not
    finite and > 0 or so small that Ω⁺ overflows, |V⁻| that overflows or underflows."""
    n = unit_vectors(rng, count)
    t = rng.standard_normal((count, 3))
    t -= np.einsum("ij,ij->i", t, n)[:, None] * n
    t /= np.linalg.norm(t, axis=1)[:, None]
    alpha1 = np.radians(rng.uniform(*alpha1_range, count))
    speed = rng.uniform(*speed_range, count)
    V = speed[:, None] * (np.cos(alpha1)[:, None] * t - np.sin(alpha1)[:, None] * n)
    kind = rng.integers(0, 40, count)
    V[kind == 0] = -speed[kind == 0, None] * n[kind == 0]                          # exact normal impact
    V[kind == 1] = speed[kind == 1, None] * (t[kind == 1] - 1e-7 * n[kind == 1])   # grazing
    V[kind == 2] = speed[kind == 2, None] * t[kind == 2]                           # along the wall
    V[kind == 3] = -V[kind == 3]                                                   # leaving the wall
    V[kind == 4] = 0.0                                                             # zero
    V[kind == 5, rng.integers(0, 3)] = np.nan
    V[kind == 6, 0] = np.inf
    V[kind == 7] = -1e-13 * n[kind == 7] + 1e-300 * t[kind == 7]                  # tiny, nearly normal
    grid_speed = kind == 8
    V[grid_speed] *= (150.0 / np.linalg.norm(V[grid_speed], axis=1))[:, None]    # a grid speed (of the small table)
    n[kind == 9] = np.array([0.0, 1.0, 0.0])                                       # axis-aligned normals
    V[kind == 9] = -speed[kind == 9, None] * n[kind == 9]
    a = rng.uniform(1e-5, 1e-3, count)
    n[kind == 10] *= rng.choice([1.5, 1.0 + 2e-6, 1.0 - 2e-6, 1e200], (kind == 10).sum())[:, None]
    a[kind == 11] = rng.choice([0.0, -1e-4, np.nan, np.inf, 5e-324], (kind == 11).sum())
    V[kind == 12] *= 1e200 / speed[kind == 12, None]                              # |V⁻| 1e200 m/s: V·V overflows
    V[kind == 13] *= 1e-160 / speed[kind == 13, None]                             # |V⁻| 1e-160 m/s: V·V underflows
    return np.ascontiguousarray(V), np.ascontiguousarray(n), a


def uniforms(rng, count, u_per_draw=13, hostile=0.0):
    """Uniforms in [0, 1) with the edges mixed in (0 and the largest double below 1); with ``hostile`` > 0,
    that fraction of the rows has one uniform outside [0, 1) or NaN (which the draws refuse)."""
    u = rng.random((count, u_per_draw))
    edge = rng.random((count, u_per_draw)) < 0.01
    u[edge] = np.where(rng.random(edge.sum()) < 0.5, 0.0, np.nextafter(1.0, 0.0))
    rows = np.flatnonzero(rng.random(count) < hostile)
    u[rows, rng.integers(0, u_per_draw, rows.size)] = rng.choice([-0.5, 1.0, 1e6, -1e300, np.nan, np.inf], rows.size)
    return u


def ordered(x: np.ndarray) -> np.ndarray:
    """float64 bits as integers ordered like the floats (so that differences count ulps)."""
    i = np.ascontiguousarray(x, dtype=np.float64).view(np.int64).astype(object)
    return np.array([v if v >= 0 else -(v & 0x7FFFFFFFFFFFFFFF) for v in i.ravel()], dtype=object).reshape(x.shape)


def max_ulp(a: np.ndarray, b: np.ndarray) -> float:
    """The largest ulp distance between a and b, element by element; NaN equals NaN; inf if NaN meets a
    number."""
    a, b = np.asarray(a, dtype=np.float64), np.asarray(b, dtype=np.float64)
    nan_a, nan_b = np.isnan(a), np.isnan(b)
    if np.any(nan_a != nan_b):
        return float("inf")
    keep = ~nan_a
    if not keep.any():
        return 0.0
    x, y = a[keep], b[keep]
    same = x.view(np.int64) == y.view(np.int64)
    if same.all():
        return 0.0
    x, y = x[~same], y[~same]
    return float(max(abs(p - q) for p, q in zip(ordered(x), ordered(y))))
