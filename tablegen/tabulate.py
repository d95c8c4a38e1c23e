"""From a cell's direct-model samples to its stored representation (docs/format.md).

The representation is a discretised inverse Rosenblatt transform of the
folded reflected state (:mod:`data_schema.table`): α2 → |β2| given an α2 bin →
(s, Ω) given an (α2, |β2|) leaf, where Ω rides on s as comonotone atoms.
Conditioning bins are cut at ranks, so each holds the same number of samples
(±1). Mirror folding: the model is exactly symmetric under Z → −Z, which maps
(β2, Ω_x, Ω_y) to their negatives; every sample is mapped to its image with
β2 ≥ 0, so all n samples inform one half-space and the runtime restores the
sign with probability ½ — the variance of the stored law is that of 2n samples
of a symmetric law.
"""

from __future__ import annotations

import numpy as np

from data_schema.samples import STATUS_NAMES, STATUS_REBOUNDED, SampleSet
from data_schema.table import (
    INDICATRIX_ALPHA2_EDGES, INDICATRIX_BETA2_EDGES, N_COLLISION_CLASSES, CellTable, TableResolution,
)


def resolution_for(particles_per_cell: int, spin_atoms_max: int = 64, samples_per_atom: int = 4) -> TableResolution:
    """The finest default resolution whose every leaf holds ``samples_per_atom`` samples per atom.

    Leaves are 16 α2 bins × 8 |β2| bins; the number of spin atoms per leaf A
    (a power of two, 8 to ``spin_atoms_max``) is the largest with
    16·8·A·samples_per_atom ≤ particles_per_cell; below 4096 particles the bins
    shrink to 8 × 4. Fewer than 256 particles per cell cannot fill a table.
    """
    if particles_per_cell < 256:
        raise ValueError(f"The 'particles_per_cell' parameter must be >= 256 to build a table; "
                         f"got {particles_per_cell!r}.")
    b1, b2 = (16, 8) if particles_per_cell >= 16 * 8 * 8 * samples_per_atom else (8, 4)
    atoms = 8
    while atoms * 2 <= spin_atoms_max and b1 * b2 * atoms * 2 * samples_per_atom <= particles_per_cell:
        atoms *= 2
    return TableResolution(alpha2_levels=64, alpha2_bins=b1, beta2_levels=32, beta2_bins=b2, spin_atoms=atoms)


def _rank_bins(x: np.ndarray, n_bins: int) -> list:
    """Indices of x split into n_bins equal-count groups by rank (ascending)."""
    order = np.argsort(x, kind="stable")
    edges = (np.arange(n_bins + 1) * len(x)) // n_bins
    return [order[edges[b]:edges[b + 1]] for b in range(n_bins)]


def _quantiles(x: np.ndarray, n_levels: int) -> np.ndarray:
    """Empirical quantile function at probabilities k/n_levels, k = 0..n_levels."""
    return np.quantile(x, np.linspace(0.0, 1.0, n_levels + 1))


def folded_state(samples: SampleSet) -> np.ndarray:
    """(α2, |β2|, s, Ω_x, Ω_y, Ω_z) of the rebounded particles, Ω_x and Ω_y times sign β2."""
    ok = samples.rebounded
    beta2 = samples.beta2[ok]
    sign = np.where(beta2 < 0.0, -1.0, 1.0)
    return np.column_stack([samples.alpha2[ok], np.abs(beta2), samples.speed_ratio[ok],
                            samples.omega[ok, 0] * sign, samples.omega[ok, 1] * sign, samples.omega[ok, 2]])


class CellAccumulator:
    """Accumulates one cell's samples chunk by chunk, then builds its :class:`CellTable`.

    Statistics (status and collision counts, means, standard deviations,
    indicatrices) cover every particle added. The representation is estimated
    from the first ``max_states`` rebounds, which bounds memory for very large
    cells (10⁸ particles) while keeping far more samples than its resolution uses.
    """

    def __init__(self, max_states: int = 4_000_000):
        self.max_states = max_states
        self.states = []
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
        state = np.column_stack([samples.alpha2[ok], samples.beta2[ok], samples.speed_ratio[ok], samples.omega[ok]])
        self.sums += state.sum(axis=0)
        self.squares += (state ** 2).sum(axis=0)
        self.hist2 += np.histogram(state[:, 0], bins=INDICATRIX_ALPHA2_EDGES)[0]
        self.hist3 += np.histogram2d(state[:, 0], state[:, 1],
                                     bins=[INDICATRIX_ALPHA2_EDGES, INDICATRIX_BETA2_EDGES])[0]
        keep = min(self.max_states - self.n_states, int(ok.sum()))
        if keep > 0:
            self.states.append(folded_state(samples)[:keep])
            self.n_states += keep

    def finish(self, resolution: TableResolution, label: str = "cell") -> CellTable:
        """The cell's representation and statistics; ``label`` names the cell in errors."""
        n = int(self.status_counts[STATUS_REBOUNDED])
        r = resolution
        if self.n_states < r.alpha2_bins * r.beta2_bins * (r.spin_atoms + 1):
            raise ValueError(f"{label}: only {self.n_states} rebounds, too few for a resolution of "
                             f"{r.alpha2_bins}x{r.beta2_bins} leaves of {r.spin_atoms + 1} samples")
        mean = self.sums / n
        std = np.sqrt(np.maximum(self.squares / n - mean ** 2, 0.0))
        d_a2 = np.diff(INDICATRIX_ALPHA2_EDGES)
        d_b2 = np.diff(INDICATRIX_BETA2_EDGES)
        return CellTable(
            **represent(np.concatenate(self.states), r),
            status_counts=self.status_counts.copy(), collision_counts=self.collision_counts.copy(),
            mean=mean, std=std,
            indicatrix_2d=(self.hist2 / (n * d_a2)).astype(np.float32),
            indicatrix_3d=(self.hist3 / (n * np.outer(d_a2, d_b2))).astype(np.float32))


def represent(folded: np.ndarray, resolution: TableResolution) -> dict:
    """The stored law (α2, β2, s, spin quantile/atom arrays) of folded states (n, 6)."""
    alpha2, beta2, speed, omega = folded[:, 0], folded[:, 1], folded[:, 2], folded[:, 3:]
    r = resolution
    beta2_q = np.empty((r.alpha2_bins, r.beta2_levels + 1))
    speed_q = np.empty((r.alpha2_bins, r.beta2_bins, r.spin_atoms + 1))
    spin = np.empty((r.alpha2_bins, r.beta2_bins, r.spin_atoms, 3), dtype=np.float32)
    atom_rank = (np.arange(r.spin_atoms) + 0.5) / r.spin_atoms
    for b, in_a in enumerate(_rank_bins(alpha2, r.alpha2_bins)):
        beta2_q[b] = _quantiles(beta2[in_a], r.beta2_levels)
        for c, in_leaf in enumerate(_rank_bins(beta2[in_a], r.beta2_bins)):
            leaf = in_a[in_leaf]
            order = leaf[np.argsort(speed[leaf], kind="stable")]
            speed_q[b, c] = _quantiles(speed[order], r.spin_atoms)
            spin[b, c] = omega[order[(atom_rank * len(order)).astype(np.int64)]]
    return {"alpha2_q": _quantiles(alpha2, r.alpha2_levels), "beta2_q": beta2_q,
            "speed_q": speed_q, "spin": spin}
