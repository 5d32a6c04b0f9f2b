"""An unloading plan: repeated decisions, each on the boxes still in place.

Decide on all detected boxes, take the chosen box out of the set, decide again on the rest,
until one box is left. Each step records the chosen box and its expected cost among the
boxes that remained at that step. The probabilities of the remaining boxes are not
re-estimated: the plan is what the reasoner would do without a new scan after each pick.

Examples
--------
>>> from unstack.supports import Supports
>>> supports = Supports(["top", "middle", "bottom"], [[0, 0.05, 0.02], [0.9, 0, 0.1], [0.8, 0.95, 0]])
>>> [step.choice for step in unloading_plan(supports).steps]
['top', 'middle', 'bottom']
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from unstack.reasoner.costs import DEFAULT_COST
from unstack.reasoner.decision import Decision, decide
from unstack.supports import Supports

__all__ = ["PLAN_FORMAT", "Plan", "PlanStep", "unloading_plan"]

PLAN_FORMAT = "unstack.plan/1"


@dataclass(frozen=True)
class PlanStep:
    """One pick of a plan: the chosen box, its expected cost, and the full decision."""

    choice: str
    expected_cost: float
    remaining: tuple[str, ...]
    decision: Decision

    @property
    def expected_cost_error(self) -> float:
        """Standard error of ``expected_cost`` (0 when exact)."""
        errors = self.decision.expected_cost_errors
        return 0.0 if errors is None else float(errors[self.decision.objects.index(self.choice)])


@dataclass(frozen=True)
class Plan:
    """The order in which to unload the boxes."""

    objects: tuple[str, ...]
    steps: tuple[PlanStep, ...]

    @property
    def order(self) -> list[str]:
        """Box ids in unloading order."""
        return [step.choice for step in self.steps]

    def to_dict(self) -> dict[str, Any]:
        """The ``unstack.plan/1`` JSON object."""
        return {
            "format": PLAN_FORMAT,
            "objects": list(self.objects),
            "order": self.order,
            "steps": [
                {
                    "choice": step.choice,
                    "expected_cost": step.expected_cost,
                    "remaining": list(step.remaining),
                    "method": step.decision.method,
                    "ties": list(step.decision.ties),
                    "expected_cost_error": step.expected_cost_error,
                    "choice_probability": step.decision.choice_probability,
                }
                for step in self.steps
            ],
        }


def unloading_plan(supports: Supports, *, method: str = "auto", cost: str = DEFAULT_COST, **sampling: Any) -> Plan:
    """Order every box by repeated minimum-EC decisions (see the module docstring).

    ``sampling``: ``time_limit``, ``samples``, ``seed`` of :func:`~unstack.reasoner.decision.decide`,
    applied to each step.
    """
    remaining = list(supports.objects)
    steps = []
    while remaining:
        decision = decide(supports.subset(remaining), method=method, cost=cost, **sampling)
        chosen = decision.objects.index(decision.choice)
        steps.append(PlanStep(decision.choice, float(decision.expected_costs[chosen]), tuple(remaining), decision))
        remaining.remove(decision.choice)
    return Plan(supports.objects, tuple(steps))
