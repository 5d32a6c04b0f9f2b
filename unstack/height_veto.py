"""The hybrid pick: the highest box that unstack does not believe holds anything up.

Over whole containers the highest detected box is rarely wrong, and the expected cost knows
what height cannot: load on a box that the detector missed but the cloud shows. The hybrid
takes the highest candidate whose expected cost is below :data:`HYBRID_MAX_COST` (the bound
of a free box in the generalisation suite); when every candidate costs more, the decision's
own minimum-EC choice. The results page measures it against the decision and the heuristics
(`unstack experiment container`, maker ``hybrid``).

Examples
--------
>>> import numpy as np
>>> from unstack.scene import Box, Scene
>>> boxes = [Box("tall", [0.4, 0.4, 0.8], [1.0, 0.0, 0.4]), Box("low", [0.4, 0.4, 0.3], [1.0, 0.5, 0.15])]
>>> scene = Scene(boxes, np.zeros((0, 3)), ["tall", "low"])
>>> highest_free_box(scene, {"tall": 0.9, "low": 0.01})
'low'
>>> highest_free_box(scene, {"tall": 0.2, "low": 0.01})
'tall'
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

from unstack.errors import InvalidArgument
from unstack.scene import Scene

__all__ = ["HYBRID_MAX_COST", "highest_free_box", "hybrid_choice"]

#: A candidate whose expected cost is below this counts as holding nothing up.
HYBRID_MAX_COST = 0.5


def highest_free_box(
    scene: Scene,
    expected_costs: Mapping[str, float],
    *,
    max_cost: float = HYBRID_MAX_COST,
    candidates: Sequence[str] | None = None,
) -> str:
    """The highest detected box whose expected cost is below ``max_cost``.

    Parameters
    ----------
    scene : Scene
        Its ``detected`` boxes are the candidates; a box's height is its centre's z.
    expected_costs : mapping of str to float
        The expected cost of every detected box (``dict(zip(decision.objects,
        decision.expected_costs))``).
    max_cost : float
        A box below it counts as free.
    candidates : sequence of str, optional
        Boxes to choose among instead of the scene's detected boxes (an ISet, say).

    Returns
    -------
    str
        Ties in height go to the larger id; when no box is below ``max_cost``, the box of
        lowest expected cost (ties to the smaller id).

    Raises
    ------
    InvalidArgument
        A detected box without an expected cost, or no detected box.
    """
    candidates = list(scene.detected if candidates is None else candidates)
    missing = [box_id for box_id in candidates if box_id not in expected_costs]
    if missing or not candidates:
        raise InvalidArgument(f"expected an expected cost for every detected box; missing {missing or 'boxes'}")
    free = [box_id for box_id in candidates if expected_costs[box_id] < max_cost]
    if not free:
        return min(sorted(candidates), key=lambda box_id: expected_costs[box_id])
    return max(free, key=lambda box_id: (float(scene.box(box_id).position[2]), box_id))


def hybrid_choice(scene: Scene, decision: Any, *, candidates: Sequence[str] | None = None) -> str:
    """The hybrid pick from a decision on ``scene``: :func:`highest_free_box` with its expected costs.

    ``decision``: anything with ``objects`` and ``expected_costs`` (``unstack.decide(scene)``).

    Examples
    --------
    >>> import numpy as np
    >>> from types import SimpleNamespace
    >>> from unstack.scene import Box, Scene
    >>> boxes = [Box("tall", [0.4, 0.4, 0.8], [1.0, 0.0, 0.4]), Box("low", [0.4, 0.4, 0.3], [1.0, 0.5, 0.15])]
    >>> scene = Scene(boxes, np.zeros((0, 3)), ["tall", "low"])
    >>> hybrid_choice(scene, SimpleNamespace(objects=("tall", "low"), expected_costs=np.array([0.2, 0.0])))
    'tall'
    """
    costs = {box_id: float(cost) for box_id, cost in zip(decision.objects, decision.expected_costs, strict=True)}
    return highest_free_box(scene, costs, candidates=candidates)
