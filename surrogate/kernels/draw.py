"""The law of one draw, in three stages, one module each, and their composition (:func:`draw_velocity`).

1. locate (:mod:`surrogate.kernels.locate`) — where the draw reads: the cell
   (the shape from the mix, the grid intervals of α1 and |V⁻| and the
   neighbour drawn with its interpolation weight), the component the alias
   table picks in it, and cache hints for those reads;
2. gather (:mod:`surrogate.kernels.gather`) — every table value the draw
   needs (the component's residual quantiles and slopes, the moments and the
   restitution factors that move it to the incident state), as a tuple;
3. arithmetic (:mod:`surrogate.kernels.arithmetic`) — the reflected state from
   those values alone, with every choice a select.

One particle (:mod:`surrogate.kernels.table_path`) calls them in turn; the
pipeline (:mod:`surrogate.kernels.pipeline`) calls each stage's block form on
a block of particles, so the two give the same bits by construction.

These are plain functions over the arrays of a table (``table.kernel_data``,
:class:`surrogate.kernels.layout.KernelData`) and pre-drawn uniforms. Every
draw consumes exactly :data:`U_PER_DRAW` uniforms from [0, 1)::

    u[0] shape from the mix        u[1] α1 neighbour       u[2] speed neighbour
    u[3] trapped or not            u[4] mixture component  u[5:11] the six chain variables
    u[11] mirror sign              u[12] in-wall axis at normal impact (:func:`surrogate.kernels.frame.impact_frame`)

Between grid points the sampler uses stochastic interpolation: the cell of the
neighbour at x_{j+1} is used with probability w = (x − x_j)/(x_{j+1} − x_j), as
Monte Carlo transport codes do between incident-energy points; a multimodal
law stays multimodal (no averaging of quantiles). By default (``scaled``) the
state drawn from the neighbour is then moved to the incident state:

* in α1, variable by variable, to the mean and standard deviation interpolated
  linearly between the two neighbouring α1 (like the unit-base interpolation
  of transport codes, which stretches a neighbour's secondary law to the
  interpolated range);
* in |V⁻|, by the wall's restitution law (:func:`surrogate.kernels.arithmetic.to_speed`), with a law that
  depends on the drawn cluster's collision regime: the velocity change and
  the spin of a rebound of one or two collisions scale with 1 + a(V), the
  normal rebound velocity of a longer one with a(V).

The hot path calls no libm function (:mod:`surrogate.kernels.fastmath`) and
branches only where the outcome is predictable (trapped, outside the grid);
choices that vary from draw to draw (neighbour cell, alias, regime, mirror
sign, quadrant) are selects.

Frame and units: the model's lab frame (wall y = 0, normal +Y, impact plane
XY, α1 from the wall); angles in radians except α1 (degrees), V⁺ in units of
|V⁻|, Ω in units of |V⁻|/a.
"""


import math

import numba

from data_schema.samples import STATUS_TRAPPED
from direct_model.elementary import sincos
from surrogate.kernels.arithmetic import NAN6, arithmetic
from surrogate.kernels.gather import gather, is_trapped
from surrogate.kernels.locate import component, hint, locate
from surrogate.kernels.options import JIT, KERNEL


U_PER_DRAW = 13


@numba.njit(**KERNEL)
def draw_in_cell(data, cell, cos_alpha1, sin_alpha1, u, scaled):
    """:func:`draw_velocity` once its cell (:func:`locate`) is known and its reads hinted; α1 given by its
    cosine and sine. A trapped draw reads nothing more."""
    drawn = cell[0]
    if is_trapped(data, drawn, u[3]):
        return (STATUS_TRAPPED,) + NAN6
    return arithmetic(gather(data, cell, component(data, drawn, u[4]), u), cos_alpha1, sin_alpha1, scaled)


@numba.njit(inline="always", **JIT)
def draw_velocity(data, mix_cdf, alpha1, speed, u, scaled=True):
    """One reflected state at (α1 deg, |V⁻| m/s) as local-frame vectors.

    ``mix_cdf`` is the cumulative shape weights in the table's shape order
    (last entry 1). Returns (status, V⁺_x, V⁺_y, V⁺_z, Ω_x, Ω_y, Ω_z) with
    V⁺ in units of |V⁻| and Ω⁺ in units of |V⁻|/a; NaN for a trapped
    particle. Outside the table's grid the law at the nearest grid edge is used.

    Between grid points the cell of a neighbour is drawn with its
    interpolation weight (stochastic interpolation). With ``scaled`` the
    draw is then moved to the incident state: in α1 to the interpolated
    means and standard deviations (:func:`surrogate.kernels.arithmetic._moved`), in |V⁻| by the wall's
    restitution law (:func:`surrogate.kernels.arithmetic.to_speed`).
    """
    cell = locate(data, mix_cdf, alpha1, speed, u)
    hint(data, cell, u)
    sin_a1, cos_a1 = sincos(math.radians(alpha1))
    return draw_in_cell(data, cell, cos_a1, sin_a1, u, scaled)
