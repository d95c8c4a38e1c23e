"""Call the single-particle rebound kernel from tests with explicit inputs."""

import numpy as np
from scipy.spatial.transform import Rotation

from direct_model.rebound import HISTORY_COLUMNS, WORK_SIZE, rebound
from direct_model.shapes import second_moment_factor, shape_code
from direct_model.simulate import incident_velocity
from direct_model.wall import CORUNDUM_ON_STEEL

MIRROR = np.diag([1.0, 1.0, -1.0])     # reflection Z → −Z (lab) and ζ → −ζ (body)


def run_one(shape, semi, R0, alpha1=45.0, speed=200.0, omega_in=(0.0, 0.0, 0.0), hand=1,
            kappa=0.3, n_max=1000, contact_tol=1e-10, set_tol=1e-9, max_steps=100_000, history_rows=0):
    """Rebound of one particle; returns (V⁺ m/s, Ω⁺ (m/s)/a, status, n_coll, e_rot, history)."""
    V, W = np.empty(3), np.empty(3)
    history = np.full((history_rows, HISTORY_COLUMNS), np.nan)
    status, _, ncoll, _, _, erot = rebound(
        shape_code(shape), np.asarray(semi, dtype=float), kappa, float(hand),
        second_moment_factor(shape, kappa), np.ascontiguousarray(R0), incident_velocity(alpha1, speed),
        np.asarray(omega_in, dtype=float) * speed, CORUNDUM_ON_STEEL.as_array(), n_max,
        contact_tol, set_tol, max_steps, V, W, history, np.empty(WORK_SIZE))
    return V, W, status, ncoll, erot, history


def random_bodies(n, seed, shapes=("ellipsoid", "prism", "cut_prism", "tetrahedron")):
    """n random (shape, semi-axes, orientation matrix, hand) tuples."""
    rng = np.random.default_rng(seed)
    out = []
    for i in range(n):
        shape = shapes[i % len(shapes)]
        ba, cb = rng.uniform(0.5, 1.0, 2)
        out.append((shape, np.array([1.0, ba, ba * cb]), Rotation.random(random_state=rng).as_matrix(),
                    int(rng.choice([-1, 1])) if shape == "tetrahedron" else 1))
    return out
