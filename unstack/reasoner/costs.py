"""Action costs (Eq. 11) and expected costs from conditional marginals (Eq. 13).

Eq. 11 charges unloading box ``X_j`` with the boxes it supports. The cost is additive over
the supported boxes, so its expectation needs only the conditional marginals:
``EC(A_j) = sum_Y w_Y P(S_jY = 1 | consistent)`` with ``w_Y = 1`` (``"count"``, the paper)
or ``w_Y`` = the mass of Y (``"mass"``).

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

__all__ = ["COSTS", "cost_weights", "expected_costs"]

#: The cost models: what unloading a box first costs for each box it supports.
COSTS = ("count", "mass")


def cost_weights(supports: Supports, cost: str) -> np.ndarray:
    """Per-box weight of the cost model: ones for ``"count"``, the masses for ``"mass"``."""
    if cost == "count":
        return np.ones(supports.n_objects)
    if cost == "mass":
        if supports.masses is None:
            raise UnstackError(
                f"{supports.source}: $.masses: the mass-weighted cost needs box masses; "
                'add "masses" (kg, aligned with objects) or use --cost count'
            )
        return np.asarray(supports.masses, dtype=np.float64)
    raise UnstackError(f"unknown cost {cost!r}; expected one of {', '.join(COSTS)}")


def expected_costs(marginals: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """``EC(A_j) = sum_Y weights[Y] * marginals[j, Y]`` (Eqs. 11 and 13)."""
    result: np.ndarray = marginals @ weights
    return result
