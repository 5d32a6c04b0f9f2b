"""How often the sampler re-inserts each box: the noisiest boxes more often than the rest.

A sweep of the sampler re-inserts :data:`~unstack.reasoner.sampling.MOVES` boxes, the next
ones of a *schedule* in turn (:mod:`unstack.reasoner.sampling`). With every box once in the
schedule, a box of a 40-box pile is re-inserted every fifth sweep. On classifier piles a few
*middle* boxes carry most of the error: such a box either has its likely supporters or its
likely supported boxes, and the boxes it supports jump between none and many when it is
re-inserted -- so its EC forgets its past about as fast as the box is re-inserted. Visiting
those boxes more often costs nothing per sweep (a sweep still makes the same number of moves)
and takes a few re-insertions from the quiet boxes, whose error hardly changes.

Every re-insertion leaves the distribution of the worlds invariant, so any fixed order of
them does too (a deterministic scan): the schedule changes how fast the chains mix, never
what they converge to. It is chosen once, from a pilot run (the first eighth of the budget,
whose records are kept): box ``b`` appears ``round((s_b / s_q) ** 2)`` times, between 1 and
:data:`MAX_VISITS`, where ``s_b`` is its EC's standard error in the pilot and ``s_q`` the
:data:`REFERENCE_QUANTILE` quantile of them (the number of re-insertions it needs for the
variance ``s_q**2`` if its variance falls in proportion to its visits). Measured on the eight
``scenes40`` piles, 16 seeded runs of 50,000 sweeps each way (``benchmarks/revisits.py``): the
largest spread of an EC across the runs fell on 7 piles of 8, by 4-27 % (0.036 to 0.028 and
0.038 to 0.028 on the two noisiest piles), and rose by 17 % on one (0.010 to 0.012); the
reported standard errors stayed as honest as before (spread / reported error: median
0.91-1.04 either way).

Examples
--------
>>> import numpy as np
>>> schedule(np.array([0.04, 0.01, 0.01, 0.01])).tolist()  # box 0 five times, spread out
[0, 0, 1, 0, 2, 0, 3, 0]
"""

from __future__ import annotations

import numpy as np

__all__ = ["MAX_VISITS", "REFERENCE_QUANTILE", "schedule", "visits"]

#: A box is re-inserted at most this many times per pass over the boxes.
MAX_VISITS = 16
#: The standard error that one visit per pass is meant for: this quantile of the boxes'.
REFERENCE_QUANTILE = 0.75


def visits(standard_errors: np.ndarray) -> np.ndarray:
    """Re-insertions of each box per pass: ``round((s_b / s_q) ** 2)`` clipped to
    ``[1, MAX_VISITS]`` (every box once when the errors are all 0).

    Examples
    --------
    >>> visits(np.array([0.03, 0.01, 0.01, 0.0])).tolist()
    [4, 1, 1, 1]
    """
    errors = np.asarray(standard_errors, dtype=np.float64)
    reference = float(np.quantile(errors, REFERENCE_QUANTILE)) if len(errors) else 0.0
    if not reference > 0.0:
        return np.ones(len(errors), dtype=np.int64)
    ratios = np.minimum(errors, np.sqrt(MAX_VISITS) * reference) / reference  # no overflow for tiny references
    counts: np.ndarray = np.clip(np.round(ratios**2), 1, MAX_VISITS).astype(np.int64)
    return counts


def schedule(standard_errors: np.ndarray) -> np.ndarray:
    """The order of the re-insertions: every box once, in index order, with each box's extra
    :func:`visits` spread evenly between them (``int64``)."""
    counts = visits(standard_errors)
    n = len(counts)
    extra = np.repeat(np.arange(n, dtype=np.int64), counts - 1)
    positions = np.concatenate([np.arange(n) / n, (np.arange(len(extra)) + 0.5) / max(len(extra), 1)])
    boxes = np.concatenate([np.arange(n, dtype=np.int64), extra])
    ordered: np.ndarray = boxes[np.argsort(positions, kind="stable")]
    return ordered
