"""Which boxes the sampler records by summing their insertion, and over which free sets.

The sampler's record gives every pair its probability given every other relation
(:mod:`unstack.reasoner.sampling`). On classifier piles a few *middle* boxes keep most of the
error: such a box either has its likely supporters or its likely supported boxes, rarely
both (transitivity would need the supporters to support the supported boxes too), so the
boxes it supports jump between none and many from world to world. Summing the box's
insertion exactly (:mod:`unstack.reasoner.insertion`) averages both sides in every world.

The sum runs over a *free set*: the boxes that the box supports or is supported by with a
pilot marginal of at least :data:`FREE_THRESHOLD`. For a fixed free set the insertions inside
it, for each preorder of the other boxes, are one cell of a partition of the worlds, so the
average over the world's cell is an unbiased record (see
:mod:`unstack.reasoner._insertion_sum_kernels`); the threshold only trades the size of the sum
against how much spread it removes. Measured on eight 31-40-box piles of ``scenes40``
(the three noisiest boxes of each, ``benchmarks/insertion_variance.py``): at 0.01 the sum
takes 5-25 times off the box's ``variance * autocorrelation time`` and costs 15-300 us (one
to a few sweeps of the sampler).

Which boxes: a pilot run gives each box's EC standard error (from its batch means) and,
from one sum per box on every chain's state, the cost of its sum (slots of the dynamic programme, a count that does
not depend on the machine). The noisiest boxes are summed, as many as give the smallest
largest predicted variance, predicting :data:`ASSUMED_REDUCTION` times less variance for a
summed box and charging every box the longer sweeps; the sums may at most double a sweep.

Examples
--------
>>> import numpy as np
>>> pilot = np.zeros((2, 3, 3)); pilot[0, 0, 1] = 8.0  # chain 0 saw box 0 on box 1, chain 1 never
>>> free_sets(pilot.mean(axis=0) / 8, np.array([0]), threshold=0.01).tolist()  # box 0's free set: box 1
[2]
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "ASSUMED_REDUCTION",
    "FREE_THRESHOLD",
    "MAX_EXTRA_COST",
    "SLOTS_PER_BOX_SWEEP",
    "SUM_SLOTS",
    "choose",
    "free_sets",
]

#: A box joins the free set of another when a pilot marginal between them reaches this.
FREE_THRESHOLD = 0.01
#: Variance taken off a summed box's EC, predicted when choosing: summed every fourth sweep
#: (:data:`unstack.reasoner._sampler_kernels.SUM_STRIDE`) the measured reduction at the
#: threshold above was 3-34 times, median 6 (the lower end, so that sums are not bought on hope).
ASSUMED_REDUCTION = 4.0
#: Sums cost at most this many sweeps per recorded sweep.
MAX_EXTRA_COST = 1.0
#: States a sum may store before it is abandoned (the world's own row is recorded instead):
#: about 100 us, three sweeps, at the most.
SUM_SLOTS = 1024
#: Slots of the dynamic programme that cost about one sweep, per box of the group (measured on
#: two 39-40-box piles: a chain's sweep 29-32 us of core time, a slot 0.094-0.098 us).
SLOTS_PER_BOX_SWEEP = 8.0


def free_sets(marginals: np.ndarray, boxes: np.ndarray, *, threshold: float = FREE_THRESHOLD) -> np.ndarray:
    """Bit mask (``int64``) of each box's free set: the boxes ``y`` with ``marginals[box, y]`` or
    ``marginals[y, box]`` at least ``threshold``."""
    linked = (marginals >= threshold) | (threshold <= marginals.T)
    np.fill_diagonal(linked, False)
    weights = np.left_shift(np.int64(1), np.arange(marginals.shape[0], dtype=np.int64))
    return np.array([int(weights[linked[box]].sum()) for box in boxes], dtype=np.int64)


def choose(variances: np.ndarray, costs: np.ndarray, eligible: np.ndarray) -> np.ndarray:
    """The boxes to sum: the ``k`` eligible boxes of largest variance, for the ``k`` whose largest
    predicted variance is smallest (see the module docstring).

    Parameters
    ----------
    variances : numpy.ndarray, shape (n,)
        Each box's EC variance from the pilot.
    costs : numpy.ndarray, shape (n,)
        Each box's sum, in sweeps (``inf``: cannot be summed).
    eligible : numpy.ndarray, shape (n,), bool

    Examples
    --------
    >>> choose(np.array([9.0, 1.0, 1.0]), np.array([0.5, 0.5, 0.5]), np.ones(3, bool)).tolist()
    [0]
    """
    order = [int(box) for box in np.argsort(-variances, kind="stable") if eligible[box]]
    best: list[int] = []
    best_variance = float(np.max(variances)) if len(variances) else 0.0
    extra = 0.0
    for k, box in enumerate(order):
        extra += float(costs[box])
        if extra > MAX_EXTRA_COST:
            break
        summed = np.zeros(len(variances), dtype=bool)
        summed[order[: k + 1]] = True
        predicted = float(np.max(np.where(summed, variances / ASSUMED_REDUCTION, variances))) * (1.0 + extra)
        if predicted < best_variance:
            best, best_variance = order[: k + 1], predicted
    return np.array(sorted(best), dtype=np.int64)
