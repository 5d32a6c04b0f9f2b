"""What a decision's or a plan's schema cannot say, checked by ``validate`` and by the pictures."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

import unstack
from unstack.errors import InvalidFile
from unstack.pictures.values import read_decision_values

SUPPORTS = unstack.Supports(["a", "b", "c"], [[0, 0.8, 0.1], [0.1, 0, 0.7], [0.0, 0.1, 0]])
#: A physics veto's record as a decision writes it (the pick tried and kept).
VETO = {"fill": "faces", "worlds": 4, "veto_at": 1.0, "vetoed": False, "tried": [{"box": "a", "expected_moved": 0.0}]}


def _written(tmp_path: Path, document: dict[str, Any]) -> Path:
    path = tmp_path / "document.json"
    path.write_text(json.dumps(document))
    return path


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"choice": "z"}, r"\$\.choice: expected one of the objects, got 'z'"),
        ({"expected_costs": [0.0, 1.0]}, r"\$\.expected_costs: expected 3 numbers \(one per object\), got 2"),
        ({"marginals": [[0.0] * 3] * 2}, r"\$\.marginals: expected a 3 x 3 matrix"),
        ({"ties": ["a", "z"]}, r"\$\.ties\[1\]: expected one of the objects, got 'z'"),
        (
            {"physics_veto": {**VETO, "skipped": ["'a' floats 0.30 m up"], "vetoed": True, "tried": []}},
            r"\$\.physics_veto\.vetoed: expected false: the veto was not applied \(skipped\)",
        ),
        (
            {"physics_veto": {**VETO, "skipped": ["'a' floats 0.30 m up"]}},
            r"\$\.physics_veto\.tried: expected no box tried: the veto was not applied \(skipped\)",
        ),
        ({"physics_veto": {**VETO, "tried": []}}, r"\$\.physics_veto\.tried: expected at least the pick tried"),
        ({"objects": ["a", "a", "c"], "choice": "a"}, r"\$\.objects: expected each box once, 'a' appears twice"),
        (
            {"marginals": [[1.0, 0.5, 0.0], [0.0] * 3, [0.0] * 3]},
            r"\$\.marginals\[0\]\[0\]: expected 0 on the diagonal",
        ),
        ({"marginal_errors": [[0.0]]}, r"\$\.marginal_errors: expected a 3 x 3 matrix"),
        ({"components": [["a", "z"]]}, r"\$\.components\[0\]\[1\]: expected one of the objects, got 'z'"),
        ({"components": [["a", "b"], ["b"]]}, r"\$\.components: expected each box once, 'b' appears twice"),
        ({"component_methods": ["exact", "sat"]}, r"\$\.component_methods: expected one method per component \(1\)"),
        ({"evidence": {"forced": [["a", "z"]]}}, r"\$\.evidence\.forced\[0\]\[1\]: expected one of the objects"),
        (
            {"pick": {"rests_at": 0.3, "height_rank": 5, "boxes": 3}},
            r"\$\.pick\.height_rank: expected at most the 3 boxes ranked",
        ),
        ({"expected_costs": [0.0, 10**400, 0.0]}, r"\$\.expected_costs\[1\]: expected a finite number, got an integer"),
    ],
)
def test_a_decision_at_odds_with_its_objects_is_invalid_for_validate_and_render(
    tmp_path: Path, change: dict[str, Any], message: str
) -> None:
    path = _written(tmp_path, {**unstack.decide(SUPPORTS).to_dict(), **change})
    with pytest.raises(InvalidFile, match=message):
        unstack.validate(path)
    with pytest.raises(InvalidFile, match=message):
        read_decision_values(path)


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (
            lambda plan: {"order": plan["order"][:-1] + plan["order"][:1]},
            r"\$\.order: expected each of the objects once",
        ),
        (lambda plan: {"order": plan["order"][::-1]}, r"\$\.steps\[0\]\.choice: expected '.*', the order's box"),
        (lambda plan: {"steps": plan["steps"][:2]}, r"\$\.steps: expected 3 steps"),
    ],
)
def test_a_plan_whose_steps_do_not_follow_its_order_is_invalid(tmp_path: Path, change: Any, message: str) -> None:
    plan = unstack.plan(SUPPORTS).to_dict()
    with pytest.raises(InvalidFile, match=message):
        unstack.validate(_written(tmp_path, {**plan, **change(plan)}))


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (lambda reasons: reasons[:2], r"\$\.reasons: expected one reason per object, in the objects' order \(3\)"),
        (lambda reasons: [{**reasons[0], "holds_up": [["z", 0.5]]}, *reasons[1:]], r"reasons\[0\]\.holds_up\[0\]\[0\]"),
        (
            lambda reasons: [{**reasons[0], "holds_up": [["b", 7.5]]}, *reasons[1:]],
            r"holds_up\[0\]\[1\]: expected a proba",
        ),
        (lambda reasons: [{**reasons[0], "held_by": ["z", 0.1]}, *reasons[1:]], r"\$\.reasons\[0\]\.held_by\[0\]"),
        (lambda reasons: [{**reasons[0], "holds_up": [[[], 0.5]]}, *reasons[1:]], r"holds_up\[0\]\[0\]: expected one"),
    ],
    ids=["short", "unknown-box", "not-a-probability", "unknown-holder", "a-list-for-a-box"],
)
def test_a_decisions_reasons_name_its_objects_with_probabilities(tmp_path: Path, change: Any, message: str) -> None:
    decision = unstack.decide(SUPPORTS).to_dict()
    with pytest.raises(InvalidFile, match=message):
        unstack.validate(_written(tmp_path, {**decision, "reasons": change(decision["reasons"])}))


PAYOFF = unstack.api.payoff(SUPPORTS).to_dict()


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"objects": ["a", "b", "b"]}, r"\$\.objects: expected each box once, 'b' appears twice"),
        ({"consistent_worlds": 999}, r"\$\.consistent_worlds: expected the 17 worlds listed"),
        ({"expected_costs": [0.0]}, r"\$\.expected_costs: expected 3 numbers \(one per object\)"),
        ({"expected_costs": [9.0, 0.0, 0.0]}, r"\$\.expected_costs\[0\]: expected the worlds' weighted cost"),
        (
            {"worlds": [{**PAYOFF["worlds"][0], "costs": [0.0]}, *PAYOFF["worlds"][1:]]},
            r"worlds\[0\]\.costs: expected 3",
        ),
        (
            {"worlds": [{**PAYOFF["worlds"][0], "supports": [["z", "a"]]}, *PAYOFF["worlds"][1:]]},
            r"\$\.worlds\[0\]\.supports\[0\]\[0\]: expected one of the objects, got 'z'",
        ),
        (
            {"worlds": [{**PAYOFF["worlds"][0], "probability": 0.9}, *PAYOFF["worlds"][1:]]},
            r"\$\.worlds: expected probabilities summing to 1",
        ),
    ],
    ids=["twice", "count", "costs-length", "not-the-weighted-sum", "world-costs", "unknown-box", "sum"],
)
def test_a_payoff_matrix_at_odds_with_its_worlds_is_invalid(
    tmp_path: Path, change: dict[str, Any], message: str
) -> None:
    with pytest.raises(InvalidFile, match=message):
        unstack.validate(_written(tmp_path, {**PAYOFF, **change}))


def test_a_decision_and_a_plan_as_written_are_valid(tmp_path: Path) -> None:
    assert unstack.validate(_written(tmp_path, unstack.decide(SUPPORTS).to_dict())).format == "unstack.decision/1"
    assert unstack.validate(_written(tmp_path, unstack.plan(SUPPORTS).to_dict())).format == "unstack.plan/1"
    assert unstack.validate(_written(tmp_path, PAYOFF)).format == "unstack.payoff/1"


def test_keys_of_a_decisions_evidence_beyond_its_two_lists_are_not_read(tmp_path: Path) -> None:
    """The schema lets the evidence object hold more; the check iterated them (a TypeError on a number)."""
    decision = unstack.decide(SUPPORTS).to_dict()
    document = {**decision, "evidence": {**decision["evidence"], "note": 1}}
    assert unstack.validate(_written(tmp_path, document)).format == "unstack.decision/1"
