"""From a cell's direct-model samples to its stored representation (docs/format.md).

The representation (:mod:`data_schema.table`) is a mixture of small triangular
chains. The folded states and their work on the wall (r, ν: :func:`work_variables`), each variable divided by
its standard deviation, are partitioned by mini-batch k-means into C clusters of about
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

CPU independence: every floating-point reduction here (the k-means distances
and centres, the moments, the least-squares fits) is a numba loop in a fixed
order, compiled without fastmath (no reassociation, no fused multiply-add),
and the random choices are integers and doubles from numpy's PCG64 stream; no
BLAS, LAPACK or numpy reduction whose SIMD kernel depends on the CPU, so a
seed gives the same bits on every x86-64 CPU (docs/design/build.md).

Mirror folding: the model is exactly symmetric under Z → −Z, which maps
(β2, Ω_x, Ω_y) to their negatives; every sample is mapped to its image with
β2 ≥ 0, so all n samples inform one half-space and the runtime restores the
sign with probability ½ — the variance of the stored law is that of 2n samples
of a symmetric law.
"""

from __future__ import annotations

import numba
import numpy as np

from data_schema import kernel_cache  # noqa: F401  (keys this module's kernels by their sources)
from data_schema.samples import STATUS_NAMES, STATUS_REBOUNDED, STATUS_TRAPPED, SampleSet, rebound_angles
from data_schema.table import (
    CHAIN_TO_STATE, FEW_COLLISIONS, INDICATRIX_ALPHA2_EDGES, INDICATRIX_BETA2_EDGES, N_CHAIN, N_COLLISION_CLASSES,
    N_SLOPES, N_WORK, N_WORK_SLOPES, WORK_SLOPE_START,
    CellTable, TableResolution, slope_index,
)
from tablegen.tabulation.resolution import SAMPLES_PER_CLUSTER

KMEANS_FIT_SAMPLES = 50_000   # cluster centres are fitted on at most this many samples, then all are assigned
RIDGE = 2.0                   # slope shrinkage: regressor sums of squares × (1 + RIDGE / cluster size)
MAX_STATES = 4_000_000        # rebounds kept per cell for the representation: bounds memory at 10⁸ particles
KMEANS_BATCH_SIZE = 4096      # mini-batch size of the partition
KMEANS_EPOCHS = 5             # random centres and a few epochs suffice (docs/design/build.md)
DICTIONARY_ITERATIONS = 300   # Lloyd iterations of the dictionary's k-means at most (it stops when no label moves)
PARTITION_KEY, DICTIONARY_KEY = 0, 1    # spawn keys of the partition's and the dictionary's random streams
SPREAD_TOL = 1e-9             # relative to the variable's scale: below it a cluster has no shape
WORK_FIELDS = ("wall_work_normal", "wall_work_tangential")    # the samples' W_n, W_t, m²/s²


def rebound_states(samples: SampleSet) -> np.ndarray:
    """(α2, β2, s, Ω_x, Ω_y, Ω_z) of the rebounded particles (radians, |V⁺|/|V⁻|, Ω⁺a/|V⁻|), lab frame."""
    ok = samples.rebounded
    alpha2, beta2, norm = rebound_angles(samples.velocity[ok])
    return np.column_stack([alpha2, beta2, norm / samples.speed, samples.omega[ok]])


def work_variables(samples: SampleSet) -> np.ndarray:
    """(r, ν) of the rebounded particles (data_schema.table.WORK_NAMES): r = E_Ω⁺/E⁻, the rotational energy
    fraction, and ν = √(W_n/(W_n + W_t)), the root of the normal share of the work on the wall (0 where there is
    none)."""
    ok = samples.rebounded
    work_n, work_t = (np.asarray(samples.extra[name], dtype=np.float64)[ok] for name in WORK_FIELDS)
    total = work_n + work_t
    root = np.sqrt(np.divide(work_n, total, out=np.zeros_like(total), where=total > 0.0))
    return np.column_stack([np.asarray(samples.extra["e_rot_ratio"], dtype=np.float64)[ok], root])


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
        self.works = []
        self.regimes = []
        self.n_states = 0
        self.status_counts = np.zeros(len(STATUS_NAMES), dtype=np.int64)
        self.collision_counts = np.zeros(N_COLLISION_CLASSES, dtype=np.int64)
        self.sums = np.zeros(6)
        self.squares = np.zeros(6)
        self.work_sums = np.zeros(N_WORK)
        self.work_squares = np.zeros(N_WORK)
        self.trapped_work = np.zeros(2)     # Σ W_n/E⁻, Σ W_t/E⁻ over the trapped particles
        self.hist2 = np.zeros(len(INDICATRIX_ALPHA2_EDGES) - 1)
        self.hist3 = np.zeros((len(INDICATRIX_ALPHA2_EDGES) - 1, len(INDICATRIX_BETA2_EDGES) - 1))

    def add(self, samples: SampleSet) -> None:
        ok = samples.rebounded
        self.status_counts += np.bincount(samples.status, minlength=len(STATUS_NAMES))[:len(STATUS_NAMES)]
        ncoll = np.minimum(samples.n_collisions[ok], N_COLLISION_CLASSES)
        self.collision_counts += np.bincount(ncoll - 1, minlength=N_COLLISION_CLASSES)
        state = rebound_states(samples)
        _add_moments(state, self.sums, self.squares)
        work = work_variables(samples)
        _add_moments(work, self.work_sums, self.work_squares)
        trapped = samples.status == STATUS_TRAPPED
        energy = 0.5 * samples.speed ** 2
        _add_moments(np.column_stack([np.asarray(samples.extra[name], dtype=np.float64)[trapped] / energy
                                      for name in WORK_FIELDS]), self.trapped_work, np.zeros(2))
        self.hist2 += np.histogram(state[:, 0], bins=INDICATRIX_ALPHA2_EDGES)[0]
        self.hist3 += np.histogram2d(state[:, 0], state[:, 1],
                                     bins=[INDICATRIX_ALPHA2_EDGES, INDICATRIX_BETA2_EDGES])[0]
        keep = min(self.max_states - self.n_states, int(ok.sum()))
        if keep > 0:
            self.states.append(folded_state(state[:keep]))
            self.works.append(work[:keep])
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
        mean, std = _moments(self.sums, self.squares, n)
        work_mean, work_std = _moments(self.work_sums, self.work_squares, n)
        n_trapped = int(self.status_counts[STATUS_TRAPPED])
        d_a2 = np.diff(INDICATRIX_ALPHA2_EDGES)
        d_b2 = np.diff(INDICATRIX_BETA2_EDGES)
        return CellTable(
            **represent(np.concatenate(self.states), np.concatenate(self.regimes), resolution, seed,
                        np.concatenate(self.works)),
            work_mean=work_mean, work_std=work_std,
            trapped_work=self.trapped_work / n_trapped if n_trapped else np.zeros(2),
            status_counts=self.status_counts.copy(), collision_counts=self.collision_counts.copy(),
            mean=mean, std=std,
            indicatrix_2d=(self.hist2 / (n * d_a2)).astype(np.float32),
            indicatrix_3d=(self.hist3 / (n * np.outer(d_a2, d_b2))).astype(np.float32))


def _moments(sums: np.ndarray, squares: np.ndarray, n: int) -> tuple:
    """(mean, standard deviation) from running sums of n values and of their squares."""
    mean = sums / n
    return mean, np.sqrt(np.maximum(squares / n - mean ** 2, 0.0))


def _stream(seed: int, *key: int) -> np.random.Generator:
    """The random stream of one use of a cell's representation seed (PCG64: the same numbers on every CPU)."""
    return np.random.default_rng(np.random.SeedSequence(seed, spawn_key=key))


def _partition(z: np.ndarray, n_clusters: int, rng: np.random.Generator) -> np.ndarray:
    """Cluster label of each row of z (already scaled): mini-batch k-means.

    Centres start at ``n_clusters`` distinct rows drawn from the first
    :data:`KMEANS_FIT_SAMPLES` (the samples are in random order), are moved by
    :data:`KMEANS_EPOCHS` epochs of mini-batches of those rows, each epoch a
    fresh permutation (:func:`_minibatch_epochs`), then every row goes to its
    nearest centre. Random initial centres and a few epochs suffice: the chains
    fitted inside the clusters, not the centres, carry the law.
    """
    if n_clusters == 1:
        return np.zeros(len(z), dtype=np.int64)
    n_fit = min(len(z), KMEANS_FIT_SAMPLES)
    centres = np.ascontiguousarray(z[rng.choice(n_fit, size=n_clusters, replace=False)])
    order = np.concatenate([rng.permutation(n_fit) for _ in range(KMEANS_EPOCHS)])
    _minibatch_epochs(z, centres, order, KMEANS_BATCH_SIZE)
    labels = np.empty(len(z), dtype=np.int64)
    _assign(z, centres, labels)
    return labels


@numba.njit(cache=True, nogil=True)
def _nearest(z, i, columns, dist):
    """Index of the centre nearest row i of z: the least squared distance summed in column order, the first
    on a tie. ``columns`` (d, k) holds the centres column by column, so that the distances to all k centres
    are summed a column at a time, k at once (SIMD; each centre's sum keeps its order, so its bits);
    ``dist`` (k,) is work space."""
    d, k = columns.shape
    dist[:] = 0.0
    for j in range(d):
        x = z[i, j]
        for c in range(k):
            t = x - columns[j, c]
            dist[c] += t * t
    best, best_d = 0, np.inf
    for c in range(k):
        if dist[c] < best_d:
            best, best_d = c, dist[c]
    return best


@numba.njit(cache=True, nogil=True)
def _assign(z, centres, labels):
    """labels[i] = the centre nearest row i of z."""
    columns = np.ascontiguousarray(centres.T)
    dist = np.empty(centres.shape[0])
    for i in range(z.shape[0]):
        labels[i] = _nearest(z, i, columns, dist)


@numba.njit(cache=True, nogil=True)
def _minibatch_epochs(z, centres, order, batch_size):
    """Mini-batch k-means (Sculley 2010) over the rows of z in ``order``, batches of ``batch_size``; moves
    ``centres`` in place. Each centre becomes the mean of every row assigned to it so far (per-centre
    learning rate 1/count), batch by batch; a centre no row reached keeps its place."""
    k, d = centres.shape
    count = np.zeros(k)
    batch_count = np.zeros(k)
    batch_sum = np.zeros((k, d))
    dist = np.empty(k)
    for start in range(0, len(order), batch_size):
        batch_count[:] = 0.0
        batch_sum[:] = 0.0
        columns = np.ascontiguousarray(centres.T)
        for i in order[start:start + batch_size]:
            c = _nearest(z, i, columns, dist)
            batch_count[c] += 1.0
            for j in range(d):
                batch_sum[c, j] += z[i, j]
        for c in range(k):
            if batch_count[c] > 0.0:
                total = count[c] + batch_count[c]
                for j in range(d):
                    centres[c, j] = (centres[c, j] * count[c] + batch_sum[c, j]) / total
                count[c] = total


@numba.njit(cache=True, nogil=True)
def _kmeans(x, u, max_iterations):
    """k-means (Lloyd) of the rows of x into len(u) centres, started by k-means++ with the uniforms u:
    (centres, label of each row). Stops when no label moves; an empty centre keeps its place."""
    n, d = x.shape
    k = len(u)
    centres = np.empty((k, d))
    nearest = np.full(n, np.inf)
    chosen = min(int(u[0] * n), n - 1)
    for c in range(k):
        for j in range(d):      # not centres[c] = x[chosen]: that compiles numba's shape-mismatch message
            centres[c, j] = x[chosen, j]
        total = 0.0
        for i in range(n):
            dist = 0.0
            for j in range(d):
                t = x[i, j] - centres[c, j]
                dist += t * t
            nearest[i] = min(nearest[i], dist)
            total += nearest[i]
        if c + 1 < k:        # the next centre: a row drawn with probability ∝ its squared distance
            target, cumulative, chosen = u[c + 1] * total, 0.0, n - 1
            for i in range(n):
                cumulative += nearest[i]
                if cumulative > target:
                    chosen = i
                    break
    labels = np.full(n, -1, dtype=np.int64)
    sums = np.zeros((k, d))
    counts = np.zeros(k)
    dist = np.empty(k)
    for _ in range(max_iterations):
        moved = False
        columns = np.ascontiguousarray(centres.T)
        for i in range(n):
            c = _nearest(x, i, columns, dist)
            moved |= c != labels[i]
            labels[i] = c
        if not moved:
            break
        sums[:] = 0.0
        counts[:] = 0.0
        for i in range(n):
            counts[labels[i]] += 1.0
            for j in range(d):
                sums[labels[i], j] += x[i, j]
        for c in range(k):
            if counts[c] > 0.0:
                for j in range(d):
                    centres[c, j] = sums[c, j] / counts[c]
    return centres, labels


@numba.njit(cache=True, nogil=True)
def _row_moments(x):
    """(mean, standard deviation) of each row of x, summed in column order (numpy's ddof = 0)."""
    n, d = x.shape
    mean = np.zeros(n)
    std = np.zeros(n)
    for i in range(n):
        for j in range(d):
            mean[i] += x[i, j]
        mean[i] /= d
        for j in range(d):
            t = x[i, j] - mean[i]
            std[i] += t * t
        std[i] = np.sqrt(std[i] / d)
    return mean, std


@numba.njit(cache=True, nogil=True)
def _sort_segments(x, starts, counts):
    """Sorts each segment x[starts[g]:starts[g] + counts[g]] in place."""
    for g in range(len(starts)):
        x[starts[g]:starts[g] + counts[g]].sort()


def _group_quantiles(x: np.ndarray, by_group: np.ndarray, counts: np.ndarray, levels: int) -> np.ndarray:
    """(G, levels + 1) quantile functions of x per group at p = i/levels (linear in the order statistics);
    ``by_group`` orders the rows by group (a stable argsort of the groups), ``counts`` the rows per group."""
    starts = np.concatenate([[0], np.cumsum(counts)[:-1]])
    xs = x[by_group]
    _sort_segments(xs, starts, counts)      # the groups' values in order: what sorting by (group, x) gives
    pos = np.linspace(0.0, 1.0, levels + 1)[None, :] * (counts[:, None] - 1)
    lo = np.floor(pos).astype(np.int64)
    hi = np.minimum(lo + 1, counts[:, None] - 1)
    f = pos - lo
    return xs[starts[:, None] + lo] * (1.0 - f) + xs[starts[:, None] + hi] * f


@numba.njit(cache=True, nogil=True)
def _group_slopes(A, x, group, counts):
    """(G, p) least-squares slopes of x on the p columns of A within each group (both centred per group).

    Ridge: each regressor's within-group sum of squares is multiplied by
    1 + RIDGE/count, negligible for clusters of hundreds, a shrinkage towards 0
    for clusters of a few samples. Sums in row order; each group's p × p
    system solved by Gaussian elimination with partial pivoting.
    """
    G, p, n = len(counts), A.shape[1], A.shape[0]
    mean_A = np.zeros((G, p))
    mean_x = np.zeros(G)
    for i in range(n):
        g = group[i]
        mean_x[g] += x[i]
        for j in range(p):
            mean_A[g, j] += A[i, j]
    for g in range(G):
        mean_x[g] /= counts[g]
        for j in range(p):
            mean_A[g, j] /= counts[g]
    S = np.zeros((G, p, p))
    r = np.zeros((G, p))
    for i in range(n):
        g = group[i]
        xc = x[i] - mean_x[g]
        for j in range(p):
            aj = A[i, j] - mean_A[g, j]
            r[g, j] += aj * xc
            for l in range(j, p):
                S[g, j, l] += aj * (A[i, l] - mean_A[g, l])
    slopes = np.empty((G, p))
    for g in range(G):
        for j in range(p):
            S[g, j, j] += RIDGE * max(S[g, j, j], 1e-300) / counts[g]
            for l in range(j + 1, p):
                S[g, l, j] = S[g, j, l]
        slopes[g] = _solve(S[g], r[g])
    return slopes


@numba.njit(cache=True, nogil=True)
def _solve(S, r):
    """x with S x = r (S p × p, overwritten with r), Gaussian elimination with partial pivoting."""
    p = len(r)
    for col in range(p):
        pivot = col
        for row in range(col + 1, p):
            if abs(S[row, col]) > abs(S[pivot, col]):
                pivot = row
        for j in range(p):
            S[col, j], S[pivot, j] = S[pivot, j], S[col, j]
        r[col], r[pivot] = r[pivot], r[col]
        for row in range(col + 1, p):
            f = S[row, col] / S[col, col]
            for j in range(col, p):
                S[row, j] -= f * S[col, j]
            r[row] -= f * r[col]
    x = np.empty(p)
    for row in range(p - 1, -1, -1):
        t = r[row]
        for j in range(row + 1, p):
            t -= S[row, j] * x[j]
        x[row] = t / S[row, row]
    return x


@numba.njit(cache=True, nogil=True)
def _residual(x, A, b, group):
    """x minus each row's fitted part Σ_j A[i, j] b[group[i], j] (summed in column order)."""
    out = np.empty(len(x))
    for i in range(len(x)):
        t = 0.0
        for j in range(A.shape[1]):
            t += A[i, j] * b[group[i], j]
        out[i] = x[i] - t
    return out


@numba.njit(cache=True, nogil=True)
def _column_moments(z):
    """(mean, standard deviation) of each column of z, summed in row order (numpy's ddof = 0)."""
    n, d = z.shape
    mean = np.zeros(d)
    std = np.zeros(d)
    for i in range(n):
        for j in range(d):
            mean[j] += z[i, j]
    mean /= n
    for i in range(n):
        for j in range(d):
            t = z[i, j] - mean[j]
            std[j] += t * t
    return mean, np.sqrt(std / n)


def _dictionary(shapes: np.ndarray, size: int, rng: np.random.Generator):
    """Compress standardised quantile functions (G, L+1) into ``size`` shapes: (dictionary, index per row).

    Dictionary shapes are k-means centres (:func:`_kmeans`), re-standardised
    and made non-decreasing (a quantile function); unused rows repeat the first.
    """
    if len(shapes) == 0:                               # no cluster with a spread: any standard shape will do
        ramp = np.linspace(-1.0, 1.0, shapes.shape[1])[None]
        return np.repeat(ramp / _row_moments(ramp)[1][0], size, axis=0), np.zeros(0, dtype=np.int64)
    m = min(size, len(shapes))
    centres, labels = _kmeans(np.ascontiguousarray(shapes), rng.random(m), DICTIONARY_ITERATIONS)
    mean, std = _row_moments(centres)
    centres = (centres - mean[:, None]) / np.maximum(std, 1e-300)[:, None]
    centres = np.maximum.accumulate(centres, axis=1)
    dictionary = np.repeat(centres[:1], size, axis=0)
    dictionary[:m] = centres
    return dictionary, labels


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
        label = _partition(np.ascontiguousarray(z[rows]), c, _stream(seed, PARTITION_KEY, reg))
        used = np.bincount(label, minlength=c) > 0          # k-means may leave a centre without samples
        group[rows] = len(label_regime) + (np.cumsum(used) - 1)[label]
        label_regime += [reg] * int(used.sum())
    return group, np.array(label_regime, dtype=np.uint8)


def represent(folded: np.ndarray, regime: np.ndarray, resolution: TableResolution, seed: int,
              work: np.ndarray) -> dict:
    """The stored law (``cluster_*``, ``shape_dictionary`` and ``work_*`` arrays but the work's moments) of folded
    states (n, 6) and their work variables (n, N_WORK: r, ν, :func:`work_variables`).

    ``regime`` (n,) is each state's collision regime (:func:`collision_regime`).
    Uses at most min(C, n // 25) clusters (at least one per regime present), partitioned on the states and
    their work variables together: the work has edges the state does not show (one collision against two),
    which a partition on the state alone blurs (docs/design/table_representation.md, "The work on the wall").
    The work variables continue each cluster's chain after the state's. The remaining rows of the C-row arrays
    have weight 0 and are never drawn.
    The arrays depend on the seed alone: not on the thread count or the CPU (module doc).
    """
    r = resolution
    z = np.ascontiguousarray(np.column_stack([folded[:, list(CHAIN_TO_STATE)], work]), dtype=np.float64)
    n = len(z)
    mean, scale = _column_moments(z)
    group, label_regime = _regime_partition((z - mean) / np.where(scale > 0, scale, 1.0),
                                            np.asarray(regime, dtype=np.int64), r.clusters, seed)
    G = len(label_regime)
    counts = np.bincount(group, minlength=G)
    weight = np.zeros(r.clusters)
    weight[:G] = counts / n
    cluster_regime = np.zeros(r.clusters, dtype=np.uint8)
    cluster_regime[:G] = label_regime
    n_all = N_CHAIN + N_WORK
    loc = np.zeros((r.clusters, n_all))
    scl = np.zeros((r.clusters, n_all))
    shape_id = np.zeros((r.clusters, n_all), dtype=np.uint8)
    slope = np.zeros((r.clusters, N_SLOPES + N_WORK_SLOPES))
    dictionary = np.empty((n_all, r.dictionary_size, r.levels + 1))
    starts = [slope_index(k, 0) for k in range(N_CHAIN)] + [N_SLOPES + w for w in WORK_SLOPE_START]
    by_group = np.argsort(group, kind="stable")
    for k in range(n_all):
        residual = z[:, k]
        if k:
            A = np.ascontiguousarray(z[:, :k])
            b = _group_slopes(A, residual, group, counts.astype(np.float64))
            slope[:G, starts[k]:starts[k] + k] = b
            residual = _residual(residual, A, b, group)
        q = _group_quantiles(residual, by_group, counts, r.levels)
        loc[:G, k], scl[:G, k] = _row_moments(q)
        # a cluster of one value (a few samples) has no shape: scale 0 and shape 0
        spread = scl[:G, k] > SPREAD_TOL * max(scale[k], 1e-300)
        scl[:G, k][~spread] = 0.0
        standard = (q[spread] - loc[:G, k, None][spread]) / scl[:G, k, None][spread]
        dictionary[k], shape_id[:G, k][spread] = _dictionary(standard, r.dictionary_size,
                                                             _stream(seed, DICTIONARY_KEY, k))
    chain, rest = slice(0, N_CHAIN), slice(N_CHAIN, n_all)
    return {"cluster_weight": weight, "cluster_loc": loc[:, chain].astype(np.float32),
            "cluster_scale": scl[:, chain].astype(np.float32), "cluster_shape": shape_id[:, chain],
            "cluster_slope": slope[:, :N_SLOPES].astype(np.float32), "cluster_regime": cluster_regime,
            "shape_dictionary": dictionary[chain].astype(np.float32),
            "work_loc": loc[:, rest].astype(np.float32), "work_scale": scl[:, rest].astype(np.float32),
            "work_shape": shape_id[:, rest], "work_slope": slope[:, N_SLOPES:].astype(np.float32),
            "work_dictionary": dictionary[rest].astype(np.float32)}
