"""An unloading plan: repeated decisions, each on the boxes still in place.

Decide on all detected boxes, take the chosen box out of the set, decide again on the rest,
until every box is taken (the last step decides on a single box). Each step records the
chosen box and its expected cost among the boxes that remained at that step. The
probabilities of the remaining boxes are not re-estimated: the plan is what the reasoner
would do without a new scan after each pick.

The steps share their work (:mod:`unstack.reasoner.reuse`): groups of linked boxes that the
pick left unchanged keep their marginals, and the group that lost the box is sampled from
where the previous step's chains ended. A ``progress(done, total)`` callback hears of every
step; the library prints nothing.

Examples
--------
>>> from unstack.supports import Supports
>>> supports = Supports(["top", "middle", "bottom"], [[0, 0.05, 0.02], [0.9, 0, 0.1], [0.8, 0.95, 0]])
>>> [step.choice for step in unloading_plan(supports).steps]
['top', 'middle', 'bottom']
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from unstack.errors import InvalidArgument
from unstack.reasoner.costs import DEFAULT_COST
from unstack.reasoner.decision import UNSAMPLED_METHODS, Decision, decide
from unstack.reasoner.reuse import WorkCache
from unstack.supports import Supports

__all__ = ["PLAN_EXACT_MAX_BOXES", "PLAN_FORMAT", "PLAN_SAMPLES", "Plan", "PlanStep", "unloading_plan"]

PLAN_FORMAT = "unstack.plan/1"
#: Largest group a plan's step counts exactly with ``auto`` (8 boxes take 2.6-4 s a step).
PLAN_EXACT_MAX_BOXES = 7
#: Recorded sweeps per sampled group and step when neither ``samples`` nor ``time_limit``
#: is given (the chains start warm from the previous step). 2048 since a sweep re-inserts
#: :data:`~unstack.reasoner.sampling.MOVES` boxes (it was 1024 sweeps of every box): about
#: the same time per plan, and no larger standard errors (docs page "Benchmarks", "Plans").
PLAN_SAMPLES = 2048


@dataclass(frozen=True)
class PlanStep:
    """One pick of a plan: the chosen box, its expected cost, and the full decision.

    Attributes
    ----------
    choice : str
        The box taken at this step.
    expected_cost : float
        Its expected cost among the boxes still in place.
    remaining : tuple of str
        The boxes in place when the step was decided (``choice`` among them).
    decision : Decision
        The whole decision on them.
    """

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
    def warnings(self) -> tuple[str, ...]:
        """Doubts about the input (those of the first decision: the input's own warnings)."""
        return self.steps[0].decision.warnings if self.steps else ()

    @property
    def order(self) -> list[str]:
        """Box ids in unloading order."""
        return [step.choice for step in self.steps]

    def to_dict(self) -> dict[str, Any]:
        """The ``unstack.plan/1`` JSON object (canonical: no wall-clock time).

        Returns
        -------
        dict

        Examples
        --------
        >>> from unstack.supports import Supports
        >>> unloading_plan(Supports(["a", "b"], [[0, 0.2], [0.7, 0]])).to_dict()["order"]
        ['a', 'b']
        """
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
                    **({"near_tie_margin": step.decision.near_tie_margin} if step.decision.near_tie_margin else {}),
                    **({"free_cost": step.decision.free_cost} if step.decision.free_cost else {}),
                }
                for step in self.steps
            ],
            "warnings": list(self.warnings),
        }


def _check_progress(progress: Any) -> None:
    """Raise before any work when ``progress`` cannot be called as ``progress(done, total)``."""
    if progress is None:
        return
    import inspect

    if not callable(progress) or isinstance(progress, type) or inspect.isgeneratorfunction(progress):
        kind = (  # a class is called to make an object, a generator function's body runs only when iterated
            f"the class {progress.__name__}" if isinstance(progress, type)
            else "a generator function" if callable(progress) else type(progress).__name__
        )  # fmt: skip
        raise InvalidArgument(f"progress must be a callable progress(done, total), got {kind}")

    try:
        signature = inspect.signature(progress)
    except (TypeError, ValueError):  # a callable without a signature to read (some builtins): trusted
        return
    try:
        signature.bind(0, 0)
    except TypeError as error:
        raise InvalidArgument(f"progress must take two arguments, progress(done, total): {error}") from None


def unloading_plan(
    supports: Supports,
    *,
    method: str = "auto",
    cost: str = DEFAULT_COST,
    time_limit: float | None = None,
    samples: int | None = None,
    seed: int | None = None,
    progress: Callable[[int, int], None] | None = None,
    near_tie_margin: float | None = None,
    choose_step: Callable[[Decision], Decision] | None = None,
) -> Plan:
    """Order every box by repeated minimum-EC decisions (see the module docstring).

    Parameters
    ----------
    supports : Supports
        The detected boxes and their support probabilities.
    method, cost, time_limit, samples, seed, near_tie_margin
        As in :func:`~unstack.reasoner.decision.decide`, applied to each step (so with a
        seed and no ``time_limit`` the plan is reproducible); without a budget each step
        samples :data:`PLAN_SAMPLES` sweeps per group, and ``auto`` counts groups of up to
        :data:`PLAN_EXACT_MAX_BOXES` boxes exactly.
    progress : callable, optional
        Called as ``progress(done, total)`` after every step (``total`` picks in all).
    choose_step : callable, optional
        Makes each step's choice from its decision (returns the decision with its ``choice``
        set; :func:`unstack.api.plan` passes the scene's free-box rule,
        :func:`unstack.height_veto.free_highest`); default: the reasoner's choice.

    Returns
    -------
    Plan

    Raises
    ------
    InvalidArgument
        An argument out of its domain (checked before the first step).

    Examples
    --------
    >>> from unstack.supports import Supports
    >>> unloading_plan(Supports(["a", "b"], [[0, 0.2], [0.7, 0]])).order
    ['a', 'b']
    """
    _check_progress(progress)
    remaining = list(supports.objects) if isinstance(supports, Supports) else []
    steps: list[PlanStep] = []
    work = WorkCache()
    if samples is None and time_limit is None and method not in UNSAMPLED_METHODS:
        samples = PLAN_SAMPLES
    while True:
        decision = decide(
            supports.subset(remaining) if steps else supports,
            method=method,
            cost=cost,
            time_limit=time_limit,
            samples=samples,
            seed=seed,
            cache=work,
            max_boxes=PLAN_EXACT_MAX_BOXES if method == "auto" else None,
            near_tie_margin=near_tie_margin,
        )
        if choose_step is not None:
            decision = choose_step(decision)
        chosen = decision.objects.index(decision.choice)
        steps.append(PlanStep(decision.choice, float(decision.expected_costs[chosen]), tuple(remaining), decision))
        remaining.remove(decision.choice)
        if progress is not None:
            progress(len(steps), len(supports.objects))
        if not remaining:
            return Plan(supports.objects, tuple(steps))
