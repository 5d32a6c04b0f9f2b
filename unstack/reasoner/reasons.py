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

__all__ = ["REASONS_PER_BOX", "REASON_COSTS", "REASON_MIN_PROBABILITY", "pick_reasons"]

#: Support relations below this conditional probability are not named as a reason.
REASON_MIN_PROBABILITY = 0.2
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
        ``hidden_load`` and ``held_by`` (the box most likely holding it up, with P).

    Examples
    --------
    >>> supports = Supports(["top", "bottom"], [[0, 0.1], [0.9, 0]])
    >>> reasons = pick_reasons(supports, np.array([[0, 0.1], [0.9, 0]]), np.array([0.1, 0.9]))
    >>> reasons[1]["holds_up"], reasons[0]["held_by"]
    ([['top', 0.9]], ['bottom', 0.9])
    """
    objects = supports.objects
    hidden = np.zeros(len(objects)) if supports.hidden_load is None else np.asarray(supports.hidden_load)
    reasons = []
    for k, box_id in enumerate(objects):
        row = [(objects[j], float(marginals[k, j])) for j in range(len(objects)) if j != k]
        held = [(objects[j], float(marginals[j, k])) for j in range(len(objects)) if j != k]
        strongest = sorted((pair for pair in row if pair[1] >= REASON_MIN_PROBABILITY), key=lambda pair: -pair[1])
        holder = max(held, key=lambda pair: pair[1], default=None)
        reasons.append(
            {
                "box": box_id,
                "expected_moves": round(max(float(expected[k]), 0.0), 4),
                "holds_up": [[other, round(p, 3)] for other, p in strongest[:REASONS_PER_BOX]],
                "hidden_load": round(float(hidden[k]), 3),
                "held_by": None if holder is None else [holder[0], round(holder[1], 3)],
            }
        )
    return reasons
