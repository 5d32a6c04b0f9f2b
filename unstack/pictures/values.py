"""What a picture shows of a decision, as plain values: ids, costs, errors, choice, order, supports.

The pictures never run the reasoner: a caller (the CLI, a planner) decides and hands the
numbers in, or they are read from a stored ``unstack.decision/1`` file.

Examples
--------
>>> values = DecisionValues(("a", "b"), [0.2, 1.0], choice="a", probabilities=[[0, 0.1], [0.9, 0]])
>>> values.cost_of("b"), values.strongest("b", limit=1)
(1.0, [('supports', 'a', 0.9)])
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from unstack.errors import InvalidArgument
from unstack.frozen import set_frozen_fields

__all__ = ["DecisionValues", "check_threshold", "read_decision_values"]


def check_threshold(threshold: float) -> float:
    """``threshold`` as a float in [0, 1], or an :class:`InvalidArgument` naming it.

    Examples
    --------
    >>> check_threshold(0.5)
    0.5
    >>> check_threshold(1.5)
    Traceback (most recent call last):
    ...
    unstack.errors.InvalidArgument: threshold must be a probability in [0, 1], got 1.5
    """
    value = float(threshold)
    if not 0.0 <= value <= 1.0:
        raise InvalidArgument(f"threshold must be a probability in [0, 1], got {threshold:g}")
    return value


@dataclass(frozen=True, eq=False)
class DecisionValues:
    """A decision as numbers: what a picture colours, marks and connects.

    Parameters
    ----------
    objects : sequence of str
        Box ids (the order of every array).
    expected_costs : array-like, shape (n,)
        EC of each box.
    expected_cost_errors : array-like, shape (n,), optional
        Standard error of each EC (0 where exact; None: all exact).
    choice : str, optional
        The box chosen first.
    order : sequence of str, optional
        The unloading order (a plan).
    probabilities : array-like, shape (n, n), optional
        ``[i, j]`` = P(objects[i] supports objects[j]), drawn as arrows above a threshold.
    cost_name : str
        What the cost counts, for the colour bar.
    source : str
        Where the values came from (for error messages).
    warnings : sequence of str
        The decision's doubts about its input, one sentence each (a picture shows none of them).
    """

    objects: tuple[str, ...]
    expected_costs: np.ndarray
    expected_cost_errors: np.ndarray
    choice: str | None
    order: tuple[str, ...]
    probabilities: np.ndarray | None
    cost_name: str
    source: str
    warnings: tuple[str, ...]

    def __init__(
        self,
        objects: Sequence[str],
        expected_costs: Any,
        expected_cost_errors: Any = None,
        *,
        choice: str | None = None,
        order: Sequence[str] | None = None,
        probabilities: Any = None,
        cost_name: str = "expected cost",
        source: str = "<values>",
        warnings: Sequence[str] = (),
    ) -> None:
        ids = tuple(str(box) for box in objects)
        n = len(ids)
        costs = np.asarray(expected_costs, dtype=np.float64).reshape(-1)
        errors = (
            np.zeros(n) if expected_cost_errors is None else np.asarray(expected_cost_errors, dtype=np.float64)
        ).reshape(-1)
        if costs.shape != (n,) or errors.shape != (n,):
            raise InvalidArgument(
                f"{source}: expected {n} expected costs and errors, got {costs.size} and {errors.size}"
            )
        matrix = None
        if probabilities is not None:
            matrix = np.asarray(probabilities, dtype=np.float64)
            if matrix.shape != (n, n):
                raise InvalidArgument(f"{source}: expected a {n} x {n} probability matrix, got shape {matrix.shape}")
        known = set(ids)
        if choice is not None and choice not in known:
            raise InvalidArgument(f"{source}: the choice {choice!r} is not one of the boxes")
        plan = tuple(order or ())
        if any(box not in known for box in plan) or len(set(plan)) != len(plan):
            raise InvalidArgument(f"{source}: the order must list distinct boxes of the decision")
        set_frozen_fields(
            self,
            objects=ids,
            expected_costs=costs,
            expected_cost_errors=errors,
            choice=choice,
            order=plan,
            probabilities=matrix,
            cost_name=cost_name,
            source=source,
            warnings=tuple(str(warning) for warning in warnings),
        )

    @classmethod
    def from_decision(cls, decision: Any, *, order: Sequence[str] | None = None, source: str = "<decision>") -> Any:
        """The numbers of a :class:`~unstack.reasoner.decision.Decision` (and a plan's order) to draw.

        Examples
        --------
        >>> from unstack.reasoner.decision import decide
        >>> from unstack.supports import Supports
        >>> values = DecisionValues.from_decision(decide(Supports(["top", "bottom"], [[0, 0.1], [0.9, 0]])))
        >>> values.choice, values.cost_name
        ('top', 'expected cost (load)')
        """
        return cls(
            decision.objects,
            decision.expected_costs,
            decision.expected_cost_errors,
            choice=decision.choice,
            order=order,
            probabilities=decision.marginals,
            cost_name=f"expected cost ({decision.cost})",
            source=source,
            warnings=decision.warnings,
        )

    def index(self, box: str) -> int:
        """Position of ``box`` in :attr:`objects`."""
        return self.objects.index(box)

    def cost_of(self, box: str) -> float:
        """EC of ``box``."""
        return float(self.expected_costs[self.index(box)])

    def error_of(self, box: str) -> float:
        """Standard error of the EC of ``box`` (0 when exact)."""
        return float(self.expected_cost_errors[self.index(box)])

    @property
    def sampled(self) -> bool:
        """Whether any EC has a standard error."""
        return bool(np.any(self.expected_cost_errors > 0))

    def cost_text(self, box: str) -> str:
        """``"EC 1.23"`` or ``"EC 1.23 ± 0.04"`` where sampled.

        Examples
        --------
        >>> DecisionValues(["a"], [1.234], [0.04]).cost_text("a")
        'EC 1.23 ± 0.04'
        """
        text = f"EC {self.cost_of(box):.2f}"
        error = self.error_of(box)
        return f"{text} ± {error:.2f}" if error > 0 else text

    def plan_number(self, box: str) -> int | None:
        """1-based position of ``box`` in the order, or None."""
        return self.order.index(box) + 1 if box in self.order else None

    def strongest(self, box: str, *, limit: int = 3, floor: float = 0.05) -> list[tuple[str, str, float]]:
        """The most probable support relations of ``box``, strongest first.

        Returns
        -------
        list of (str, str, float)
            ``("supports", other, p)`` (``box`` supports ``other``) or ``("rests on", other, p)``.
        """
        if self.probabilities is None:
            return []
        i = self.index(box)
        relations = [("supports", other, float(self.probabilities[i, j])) for j, other in enumerate(self.objects)]
        relations += [("rests on", other, float(self.probabilities[j, i])) for j, other in enumerate(self.objects)]
        kept = [relation for relation in relations if relation[1] != box and relation[2] >= floor]
        return sorted(kept, key=lambda relation: -relation[2])[:limit]

    def arrows(self, threshold: float) -> list[tuple[str, str, float]]:
        """Every ordered pair (supporter, supported, p) with p >= ``threshold`` (> 0), strongest last.

        Examples
        --------
        >>> DecisionValues(["a", "b"], [0, 1], probabilities=[[0, 0.2], [0.7, 0]]).arrows(0.5)
        [('b', 'a', 0.7)]
        """
        threshold = check_threshold(threshold)
        if self.probabilities is None:
            return []
        pairs = [
            (self.objects[i], self.objects[j], float(self.probabilities[i, j]))
            for i in range(len(self.objects))
            for j in range(len(self.objects))
            if i != j and self.probabilities[i, j] >= threshold and self.probabilities[i, j] > 0
        ]
        return sorted(pairs, key=lambda pair: pair[2])

    def check_boxes(self, box_ids: Sequence[str], scene_source: str) -> None:
        """Refuse values whose boxes are not all in the scene (``box_ids``).

        Raises
        ------
        InvalidArgument
            Naming the first few boxes the scene lacks.
        """
        missing = [box for box in self.objects if box not in set(box_ids)]
        if missing:
            shown = ", ".join(repr(box) for box in missing[:3]) + (" ..." if len(missing) > 3 else "")
            raise InvalidArgument(
                f"{self.source}: the decision's boxes do not match {scene_source}: {shown} "
                f"{'is' if len(missing) == 1 else 'are'} not in the scene"
            )


def read_decision_values(path: str | os.PathLike[str]) -> DecisionValues:
    """The values of a stored ``unstack.decision/1`` file (arrows from its consistent marginals).

    Raises
    ------
    InvalidFile
        Missing, not JSON, another format, or against the schema.

    Examples
    --------
    >>> import json, tempfile, pathlib
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "decision.json"
    >>> _ = path.write_text(json.dumps({"format": "unstack.decision/1", "objects": ["a", "b"], "choice": "a",
    ...     "expected_costs": [0.1, 0.9], "marginals": [[0, 0.1], [0.9, 0]], "method": "exact", "cost": "count"}))
    >>> read_decision_values(path).choice
    'a'
    """
    from unstack.checks import check_decision_document
    from unstack.jsonio import read_document, validate_document

    document = read_document(path)
    validate_document(document, ["unstack.decision/1"])
    check_decision_document(document)
    data = document.data
    objects, marginals = data["objects"], data["marginals"]
    return DecisionValues(
        objects,
        data["expected_costs"],
        data.get("expected_cost_errors"),
        choice=data["choice"],
        probabilities=marginals,
        cost_name=f"expected cost ({data['cost']})",
        source=document.source,
        warnings=data.get("warnings", ()),
    )
