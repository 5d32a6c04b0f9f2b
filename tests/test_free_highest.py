"""The default pick on a scene: the highest box whose expected cost is below the free cost."""

from __future__ import annotations

import dataclasses

import jsonschema
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import unstack
from unstack.errors import InvalidArgument
from unstack.height_veto import FREE_COST, free_highest
from unstack.jsonio import load_schema
from unstack.reasoner.decision import Decision, decide
from unstack.scene import Box, Scene
from unstack.supports import Supports


@pytest.fixture
def tall_and_low() -> Scene:
    """'tall' (centre 0.4 m) and 'low' (centre 0.15 m) stand on the floor side by side."""
    boxes = [Box("tall", [0.4, 0.4, 0.8], [1.0, 0.0, 0.4]), Box("low", [0.4, 0.4, 0.3], [1.0, 0.5, 0.15])]
    return Scene(boxes, np.zeros((0, 3)), ["tall", "low"])


def reasoned(costs: list[float], errors: list[float] | None = None) -> Decision:
    """A decision on 'tall' and 'low' with the given expected costs (and standard errors)."""
    decision = decide(Supports(["tall", "low"], [[0.0, 0.0], [0.0, 0.0]], heights=[0.0, 0.0]))
    given_errors = None if errors is None else np.array(errors)
    return dataclasses.replace(decision, expected_costs=np.array(costs), expected_cost_errors=given_errors)


def test_the_highest_free_box_is_taken_over_the_minimum(tall_and_low: Scene) -> None:
    decision = free_highest(reasoned([0.3, 0.0]), tall_and_low)
    assert (decision.choice, decision.ties, decision.free_cost) == ("tall", ("low", "tall"), FREE_COST)
    assert decision.to_dict()["free_cost"] == FREE_COST


def test_a_box_at_the_free_cost_is_not_free(tall_and_low: Scene) -> None:
    assert free_highest(reasoned([FREE_COST, 0.0]), tall_and_low).choice == "low"


def test_a_box_statics_found_holding_another_is_not_free_while_another_is(tall_and_low: Scene) -> None:
    decision = free_highest(reasoned([0.3, 0.0]), tall_and_low, holding={"tall"})
    assert (decision.choice, decision.ties) == ("low", ("low",))
    assert decision.warnings[-1].endswith(
        "'tall' (EC 0.30) below 0.5 but found by statics holding another box up: not taken as free"
    )
    only = free_highest(reasoned([0.3, 0.9]), tall_and_low, holding={"tall"})  # no other free box: as before
    assert (only.choice, only.ties) == ("tall", ("tall",))


@pytest.mark.parametrize(
    ("found", "ties"), [([("tall", "low")], ("low",)), ([("tall", "low"), ("low", "tall")], ("low", "tall"))]
)
def test_two_boxes_found_holding_each_other_up_are_both_free(
    tall_and_low: Scene, found: list[tuple[str, str]], ties: tuple[str, ...]
) -> None:
    """Findings that contradict each other come of poses off: neither keeps a box from being free."""
    from unstack.api import _free_highest

    findings = [{"supporter": supporter, "held": held} for supporter, held in found]
    supports = Supports(["tall", "low"], [[0.0, 0.3], [0.0, 0.0]], metadata={"tip_supports": findings})
    assert _free_highest(reasoned([0.3, 0.2]), tall_and_low, supports, None, None).ties == ties


def test_decide_on_a_scene_does_not_take_the_box_statics_found_holding_another() -> None:
    """'lean' leans on 'upright' (statics finds it); 'upright' is the highest box: never taken free."""
    scene = unstack.load("examples/leaning.scene.json")
    supports = unstack.support_probabilities(scene)
    assert {(found["supporter"], found["held"]) for found in supports.metadata["tip_supports"]} == {("upright", "lean")}
    for free_cost in (0.5, 0.7, 0.9):
        decision = unstack.decide(scene, seed=0, free_cost=free_cost)
        assert decision.choice != "upright" and "upright" not in decision.ties


def test_no_free_box_keeps_the_reasoners_choice(tall_and_low: Scene) -> None:
    decision = reasoned([0.9, 0.7])
    assert free_highest(decision, tall_and_low) is decision


def test_a_zero_free_cost_keeps_the_decision(tall_and_low: Scene) -> None:
    decision = reasoned([0.3, 0.0])
    assert free_highest(decision, tall_and_low, free_cost=0.0) is decision


def test_the_choice_probability_is_that_of_lying_below_the_free_cost(tall_and_low: Scene) -> None:
    exact = free_highest(reasoned([0.3, 0.0]), tall_and_low)
    sampled = free_highest(reasoned([0.5 - 0.1, 0.0], [0.1, 0.0]), tall_and_low)
    assert exact.choice_probability == 1.0
    assert sampled.choice_probability == pytest.approx(0.8413, abs=1e-4)  # one standard error below


@pytest.mark.parametrize("free_cost", [-0.1, float("nan"), float("inf"), "0.5", True])
def test_a_bad_free_cost_is_refused(tall_and_low: Scene, free_cost: object) -> None:
    with pytest.raises(InvalidArgument, match="free_cost must be"):
        free_highest(reasoned([0.3, 0.0]), tall_and_low, free_cost=free_cost)  # type: ignore[arg-type]


def test_a_box_of_another_scene_is_refused(tall_and_low: Scene) -> None:
    other = Scene([Box("x", [0.4, 0.4, 0.4], [1.0, 0.0, 0.2])], np.zeros((0, 3)), ["x"])
    with pytest.raises(InvalidArgument, match=r"the decision's boxes \['tall', 'low'\] are not in the scene"):
        free_highest(reasoned([0.3, 0.0]), other)


@settings(max_examples=80, deadline=None)
@given(
    costs=st.lists(st.floats(0.0, 3.0), min_size=2, max_size=2),
    heights=st.lists(st.floats(0.2, 2.0), min_size=2, max_size=2),
    free_cost=st.floats(0.0, 1.0),
)
def test_the_choice_is_the_highest_free_box_or_the_reasoners(
    costs: list[float], heights: list[float], free_cost: float
) -> None:
    boxes = [
        Box(box_id, [0.4, 0.4, 0.4], [1.0, 0.5 * k, z])
        for k, (box_id, z) in enumerate(zip(("tall", "low"), heights, strict=True))
    ]
    scene = Scene(boxes, np.zeros((0, 3)), ["tall", "low"])
    decision = reasoned(costs)
    chosen = free_highest(decision, scene, free_cost=free_cost)
    free = [box_id for box_id, cost in zip(("tall", "low"), costs, strict=True) if cost < free_cost]
    if not free:
        assert chosen.choice == decision.choice
    else:
        assert chosen.choice in free
        assert scene.box(chosen.choice).position[2] == max(scene.box(box_id).position[2] for box_id in free)
        jsonschema.validate(chosen.to_dict(), load_schema("unstack.decision/1"))


def test_decide_on_a_scene_takes_the_highest_free_box_by_default() -> None:
    scene = unstack.load("examples/scene3.json")
    decision = unstack.decide(scene, seed=0)
    costs = dict(zip(decision.objects, decision.expected_costs, strict=True))
    free = [box_id for box_id in decision.objects if costs[box_id] < FREE_COST]
    assert decision.free_cost == FREE_COST and decision.choice in free
    assert decision.choice == max(free, key=lambda box_id: (scene.box(box_id).position[2], box_id))
    assert unstack.decide(scene, seed=0, near_tie_margin=0.0).free_cost == 0.0  # Eq. 12 exactly


def test_decide_on_support_probabilities_refuses_a_free_cost() -> None:
    supports = unstack.load("examples/stack5.supports.json")
    assert unstack.decide(supports).free_cost == 0.0
    with pytest.raises(InvalidArgument, match="free_cost takes the highest box by its centre"):
        unstack.decide(supports, free_cost=0.5)


def test_the_moves_cost_refuses_a_free_cost() -> None:
    with pytest.raises(InvalidArgument, match="the moves cost ties by near_tie_margin alone"):
        unstack.decide(unstack.load("examples/scene3.json"), cost="moves", free_cost=0.5)


def test_a_plan_on_a_scene_takes_the_highest_free_box_at_every_step() -> None:
    scene = unstack.load("examples/leaning.scene.json")
    document = unstack.plan(scene, seed=0).to_dict()
    jsonschema.validate(document, load_schema("unstack.plan/1"))
    assert document["order"][0] == unstack.decide(scene, seed=0).choice == "lean"
    assert all(step["free_cost"] == FREE_COST for step in document["steps"])
    assert unstack.plan(scene, seed=0, free_cost=0).order[0] == unstack.decide(scene, seed=0, free_cost=0).choice


def test_a_plan_on_support_probabilities_refuses_a_free_cost() -> None:
    supports = unstack.load("examples/stack5.supports.json")
    assert "free_cost" not in unstack.plan(supports).to_dict()["steps"][0]
    with pytest.raises(InvalidArgument, match="free_cost takes the highest box by its centre"):
        unstack.plan(supports, free_cost=0.5)
