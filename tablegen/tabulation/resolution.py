"""The default resolution of a table for a number of particles per cell (no scikit-learn needed)."""

from __future__ import annotations

from data_schema.table import TableResolution

SAMPLES_PER_CLUSTER = 25      # target cluster size; smaller clusters fit better down to ~25 (docs/design/build.md)
MIN_CLUSTERS = 16             # a cell's law needs a few clusters even from few particles
MAX_CLUSTERS = 500            # memory budget: 35·C + 6·M·(L + 1) numbers per cell
DICTIONARY_SIZE = 16          # standard quantile shapes per chain variable
LEVELS = 24                   # quantile function stored at LEVELS + 1 probability levels
MIN_PARTICLES_PER_CELL = 256  # fewer leave too few rebounds for one cluster per collision regime


def resolution_for(particles_per_cell: int) -> TableResolution:
    """The default resolution: C = clip(particles_per_cell // 25, 16, 500) clusters, M = 16, L = 24.

    Cells with fewer rebounds than particles use fewer clusters
    (:func:`tablegen.tabulation.tabulate.represent`).
    """
    if particles_per_cell < MIN_PARTICLES_PER_CELL:
        raise ValueError(f"The 'particles_per_cell' parameter must be >= {MIN_PARTICLES_PER_CELL} to build a "
                         f"table; got {particles_per_cell!r}.")
    clusters = min(max(particles_per_cell // SAMPLES_PER_CLUSTER, MIN_CLUSTERS), MAX_CLUSTERS)
    return TableResolution(clusters=clusters, dictionary_size=DICTIONARY_SIZE, levels=LEVELS)
