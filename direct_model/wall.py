"""The wall law of one collision: restitution and friction (docs/model.md §4).

Two empirical coefficients close the impulse model:

* normal restitution of the contact point (Lashkov's corundum/St3 correlation,
  valid for 50–300 m/s)::

      a_nc = 1 − [1 − exp(−k |V_c⁻|^p)] · |v_c⁻| / |V_c⁻|       (|V_c⁻| in m/s)

  where |v_c⁻|/|V_c⁻| is the sine of the contact point's impact angle, so
  a_nc ∈ (0, 1];
* the friction factor (Panfilov & Tsirkunov's heuristic)::

      C_f = exp(q · cos γ),   cos γ = (r_c · V_p⁻) / (|r_c| |V_p⁻|)

  with V_p⁻ the centre-of-mass velocity just before the current collision.

The published law is k = 0.1, p = 0.61, q = 1 (:data:`CORUNDUM_ON_STEEL`).
Another particle/wall pair of the same functional family is another
:class:`WallMaterial`; the kernels receive it as the array :meth:`as_array`.
"""

from __future__ import annotations

import dataclasses

import numba
import numpy as np

from direct_model.options import KERNEL


@dataclasses.dataclass(frozen=True)
class WallMaterial:
    """Coefficients of the restitution and friction laws (see module doc).

    Attributes
    ----------
    k : float
        Restitution rate constant, (m/s)^(−p); > 0.
    p : float
        Restitution speed exponent; > 0.
    q : float
        Friction exponent scale in C_f = exp(q cos γ); finite.
    name : str
        Label stored with results.
    """

    k: float = 0.1
    p: float = 0.61
    q: float = 1.0
    name: str = "corundum_on_St3_Lashkov1991"

    def __post_init__(self):
        for key in ("k", "p"):
            value = getattr(self, key)
            if not (np.isfinite(value) and value > 0):
                raise ValueError(f"The wall law parameter '{key}' must be finite and > 0; got {value!r}.")
        if not np.isfinite(self.q):
            raise ValueError(f"The wall law parameter 'q' must be finite; got {self.q!r}.")

    def as_array(self) -> np.ndarray:
        """The coefficients (k, p, q) as the float64 array the kernels take, read-only as the slice of the model's
        parameters that the runtime passes (a writable one would compile the kernels a second time)."""
        coefficients = np.array([self.k, self.p, self.q], dtype=np.float64)
        coefficients.setflags(write=False)
        return coefficients


CORUNDUM_ON_STEEL = WallMaterial()


@numba.njit(**KERNEL)
def restitution(wall, contact_speed, sin_impact):
    """Normal restitution a_nc of the contact point; ``contact_speed`` in m/s."""
    return 1.0 - (1.0 - np.exp(-wall[0] * contact_speed ** wall[1])) * sin_impact


@numba.njit(**KERNEL)
def friction_factor(wall, cos_gamma):
    """Friction factor C_f = exp(q cos γ)."""
    return np.exp(wall[2] * cos_gamma)
