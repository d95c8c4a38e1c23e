"""The sampler's numba kernels: O(1) work per reflected state, callable from a solver's ``@njit`` code.

Plain functions over the arrays of a table (``table.kernel_data``) and
uniforms: :data:`U_PER_DRAW` per draw, given or drawn from a caller-owned
xoshiro256+ state. Where each part lives:

===============  ==============================================================
``layout``       the table as the kernels take it (:class:`KernelData`), its record layouts
``draw``         the law of one draw in the local frame, its three stages composed: :func:`draw_velocity`
``locate``       stage 1: where a draw reads (:func:`locate`: the cell; the component; cache hints)
``gather``       stage 2: the table values a draw needs (:func:`gather`)
``arithmetic``   stage 3: the reflected state from those values (:func:`arithmetic`)
``frame``        the impact frame of a hit and the way back to the global frame
``table_path``   the table path, one particle: :func:`table_rebound` (global frame), :func:`draw_local` (local frame)
``direct_path``  the direct path, the direct model instead of the table: :func:`direct_rebound` (one particle),
                 :func:`direct_rebound_parallel_rng` (many, all threads)
``wall_hit``     every hit answered, spinning or not (the call a solver reaches first): :func:`rebound` (one
                 particle), :func:`rebound_parallel_rng` (many, all threads), :func:`rebound_path` (which path
                 answers a hit: the table where it is valid, the direct model elsewhere); METHOD_*,
                 SPIN_TOLERANCE
``hit``          what a hit did, as a record (the twin of C's rbs_result): ``Hit`` (one), ``Rebounds``
                 (many; both exported by :mod:`surrogate`); PATH_*
``grain``        grain keys: a particle's shape, proportions and hand from its key (:func:`keyed_uniforms`,
                 :func:`grain_properties`, :func:`grain_key`); NO_KEY
``block``        the block form of the stages' records, field-major over BLOCK particles
``pipeline``     many particles on one thread, the stages' block forms scheduled: :func:`table_rebound_many`,
                 :func:`table_rebound_many_rng`
``parallel``     many particles on all threads, by chunks: :func:`table_rebound_parallel`,
                 :func:`draw_local_parallel`
``rng``          xoshiro256+ streams: :func:`seed_state`, :func:`fill_uniforms`, the SIMD lanes
``fastmath``     fused multiply-add, trigonometry, the restitution factor: no libm call on the hot path
``memory``       loads and cache hints
``checks``       input checks: the NumPy API's in one parallel pass, the array shapes of the many-particle kernels
``options``      the numba options every kernel is compiled with
===============  ==============================================================

Global-frame kernels take V⁻ in m/s and return V⁺ in m/s and Ω⁺ in rad/s;
local-frame ones use the model's lab frame (wall y = 0, normal +Y, impact
plane XY, α1 in degrees from the wall), V⁺ in units of |V⁻| and Ω⁺ in units
of |V⁻|/a. One particle, the pipeline and the parallel kernels give the same
bits for the same uniforms.
"""

from data_schema.samples import STATUS_INVALID
from direct_model.runtime import U_PER_REBOUND
from surrogate.kernels.arithmetic import arithmetic
from surrogate.kernels.block import BLOCK
from surrogate.kernels.direct_path import direct_rebound, direct_rebound_parallel_rng
from surrogate.kernels.draw import U_PER_DRAW, draw_velocity
from surrogate.kernels.frame import impact_frame
from surrogate.kernels.gather import gather
from surrogate.kernels.layout import KernelData
from surrogate.kernels.locate import grid_interval, locate
from surrogate.kernels.parallel import (draw_local_parallel, draw_local_parallel_rng, table_rebound_parallel,
                                        table_rebound_parallel_rng)
from surrogate.kernels.pipeline import table_rebound_many, table_rebound_many_rng, table_rebound_uniforms
from surrogate.kernels.rng import CHUNK_ROWS, chunk_states, fill_uniforms, next_uniform, seed_state
from surrogate.kernels.table_path import draw_local, table_rebound
from surrogate.kernels.hit import PATH_DIRECT, PATH_NONE, PATH_TABLE
from surrogate.kernels.wall_hit import (MAX_WALL_HITS, METHOD_AUTO, METHOD_DIRECT, METHOD_TABLE, SPIN_TOLERANCE,
                                        rebound, rebound_parallel_rng, rebound_path)

__all__ = ["BLOCK", "CHUNK_ROWS", "KernelData", "MAX_WALL_HITS", "METHOD_AUTO", "METHOD_DIRECT", "METHOD_TABLE", "PATH_DIRECT",
           "PATH_NONE", "PATH_TABLE", "SPIN_TOLERANCE", "STATUS_INVALID", "U_PER_DRAW", "U_PER_REBOUND",
           "arithmetic", "chunk_states", "direct_rebound", "direct_rebound_parallel_rng", "draw_local",
           "draw_local_parallel", "draw_local_parallel_rng", "draw_velocity", "fill_uniforms", "gather",
           "grid_interval", "impact_frame", "locate", "next_uniform", "rebound", "rebound_parallel_rng",
           "rebound_path", "seed_state", "table_rebound", "table_rebound_many", "table_rebound_many_rng",
           "table_rebound_parallel", "table_rebound_parallel_rng", "table_rebound_uniforms"]
