"""An independent brute-force oracle: every one of the 2^(n(n-1)) worlds, checked by numpy; and
the rule a sampled answer is held to against an exact one."""

from __future__ import annotations

from itertools import permutations

import numpy as np

from unstack.reasoner.sampling import SampledMarginals


def brute_force(probabilities: np.ndarray) -> tuple[np.ndarray, int]:
    """Conditional marginals and the number of consistent worlds of non-zero weight."""
    n = probabilities.shape[0]
    pairs = list(permutations(range(n), 2))
    m = len(pairs)
    codes = np.arange(2**m, dtype=np.int64)
    bits = ((codes[:, None] >> np.arange(m)[None, :]) & 1).astype(bool)
    index = {pair: k for k, pair in enumerate(pairs)}
    consistent = np.ones(len(codes), dtype=bool)
    for x, y, z in permutations(range(n), 3):
        consistent &= ~(bits[:, index[x, y]] & bits[:, index[y, z]]) | bits[:, index[x, z]]
    p = np.array([probabilities[x, y] for x, y in pairs])
    weights = np.prod(np.where(bits, p, 1 - p), axis=1) * consistent
    live = weights > 0
    marginals = np.zeros((n, n))
    for (x, y), k in index.items():
        marginals[x, y] = weights[bits[:, k]].sum() / weights.sum()
    return marginals, int(live.sum())


def assert_within_errors(result: SampledMarginals, exact: np.ndarray) -> None:
    """Every sampled marginal and expected cost (unit weights) within 5 of its standard errors
    (and 2e-3) of the exact marginals ``exact``."""
    off = ~np.eye(len(exact), dtype=bool)
    assert np.all(np.abs(result.marginals - exact)[off] <= 5 * result.standard_errors[off] + 2e-3)
    costs, covariance = result.errors_of(np.ones(len(exact)))
    assert np.all(np.abs(costs - exact.sum(axis=1)) <= 5 * np.sqrt(np.diag(covariance)) + 2e-3)
