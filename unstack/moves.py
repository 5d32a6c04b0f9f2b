"""The cost a robot pays: the boxes a pick is expected to move, and the decision on it.

The reasoner's expected cost (Eq. 13) counts the boxes a pick holds up. What a robot pays
is every box that moves when the pick is taken out. :func:`decide_on_moves` computes the
reasoner's decision (the ``load`` cost, its marginals), turns each detected box's situation
into the features of :mod:`unstack.learning.pick_features`, asks the disturbance model
(:mod:`unstack.learning.disturbance`) how many boxes each pick moves, and takes the box of
fewest expected moves -- near ties (:data:`MOVES_NEAR_TIE_MARGIN`) to the box resting highest,
one layer by the fewest moves, as :func:`unstack.reasoner.decision.choose` does. Each box gets
its reasons (:func:`pick_reasons`): the relations and the load that drive its cost.

Needs a scene (a cloud and poses): a supports file has neither, and is decided on ``load``.

Examples
--------
>>> import unstack
>>> decision = unstack.decide(unstack.load("examples/pile5.scene.json"), cost="moves", seed=0)
>>> decision.cost, decision.choice in decision.objects
('moves', True)
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

from unstack.reasoner.reasons import REASON_MIN_PROBABILITY, pick_reasons
from unstack.scene import Scene
from unstack.supports import Supports

__all__ = [
    "MOVES_EXACT_MAX_BOXES",
    "MOVES_NEAR_TIE_MARGIN",
    "MOVES_RULES",
    "MOVES_VETO",
    "REASON_MIN_PROBABILITY",
    "choose_on_moves",
    "decide_on_moves",
    "pick_reasons",
]

#: Picks whose expected boxes moved lie within this of the fewest count as tied (the box
#: resting highest of them is taken).
MOVES_NEAR_TIE_MARGIN = 0.05
#: How the pick is chosen from the expected moves: ``fewest`` -- the fewest (near ties to the
#: box resting highest); ``veto`` -- the box resting highest whose expected moves are below
#: :data:`MOVES_VETO`, else the fewest (height first, vetoed where the model expects trouble).
MOVES_RULES = ("fewest", "veto")
#: A pick expected to move this many boxes or more is vetoed by the ``veto`` rule.
MOVES_VETO = 0.5
#: Groups of linked boxes up to this size get exact marginals, larger ones are sampled: the
#: compiled walk of 8 boxes takes about a second, sampling them 30 ms, and the disturbance
#: model reads marginals as features, not as the cost itself.
MOVES_EXACT_MAX_BOXES = 7


def choose_on_moves(
    objects: tuple[str, ...], moves: np.ndarray, heights: np.ndarray, *, rule: str = "fewest", margin: float
) -> tuple[str, tuple[str, ...]]:
    """The pick by ``rule`` (:data:`MOVES_RULES`) and the boxes it was chosen among.

    Examples
    --------
    >>> objects, moves, heights = ("low", "high"), np.array([0.1, 0.3]), np.array([0.0, 0.4])
    >>> choose_on_moves(objects, moves, heights, rule="fewest", margin=0.05)[0]
    'low'
    >>> choose_on_moves(objects, moves, heights, rule="veto", margin=0.05)[0]
    'high'
    """
    from unstack.errors import InvalidArgument
    from unstack.reasoner.decision import choose

    if rule not in MOVES_RULES:
        raise InvalidArgument(f"unknown moves rule {rule!r}; expected one of {', '.join(MOVES_RULES)}")
    if rule == "veto":
        allowed = [k for k in range(len(objects)) if moves[k] < MOVES_VETO]
        if allowed:
            best = max(allowed, key=lambda k: (float(heights[k]), objects[k]))
            return objects[best], tuple(sorted(objects[k] for k in allowed))
    return choose(objects, moves, heights=heights, margin=margin)


def decide_on_moves(
    scene: Scene,
    supports: Supports,
    *,
    disturbance: Any = None,
    near_tie_margin: float | None = None,
    rule: str = "fewest",
    **reasoning: Any,
) -> Any:
    """The box whose removal is expected to move the fewest boxes.

    Parameters
    ----------
    scene : Scene
        The scene ``supports`` was computed from (its detected boxes and cloud are read).
    supports : Supports
        Its support probabilities (:func:`unstack.support_probabilities`).
    disturbance : DisturbanceModel, optional
        Default: the shipped model (:func:`unstack.learning.disturbance.load_disturbance_model`).
    near_tie_margin : float, optional
        Expected moves within this of the fewest count as tied (default
        :data:`MOVES_NEAR_TIE_MARGIN`; 0: the plain minimum).
    rule : {"fewest", "veto"}
        How the pick is chosen from the expected moves (:func:`choose_on_moves`).
    **reasoning
        ``method``, ``seed``, ``samples``, ``time_limit``, ``max_boxes`` (default
        :data:`MOVES_EXACT_MAX_BOXES`) of the reasoner's decision.

    Returns
    -------
    Decision
        ``cost == "moves"``; ``expected_costs`` are the expected boxes moved; ``marginals``
        the reasoner's; ``reasons`` per box (:func:`pick_reasons`).
    """
    from unstack.learning.disturbance import load_disturbance_model
    from unstack.learning.pick_features import pick_features
    from unstack.reasoner.arguments import check_margin
    from unstack.reasoner.decision import decide

    model = _disturbance(disturbance) if disturbance is not None else _shipped(load_disturbance_model)
    margin = MOVES_NEAR_TIE_MARGIN if near_tie_margin is None else check_margin(near_tie_margin, "near_tie_margin")
    reasoning.setdefault("max_boxes", MOVES_EXACT_MAX_BOXES)
    base = decide(supports, cost="load", **reasoning)
    features = pick_features(scene, supports, base.marginals, base.expected_costs)
    moves = model.expected_moves(features)
    heights = np.asarray(supports.heights)
    choice, ties = choose_on_moves(supports.objects, moves, heights, rule=rule, margin=margin)
    return dataclasses.replace(
        base,
        choice=choice,
        ties=ties,
        expected_costs=moves,
        expected_cost_errors=None,
        cost="moves",
        choice_probability=1.0,
        near_tie_margin=margin,
        reasons=tuple(pick_reasons(supports, base.marginals, moves)),
        disturbance_model=model.source,
    )


_SHIPPED: dict[str, Any] = {}


def _shipped(loader: Any) -> Any:
    """The shipped disturbance model, loaded once per process."""
    if "model" not in _SHIPPED:
        _SHIPPED["model"] = loader()
    return _SHIPPED["model"]


def _disturbance(model: Any) -> Any:
    import os

    from unstack.errors import InvalidArgument
    from unstack.learning.disturbance import load_disturbance_model

    if isinstance(model, str | os.PathLike):
        return load_disturbance_model(model)
    if not hasattr(model, "expected_moves"):
        raise InvalidArgument(
            f"disturbance must be a model file path or a DisturbanceModel, got {type(model).__name__}"
        )
    return model
