"""The payoff matrix of Table II: consistent worlds, their probabilities, action costs.

``c_ij`` is the cost of unloading box ``j`` first in world ``i`` (Eq. 11: the number of
boxes it supports, or their total mass), and ``EC(A_j) = sum_i P(w_i^c) c_ij`` (Eq. 13).
Only small scenes: the matrix has one row per consistent world.

Examples
--------
>>> from unstack.supports import Supports
>>> table = payoff_matrix(Supports(["a", "b"], [[0, 0.9], [0.0, 0]]))
>>> table.costs.tolist()
[[0.0, 0.0], [1.0, 0.0]]
>>> table.expected_costs().round(3).tolist()
[0.9, 0.0]
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from unstack.reasoner.costs import cost_weights, own_costs, weight_doubts
from unstack.reasoner.worlds import SAT_MAX_BOXES, WorldSet, enumerate_worlds
from unstack.supports import Supports

__all__ = ["PAYOFF_FORMAT", "PayoffMatrix", "payoff_matrix"]

PAYOFF_FORMAT = "unstack.payoff/1"


@dataclass(frozen=True, eq=False)
class PayoffMatrix:
    """Table II for one scene.

    Built by :func:`payoff_matrix` from the worlds the SAT listing finds; ``unstack worlds``
    prints it, and :meth:`to_dict` is its ``unstack.payoff/1`` document.

    Attributes
    ----------
    worlds : WorldSet
        The consistent worlds and their probabilities ``pw_i``.
    costs : numpy.ndarray, shape (q', n)
        ``costs[i, j]`` = cost of unloading box ``j`` first in world ``i``.
    cost : str
        ``"count"`` (Eq. 11), ``"mass"`` or ``"load"``.
    warnings : tuple of str
        Doubts about the input (:attr:`unstack.supports.Supports.warnings`), one sentence each.
    """

    worlds: WorldSet
    costs: np.ndarray
    cost: str
    warnings: tuple[str, ...] = ()

    @property
    def objects(self) -> tuple[str, ...]:
        """Box ids (the actions, in order)."""
        return self.worlds.objects

    def expected_costs(self) -> np.ndarray:
        """``EC(A_j)`` of every box (Eq. 13)."""
        return np.asarray(self.worlds.probabilities @ self.costs)

    def to_dict(self) -> dict[str, Any]:
        """The ``unstack.payoff/1`` JSON object: every consistent world with its probability and costs.

        Returns
        -------
        dict
            Valid against ``payoff-1.schema.json``.

        Examples
        --------
        >>> from unstack.supports import Supports
        >>> document = payoff_matrix(Supports(["a", "b"], [[0, 0.9], [0.0, 0]])).to_dict()
        >>> document["consistent_worlds"], document["worlds"][1]["supports"]
        (2, [['a', 'b']])
        """
        objects = self.objects
        return {
            "format": PAYOFF_FORMAT,
            "objects": list(objects),
            "cost": self.cost,
            "consistent_worlds": len(self.worlds),
            "expected_costs": self.expected_costs().tolist(),
            "worlds": [
                {
                    "probability": float(self.worlds.probabilities[i]),
                    "supports": [
                        [objects[x], objects[y]] for x, y in zip(*self.worlds.worlds[i].nonzero(), strict=True)
                    ],
                    "costs": self.costs[i].tolist(),
                }
                for i in range(len(self.worlds))
            ],
            **({"warnings": list(self.warnings)} if self.warnings else {}),
        }


def payoff_matrix(supports: Supports, *, cost: str = "count", max_boxes: int = SAT_MAX_BOXES) -> PayoffMatrix:
    """Build Table II by listing the consistent worlds with the SAT solver.

    Parameters
    ----------
    supports : Supports
        The detected boxes and their support probabilities.
    cost : {"count", "mass", "load"}
        Eq. 11 (number of supported boxes), the total supported mass, or decide's ``load``: each
        box counted with the hidden load on it, the box taken out with its own.
    max_boxes : int
        Largest scene accepted.
    """
    weights = cost_weights(supports, cost)
    worlds = enumerate_worlds(supports, max_boxes=max_boxes)
    costs = worlds.worlds.astype(np.float64) @ weights + own_costs(supports, cost)  # load: the box's own too
    return PayoffMatrix(worlds, costs, cost, supports.warnings + weight_doubts(supports, cost))
