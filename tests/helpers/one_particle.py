"""Call the single-particle rebound kernel from tests with explicit inputs: a family by name or any shape's
record (a user's grain), its (b/a, c/b) and hand, an orientation and an incident state."""

from typing import NamedTuple

import numpy as np
from scipy.spatial.transform import Rotation

from direct_model.body_rebound import HISTORY_COLUMNS, WORK_SIZE, body_rebound
from direct_model.shape_arrays import bounding_radius, family_shape_arrays, particle_body, particle_hull, shape_arrays
from direct_model.shapes import SHAPES, AspectRatioLaw, second_moment_factors
from direct_model.simulate import incident_velocity
from direct_model.wall import CORUNDUM_ON_STEEL

MIRROR = np.diag([1.0, 1.0, -1.0])     # reflection Z → −Z (lab) and ζ → −ζ (body)


class Body(NamedTuple):
    """One particle's body (:func:`direct_model.shape_arrays.particle_body`), units of a."""

    kind: int
    vertices: np.ndarray     # (nv, 3) body frame; (0, 3) for an ellipsoid
    semi: np.ndarray         # half-extents along ξ, η, ζ (an ellipsoid's semi-axes)
    K: np.ndarray            # principal J/m, a²
    radius: float            # bounding radius
    hull: tuple              # the kernels' hull argument (direct_model.shape_arrays.particle_hull)


def body(shape, ratios=(1.0, 1.0), hand=1, kappa=0.3) -> Body:
    """The body of a family (by name, at κ) or of a record, at (b/a, c/b) and hand."""
    if isinstance(shape, str):
        arrays, index = family_shape_arrays(kappa, AspectRatioLaw(), second_moment_factors(kappa)), SHAPES.index(shape)
    else:
        arrays, index = shape_arrays([shape]), 0
    count = arrays.vertex_start[index + 1] - arrays.vertex_start[index]
    verts, K, semi, scale = np.empty((count, 3)), np.empty(3), np.empty(3), np.empty(3)
    nv = particle_body(arrays, index, float(ratios[0]), float(ratios[1]), float(hand), verts, K, semi, scale)
    kind = int(arrays.kind[index])
    hull = particle_hull.py_func(arrays, index, scale)     # compiled, it would hand Python the whole arrays
    return Body(kind, verts[:nv].copy(), semi, K, bounding_radius(kind, semi, verts, nv, hull), hull)


def run_one(shape, ratios, R0, alpha1=45.0, speed=200.0, omega_in=(0.0, 0.0, 0.0), hand=1,
            kappa=0.3, n_max=1000, contact_tol=1e-10, set_tol=1e-9, max_steps=100_000, history_rows=0):
    """Rebound of one particle (``shape`` and ``ratios`` as :func:`body`); returns (V⁺ m/s, Ω⁺ (m/s)/a, status,
    n_coll, e_rot, history)."""
    done, V, W, history, _ = _rebound(shape, ratios, R0, alpha1, speed, omega_in, hand, kappa, n_max, contact_tol,
                                      set_tol, max_steps, history_rows)
    return V, W, done.status, done.n_collisions, done.rotational_energy, history


def rebound_one(shape, ratios, R0, alpha1=45.0, speed=200.0, omega_in=(0.0, 0.0, 0.0), hand=1, kappa=0.3,
                n_max=1000):
    """:func:`run_one`'s rebound as the kernel returns it (:class:`direct_model.body_rebound.BodyRebound`: V and
    Omega after the last collision, the wall work, ...) and the incident kinetic energy per unit mass E⁻ =
    ½|V⁻|² + ½Ω⁻·KΩ⁻ (m²/s², K the lab-frame J/m at the orientation R0)."""
    done, _, _, _, b = _rebound(shape, ratios, R0, alpha1, speed, omega_in, hand, kappa, n_max, 1e-10, 1e-9, 100_000,
                                0)
    V0, W0 = incident_velocity(alpha1, speed), np.asarray(omega_in, dtype=float) * speed
    return done, 0.5 * V0 @ V0 + 0.5 * W0 @ (R0 @ np.diag(b.K) @ R0.T) @ W0


def _rebound(shape, ratios, R0, alpha1, speed, omega_in, hand, kappa, n_max, contact_tol, set_tol, max_steps,
             history_rows):
    b = body(shape, ratios, hand, kappa)
    verts = np.zeros((max(len(b.vertices), 1), 3))         # an ellipsoid's support point goes to row 0
    verts[:len(b.vertices)] = b.vertices
    V, W = np.empty(3), np.empty(3)
    history = np.full((history_rows, HISTORY_COLUMNS), np.nan)
    done = body_rebound(
        b.kind, verts, len(b.vertices), b.semi, b.K, b.radius, np.ascontiguousarray(R0),
        incident_velocity(alpha1, speed), np.asarray(omega_in, dtype=float) * speed, CORUNDUM_ON_STEEL.as_array(),
        n_max, contact_tol, set_tol, max_steps, V, W, history, np.empty(WORK_SIZE), b.hull)
    return done, V, W, history, b


def random_bodies(n, seed, shapes=("ellipsoid", "prism", "cut_prism", "tetrahedron")):
    """n random (shape, (b/a, c/b), orientation matrix, hand) tuples; a shape is a family's name or a record
    (hands drawn for the tetrahedron and for a record in both hands)."""
    rng = np.random.default_rng(seed)
    out = []
    for i in range(n):
        shape = shapes[i % len(shapes)]
        ratios = tuple(rng.uniform(0.5, 1.0, 2))
        both = shape == "tetrahedron" or getattr(shape, "both_hands", False)
        out.append((shape, ratios, Rotation.random(random_state=rng).as_matrix(),
                    int(rng.choice([-1, 1])) if both else 1))
    return out
