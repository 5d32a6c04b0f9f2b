"""Shared check: a sampler's chains, run as they are set up, against the exact engine."""

from __future__ import annotations

import numpy as np

from unstack.reasoner.sampling import _Chains


def seven_boxes(seed: int) -> np.ndarray:
    """A dense 7-box matrix, small enough for the exact engine."""
    p = np.random.default_rng(seed).uniform(0.02, 0.98, (7, 7))
    np.fill_diagonal(p, 0.0)
    return p


def assert_costs_match_exact(chains: _Chains, exact: np.ndarray, *, batches: int = 12, sweeps: int = 1024) -> None:
    """Every box's EC (unit weights) from ``batches`` recorded runs of ``sweeps`` sweeps lies within
    4 batch standard errors (plus 1e-3) of the exact marginals' row sums."""
    costs = []
    for _ in range(batches):
        chains.sums[:] = 0.0
        chains.advance(sweeps, record=True)
        costs.append(chains.sums[:, 0].sum(axis=0).sum(axis=1) / (len(chains.rng) * sweeps))  # one round
    batch_costs = np.array(costs)
    errors = np.abs(batch_costs.mean(axis=0) - exact.sum(axis=1))
    standard_errors = batch_costs.std(axis=0, ddof=1) / np.sqrt(batches)
    assert np.all(errors < 4 * standard_errors + 1e-3)
