"""Decision making (§IV): unload the box of minimum expected cost (Eqs. 11-13).

``EC(A_j) = sum_i P(w_i^c) c_ij`` (Eq. 13) with the additive cost of Eq. 11 equals
``sum_Y w_Y P(S_jY = 1 | consistent)``, so the decision needs only the conditional
marginals, which the exact engine computes without listing worlds; the SAT method lists
the worlds (Table II) and sums them.

Ties. Boxes whose EC is within ``1e-12 * max(1, min EC)`` of the minimum are tied; the
choice among them is the smallest id in Unicode code-point order. The rule depends on the
ids only, so reordering the boxes in the input never changes the choice.

Examples
--------
>>> from unstack.supports import Supports
>>> supports = Supports(["top", "bottom"], [[0.0, 0.1], [0.9, 0.0]])
>>> decision = decide(supports)
>>> decision.choice
'top'
>>> decision.expected_costs.round(3).tolist()
[0.1, 0.9]
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from unstack.errors import UnstackError
from unstack.reasoner.components import support_components
from unstack.reasoner.consistency import PREORDER_COUNTS
from unstack.reasoner.costs import cost_weights, expected_costs
from unstack.reasoner.marginals import EXACT_MAX_BOXES
from unstack.reasoner.pruning import Evidence, propagate_evidence
from unstack.reasoner.worlds import SAT_MAX_BOXES
from unstack.supports import Supports

__all__ = [
    "AUTO_SAT_MAX_BOXES",
    "DECISION_FORMAT",
    "METHODS",
    "TIE_TOLERANCE",
    "Decision",
    "choose",
    "decide",
]

DECISION_FORMAT = "unstack.decision/1"
#: Reasoning methods: ``exact`` (weighted preorder counting), ``sat`` (list worlds).
METHODS = ("auto", "exact", "sat")
#: ``auto`` lists worlds with SAT up to this size and uses the exact engine above it.
#: Measured end to end (``unstack decide --json``, best of 3, 2-core machine): SAT 0.41 s
#: vs exact 0.81 s at n = 5 (loading numba's cached engine dominates), SAT 5.2 s vs
#: exact 0.96 s at n = 6.
AUTO_SAT_MAX_BOXES = 5
#: Relative tolerance under which two expected costs count as tied.
TIE_TOLERANCE = 1e-12


@dataclass(frozen=True, eq=False)
class Decision:
    """Which box to unload first, and why.

    Attributes
    ----------
    objects : tuple of str
        Box ids (the order of every array).
    choice : str
        The box to unload first.
    expected_costs : numpy.ndarray, shape (n,)
        ``EC(A_j)`` for each box.
    marginals : numpy.ndarray, shape (n, n)
        ``P(SUPP(objects[i], objects[j]) | consistent)``.
    method : str
        ``"exact"`` or ``"sat"``.
    cost : str
        ``"count"`` or ``"mass"``.
    consistent_worlds : int or None
        Number of consistent worlds of non-zero probability, when the method counted them.
    ties : tuple of str
        Every box whose EC equals the minimum (the choice is the smallest id).
    components : tuple of tuple of str
        Groups of boxes linked by non-zero support probabilities; the reasoning runs on each
        group alone (see :mod:`unstack.reasoner.components`).
    evidence : Evidence
        Hard evidence after propagation.
    seconds : float
        Wall time of the reasoning.
    """

    objects: tuple[str, ...]
    choice: str
    expected_costs: np.ndarray
    marginals: np.ndarray
    method: str
    cost: str
    consistent_worlds: int | None
    ties: tuple[str, ...]
    evidence: Evidence
    components: tuple[tuple[str, ...], ...] = ()
    seconds: float = field(default=0.0)

    def to_dict(self) -> dict[str, Any]:
        """The ``unstack.decision/1`` JSON object."""
        data: dict[str, Any] = {
            "format": DECISION_FORMAT,
            "objects": list(self.objects),
            "choice": self.choice,
            "expected_costs": self.expected_costs.tolist(),
            "marginals": self.marginals.tolist(),
            "method": self.method,
            "cost": self.cost,
        }
        if self.consistent_worlds is not None:
            data["consistent_worlds"] = self.consistent_worlds
        data["ties"] = list(self.ties)
        data["components"] = [list(group) for group in self.components]
        data["evidence"] = {
            "forced": [list(pair) for pair in self.evidence.forced],
            "forbidden": [list(pair) for pair in self.evidence.forbidden],
        }
        data["seconds"] = round(self.seconds, 6)
        return data


def choose(objects: tuple[str, ...], costs: np.ndarray) -> tuple[str, tuple[str, ...]]:
    """Pick the minimum-EC box; ties (within :data:`TIE_TOLERANCE`) go to the smallest id.

    Examples
    --------
    >>> choose(("b", "a", "c"), np.array([0.5, 0.5, 0.7]))
    ('a', ('a', 'b'))
    """
    lowest = float(np.min(costs))
    tolerance = TIE_TOLERANCE * max(1.0, abs(lowest))
    tied = tuple(sorted(objects[i] for i in np.flatnonzero(costs <= lowest + tolerance)))
    return tied[0], tied


def _resolve_method(method: str, largest: int, n: int) -> str:
    """The method for groups of at most ``largest`` linked boxes (of ``n`` in all)."""
    if method not in METHODS:
        raise UnstackError(f"unknown method {method!r}; expected one of {', '.join(METHODS)}")
    if method == "auto":
        if largest <= AUTO_SAT_MAX_BOXES:
            return "sat"
        if largest > EXACT_MAX_BOXES:
            raise _too_large_for_all(largest, n)
        return "exact"
    return method


def _too_large_for_all(largest: int, n: int) -> UnstackError:
    from unstack.errors import TooLarge

    count = PREORDER_COUNTS[largest] if largest < len(PREORDER_COUNTS) else "over 1e13"
    where = f"{largest} linked boxes" if largest == n else f"a group of {largest} linked boxes (of {n})"
    return TooLarge(
        f"{where}: exact reasoning is limited to {EXACT_MAX_BOXES} boxes per group of boxes linked by "
        f"non-zero support probabilities ({largest} boxes have {count} consistent worlds); decide on a "
        "subset of the detected boxes"
    )


def _group_marginals(
    supports: Supports, evidence: Evidence, group: np.ndarray, method: str, max_boxes: int | None
) -> tuple[np.ndarray, int | None]:
    """Conditional marginals and world count of one group of linked boxes."""
    probabilities = evidence.probabilities[np.ix_(group, group)]
    if method == "sat":
        from unstack.reasoner.worlds import enumerate_worlds

        objects = [supports.objects[i] for i in group]
        world_set = enumerate_worlds(Supports(objects, probabilities), max_boxes=max_boxes or SAT_MAX_BOXES)
        return world_set.marginals(), len(world_set)
    from unstack.reasoner.marginals import exact_marginals

    result = exact_marginals(probabilities, max_boxes=max_boxes or EXACT_MAX_BOXES)
    return result.marginals, result.consistent_worlds


def decide(
    supports: Supports,
    *,
    method: str = "auto",
    cost: str = "count",
    max_boxes: int | None = None,
) -> Decision:
    """Choose the box to unload first (Eq. 12) from pairwise support probabilities.

    Parameters
    ----------
    supports : Supports
        Detected boxes and ``P(SUPP(X, Y))`` for every ordered pair.
    method : {"auto", "exact", "sat"}
        ``exact``: weighted counting of preorders (no world list, up to 8 boxes by
        default); ``sat``: list the consistent worlds with CaDiCaL (up to 6 boxes);
        ``auto``: the faster of the two for the size.
    cost : {"count", "mass"}
        Eq. 11 (number of supported boxes) or their total mass (needs masses).
    max_boxes : int, optional
        Override the method's size limit.

    Returns
    -------
    Decision

    Raises
    ------
    NoConsistentWorld
        Hard evidence contradicts transitivity (the message names the relations).
    TooLarge
        The scene is beyond the method's limit.
    """
    start = time.perf_counter()
    n = supports.n_objects
    weights = cost_weights(supports, cost)
    evidence = propagate_evidence(supports.objects, supports.probabilities)
    groups = support_components(evidence.probabilities)
    largest = max(len(group) for group in groups)
    chosen_method = _resolve_method(method, largest, n)
    marginals = np.zeros((n, n))
    worlds: int | None = 1
    for group in groups:
        if len(group) == 1:
            continue
        group_marginals, group_worlds = _group_marginals(supports, evidence, group, chosen_method, max_boxes)
        marginals[np.ix_(group, group)] = group_marginals
        worlds = None if worlds is None or group_worlds is None else worlds * group_worlds
    costs = expected_costs(marginals, weights)
    choice, ties = choose(supports.objects, costs)
    return Decision(
        objects=supports.objects,
        choice=choice,
        components=tuple(tuple(supports.objects[i] for i in group) for group in groups),
        expected_costs=costs,
        marginals=marginals,
        method=chosen_method,
        cost=cost,
        consistent_worlds=worlds,
        ties=ties,
        evidence=evidence,
        seconds=time.perf_counter() - start,
    )
