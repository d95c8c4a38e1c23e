"""Grain keys from NumPy: a particle that keeps its grain from one wall hit to the next (docs/model.md §11).

Give :func:`surrogate.sample_global` or :func:`surrogate.sample_direct` one key per particle (``grain_key``, an
int64 ≥ 0 the particle keeps for life) and every hit of that particle is the same grain: its shape is drawn
from the mix by the key, not by the stream, on either path; under the direct path its proportions (b/a, c/b)
and hand are the key's too. Under the table path only the shape is the key's: the table holds each shape's law
over its random proportions. Everything else (the orientation at impact, the table's draw) stays random per
hit. :func:`grain_key` derives keys from integers (a seed, a particle's ids) the same way in Python and C
(rbs_grain_key); :func:`grain_of` says which grain a key is.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from surrogate.kernels.grain import grain_key as _grain_keys
from surrogate.kernels.grain import grain_table
from surrogate.table import SurrogateTable
from surrogate.validation import check_grain_key, check_shape


class Grains(NamedTuple):
    """The grains of keys (arrays of length n, :func:`grain_of`)."""

    shape: np.ndarray       # str (object): the table's shape name
    ratio_ba: np.ndarray    # b/a the direct path gives the grain on every hit; NaN: fixed proportions, or none
    ratio_cb: np.ndarray    # c/b, likewise
    hand: np.ndarray        # +1, or −1 for the mirror image; NaN for a shape of one hand


def grain_key(seed, *ids):
    """The grain key of (seed, ids...): splitmix64 chained over the seed and the ids, the top bit cleared
    (:func:`surrogate.kernels.grain.grain_key`; C: rbs_grain_key with two ids), an int64 in [0, 2**63).

    ``seed`` and each of ``ids`` are integers in [0, 2**64) or integer arrays of such, broadcast together
    (e.g. ``grain_key(seed, rank, np.arange(n))``). Returns an int for scalars, else an int64 array of the
    broadcast shape. ValueError naming a value that is no integer in that range.
    """
    values = [_uint64(f"ids[{k - 1}]" if k else "seed", v) for k, v in enumerate((seed,) + ids)]
    arrays = np.broadcast_arrays(*values)
    keys = _grain_keys(np.ascontiguousarray(np.stack([a.reshape(-1) for a in arrays])))
    return int(keys[0]) if arrays[0].shape == () else keys.reshape(arrays[0].shape)


def _uint64(name: str, value) -> np.ndarray:
    """``value`` as a uint64 array; ValueError unless it is integers in [0, 2**64)."""
    if isinstance(value, (bool, np.bool_)):
        raise ValueError(f"The '{name}' of grain_key must be integers in [0, 2**64); got {value!r}.")
    if isinstance(value, int):
        if not 0 <= value < 2 ** 64:
            raise ValueError(f"The '{name}' of grain_key must be integers in [0, 2**64); got {value}.")
        return np.asarray(value, dtype=np.uint64)
    array = np.asarray(value)
    if array.dtype.kind not in "iu":
        raise ValueError(f"The '{name}' of grain_key must be integers in [0, 2**64); got dtype {array.dtype}.")
    if array.dtype.kind == "i" and array.size and array.min() < 0:
        raise ValueError(f"The '{name}' of grain_key must be integers in [0, 2**64); got {array.min()}.")
    return array.astype(np.uint64)


def grain_of(table: SurrogateTable, grain_key, shape="mix") -> Grains:
    """The grain of each key of ``grain_key`` ((n,) integers ≥ 0, :func:`surrogate.validation.check_grain_key`)
    in the mix ``shape`` of ``table`` (a mix or one shape name per key, as :func:`surrogate.sample_global`'s
    ``shape``): its shape's name (a given shape name wins over the key), and the proportions b/a, c/b and the
    hand the direct path gives it on every hit (the same numbers as C's rbs_grain_info). Under the table path
    only the shape is fixed. NaN where the key draws nothing: a shape of fixed proportions (a user grain given
    as is), the hand of a shape of one hand, every property without the direct model's parameters."""
    keys = check_grain_key(grain_key, np.size(grain_key) if np.ndim(grain_key) else 1)
    cdf, shapes = check_shape(table, shape, len(keys))
    index = np.empty(len(keys), dtype=np.int64)
    properties = np.empty((len(keys), 3))
    grain_table(table.shape_arrays, table.model_shapes, cdf, shapes, keys, index, properties)
    names = np.array(table.shapes, dtype=object)[index]
    return Grains(shape=names, ratio_ba=properties[:, 0], ratio_cb=properties[:, 1], hand=properties[:, 2])
