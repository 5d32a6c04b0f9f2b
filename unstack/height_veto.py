"""The highest box that unstack does not believe holds anything up: the default pick on a scene.

Over whole containers the highest detected box is rarely wrong, and the expected cost knows
what height cannot: load on a box that the detector missed but the cloud shows, a box that
holds up another. :func:`free_highest` takes the highest detected box (its centre's height)
whose expected cost is below :data:`FREE_COST` (the bound of a free box in the
generalisation suite); when every box costs more, the reasoner's own choice (near ties to the
box resting highest). It is the default decision on a scene (:func:`unstack.decide`,
``unstack decide scene.json``): with a detector that misses half the boxes it moved fewer
boxes than the reasoner's near ties alone on every family of the results page.
:func:`hybrid_choice` is the measured ``hybrid`` container maker, which falls back to the
minimum expected cost instead.

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

from collections.abc import Collection, Mapping, Sequence
from typing import TYPE_CHECKING, Any

from unstack.errors import InvalidArgument
from unstack.scene import Scene

if TYPE_CHECKING:
    from unstack.reasoner.decision import Decision

__all__ = ["FREE_COST", "HYBRID_MAX_COST", "free_highest", "highest_free_box", "hybrid_choice", "probability_below"]

#: A box whose expected cost is below this counts as holding nothing up.
FREE_COST = 0.5
#: The ``hybrid`` maker's bound (:data:`FREE_COST`).
HYBRID_MAX_COST = FREE_COST


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


def free_highest(
    decision: Decision, scene: Scene, *, free_cost: float = FREE_COST, holding: Collection[str] = ()
) -> Decision:
    """The decision with its choice the highest box whose expected cost is below ``free_cost``.

    Parameters
    ----------
    decision : Decision
        The reasoner's decision on ``scene``'s detected boxes (its ``objects``).
    scene : Scene
        Where the boxes are: a box's height is its centre's z.
    free_cost : float
        Boxes below it count as holding nothing up; 0 keeps the decision as it is.
    holding : collection of str
        Boxes known to hold another up whatever their expected cost (statics' findings:
        ``supports.metadata["tip_supports"]``): not free while another box is.

    Returns
    -------
    Decision
        With ``choice`` the highest free box (ties in height: the larger id), ``ties`` every
        free box, ``free_cost`` set and ``choice_probability`` the probability that the
        choice's true expected cost is below ``free_cost`` (normal, from its standard error);
        the decision unchanged when no box is free.

    Raises
    ------
    InvalidArgument
        ``free_cost`` negative or not finite, or a box of the decision not in the scene.

    Examples
    --------
    'lean' leans on 'upright'; it and 'free' hold nothing up, and 'lean' is the higher:

    >>> import unstack
    >>> scene = unstack.load("examples/leaning.scene.json")
    >>> reasoner = unstack.decide(scene, free_cost=0)  # the reasoner's own choice
    >>> reasoner.choice, free_highest(reasoner, scene).choice, free_highest(reasoner, scene, free_cost=0.05).choice
    ('free', 'lean', 'free')
    """
    import dataclasses

    from unstack.reasoner.arguments import check_margin

    free_cost = check_margin(free_cost, "free_cost")
    unknown = [box_id for box_id in decision.objects if box_id not in scene.box_ids]
    if unknown:
        raise InvalidArgument(f"{scene.source}: the decision's boxes {unknown} are not in the scene")
    costs = {box_id: float(cost) for box_id, cost in zip(decision.objects, decision.expected_costs, strict=True)}
    free = sorted(box_id for box_id in decision.objects if costs[box_id] < free_cost)
    held = [box_id for box_id in free if box_id in holding]
    said = decision.warnings
    if held and len(held) < len(free):  # another box is free: those statics found holding a box up are not
        free = [box_id for box_id in free if box_id not in holding]
        said = (
            *said,
            f"{scene.source}: {', '.join(f'{box_id!r} (EC {costs[box_id]:.2f})' for box_id in held)} below "
            f"{free_cost:g} but found by statics holding another box up: not taken as free",
        )
    if not free:
        return decision
    choice = highest_free_box(scene, costs, max_cost=free_cost, candidates=free)
    below = probability_below(decision, choice, free_cost)
    return dataclasses.replace(
        decision, choice=choice, ties=tuple(free), free_cost=free_cost, choice_probability=below, warnings=said
    )


def probability_below(decision: Decision, box_id: str, bound: float) -> float:
    """The probability that the true expected cost of ``box_id`` is below ``bound``: 0 or 1 for
    an exact cost, else normal from its standard error.

    Examples
    --------
    >>> import unstack
    >>> decision = unstack.decide(unstack.Supports(["a", "b"], [[0, 0.2], [0.7, 0]]))
    >>> probability_below(decision, "a", 0.5), probability_below(decision, "b", 0.5)
    (1.0, 0.0)
    """
    import math

    index = decision.objects.index(box_id)
    cost = float(decision.expected_costs[index])
    errors = decision.expected_cost_errors
    error = 0.0 if errors is None else float(errors[index])
    if error == 0.0:
        return 1.0 if cost < bound else 0.0
    return 0.5 * (1.0 + math.erf((bound - cost) / (error * math.sqrt(2.0))))
