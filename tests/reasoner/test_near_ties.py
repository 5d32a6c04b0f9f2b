"""Near ties in expected cost go to the box resting highest (the default decision when heights are known)."""

from __future__ import annotations

import json
from pathlib import Path

import jsonschema
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from unstack.errors import InvalidArgument, InvalidSupports
from unstack.jsonio import load_schema
from unstack.reasoner.confidence import choice_probability
from unstack.reasoner.decision import LAYER_TOLERANCE, NEAR_TIE_MARGIN, choose, decide
from unstack.supports import Supports


@pytest.fixture
def low_free_high_free_and_loaded() -> Supports:
    """'low' and 'high' hold nothing up (EC 0.01 and 0.03); 'base' holds 'high' (EC about 0.95).

    'low' and 'base' stand on the floor, 'high' rests on 'base' at 0.6 m.
    """
    probabilities = np.array(
        [
            [0.0, 0.01, 0.0],  # low
            [0.0, 0.0, 0.03],  # high
            [0.0, 0.95, 0.0],  # base
        ]
    )
    return Supports(["low", "high", "base"], probabilities, heights=[0.0, 0.6, 0.0])


def test_a_near_tie_goes_to_the_box_resting_highest(low_free_high_free_and_loaded: Supports) -> None:
    decision = decide(low_free_high_free_and_loaded)
    assert decision.near_tie_margin == NEAR_TIE_MARGIN
    assert decision.choice == "high"
    assert decision.ties == ("high", "low")
    assert decision.ranking()[0][0] == "high"


def test_a_zero_margin_keeps_eq13s_minimum(low_free_high_free_and_loaded: Supports) -> None:
    decision = decide(low_free_high_free_and_loaded, near_tie_margin=0.0)
    assert (decision.choice, decision.ties, decision.near_tie_margin) == ("low", ("low",), 0.0)
    assert "near_tie_margin" not in decision.to_dict()


def test_supports_without_heights_keep_eq13_and_refuse_a_margin() -> None:
    supports = Supports(["low", "high"], [[0.0, 0.01], [0.03, 0.0]])
    decision = decide(supports)  # EC(low) = 0.01, EC(high) = 0.03: within the margin, but no heights
    assert (decision.choice, decision.near_tie_margin) == ("low", 0.0)
    with pytest.raises(InvalidArgument, match="carry no heights"):
        decide(supports, near_tie_margin=0.05)


@pytest.mark.parametrize("margin", [-0.1, float("nan"), float("inf"), "0.05", True])
def test_a_bad_margin_is_refused(low_free_high_free_and_loaded: Supports, margin: object) -> None:
    with pytest.raises(InvalidArgument, match="near_tie_margin must be"):
        decide(low_free_high_free_and_loaded, near_tie_margin=margin)  # type: ignore[arg-type]


def test_a_box_beyond_the_margin_is_not_tied(low_free_high_free_and_loaded: Supports) -> None:
    assert decide(low_free_high_free_and_loaded, near_tie_margin=0.01).choice == "low"  # 0.03 > 0.01 + 0.01
    assert decide(low_free_high_free_and_loaded, near_tie_margin=2.0).choice == "high"  # 'base' is tied but lower


def test_on_one_layer_the_lowest_cost_wins_then_the_smallest_id() -> None:
    choice, ties = choose(("b", "a", "c"), np.array([0.0, 0.02, 0.5]), heights=np.array([0.3, 0.32, 0.9]), margin=0.05)
    assert (choice, ties) == ("b", ("a", "b"))
    choice, _ = choose(("b", "a"), np.array([0.01, 0.01]), heights=np.array([0.3, 0.3]), margin=0.05)
    assert choice == "a"


def test_a_taller_box_on_the_floor_is_not_preferred_to_a_free_one() -> None:
    """A box leaning on 'upright' that the model missed: EC 0.056 against the free box's 0.019."""
    costs = np.array([0.056, 0.072, 0.019])
    choice, ties = choose(("upright", "lean", "free"), costs, heights=np.array([0.0, 0.001, 0.0]), margin=0.05)
    assert choice == "free" and ties == ("free", "upright")


def test_a_box_resting_on_others_beats_the_boxes_under_it() -> None:
    """A wide box on three cubes whose support the model half missed (EC 0.05 each, the wide box 0.08)."""
    costs = np.array([0.05, 0.05, 0.049, 0.081])
    heights = np.array([0.0, 0.0, 0.0, 0.3])
    assert choose(("cube0", "cube1", "cube2", "wide"), costs, heights=heights, margin=0.05)[0] == "wide"


def test_boxes_within_the_layer_tolerance_rest_on_one_layer() -> None:
    heights = np.array([0.0, LAYER_TOLERANCE * 0.9])
    assert choose(("cheap", "dear"), np.array([0.01, 0.03]), heights=heights, margin=0.05)[0] == "cheap"
    heights = np.array([0.0, LAYER_TOLERANCE * 1.5])
    assert choose(("cheap", "dear"), np.array([0.01, 0.03]), heights=heights, margin=0.05)[0] == "dear"


def test_the_decision_with_near_ties_is_valid_json(low_free_high_free_and_loaded: Supports) -> None:
    document = decide(low_free_high_free_and_loaded).to_dict()
    assert document["near_tie_margin"] == NEAR_TIE_MARGIN and document["choice"] == "high"
    jsonschema.validate(json.loads(json.dumps(document)), load_schema("unstack.decision/1"))


def test_heights_travel_with_the_supports_file(low_free_high_free_and_loaded: Supports, tmp_path: Path) -> None:
    from unstack.supports import load_supports

    path = tmp_path / "s.supports.json"
    low_free_high_free_and_loaded.save(path)
    loaded = load_supports(path)
    assert loaded.heights is not None and loaded.heights.tolist() == [0.0, 0.6, 0.0]
    assert loaded.subset(["base", "low"]).heights.tolist() == [0.0, 0.0]  # type: ignore[union-attr]
    assert decide(loaded).choice == "high"


def test_a_non_finite_height_names_its_json_path() -> None:
    with pytest.raises(InvalidSupports, match=r"\$\.heights\[1\]"):
        Supports(["a", "b"], np.zeros((2, 2)), heights=[0.1, float("nan")])


def test_the_choice_probability_counts_a_choice_within_the_margin() -> None:
    costs, sd = np.array([0.00, 0.03]), 0.01
    covariance = np.eye(2) * sd**2
    strict = choice_probability(costs, covariance, 1, seed=0)
    within = choice_probability(costs, covariance, 1, seed=0, margin=0.05)
    assert strict < 0.05 and within > 0.9


@settings(max_examples=60, deadline=None)
@given(
    costs=st.lists(st.floats(0.0, 3.0), min_size=1, max_size=8),
    margin=st.floats(0.0, 0.5),
    data=st.data(),
)
def test_the_choice_rests_highest_within_a_margin_and_never_costs_more_than_it(
    costs: list[float], margin: float, data: st.DataObject
) -> None:
    heights = data.draw(st.lists(st.floats(0.0, 3.0), min_size=len(costs), max_size=len(costs)))
    objects = tuple(f"b{i}" for i in range(len(costs)))
    choice, ties = choose(objects, np.array(costs), heights=np.array(heights), margin=margin)
    chosen = objects.index(choice)
    assert costs[chosen] <= min(costs) + margin + 1e-12
    if margin == 0.0:  # Eq. 12 exactly: exact ties go to the smallest id, whatever the heights
        assert choice == ties[0]
    else:
        top = max(heights[objects.index(box)] for box in ties)
        assert heights[chosen] >= top - LAYER_TOLERANCE
        layer = [objects.index(box) for box in ties if heights[objects.index(box)] >= top - LAYER_TOLERANCE]
        assert costs[chosen] <= min(costs[i] for i in layer) + 1e-12


def test_a_plan_breaks_near_ties_at_every_step_and_says_so(low_free_high_free_and_loaded: Supports) -> None:
    from unstack.reasoner.plan import unloading_plan

    plan = unloading_plan(low_free_high_free_and_loaded)
    assert plan.order == [
        "high",
        "base",
        "low",
    ]  # 'high' first (near tie), then 'base' (0 vs 'low' 0, one layer: smallest id)
    document = plan.to_dict()
    assert all(step["near_tie_margin"] == NEAR_TIE_MARGIN for step in document["steps"])
    jsonschema.validate(json.loads(json.dumps(document)), load_schema("unstack.plan/1"))
    strict = unloading_plan(low_free_high_free_and_loaded, near_tie_margin=0.0)
    assert strict.order[0] == "low" and "near_tie_margin" not in strict.to_dict()["steps"][0]
