"""From a cell's direct-model samples to its stored representation (docs/format.md).

The representation (:mod:`data_schema.table`) is a mixture of small triangular
chains. The folded states, each variable divided by its standard deviation,
are partitioned by mini-batch k-means into C clusters of about
:data:`SAMPLES_PER_CLUSTER` samples. Inside a cluster each chain variable is
regressed (least squares) on the variables before it, and the residual's
quantile function is stored at L + 1 probability levels, standardised to
(location, scale, shape); the C shapes of each variable are compressed into a
dictionary of M shapes by k-means. Rebounds of at most two collisions and
rebounds of more are clustered apart (``cluster_regime``), with clusters
shared in proportion to their numbers: the sampler moves the two regimes
between grid speeds by different laws. Every stored quantity is estimated from all
the cell's samples (each sample is in one cluster), which is what lets the
table reproduce the joint law: a law built from a subsample carries that
subsample's noise, which a classifier detects (docs/design/table_representation.md).

Mirror folding: the model is exactly symmetric under Z → −Z, which maps
(β2, Ω_x, Ω_y) to their negatives; every sample is mapped to its image with
β2 ≥ 0, so all n samples inform one half-space and the runtime restores the
sign with probability ½ — the variance of the stored law is that of 2n samples
of a symmetric law.
"""

from __future__ import annotations

import numba
import numpy as np
from sklearn.cluster import KMeans, MiniBatchKMeans
from threadpoolctl import threadpool_limits

from data_schema.samples import STATUS_NAMES, STATUS_REBOUNDED, SampleSet, rebound_angles
from data_schema.table import (
    CHAIN_TO_STATE, FEW_COLLISIONS, INDICATRIX_ALPHA2_EDGES, INDICATRIX_BETA2_EDGES, N_CHAIN, N_COLLISION_CLASSES,
    N_SLOPES,
    CellTable, TableResolution, slope_index,
)
from tablegen.tabulation.resolution import SAMPLES_PER_CLUSTER

KMEANS_FIT_SAMPLES = 50_000   # cluster centres are fitted on at most this many samples, then all are assigned
RIDGE = 2.0                   # slope shrinkage: regressor sums of squares × (1 + RIDGE / cluster size)
MAX_STATES = 4_000_000        # rebounds kept per cell for the representation: bounds memory at 10⁸ particles
KMEANS_BATCH_SIZE = 4096      # mini-batch size of the partition
KMEANS_EPOCHS = 5             # random centres and a few epochs suffice (docs/design/build.md)
SPREAD_TOL = 1e-9             # relative to the variable's scale: below it a cluster has no shape


def rebound_states(samples: SampleSet) -> np.ndarray:
    """(α2, β2, s, Ω_x, Ω_y, Ω_z) of the rebounded particles (radians, |V⁺|/|V⁻|, Ω⁺a/|V⁻|), lab frame."""
    ok = samples.rebounded
    alpha2, beta2, norm = rebound_angles(samples.velocity[ok])
    return np.column_stack([alpha2, beta2, norm / samples.speed, samples.omega[ok]])


def folded_state(state: np.ndarray) -> np.ndarray:
    """:func:`rebound_states` with β2 → |β2| and Ω_x, Ω_y times sign β2."""
    sign = np.where(state[:, 1] < 0.0, -1.0, 1.0)
    return np.column_stack([state[:, 0], np.abs(state[:, 1]), state[:, 2], state[:, 3] * sign, state[:, 4] * sign,
                            state[:, 5]])


@numba.njit(cache=True, nogil=True)
def _add_moments(state, sums, squares):
    """Running sums of each column and of its squares, row by row (an order no SIMD kernel choice changes)."""
    for i in range(state.shape[0]):
        for k in range(state.shape[1]):
            sums[k] += state[i, k]
            squares[k] += state[i, k] * state[i, k]


def collision_regime(samples: SampleSet) -> np.ndarray:
    """Collision regime of the rebounded particles: 0 for at most FEW_COLLISIONS collisions, 1 for more."""
    return (samples.n_collisions[samples.rebounded] > FEW_COLLISIONS).astype(np.uint8)


class CellAccumulator:
    """Accumulates one cell's samples chunk by chunk, then builds its :class:`CellTable`.

    Statistics (status and collision counts, means, standard deviations,
    indicatrices) cover every particle added. The representation is estimated
    from the first ``max_states`` rebounds, which bounds memory for very large
    cells (10⁸ particles) while keeping far more samples than its resolution uses.
    """

    def __init__(self, max_states: int = MAX_STATES):
        self.max_states = max_states
        self.states = []
        self.regimes = []
        self.n_states = 0
        self.status_counts = np.zeros(len(STATUS_NAMES), dtype=np.int64)
        self.collision_counts = np.zeros(N_COLLISION_CLASSES, dtype=np.int64)
        self.sums = np.zeros(6)
        self.squares = np.zeros(6)
        self.hist2 = np.zeros(len(INDICATRIX_ALPHA2_EDGES) - 1)
        self.hist3 = np.zeros((len(INDICATRIX_ALPHA2_EDGES) - 1, len(INDICATRIX_BETA2_EDGES) - 1))

    def add(self, samples: SampleSet) -> None:
        ok = samples.rebounded
        self.status_counts += np.bincount(samples.status, minlength=len(STATUS_NAMES))[:len(STATUS_NAMES)]
        ncoll = np.minimum(samples.n_collisions[ok], N_COLLISION_CLASSES)
        self.collision_counts += np.bincount(ncoll - 1, minlength=N_COLLISION_CLASSES)
        state = rebound_states(samples)
        _add_moments(state, self.sums, self.squares)
        self.hist2 += np.histogram(state[:, 0], bins=INDICATRIX_ALPHA2_EDGES)[0]
        self.hist3 += np.histogram2d(state[:, 0], state[:, 1],
                                     bins=[INDICATRIX_ALPHA2_EDGES, INDICATRIX_BETA2_EDGES])[0]
        keep = min(self.max_states - self.n_states, int(ok.sum()))
        if keep > 0:
            self.states.append(folded_state(state[:keep]))
            self.regimes.append(collision_regime(samples)[:keep])
            self.n_states += keep

    def finish(self, resolution: TableResolution, seed: int, label: str = "cell") -> CellTable:
        """The cell's representation and statistics.

        ``seed`` seeds the k-means partition (so the table is reproducible);
        ``label`` names the cell in errors.
        """
        n = int(self.status_counts[STATUS_REBOUNDED])
        if self.n_states < SAMPLES_PER_CLUSTER:
            raise ValueError(f"{label}: only {self.n_states} rebounds; a table cell needs at least "
                             f"{SAMPLES_PER_CLUSTER}")
        mean = self.sums / n
        std = np.sqrt(np.maximum(self.squares / n - mean ** 2, 0.0))
        d_a2 = np.diff(INDICATRIX_ALPHA2_EDGES)
        d_b2 = np.diff(INDICATRIX_BETA2_EDGES)
        return CellTable(
            **represent(np.concatenate(self.states), np.concatenate(self.regimes), resolution, seed),
            status_counts=self.status_counts.copy(), collision_counts=self.collision_counts.copy(),
            mean=mean, std=std,
            indicatrix_2d=(self.hist2 / (n * d_a2)).astype(np.float32),
            indicatrix_3d=(self.hist3 / (n * np.outer(d_a2, d_b2))).astype(np.float32))


def _partition(z: np.ndarray, n_clusters: int, seed: int) -> np.ndarray:
    """Cluster label of each row of z (already scaled): mini-batch k-means.

    Centres are fitted on the first :data:`KMEANS_FIT_SAMPLES` rows (the
    samples are in random order), then every row goes to its nearest centre.
    Random initial centres and a few epochs suffice: the chains fitted inside
    the clusters, not the centres, carry the law.
    """
    if n_clusters == 1:
        return np.zeros(len(z), dtype=np.int64)
    km = MiniBatchKMeans(n_clusters, init="random", n_init=1, batch_size=KMEANS_BATCH_SIZE, max_iter=KMEANS_EPOCHS,
                         max_no_improvement=2, random_state=seed).fit(z[:KMEANS_FIT_SAMPLES])
    return km.predict(z).astype(np.int64)


def _group_quantiles(x: np.ndarray, group: np.ndarray, counts: np.ndarray, levels: int) -> np.ndarray:
    """(G, levels + 1) quantile functions of x per group at p = i/levels (linear in the order statistics)."""
    order = np.lexsort((x, group))
    starts = np.concatenate([[0], np.cumsum(counts)[:-1]])
    pos = np.linspace(0.0, 1.0, levels + 1)[None, :] * (counts[:, None] - 1)
    lo = np.floor(pos).astype(np.int64)
    hi = np.minimum(lo + 1, counts[:, None] - 1)
    f = pos - lo
    xs = x[order]
    return xs[starts[:, None] + lo] * (1.0 - f) + xs[starts[:, None] + hi] * f


def _group_slopes(A: np.ndarray, x: np.ndarray, group: np.ndarray, counts: np.ndarray) -> np.ndarray:
    """(G, p) least-squares slopes of x on the p columns of A within each group (both centred per group).

    Ridge: each regressor's within-group sum of squares is multiplied by
    1 + RIDGE/count, negligible for clusters of hundreds, a shrinkage towards 0
    for clusters of a few samples.
    """
    G, p = len(counts), A.shape[1]
    mean_A = np.stack([np.bincount(group, A[:, i], G) for i in range(p)], axis=1) / counts[:, None]
    Ac = A - mean_A[group]
    xc = x - (np.bincount(group, x, G) / counts)[group]
    S = np.empty((G, p, p))
    r = np.empty((G, p))
    for i in range(p):
        r[:, i] = np.bincount(group, Ac[:, i] * xc, G)
        for j in range(i, p):
            S[:, i, j] = S[:, j, i] = np.bincount(group, Ac[:, i] * Ac[:, j], G)
    diag = np.maximum(np.einsum("gii->gi", S), 1e-300)
    S += (RIDGE * diag / counts[:, None])[:, :, None] * np.eye(p)
    return np.linalg.solve(S, r[..., None])[..., 0]


def _dictionary(shapes: np.ndarray, size: int, seed: int):
    """Compress standardised quantile functions (G, L+1) into ``size`` shapes: (dictionary, index per row).

    Dictionary shapes are k-means centres, re-standardised and made
    non-decreasing (a quantile function); unused rows repeat the first.
    """
    if len(shapes) == 0:                               # no cluster with a spread: any standard shape will do
        ramp = np.linspace(-1.0, 1.0, shapes.shape[1])
        return np.repeat((ramp / ramp.std())[None], size, axis=0), np.zeros(0, dtype=np.int64)
    m = min(size, len(shapes))
    km = KMeans(m, n_init=1, random_state=seed).fit(shapes)
    centres = km.cluster_centers_
    centres = (centres - centres.mean(axis=1, keepdims=True)) / np.maximum(centres.std(axis=1, keepdims=True),
                                                                            1e-300)
    centres = np.maximum.accumulate(centres, axis=1)
    dictionary = np.repeat(centres[:1], size, axis=0)
    dictionary[:m] = centres
    return dictionary, km.labels_


def regime_clusters(counts, clusters: int) -> list:
    """Clusters given to each collision regime of ``counts`` rebounds (total ≤ ``clusters``).

    In proportion to the counts, at least one for a regime that has rebounds,
    and at most one per :data:`SAMPLES_PER_CLUSTER` rebounds of the regime.
    """
    counts = np.asarray(counts, dtype=np.int64)
    share = np.where(counts > 0, np.maximum(np.floor(clusters * counts / counts.sum()), 1), 0).astype(np.int64)
    share[np.argmax(counts)] += clusters - share.sum()      # the largest regime takes the rounding remainder
    return [int(c) if n == 0 else int(max(1, min(c, n // SAMPLES_PER_CLUSTER))) for c, n in zip(share, counts)]


def _regime_partition(z: np.ndarray, regime: np.ndarray, clusters: int, seed: int) -> tuple:
    """Cluster label of each row of z, clustering each collision regime apart: (labels, regime of each label).

    Labels of empty k-means centres are dropped, so labels run over 0..G−1.
    """
    counts = np.bincount(regime, minlength=2)
    group = np.empty(len(z), dtype=np.int64)
    label_regime = []
    for reg, c in enumerate(regime_clusters(counts, clusters)):
        rows = np.flatnonzero(regime == reg)
        if rows.size == 0:
            continue
        label = _partition(z[rows], c, seed + reg)
        used = np.bincount(label, minlength=c) > 0          # k-means may leave a centre without samples
        group[rows] = len(label_regime) + (np.cumsum(used) - 1)[label]
        label_regime += [reg] * int(used.sum())
    return group, np.array(label_regime, dtype=np.uint8)


def represent(folded: np.ndarray, regime: np.ndarray, resolution: TableResolution, seed: int) -> dict:
    """The stored law (``cluster_*`` and ``shape_dictionary`` arrays) of folded states (n, 6).

    ``regime`` (n,) is each state's collision regime (:func:`collision_regime`).
    Uses at most min(C, n // 25) clusters (at least one per regime present);
    the remaining rows of the C-row arrays have weight 0 and are never drawn.
    Single-threaded BLAS and OpenMP (threadpool_limits), so the arrays do not
    depend on the thread count.
    """
    r = resolution
    seed = seed % 2 ** 31                              # scikit-learn takes 32-bit seeds (seed + 5 still fits)
    z = folded[:, list(CHAIN_TO_STATE)].astype(np.float64)
    n = len(z)
    with threadpool_limits(1):
        scale = z.std(axis=0)
        group, label_regime = _regime_partition((z - z.mean(axis=0)) / np.where(scale > 0, scale, 1.0),
                                                np.asarray(regime, dtype=np.int64), r.clusters, seed)
        G = len(label_regime)
        counts = np.bincount(group, minlength=G)
        weight = np.zeros(r.clusters)
        weight[:G] = counts / n
        cluster_regime = np.zeros(r.clusters, dtype=np.uint8)
        cluster_regime[:G] = label_regime
        loc = np.zeros((r.clusters, N_CHAIN))
        scl = np.zeros((r.clusters, N_CHAIN))
        shape_id = np.zeros((r.clusters, N_CHAIN), dtype=np.uint8)
        slope = np.zeros((r.clusters, N_SLOPES))
        dictionary = np.empty((N_CHAIN, r.dictionary_size, r.levels + 1))
        for k in range(N_CHAIN):
            residual = z[:, k]
            if k:
                b = _group_slopes(z[:, :k], residual, group, counts)
                slope[:G, slope_index(k, 0):slope_index(k, 0) + k] = b
                residual = residual - np.einsum("ij,ij->i", z[:, :k], b[group])
            q = _group_quantiles(residual, group, counts, r.levels)
            loc[:G, k] = q.mean(axis=1)
            scl[:G, k] = q.std(axis=1)
            # a cluster of one value (a few samples) has no shape: scale 0 and shape 0
            spread = scl[:G, k] > SPREAD_TOL * max(scale[k], 1e-300)
            scl[:G, k][~spread] = 0.0
            standard = (q[spread] - loc[:G, k, None][spread]) / scl[:G, k, None][spread]
            dictionary[k], shape_id[:G, k][spread] = _dictionary(standard, r.dictionary_size, seed + k)
    return {"cluster_weight": weight, "cluster_loc": loc.astype(np.float32), "cluster_scale": scl.astype(np.float32),
            "cluster_shape": shape_id, "cluster_slope": slope.astype(np.float32), "cluster_regime": cluster_regime,
            "shape_dictionary": dictionary.astype(np.float32)}
