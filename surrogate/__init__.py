"""surrogate: the runtime rebound sampler.

Reads tables made by ``tablegen build`` through :mod:`data_schema` and never
imports :mod:`tablegen`, so a flow solver installs the runtime alone::

    import surrogate
    table = surrogate.load("table.h5")
    hits = surrogate.sample_global(table, V, normals, half_size, shape="prism", random_state=1)
    hits.V, hits.Omega, hits.status          # V⁺ m/s, Ω⁺ rad/s, 0 rebounded (surrogate.Rebounds: by name)

From numba code, the call that answers any wall hit is :func:`surrogate.kernels.rebound` (module doc's last
paragraph); the table path alone is :func:`surrogate.kernels.table_rebound`, called with ``table.kernel_data``
and ``U_PER_DRAW`` uniforms per call; :func:`fill_uniforms` draws them fast from
a caller-owned xoshiro256+ state (:func:`seed_state`). A solver that collects
its wall hits of a time step should pass them all to
:func:`surrogate.kernels.table_rebound_many_rng` (uniforms from a state) or
:func:`surrogate.kernels.table_rebound_many` (uniforms given), which pipeline
blocks of particles, overlap their table reads and compute their draws as
SIMD loops, with the per-particle results bit for bit;
:func:`surrogate.kernels.table_rebound_parallel_rng` does the same on all threads,
as :func:`sample_global` does. :mod:`surrogate.kernels` maps where each part lives.

Where the table does not apply (a particle spinning before it hits, an α1 or |V⁻| off its grid), the direct
model answers: :func:`sample_global` with its default ``method="auto"`` picks, per hit, the table where it is
valid (|Ω⁻|a/|V⁻| ≤ :data:`SPIN_TOLERANCE`, inside the grid) and the direct model elsewhere; from numba,
:func:`surrogate.kernels.rebound` (13 uniforms per hit whatever the path) and
:func:`surrogate.kernels.rebound_path`. The direct model alone: :func:`sample_direct` from NumPy,
:func:`surrogate.kernels.direct_rebound` from numba with ``table.direct_parameters``, ``table.shape_arrays`` and
``U_PER_REBOUND`` uniforms per call (docs/model.md §10).

A particle that keeps its grain from one wall hit to the next: give it a grain key (``grain_key=`` of
:func:`sample_global` and :func:`sample_direct`; :func:`grain_key` derives keys from a seed and ids,
:func:`grain_of` says which grain a key is; :mod:`surrogate.grains`).

Every argument of the NumPy API goes through :mod:`surrogate.validation` (``check_random_state``,
``check_shape``, ``mix_cdf``, ...), which a caller may use too.
"""

from data_schema.samples import STATUS_FAILED, STATUS_INVALID, STATUS_REBOUNDED, STATUS_TRAPPED
from direct_model.runtime import U_PER_REBOUND
from surrogate.grains import Grains, grain_key, grain_of
from surrogate.kernels import MAX_WALL_HITS, SPIN_TOLERANCE, U_PER_DRAW, fill_uniforms, seed_state
from surrogate.kernels.hit import Hit, Rebounds, empty_rebounds
from surrogate.sampling import LocalDraws, WallLawRangeWarning, sample_direct, sample_global, sample_local
from surrogate.table import SurrogateTable, load
from surrogate.validation import METHODS, check_random_state, mix_cdf

__all__ = ["Grains", "Hit", "LocalDraws", "MAX_WALL_HITS", "METHODS", "Rebounds", "SPIN_TOLERANCE", "STATUS_FAILED", "STATUS_INVALID",
           "STATUS_REBOUNDED", "STATUS_TRAPPED", "SurrogateTable", "U_PER_DRAW", "U_PER_REBOUND", "WallLawRangeWarning",
           "check_random_state", "empty_rebounds", "fill_uniforms", "grain_key", "grain_of", "load", "mix_cdf", "sample_direct",
           "sample_global", "sample_local", "seed_state"]
