"""The random variables S_XY of the possible worlds (§III), named by domain tuples.

Each ordered pair of distinct detected boxes ``(X, Y)`` has a binary variable
``S_XY = 1`` iff SUPP(X, Y). The SAT encoding numbers them with python-sat's
:class:`~pysat.formula.IDPool` under the names ``("supports", X, Y)``; the integers never
leave this module's API.

Examples
--------
>>> variables = SupportVariables(["a", "b", "c"])
>>> len(variables)
6
>>> variables.relation(variables.id("b", "c"))
('b', 'c')
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from itertools import permutations

from pysat.formula import IDPool

__all__ = ["SupportVariables"]

#: The first element of every variable name.
SUPPORTS = "supports"


class SupportVariables:
    """The support variables ``("supports", X, Y)`` of a set of boxes.

    Parameters
    ----------
    objects : sequence of str
        The detected boxes, in the scene's order.
    """

    def __init__(self, objects: Sequence[str]) -> None:
        self.objects = tuple(objects)
        self.pool = IDPool()
        self.pairs: tuple[tuple[str, str], ...] = tuple(permutations(self.objects, 2))
        for supporter, supported in self.pairs:
            self.pool.id((SUPPORTS, supporter, supported))

    def __len__(self) -> int:
        return len(self.pairs)

    def __iter__(self) -> Iterator[tuple[str, str]]:
        return iter(self.pairs)

    def id(self, supporter: str, supported: str) -> int:
        """The SAT variable of ``SUPP(supporter, supported)``."""
        name = (SUPPORTS, supporter, supported)
        if name not in self.pool.obj2id:
            raise KeyError(f"no variable for SUPP({supporter}, {supported})")
        return int(self.pool.obj2id[name])

    def relation(self, variable: int) -> tuple[str, str]:
        """The ``(supporter, supported)`` pair a SAT variable (or its negation) stands for."""
        name = self.pool.obj(abs(variable))
        if name is None:
            raise KeyError(f"unknown variable {variable}")
        return name[1], name[2]
