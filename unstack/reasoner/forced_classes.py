"""Boxes that hard evidence makes one: classes of boxes that surely support each other.

When ``P(x supports y) = P(y supports x) = 1`` (directly, or through a cycle of certain
relations), every consistent world relates ``x`` and ``y`` to each other box alike: by
transitivity ``x`` supports ``z`` exactly when ``y`` does, and ``z`` supports ``x`` exactly when it
supports ``y``. Such boxes form a class, and the distribution over consistent worlds is the
distribution over the classes' worlds, where class ``A`` supports class ``B`` with

    logit P(A supports B) = sum of logit P(x supports y) over x in A, y in B,

since a world's weight (Eq. 8) multiplies ``p_xy`` or ``1 - p_xy`` over every pair, and the pairs
between two classes all take the same value; the factor ``prod p + prod (1 - p)`` is the same in
every world and cancels. The sampler's moves re-insert one box at a time, so a class of two or
more boxes never changes its relations to the others (moving one member alone would break the
certain relation): it samples the classes instead (:func:`quotient_probabilities`) and spreads
the result back over the boxes (:func:`spread_pairs`).

Examples
--------
>>> p = np.array([[0.0, 1.0, 0.9], [1.0, 0.0, 0.5], [0.2, 0.5, 0.0]])
>>> forced_classes(p).tolist()
[0, 0, 1]
>>> quotient_probabilities(p, forced_classes(p)).round(3).tolist()
[[0.0, 0.9], [0.2, 0.0]]
"""

from __future__ import annotations

import numpy as np

__all__ = ["forced_classes", "quotient_probabilities", "spread_pairs"]


def forced_classes(probabilities: np.ndarray) -> np.ndarray | None:
    """The class of each box (numbered in the order of their first box), or None when no two
    boxes surely support each other.

    Examples
    --------
    >>> forced_classes(np.array([[0.0, 1.0], [0.5, 0.0]])) is None
    True
    """
    reach = np.asarray(probabilities) >= 1.0
    if not reach.any():
        return None
    reach = reach | np.eye(len(reach), dtype=bool)
    for k in range(len(reach)):  # transitive closure of the certain relations (Floyd-Warshall)
        reach |= reach[:, [k]] & reach[[k], :]
    same = reach & reach.T
    classes = np.full(len(same), -1, dtype=np.int64)
    count = 0
    for box in range(len(same)):
        if classes[box] < 0:
            classes[same[box]] = count
            count += 1
    return classes if count < len(same) else None


def quotient_probabilities(probabilities: np.ndarray, classes: np.ndarray) -> np.ndarray:
    """``P(class A supports class B)`` for the classes of :func:`forced_classes`: 1 where a pair
    between them is certain, 0 where one is impossible, else the logit sum over their pairs."""
    p = np.asarray(probabilities, dtype=np.float64)
    count = int(classes.max()) + 1
    merged = np.zeros((count, count))
    with np.errstate(divide="ignore"):
        logits = np.log(p) - np.log1p(-p)
    for a in range(count):
        for b in range(count):
            if a == b:
                continue
            pairs = p[np.ix_(classes == a, classes == b)]
            if (pairs >= 1.0).any():
                merged[a, b] = 1.0
            elif (pairs <= 0.0).any():
                merged[a, b] = 0.0
            else:
                merged[a, b] = 1.0 / (1.0 + np.exp(-logits[np.ix_(classes == a, classes == b)].sum()))
    return merged


def spread_pairs(pairs: np.ndarray, classes: np.ndarray, within: float) -> np.ndarray:
    """A matrix over the classes (its last two axes) spread over the boxes: ``within`` between
    two boxes of one class, 0 on the diagonal.

    Examples
    --------
    >>> spread_pairs(np.array([[0.0, 0.3], [0.6, 0.0]]), np.array([0, 0, 1]), 1.0).tolist()
    [[0.0, 1.0, 0.3], [1.0, 0.0, 0.3], [0.6, 0.6, 0.0]]
    """
    spread = np.array(pairs[..., classes[:, None], classes[None, :]], dtype=np.float64)
    same = (classes[:, None] == classes[None, :]) & ~np.eye(len(classes), dtype=bool)
    spread[..., same] = within
    spread[..., np.eye(len(classes), dtype=bool)] = 0.0
    return spread
