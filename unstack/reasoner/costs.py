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

from unstack.errors import InvalidArgument
from unstack.supports import Supports

__all__ = [
    "COSTS",
    "DEFAULT_COST",
    "PAYOFF_COSTS",
    "cost_weights",
    "expected_costs",
    "largest_expected_cost",
    "margin_beyond_every_cost",
    "own_costs",
    "weight_doubts",
]

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
            raise InvalidArgument(
                f"{supports.source}: $.masses: the mass-weighted cost needs box masses; "
                'add "masses" (kg, aligned with objects) or use the count cost'
            )
        return np.asarray(supports.masses, dtype=np.float64)
    raise InvalidArgument(f"unknown cost {cost!r}; expected one of {', '.join(COSTS)}")


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


def largest_expected_cost(supports: Supports, cost: str) -> float:
    """The largest expected cost any box of ``supports`` can have: its own cost with every
    other box held up.

    Examples
    --------
    >>> supports = Supports(["a", "b", "c"], [[0, 0.5, 0], [0, 0, 0.5], [0, 0, 0]], masses=[10.0, 2.0, 1.0])
    >>> largest_expected_cost(supports, "count"), largest_expected_cost(supports, "mass")
    (2.0, 12.0)
    """
    weights = cost_weights(supports, cost)
    return float(np.max(own_costs(supports, cost) + weights.sum() - weights))


def margin_beyond_every_cost(supports: Supports, cost: str, name: str, margin: float | None) -> str | None:
    """A warning when a margin on expected costs (``near_tie_margin``, ``free_cost``) is larger
    than any expected cost the boxes can have -- every box is then tied, or free, whatever holds
    what up: a typing error, or the reasoning switched off -- else ``None``.

    Examples
    --------
    >>> supports = Supports(["a", "b"], [[0, 0.5], [0, 0]])
    >>> print(margin_beyond_every_cost(supports, "count", "free_cost", 1e300))  # doctest: +ELLIPSIS
    free_cost 1e+300 is above any expected cost these boxes can have (1 for the count cost): every box counts ...
    >>> margin_beyond_every_cost(supports, "count", "free_cost", 0.5) is None
    True
    """
    if margin is None or supports.n_objects < 2:
        return None
    bound = largest_expected_cost(supports, cost)
    if margin <= bound:
        return None
    what = "is a near tie" if name == "near_tie_margin" else "counts as free"
    return (
        f"{name} {margin:g} is above any expected cost these boxes can have ({bound:.3g} for the {cost} cost): "
        f"every box {what} whatever it holds up, and the highest is taken"
    )


def weight_doubts(supports: Supports, cost: str) -> tuple[str, ...]:
    """What is doubtful in the weights ``cost`` gives the boxes, one sentence each: boxes lighter
    than a carton for ``"mass"``, more undetected boxes on a box than a stack holds for ``"load"``.

    Examples
    --------
    >>> weight_doubts(Supports(["a", "b"], [[0, 0.5], [0.2, 0]], masses=[12.0, 1e-9]), "mass")
    ("box 'b' (1e-09 kg) weighs less than 0.01 kg, lighter than a carton; masses in kg?",)
    """
    from unstack.checks import heavy_loads, light_boxes

    light = light_boxes(supports.objects, supports.masses) if cost == "mass" and supports.masses is not None else None
    loaded = supports.hidden_load is not None and cost == "load"
    heavy = heavy_loads(supports.objects, supports.hidden_load) if loaded else None
    return tuple(supports.named(doubt) for doubt in (light, heavy) if doubt is not None)
