"""Action costs (Eq. 11) and expected costs from conditional marginals (Eq. 13).

Eq. 11 charges unloading box ``X_j`` with the boxes it supports. The cost is additive over
the supported boxes, so its expectation needs only the conditional marginals:
``EC(A_j) = own_j + sum_Y w_Y P(S_jY = 1 | consistent)`` with

* ``"count"`` (Eq. 11 exactly, the paper): ``w_Y = 1``, ``own_j = 0``;
* ``"mass"``: ``w_Y`` = the mass of Y, ``own_j = 0``;
* ``"load"`` (the default): every box counted with the undetected load resting on it,
  ``w_Y = 1 + h_Y`` and ``own_j = h_j``, where ``h`` is :attr:`Supports.hidden_load`
  (what the cloud shows on a box that no detected box explains, see
  :mod:`unstack.understanding.hidden_load`). Without a hidden load it equals ``"count"``.

Examples
--------
>>> import numpy as np
>>> expected_costs(np.array([[0, 0.5], [0.25, 0]]), np.array([1.0, 1.0])).tolist()
[0.5, 0.25]
"""

from __future__ import annotations

import numpy as np

from unstack.errors import UnstackError
from unstack.supports import Supports

__all__ = ["COSTS", "DEFAULT_COST", "PAYOFF_COSTS", "cost_weights", "expected_costs", "own_costs"]

#: The cost models: what unloading a box first costs for each box it supports.
COSTS = ("load", "count", "mass")
#: The cost a decision uses unless told otherwise.
DEFAULT_COST = "load"
#: The costs a payoff matrix (Table II) tabulates world by world.
PAYOFF_COSTS = ("count", "mass")


def cost_weights(supports: Supports, cost: str) -> np.ndarray:
    """Per-box weight of the cost model: ones for ``"count"``, the masses for ``"mass"``,
    one plus the hidden load for ``"load"``."""
    if cost == "count":
        return np.ones(supports.n_objects)
    if cost == "load":
        weights: np.ndarray = 1.0 + own_costs(supports, cost)
        return weights
    if cost == "mass":
        if supports.masses is None:
            raise UnstackError(
                f"{supports.source}: $.masses: the mass-weighted cost needs box masses; "
                'add "masses" (kg, aligned with objects) or use the count cost'
            )
        return np.asarray(supports.masses, dtype=np.float64)
    raise UnstackError(f"unknown cost {cost!r}; expected one of {', '.join(COSTS)}")


def own_costs(supports: Supports, cost: str) -> np.ndarray:
    """What unloading each box costs whatever it supports among the detected boxes: its
    hidden load for ``"load"``, 0 otherwise.

    Examples
    --------
    >>> supports = Supports(["a", "b"], [[0, 0.5], [0.2, 0]], hidden_load=[1.0, 0.0])
    >>> own_costs(supports, "load").tolist(), own_costs(supports, "count").tolist()
    ([1.0, 0.0], [0.0, 0.0])
    """
    if cost == "load" and supports.hidden_load is not None:
        load: np.ndarray = np.asarray(supports.hidden_load, dtype=np.float64)
        return load
    return np.zeros(supports.n_objects)


def expected_costs(marginals: np.ndarray, weights: np.ndarray, own: np.ndarray | None = None) -> np.ndarray:
    """``EC(A_j) = own[j] + sum_Y weights[Y] * marginals[j, Y]`` (Eqs. 11 and 13)."""
    result: np.ndarray = marginals @ weights
    return result if own is None else result + own
