"""The direct model at run time: one particle's whole rebound from U_PER_REBOUND uniforms (docs/model.md §10).

:func:`rebound_model_frame` is :func:`direct_model.body_rebound.body_rebound` with its random inputs drawn from
uniforms the caller passes, the particle's shape from the shapes as arrays
(:class:`direct_model.shape_arrays.ShapeArrays`) and every other model parameter from one float64 array
(:func:`model_parameters`, layout P_*), so that a runtime reads the parameters a table was built with and
calls the model from ``@njit`` code. The P_* array still holds the families' law, κ and factors s, from which a
runtime builds their arrays (:func:`family_shapes`). It works in the model's frame (wall y = 0, normal +Y;
docs/model.md §2); :func:`surrogate.kernels.direct_path.direct_rebound` puts a hit in that frame and back.

The uniforms, all in [0, 1): u[0:3] the orientation (Shoemake's uniform quaternion: Haar measure, like the
batch's normalised Gaussian quaternion), u[3:5] b/a and c/b (inverse CDF of the shape's truncated normal law,
like :meth:`direct_model.shapes.AspectRatioLaw.ppf`; unused for fixed proportions), u[5] the hand of a shape
drawn in both hands (the tetrahedron; +1 below ½), u[6] the
direction ex of the model frame at normal impact (used by the caller's frame, not here). A fixed count,
so the caller draws them from any stream (xoshiro256+ in :mod:`surrogate`, ``rbs_rng`` in C) and the same
uniforms give the same rebound in every implementation. Needs numpy and numba only.
"""

import math

import numba
import numpy as np

from direct_model.options import KERNEL
from direct_model.body_rebound import HISTORY_COLUMNS, WORK_SIZE, quaternion_to_matrix, body_rebound
from direct_model.shape_arrays import ShapeArrays, bounding_radius, family_shape_arrays, particle_body, particle_hull
from direct_model.shapes import SHAPES, AspectRatioLaw, check_kappa, normal_cdf
from direct_model.hull_walk import WALK_ABOVE
from direct_model.wall import WALL_ARRAY_SIZE, Wall, wall_from_array

U_PER_REBOUND = 7
U_ORIENTATION, U_RATIOS, U_HAND, U_AXIS = 0, 3, 5, 6

# layout of the parameter array (float64)
P_ASPECT_MEAN, P_ASPECT_SD, P_ASPECT_LOW, P_ASPECT_HIGH = 0, 1, 2, 3   # the aspect-ratio law (b/a and c/b)
P_CDF_LOW, P_CDF_HIGH = 4, 5     # Φ((low − mean)/sd), Φ((high − mean)/sd): the law's CDF bounds
P_KAPPA, P_N_MAX = 6, 7                              # κ, n_max
P_CONTACT_TOL, P_SET_TOL, P_MAX_STEPS = 8, 9, 10    # units of a, units of a, search steps per flight
P_KFAC = 11                                          # second-moment factor s per shape code, 11..14
P_WALL = P_KFAC + len(SHAPES)                        # the wall's array (direct_model.wall, layout W_*), zero-padded
N_PARAMS = P_WALL + WALL_ARRAY_SIZE

# the scratch of one call: rebound's work, then the body's vertices (a scanned hull's; a walked one needs none),
# its half-extents, J/m and scale, R0, V0, W0, V, W
_VERTS = WORK_SIZE
_SEMI = _VERTS + 3 * WALK_ABOVE
_K = _SEMI + 3
_SCALE = _K + 3
_R0 = _SCALE + 3
_V0 = _R0 + 9
SCRATCH_SIZE = _V0 + 12


def model_parameters(aspect: AspectRatioLaw, kappa: float, n_max: int, wall: Wall, contact_tol: float,
                     set_tol: float, max_steps: int, second_moment_factors) -> np.ndarray:
    """The parameter array of :func:`rebound_model_frame` (P_* layout), read-only; ValueError naming a value
    outside its range. Units: tolerances in units of a, the wall law as a :class:`direct_model.wall.Wall`."""
    kappa = check_kappa(kappa)
    for name, value in (("n_max", n_max), ("max_steps", max_steps)):
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or not 1 <= value < 2 ** 53:
            raise ValueError(f"The '{name}' parameter must be an integer in [1, 2**53); got {value!r}.")
    for name, value in (("contact_tol", contact_tol), ("set_tol", set_tol)):
        if not (math.isfinite(value) and value > 0.0):
            raise ValueError(f"The '{name}' parameter must be finite and > 0 (units of a); got {value!r}.")
    kfac = np.asarray(second_moment_factors, dtype=np.float64)
    if kfac.shape != (len(SHAPES),) or not np.all((kfac > 0.0) & (kfac < 1.0)):
        raise ValueError(f"The 'second_moment_factors' parameter must be {len(SHAPES)} numbers in (0, 1), one per "
                         f"shape code; got {second_moment_factors!r}.")
    p = np.zeros(N_PARAMS)
    p[P_ASPECT_MEAN:P_ASPECT_HIGH + 1] = aspect.mean, aspect.sd, aspect.low, aspect.high
    p[P_CDF_LOW] = normal_cdf((aspect.low - aspect.mean) / aspect.sd)
    p[P_CDF_HIGH] = normal_cdf((aspect.high - aspect.mean) / aspect.sd)
    p[P_KAPPA], p[P_N_MAX] = kappa, n_max
    wall_array = wall.as_array()
    p[P_WALL:P_WALL + len(wall_array)] = wall_array
    p[P_CONTACT_TOL], p[P_SET_TOL], p[P_MAX_STEPS] = contact_tol, set_tol, max_steps
    p[P_KFAC:P_KFAC + len(SHAPES)] = kfac
    p.flags.writeable = False
    return p


def model_settings(params) -> dict:
    """The settings a parameter array holds (the inverse of :func:`model_parameters` but for the factors s), as
    keywords of :func:`direct_model.simulate.simulate`: κ, the b/a and c/b law, n_max, the wall law and the
    search's tolerances (units of a) and step budget."""
    return {"kappa": float(params[P_KAPPA]),
            "aspect": AspectRatioLaw(*map(float, params[P_ASPECT_MEAN:P_ASPECT_HIGH + 1])),
            "n_max": int(params[P_N_MAX]),
            "wall": wall_from_array(params[P_WALL:], name="from the model's parameters"),
            "contact_tol": float(params[P_CONTACT_TOL]), "set_tol": float(params[P_SET_TOL]),
            "max_steps": int(params[P_MAX_STEPS])}


def family_shapes(params, grains=()) -> ShapeArrays:
    """The four families' shape arrays at the κ, aspect-ratio law and factors s of a parameter array
    (:func:`model_parameters`), in shape-code order, then the records ``grains`` (a table's other polyhedra):
    what a runtime builds from a table."""
    settings = model_settings(params)
    return family_shape_arrays(settings["kappa"], settings["aspect"], params[P_KFAC:P_KFAC + len(SHAPES)], grains)


@numba.njit(**KERNEL)
def normal_quantile(p):
    """Φ⁻¹(p) for p in (0, 1): Wichura's AS 241 (PPND16), relative error about 1e-16; log and sqrt only."""
    q = p - 0.5
    if abs(q) <= 0.425:
        r = 0.180625 - q * q
        return q * (((((((2509.0809287301226727 * r + 33430.575583588128105) * r + 67265.770927008700853) * r
                         + 45921.953931549871457) * r + 13731.693765509461125) * r + 1971.5909503065514427) * r
                      + 133.14166789178437745) * r + 3.387132872796366608) / (
            ((((((5226.495278852545925 * r + 28729.085735721942674) * r + 39307.89580009271061) * r
                + 21213.794301586595867) * r + 5394.1960214247511077) * r + 687.1870074920579083) * r
             + 42.313330701600911252) * r + 1.0)
    r = math.sqrt(-math.log(p if q < 0.0 else 1.0 - p))
    if r <= 5.0:
        r -= 1.6
        x = (((((((7.7454501427834140764e-4 * r + 0.0227238449892691845833) * r + 0.24178072517745061177) * r
                 + 1.27045825245236838258) * r + 3.64784832476320460504) * r + 5.7694972214606914055) * r
              + 4.6303378461565452959) * r + 1.42343711074968357734) / (
            ((((((1.05075007164441684324e-9 * r + 5.475938084995344946e-4) * r + 0.0151986665636164571966) * r
                + 0.14810397642748007459) * r + 0.68976733498510000455) * r + 1.6763848301838038494) * r
             + 2.05319162663775882187) * r + 1.0)
    else:
        r -= 5.0
        x = (((((((2.01033439929228813265e-7 * r + 2.71155556874348757815e-5) * r + 0.0012426609473880784386) * r
                 + 0.026532189526576123093) * r + 0.29656057182850489123) * r + 1.7848265399172913358) * r
              + 5.4637849111641143699) * r + 6.6579046435011037772) / (
            ((((((2.04426310338993978564e-15 * r + 1.4215117583164458887e-7) * r + 1.8463183175100546818e-5) * r
                + 7.868691311456132591e-4) * r + 0.0148753612908506148525) * r + 0.13692988092273580531) * r
             + 0.59983220655588793769) * r + 1.0)
    return -x if q < 0.0 else x


@numba.njit(**KERNEL)
def aspect_ratio(law, cdf, u):
    """The quantile at u ∈ [0, 1) of the aspect-ratio law ``law`` = (mean, sd, low, high) whose CDF bounds are
    ``cdf`` = (Φ_low, Φ_high) (:class:`direct_model.shape_arrays.ShapeArrays`' aspect and aspect_cdf rows):
    mean + sd Φ⁻¹(Φ_low + u (Φ_high − Φ_low)), in [low, high]."""
    lo, hi = cdf[0], cdf[1]
    x = law[0] + law[1] * normal_quantile(lo + u * (hi - lo))
    return min(max(x, law[2]), law[3])


@numba.njit(**KERNEL)
def uniform_quaternion(u0, u1, u2, q):
    """q = a unit quaternion uniform on S³ (Shoemake 1992) from three uniforms: Haar-uniform rotations."""
    s, c = math.sqrt(1.0 - u0), math.sqrt(u0)
    q[0], q[1] = s * math.sin(2.0 * math.pi * u1), s * math.cos(2.0 * math.pi * u1)
    q[2], q[3] = c * math.sin(2.0 * math.pi * u2), c * math.cos(2.0 * math.pi * u2)


@numba.njit(**KERNEL)
def rebound_model_frame(params, shape_arrays, shape, vt, vn, wx, wy, wz, u, scratch):
    """One particle's whole rebound (docs/model.md §5) in the model frame, its random inputs from ``u``.

    Parameters
    ----------
    params : (N_PARAMS,) :func:`model_parameters`.
    shape_arrays : the shapes (:class:`direct_model.shape_arrays.ShapeArrays`).
    shape : the particle's shape, an index into ``shape_arrays``.
    vt, vn : incident velocity (vt, vn, 0) in m/s, model frame (vn < 0: into the wall y = 0).
    wx, wy, wz : incident angular velocity in (m/s)/a, i.e. Ω⁻ (rad/s) times a (m), model frame; all zero:
        the body starts touching the wall, otherwise clear of it with the flight in simulated (§5.3).
    u : (≥ U_PER_REBOUND,) uniforms in [0, 1) (module doc).
    scratch : (SCRATCH_SIZE,) float64 work space.

    Returns
    -------
    :class:`direct_model.body_rebound.BodyRebound`, model frame: V⁺ in m/s, Ω⁺ in (m/s)/a; the work of the
    rebound on the wall per unit particle mass, ``wall_work_normal`` and ``wall_work_tangential`` in m²/s²
    (docs/model.md §4.7; a scalar of the rebound, the same in every frame).
    """
    verts = scratch[_VERTS:_VERTS + 3 * WALK_ABOVE].reshape((WALK_ABOVE, 3))
    semi, K, scale = scratch[_SEMI:_SEMI + 3], scratch[_K:_K + 3], scratch[_SCALE:_SCALE + 3]
    R0 = scratch[_R0:_R0 + 9].reshape((3, 3))
    V0, W0 = scratch[_V0:_V0 + 3], scratch[_V0 + 3:_V0 + 6]
    V, W = scratch[_V0 + 6:_V0 + 9], scratch[_V0 + 9:_V0 + 12]
    quat = scratch[_V0 + 6:_V0 + 10]        # V and W[0]: free until rebound starts from V0, W0
    uniform_quaternion(u[U_ORIENTATION], u[U_ORIENTATION + 1], u[U_ORIENTATION + 2], quat)
    quaternion_to_matrix(quat, R0)
    law, cdf = shape_arrays.aspect[shape], shape_arrays.aspect_cdf[shape]
    if np.isnan(law[0]):                    # fixed proportions: no quantile of NaN (C: no FE_INVALID)
        ratio_ba, ratio_cb = 1.0, 1.0
    else:
        ratio_ba, ratio_cb = aspect_ratio(law, cdf, u[U_RATIOS]), aspect_ratio(law, cdf, u[U_RATIOS + 1])
    hand = 1.0 if shape_arrays.both_hands[shape] == 0 or u[U_HAND] < 0.5 else -1.0
    nv = particle_body(shape_arrays, shape, ratio_ba, ratio_cb, hand, verts, K, semi, scale)
    hull = particle_hull(shape_arrays, shape, scale)
    kind = np.int64(shape_arrays.kind[shape])
    V0[0], V0[1], V0[2] = vt, vn, 0.0
    W0[0], W0[1], W0[2] = wx, wy, wz
    return body_rebound(
        kind, verts, nv, semi, K, bounding_radius(kind, semi, verts, nv, hull), R0, V0, W0, params[P_WALL:],
        int(params[P_N_MAX]), params[P_CONTACT_TOL], params[P_SET_TOL], int(params[P_MAX_STEPS]), V, W,
        scratch[:0].reshape((0, HISTORY_COLUMNS)), scratch[:WORK_SIZE], hull)
