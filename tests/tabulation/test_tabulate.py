"""The stored representation of a cell (tablegen.tabulation.tabulate.represent) on laws with known answers."""

import numpy as np
import pytest
from scipy import stats

from data_schema.table import CHAIN_TO_STATE, N_CHAIN, N_SLOPES, N_WORK, WORK_SLOPE_START, TableResolution, slope_index
from tablegen.tabulation.resolution import resolution_for
from tablegen.tabulation.tabulate import _regime_partition, regime_clusters, represent

N = 40_000


def _folded(chain: np.ndarray) -> np.ndarray:
    """Folded-state columns (α2, |β2|, s, Ω_x, Ω_y, Ω_z) from chain-order columns (the work's left out)."""
    folded = np.empty((len(chain), N_CHAIN))
    folded[:, list(CHAIN_TO_STATE)] = chain[:, :N_CHAIN]
    return folded


def _work(chain: np.ndarray) -> np.ndarray:
    """The work variables' columns of a chain (those after the state's)."""
    return chain[:, N_CHAIN:]


def _one_regime(x):
    return np.zeros(len(x), dtype=np.uint8)


def _linear_chain(n, seed):
    """x0 uniform on [1, 2]; x_k = 0.5 x_{k−1} + 0.1 ε_k, ε_k standard normal (k ≥ 1): the six state
    variables, then the two work variables."""
    rng = np.random.default_rng(seed)
    x = np.empty((n, N_CHAIN + N_WORK))
    x[:, 0] = 1.0 + rng.random(n)
    for k in range(1, N_CHAIN + N_WORK):
        x[:, k] = 0.5 * x[:, k - 1] + 0.1 * rng.standard_normal(n)
    return x


def test_one_cluster_recovers_the_slopes_and_residual_shapes():
    """With a single component the chain is ordinary least squares plus residual quantiles, the work variables'
    (which continue it) as the state's.

    Slopes are fitted jointly on x_0..x_{k−1}, so the standard error of the
    slope on x_j is σ_ε/(sd(x_j | other regressors) √N). Given its neighbours
    in the chain, x_j has variance 0.01/(1 + 0.25) (sd 0.089), so SE ≤
    0.1/(0.089 · 200) = 0.0056; allow 5 SE. Slopes on all but x_{k−1} are 0 in the law. The standardised
    residual quantile function must be the normal one at interior levels
    (sample quantiles at p ∈ [1/24, 23/24] have SE ≤ 0.013 in σ units at N = 4·10⁴).
    """
    x = _linear_chain(N, seed=1)
    cell = represent(_folded(x), _one_regime(x), TableResolution(clusters=1, dictionary_size=1, levels=24),
                     seed=0, work=_work(x))
    slope = np.concatenate([cell["cluster_slope"][0], cell["work_slope"][0]])
    starts = [slope_index(k, 0) for k in range(N_CHAIN)] + [N_SLOPES + w for w in WORK_SLOPE_START]
    for k in range(1, N_CHAIN + N_WORK):
        for j in range(k):
            expected = 0.5 if j == k - 1 else 0.0
            assert abs(slope[starts[k] + j] - expected) < 5 * 0.0056, (k, j)
    assert cell["cluster_weight"][0] == 1.0
    p = np.arange(1, 24) / 24
    # variable 0 is uniform: its standardised quantile function is linear in p
    uniform = (p - 0.5) / np.sqrt(np.mean((np.arange(25) / 24 - 0.5) ** 2))
    np.testing.assert_allclose(cell["shape_dictionary"][0, 0, 1:-1], uniform, atol=0.02)
    # residuals of the later variables are N(c, 0.1²): their interior knots lie on a line in
    # the normal quantiles z_p with slope σ_ε = 0.1 (a sample quantile's SE is at most
    # √(p(1−p)/N)/φ(z_p) · σ = 0.001 here; allow 3 % on σ and 0.005 off the line)
    z = stats.norm.ppf(p)
    loc, scale = (np.concatenate([cell["cluster_" + name][0], cell["work_" + name][0]]) for name in ("loc", "scale"))
    dictionary = np.concatenate([cell["shape_dictionary"], cell["work_dictionary"]])
    for k in range(1, N_CHAIN + N_WORK):
        knots = loc[k] + scale[k] * dictionary[k, 0, 1:-1]
        sigma, intercept = np.polyfit(z, knots, 1)
        assert abs(sigma - 0.1) < 0.003, k
        assert np.max(np.abs(knots - (intercept + sigma * z))) < 0.005, k


def test_clusters_follow_the_number_of_samples():
    """min(C, n // 25) components are used, weighted by their sample counts; the rest have weight 0."""
    x = _linear_chain(2_000, seed=2)
    cell = represent(_folded(x), _one_regime(x), TableResolution(clusters=500, dictionary_size=16, levels=24),
                     seed=0, work=_work(x))
    w = cell["cluster_weight"]
    used = np.count_nonzero(w)
    assert 0.8 * 80 <= used <= 80 and np.all(w[used:] == 0)
    np.testing.assert_allclose(w.sum(), 1.0, rtol=1e-12)
    np.testing.assert_allclose(w * 2_000, np.round(w * 2_000), atol=1e-9)   # counts over n


def test_same_seed_same_arrays_and_the_seed_matters():
    chain = _linear_chain(5_000, seed=3)
    x = _folded(chain)
    r = resolution_for(5_000)
    regime = (x[:, 0] > 1.5).astype(np.uint8)
    a, b, c = (represent(x, regime, r, seed, _work(chain)) for seed in (5, 5, 6))
    for name in a:
        assert a[name].tobytes() == b[name].tobytes(), name
    assert any(a[name].tobytes() != c[name].tobytes() for name in a)


def test_each_collision_regime_gets_its_own_clusters():
    """Clusters never mix regimes: each regime's cluster weights add up to its share of the samples.

    Regime 1 is x0 > 1.7 (30 % of a uniform x0 on [1, 2]); the 200 clusters are
    shared 140/60 (in proportion), each regime's weights are its counts over n.
    """
    x = _linear_chain(10_000, seed=4)
    regime = (x[:, 0] > 1.7).astype(np.uint8)
    cell = represent(_folded(x), regime, TableResolution(clusters=200, dictionary_size=16, levels=24), seed=0,
                     work=_work(x))
    w, reg = cell["cluster_weight"], cell["cluster_regime"]
    for r in (0, 1):
        assert w[(reg == r) & (w > 0)].sum() == pytest.approx(np.mean(regime == r), rel=1e-12)
    share = [np.count_nonzero((reg == r) & (w > 0)) for r in (0, 1)]
    n1 = int(regime.sum())
    assert 0.8 * 140 <= share[0] <= 140 and 0.8 * 60 <= share[1] <= 60, (share, n1)
    # the partition itself: every state's cluster is of the state's regime
    group, label_regime = _regime_partition(_folded(x), regime.astype(np.int64), 200, seed=0)
    assert np.array_equal(label_regime[group], regime)
    assert np.array_equal(np.unique(group), np.arange(len(label_regime)))


def test_clusters_of_one_value_get_scale_zero_and_leave_the_dictionary_standard():
    """A regime of 3 identical states forms a cluster without spread: scale 0, and the dictionary stays
    made of standardised quantile functions (mean 0, sd 1); a variable constant in the whole cell gets
    scale 0 everywhere and a standard dictionary too."""
    x = _linear_chain(2_000, seed=5)
    x[:, 5] = 0.25                                          # constant in the whole cell
    x[:3] = x[0]                                            # three identical states ...
    regime = np.zeros(len(x), dtype=np.uint8)
    regime[:3] = 1                                          # ... alone in regime 1
    cell = represent(_folded(x), regime, TableResolution(clusters=80, dictionary_size=16, levels=24), seed=0,
                     work=_work(x))
    one = np.flatnonzero((cell["cluster_regime"] == 1) & (cell["cluster_weight"] > 0))
    assert len(one) == 1 and np.all(cell["cluster_scale"][one[0]] == 0.0)
    assert np.all(cell["cluster_scale"][:, 5] == 0.0)
    np.testing.assert_allclose(cell["cluster_loc"][cell["cluster_weight"] > 0, 5], 0.25, rtol=1e-6)
    dic = cell["shape_dictionary"].astype(np.float64)
    np.testing.assert_allclose(dic.mean(axis=-1), 0.0, atol=1e-5)
    np.testing.assert_allclose(dic.std(axis=-1), 1.0, rtol=1e-5)


@pytest.mark.parametrize("counts, clusters, expected", [
    ((7000, 3000), 100, [70, 30]),      # proportional
    ((9950, 50), 100, [99, 1]),         # a small regime keeps one cluster
    ((10000, 0), 100, [100, 0]),        # an empty regime gets none
    ((100, 900), 500, [4, 36]),         # at most one cluster per 25 samples
])
def test_clusters_are_shared_between_regimes(counts, clusters, expected):
    assert regime_clusters(counts, clusters) == expected


@pytest.mark.parametrize("n, clusters", [(256, 16), (10_000, 400), (25_000, 500), (10 ** 8, 500)])
def test_default_resolution(n, clusters):
    r = resolution_for(n)
    assert (r.clusters, r.dictionary_size, r.levels) == (clusters, 16, 24)


def test_resolution_rejects_bad_sizes():
    with pytest.raises(ValueError, match="dictionary_size"):
        TableResolution(dictionary_size=300)
    with pytest.raises(ValueError, match="clusters"):
        TableResolution(clusters=0)
    with pytest.raises(ValueError, match="particles_per_cell"):
        resolution_for(100)
