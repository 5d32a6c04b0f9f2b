"""Deciding on what a pick is expected to move (the moves cost)."""

from __future__ import annotations

import json
from pathlib import Path

import jsonschema
import numpy as np
import pytest

import unstack
from unstack.errors import InvalidArgument
from unstack.jsonio import load_schema
from unstack.moves import pick_reasons
from unstack.supports import Supports

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


@pytest.fixture(scope="module")
def decision() -> unstack.Decision:
    return unstack.decide(unstack.load(EXAMPLES / "pile5.scene.json"), cost="moves", seed=0)


@pytest.mark.slow  # the support model and the disturbance model load
def test_the_choice_has_the_fewest_expected_moves_up_to_the_near_tie_margin(decision: unstack.Decision) -> None:
    from unstack.moves import MOVES_NEAR_TIE_MARGIN

    moves = dict(zip(decision.objects, decision.expected_costs, strict=True))
    assert decision.cost == "moves" and (decision.expected_costs >= 0).all()
    assert moves[decision.choice] <= min(moves.values()) + MOVES_NEAR_TIE_MARGIN


@pytest.mark.slow  # the support model and the disturbance model load
def test_every_box_has_its_reasons(decision: unstack.Decision) -> None:
    assert [reason["box"] for reason in decision.reasons] == list(decision.objects)
    for reason, moves in zip(decision.reasons, decision.expected_costs, strict=True):
        assert reason["expected_moves"] == pytest.approx(moves, abs=1e-4)
        assert all(p >= 0.2 for _, p in reason["holds_up"])


@pytest.mark.slow  # the support model and the disturbance model load
def test_the_json_names_the_cost_and_validates(decision: unstack.Decision) -> None:
    document = json.loads(json.dumps(decision.to_dict()))
    jsonschema.validate(document, load_schema("unstack.decision/1"))
    assert document["cost"] == "moves" and "choice_probability" not in document and document["reasons"]


@pytest.mark.slow  # the support model and the disturbance model load
def test_the_same_seed_gives_the_same_decision(decision: unstack.Decision, examples: Path) -> None:
    again = unstack.decide(unstack.load(examples / "pile5.scene.json"), cost="moves", seed=0)
    assert again.to_dict() == decision.to_dict()


def test_supports_alone_cannot_be_decided_on_moves() -> None:
    with pytest.raises(InvalidArgument, match="moves cost reads the scene's poses and cloud"):
        unstack.decide(Supports(["a", "b"], [[0, 0.2], [0.7, 0]]), cost="moves")


@pytest.mark.slow  # the support model and the disturbance model load
def test_a_disturbance_model_without_the_moves_cost_is_refused(examples: Path) -> None:
    with pytest.raises(InvalidArgument, match="used by the moves cost only"):
        unstack.decide(unstack.load(examples / "pile5.scene.json"), disturbance="model.skops")


def test_reasons_name_the_relations_above_the_threshold() -> None:
    supports = Supports(["a", "b", "c"], [[0, 0.8, 0.1], [0.1, 0, 0.5], [0, 0, 0]], hidden_load=[0.0, 0.4, 0.0])
    marginals = np.array([[0, 0.8, 0.1], [0.1, 0, 0.5], [0, 0, 0]])
    reasons = pick_reasons(supports, marginals, np.array([1.5, 0.6, 0.0]))
    assert reasons[0]["holds_up"] == [["b", 0.8]] and reasons[1]["hidden_load"] == 0.4
    assert reasons[2]["held_by"] == ["b", 0.5] and reasons[2]["holds_up"] == []
