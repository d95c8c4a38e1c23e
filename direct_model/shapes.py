"""Particle shapes (docs/model.md §3): geometry, mass properties, shape sampling.

Body frame Oξηζ: origin at the centroid, axes along the principal axes of
inertia. Half-extents ``a, b, c`` along ξ, η, ζ. All lengths are in units of
``a`` inside the kernels (``a = 1``): every dimensionless result is independent
of the particle size (docs/model.md §7).

Four shapes, identified in arrays by an integer code:

=============  ====  ======================================================
name           code  definition
=============  ====  ======================================================
ellipsoid      0     semi-axes a, b, c
prism          1     box with vertices (±a, ±b, ±c)
cut_prism      2     the box with its 8 corners cut off at fraction κ of the
                     half-extents (24 vertices)
tetrahedron    3     vertices (a,b,c), (a,−b,−c), (−a,b,−c), (−a,−b,c); the
                     mirror hand has c → −c
=============  ====  ======================================================

Inertia per unit mass. Every shape here is the image of a fixed "unit" shape
(a = b = c = 1, cubic symmetry) under the stretch diag(a, b, c). The second
moments of a uniform body then scale as ∫ξ² dm / m = s a² (likewise η, ζ),
with no products of inertia, where ``s`` is one number per unit shape. Hence

    J/m = s · (b² + c², a² + c², a² + b²)        (principal, body frame)

with s = 1/5 (ellipsoid, tetrahedron), 1/3 (box) and s(κ) for the cut prism.
For the polyhedra ``s`` is computed by the general routine
:func:`polyhedron_mass_properties` (tetrahedral decomposition), which the tests
check against the closed forms.
"""

from __future__ import annotations

import dataclasses
import math

import numba
import numpy as np

from data_schema.samples import SHAPE_NAMES
from direct_model.options import JIT

ELLIPSOID, PRISM, CUT_PRISM, TETRAHEDRON = 0, 1, 2, 3
SHAPES = SHAPE_NAMES
MIX = "mix"
MAX_VERTICES = 24
DEFAULT_KAPPA = 0.3


def shape_code(name: str) -> int:
    """Integer code of a shape name; ValueError naming the allowed names."""
    if name not in SHAPES:
        raise ValueError(
            f"The 'shape' parameter must be one of {', '.join(SHAPES)} or {MIX!r}; got {name!r}."
        )
    return SHAPES.index(name)


def check_kappa(kappa: float) -> float:
    """Validate the corner-truncation fraction κ of the cut prism, in [0, 1)."""
    kappa = float(kappa)
    if not (0.0 <= kappa < 1.0):
        raise ValueError(f"The 'kappa' parameter must be in [0, 1); got {kappa!r}.")
    return kappa


@numba.njit(**JIT)
def body_vertices(shape, a, b, c, kappa, hand, out):
    """Fill ``out[:n]`` with the body-frame vertices of a polyhedron; return n.

    ``hand`` = +1 or −1 selects the tetrahedron's hand (−1: c → −c); other
    shapes ignore it. For the ellipsoid, return 0 (no vertices). For the cut
    prism, corner (sa·a, sb·b, sc·c) is replaced by the three points at a
    fraction κ of the half-extent from it along its edges; κ = 0 gives the box
    with each corner repeated three times.
    """
    if shape == ELLIPSOID:
        return 0
    if shape == TETRAHEDRON:
        ch = c * hand
        out[0, 0], out[0, 1], out[0, 2] = a, b, ch
        out[1, 0], out[1, 1], out[1, 2] = a, -b, -ch
        out[2, 0], out[2, 1], out[2, 2] = -a, b, -ch
        out[3, 0], out[3, 1], out[3, 2] = -a, -b, ch
        return 4
    n = 0
    for sa in (-1.0, 1.0):
        for sb in (-1.0, 1.0):
            for sc in (-1.0, 1.0):
                if shape == PRISM:
                    out[n, 0], out[n, 1], out[n, 2] = sa * a, sb * b, sc * c
                    n += 1
                else:
                    out[n, 0], out[n, 1], out[n, 2] = sa * a * (1.0 - kappa), sb * b, sc * c
                    out[n + 1, 0], out[n + 1, 1], out[n + 1, 2] = sa * a, sb * b * (1.0 - kappa), sc * c
                    out[n + 2, 0], out[n + 2, 1], out[n + 2, 2] = sa * a, sb * b, sc * c * (1.0 - kappa)
                    n += 3
    return n


def shape_vertices(shape: str, a: float = 1.0, b: float = 1.0, c: float = 1.0,
                   kappa: float = DEFAULT_KAPPA, hand: int = 1) -> np.ndarray:
    """Body-frame vertices (n, 3) of a polyhedral shape (Python wrapper)."""
    code = shape_code(shape)
    if code == ELLIPSOID:
        raise ValueError("The 'shape' parameter must be a polyhedron; got 'ellipsoid'.")
    out = np.empty((MAX_VERTICES, 3))
    n = body_vertices(code, float(a), float(b), float(c), check_kappa(kappa), float(hand), out)
    return out[:n].copy()


def polyhedron_mass_properties(vertices: np.ndarray):
    """Volume, centroid and inertia tensor per unit mass of a uniform convex polyhedron.

    General routine: the convex hull of ``vertices`` is triangulated and split
    into tetrahedra joining each boundary triangle to an interior point; each
    tetrahedron with vertices p0..p3 contributes its volume V and the second
    moment ∫ x xᵀ dV = V/20 (Σ pᵢpᵢᵀ + (Σpᵢ)(Σpᵢ)ᵀ).

    Parameters
    ----------
    vertices : (n, 3) array, any length unit; duplicates are allowed.

    Returns
    -------
    volume : float
    centroid : (3,) array
    inertia_per_mass : (3, 3) array, J/m about the centroid (length² units).
    """
    from scipy.spatial import ConvexHull     # here: the run-time kernel needs numpy and numba only

    pts = np.unique(np.asarray(vertices, dtype=float), axis=0)
    hull = ConvexHull(pts)
    p0 = pts.mean(axis=0)
    tri = pts[hull.simplices] - p0                      # (m, 3, 3), relative to p0
    vol = np.abs(np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2]))) / 6.0
    volume = vol.sum()
    # the apex p0 sits at the origin of the relative coordinates
    s = tri.sum(axis=1)
    centroid_rel = (vol[:, None] * s / 4.0).sum(axis=0) / volume
    second = (vol[:, None, None] / 20.0
              * (np.einsum("mki,mkj->mij", tri, tri) + np.einsum("mi,mj->mij", s, s))).sum(axis=0)
    cov = second / volume - np.outer(centroid_rel, centroid_rel)   # about the centroid
    inertia = np.trace(cov) * np.eye(3) - cov
    return volume, centroid_rel + p0, inertia


def second_moment_factor(shape: str, kappa: float = DEFAULT_KAPPA) -> float:
    """The factor s with J/m = s·(b²+c², a²+c², a²+b²) for a shape (see module doc).

    Polyhedra: from :func:`polyhedron_mass_properties` on the unit shape.
    Ellipsoid: 1/5 (closed form).
    """
    if shape_code(shape) == ELLIPSOID:
        return 0.2
    _, _, inertia = polyhedron_mass_properties(shape_vertices(shape, kappa=kappa))
    return inertia[0, 0] / 2.0


def second_moment_factors(kappa: float = DEFAULT_KAPPA) -> np.ndarray:
    """Array of :func:`second_moment_factor` indexed by shape code (kernel input)."""
    return np.array([second_moment_factor(s, kappa) for s in SHAPES])


def normal_cdf(x: float) -> float:
    """Φ(x), the standard normal CDF (libm's erfc: no scipy at run time); the aspect-ratio law's CDF bounds."""
    return 0.5 * math.erfc(-x / math.sqrt(2.0))


@dataclasses.dataclass(frozen=True)
class AspectRatioLaw:
    """Distribution of a particle's aspect ratios b/a and c/b (docs/model.md §3).

    Each ratio is independent, normal with ``mean`` and standard deviation
    ``sd``, truncated to [``low``, ``high``] ⊂ (0, 1]. Since b/a ≤ 1 and
    c/b ≤ 1, ``a`` is the largest half-extent.
    """

    mean: float = 0.8
    sd: float = 0.2
    low: float = 0.5
    high: float = 1.0

    def __post_init__(self):
        if not (0.0 < self.low < self.high <= 1.0):
            raise ValueError(
                "The aspect-ratio bounds must satisfy 0 < low < high <= 1; "
                f"got low={self.low!r}, high={self.high!r}.")
        if not (self.sd > 0.0 and np.isfinite(self.sd)):
            raise ValueError(f"The aspect-ratio 'sd' must be finite and > 0; got {self.sd!r}.")
        if not np.isfinite(self.mean):
            raise ValueError(f"The aspect-ratio 'mean' must be finite; got {self.mean!r}.")

    def ppf(self, u: np.ndarray) -> np.ndarray:
        """Inverse CDF of the truncated normal at probabilities ``u`` ∈ [0, 1]."""
        from scipy.special import ndtr, ndtri     # here: the run-time kernel needs numpy and numba only

        lo = ndtr((self.low - self.mean) / self.sd)
        hi = ndtr((self.high - self.mean) / self.sd)
        x = self.mean + self.sd * ndtri(lo + np.asarray(u) * (hi - lo))
        return np.clip(x, self.low, self.high)

    def sample(self, rng: np.random.Generator, size: int) -> np.ndarray:
        """Draw ``size`` pairs (b/a, c/b) as an array of shape (size, 2)."""
        return self.ppf(rng.random((size, 2)))
