"""Consistency of possible worlds: support is transitive (§III-B).

A world is consistent iff ``S_XY`` and ``S_YZ`` imply ``S_XZ`` for all distinct X, Y, Z;
mutual support (``S_XY = S_YX = 1``) is allowed, as in the paper. The consistent worlds
are exactly the preorders on the boxes (OEIS A000798).

Examples
--------
>>> import numpy as np
>>> is_transitive(np.array([[0, 1, 1], [0, 0, 1], [0, 0, 0]], dtype=bool))
True
>>> is_transitive(np.array([[0, 1, 0], [0, 0, 1], [0, 0, 0]], dtype=bool))
False
"""

from __future__ import annotations

from itertools import permutations
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:  # the SAT encoding loads python-sat; the counts must not
    from unstack.reasoner.variables import SupportVariables

__all__ = ["PREORDER_COUNTS", "is_transitive", "transitivity_clauses"]

#: Number of consistent worlds (preorders) on n = 0, 1, 2, ... labelled boxes, OEIS A000798.
PREORDER_COUNTS: tuple[int, ...] = (
    1,
    1,
    4,
    29,
    355,
    6942,
    209527,
    9535241,
    642779354,
    63260289423,
    8977053873043,
)


def transitivity_clauses(variables: SupportVariables) -> list[list[int]]:
    """CNF clauses ``(¬S_XY ∨ ¬S_YZ ∨ S_XZ)`` for all distinct X, Y, Z.

    Examples
    --------
    >>> from unstack.reasoner.variables import SupportVariables
    >>> len(transitivity_clauses(SupportVariables(["a", "b", "c"])))
    6
    """
    return [
        [-variables.id(x, y), -variables.id(y, z), variables.id(x, z)] for x, y, z in permutations(variables.objects, 3)
    ]


def is_transitive(world: np.ndarray) -> bool:
    """Whether a boolean support matrix (diagonal ignored) is a consistent world."""
    relation = np.asarray(world, dtype=bool).copy()
    np.fill_diagonal(relation, False)
    two_steps = (relation.astype(np.int64) @ relation.astype(np.int64)) > 0
    np.fill_diagonal(two_steps, False)
    return bool(np.all(relation[two_steps]))
