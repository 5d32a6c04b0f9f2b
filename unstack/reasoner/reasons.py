"""Why a box costs what it costs: the relations and the load behind its expected cost.

The decision's expected cost of a box (Eq. 13) is a sum over the boxes it would bring down;
the reasons name the terms that matter: the detected boxes it holds up with their
conditional probability (given a consistent world), the undetected load the point cloud
shows on it, and the box most likely holding it up. ``unstack decide`` prints them for the
pick and the runner-up; ``unstack.decision/1`` carries them for every box.

Examples
--------
>>> import numpy as np
>>> from unstack.supports import Supports
>>> supports = Supports(["a", "b"], [[0, 0.8], [0.1, 0]], hidden_load=[0.0, 0.5])
>>> pick_reasons(supports, np.array([[0, 0.8], [0.1, 0]]), np.array([1.2, 0.4]))[0]["holds_up"]
[['b', 0.8]]
"""

from __future__ import annotations

from typing import Any

import numpy as np

from unstack.supports import Supports

__all__ = ["MAY_HOLD_PROBABILITY", "REASONS_PER_BOX", "REASON_COSTS", "REASON_MIN_PROBABILITY", "pick_reasons"]

#: Support relations below this conditional probability are not named as a reason.
REASON_MIN_PROBABILITY = 0.2
#: A box none of whose relations is named still names its likeliest one at or above this
#: probability (``may_hold_up``), with how many are: together they may make its cost.
MAY_HOLD_PROBABILITY = 0.05
#: At most this many relations are named per box.
REASONS_PER_BOX = 3
#: The costs whose expected cost counts boxes (the reasons' ``expected_moves``); ``mass`` counts
#: kilograms and has no reasons.
REASON_COSTS = ("load", "count", "moves")


def pick_reasons(supports: Supports, marginals: np.ndarray, expected: np.ndarray) -> list[dict[str, Any]]:
    """What drives each box's cost: the boxes it holds up (conditional P), its hidden load.

    Parameters
    ----------
    supports : Supports
        The decision's input (its objects and ``hidden_load``).
    marginals : numpy.ndarray, shape (n, n)
        ``P(SUPP(objects[i], objects[j]) | consistent)``.
    expected : numpy.ndarray, shape (n,)
        Boxes each pick is expected to move (the decision's expected costs, when they count boxes).

    Returns
    -------
    list of dict
        Per object: ``box``, ``expected_moves``, ``holds_up`` (up to :data:`REASONS_PER_BOX`
        ``[box, P]`` pairs with P at least :data:`REASON_MIN_PROBABILITY`, largest first),
        ``hidden_load`` and ``held_by`` (the box most likely holding it up, with P); a box with
        none to name has ``may_hold_up`` (``[box, P, count]``: its likeliest relation and how
        many are at least :data:`MAY_HOLD_PROBABILITY`) where one is.

    Examples
    --------
    >>> supports = Supports(["top", "bottom"], [[0, 0.1], [0.9, 0]])
    >>> reasons = pick_reasons(supports, np.array([[0, 0.1], [0.9, 0]]), np.array([0.1, 0.9]))
    >>> reasons[1]["holds_up"], reasons[0]["held_by"]
    ([['top', 0.9]], ['bottom', 0.9])
    """
    objects = supports.objects
    n = len(objects)
    hidden = np.zeros(n) if supports.hidden_load is None else np.asarray(supports.hidden_load, dtype=np.float64)
    others = np.asarray(marginals, dtype=np.float64).copy()
    np.fill_diagonal(others, -np.inf)  # a box is never its own reason
    strongest = np.argsort(-others, axis=1, kind="stable")[:, :REASONS_PER_BOX]
    holders = np.argmax(others, axis=0) if n > 1 else np.zeros(n, dtype=np.int64)
    reasons = []
    for k, box_id in enumerate(objects):
        named = [j for j in strongest[k] if others[k, j] >= REASON_MIN_PROBABILITY]
        holder = int(holders[k])
        reason = {
            "box": box_id,
            "expected_moves": round(max(float(expected[k]), 0.0), 4),
            "holds_up": [[objects[j], round(float(others[k, j]), 3)] for j in named],
            "hidden_load": round(float(hidden[k]), 3),
            "held_by": None if n < 2 else [objects[holder], round(float(others[holder, k]), 3)],
        }
        if not named and n > 1 and others[k, strongest[k][0]] >= MAY_HOLD_PROBABILITY:
            likeliest = int(strongest[k][0])  # each relation under the naming bound: the likeliest, and how many
            count = int(np.sum(others[k] >= MAY_HOLD_PROBABILITY))
            reason["may_hold_up"] = [objects[likeliest], round(float(others[k, likeliest]), 3), count]
        reasons.append(reason)
    return reasons
