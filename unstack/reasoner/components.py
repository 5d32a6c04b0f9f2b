"""Factorising the distribution over independent groups of boxes.

Link two boxes when either may support the other (a probability above 0 in either
direction, after hard evidence has been propagated). If no link joins two groups A and
B, every relation between them is 0 in every world of non-zero weight, so a consistent
world is a consistent world on A next to one on B, with no relation across: no
transitivity clause can mix them, because each clause needs a relation across to fire.
The weight of such a world is the product of the groups' weights (Eq. 8 is a product over
pairs, and the cross pairs contribute ``1 - 0 = 1``). Hence

* the distribution over consistent worlds is the product of the groups' distributions,
* every conditional marginal inside a group is the group's own marginal, every marginal
  across groups is 0, and
* the number of consistent worlds is the product of the groups' counts.

So a scene of many boxes is exact whenever each connected group is small enough for an
exact method. The tests check this against the unfactorised engine.

Examples
--------
>>> import numpy as np
>>> p = np.zeros((4, 4)); p[0, 1] = 0.9; p[3, 2] = 0.4
>>> [group.tolist() for group in support_components(p)]
[[0, 1], [2, 3]]
"""

from __future__ import annotations

import numpy as np

__all__ = ["support_components"]


def support_components(probabilities: np.ndarray) -> list[np.ndarray]:
    """Groups of box indices linked by a non-zero probability in either direction.

    Groups are sorted by their smallest index; indices inside a group are increasing.
    """
    linked = (probabilities > 0) | (probabilities.T > 0)
    n = linked.shape[0]
    unseen = np.ones(n, dtype=bool)
    groups = []
    for start in range(n):
        if not unseen[start]:
            continue
        members = np.zeros(n, dtype=bool)
        members[start] = True
        frontier = members.copy()
        while frontier.any():
            frontier = linked[frontier].any(axis=0) & ~members
            members |= frontier
        unseen &= ~members
        groups.append(np.flatnonzero(members).astype(np.int64))
    return groups
