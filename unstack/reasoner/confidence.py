"""How sure a decision is: the probability that the chosen box truly has the minimum EC.

Exact methods give every expected cost without error, so the choice is certain. Sampled
expected costs carry a covariance (from the batch means, see
:mod:`unstack.reasoner.sampling`); treating the estimate as normal around the true values,
the probability that the chosen box is the true minimum is the share of draws from
``N(estimate, covariance)`` in which it has the smallest cost (a draw below zero counts as
zero: an expected count of boxes is never negative). Boxes too far above the
choice to win (:data:`CONTENDER_SIGMAS`) are left out of the draws. Boxes in different groups of
linked boxes are estimated independently, so the covariance is block-diagonal.

Examples
--------
>>> import numpy as np
>>> costs = np.array([1.0, 1.1, 3.0])
>>> choice_probability(costs, np.diag([0.0, 0.0, 0.0]), 0)
1.0
>>> round(choice_probability(costs, np.diag([0.05, 0.05, 0.05]) ** 2, 0, seed=0), 2)
0.92
"""

from __future__ import annotations

import numpy as np

__all__ = ["CONTENDER_SIGMAS", "DRAWS", "choice_probability"]

#: Normal draws behind the probability (its own error is below 0.008).
DRAWS = 4000
#: A box whose cost lies more than this many standard deviations (its own plus the
#: choice's) above the choice's cannot be the minimum in any draw that matters (a normal
#: draw passes 6 standard deviations with probability 1e-9): it is left out of the draws.
CONTENDER_SIGMAS = 6.0


def choice_probability(
    expected_costs: np.ndarray,
    covariance: np.ndarray,
    choice: int,
    *,
    seed: int | None = 0,
    draws: int = DRAWS,
    margin: float = 0.0,
) -> float:
    """Probability that box ``choice`` has the smallest true expected cost (within ``margin``).

    A box tied with others at the smallest cost has it: exact costs tied at the minimum (the
    zeros of boxes that certainly hold nothing up) make a choice among them certain, whichever
    of them it is.

    Parameters
    ----------
    expected_costs : numpy.ndarray, shape (n,)
        Estimated EC of every box.
    covariance : numpy.ndarray, shape (n, n)
        Covariance of the estimate (zeros for exact values).
    choice : int
        Index of the chosen box.
    seed : int, optional
        Seed of the normal draws.
    draws : int
        Number of draws.
    margin : float
        The choice counts as right when its true cost is at most this far above the smallest
        (the near-tie margin of the decision; 0: it must be the smallest).

    Returns
    -------
    float
        1.0 when no cost carries an error.
    """
    deviations = np.sqrt(np.maximum(np.diag(covariance), 0.0))
    reach = expected_costs[choice] + CONTENDER_SIGMAS * deviations[choice]
    contenders = np.flatnonzero(expected_costs - CONTENDER_SIGMAS * deviations <= reach)  # holds the choice
    uncertain = contenders[deviations[contenders] > 0]
    if len(uncertain) == 0:
        return 1.0
    rng = np.random.default_rng(seed)
    samples = np.tile(expected_costs[contenders], (draws, 1))
    columns = np.searchsorted(contenders, uncertain)
    block = covariance[np.ix_(uncertain, uncertain)]
    drawn = rng.multivariate_normal(expected_costs[uncertain], block, size=draws, method="eigh")
    samples[:, columns] = np.maximum(drawn, 0.0)  # an expected count of boxes is never negative
    own = int(np.searchsorted(contenders, choice))
    return float(np.mean(samples[:, own] <= samples.min(axis=1) + margin))
