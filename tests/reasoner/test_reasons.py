"""Why a box costs what it costs: the reasons every box-counting decision carries."""

from __future__ import annotations

import json

import jsonschema
import numpy as np
import pytest

from unstack.jsonio import load_schema
from unstack.reasoner.decision import decide
from unstack.reasoner.reasons import MAY_HOLD_PROBABILITY, REASON_MIN_PROBABILITY, REASONS_PER_BOX, pick_reasons
from unstack.supports import Supports


@pytest.fixture
def random_supports() -> Supports:
    rng = np.random.default_rng(7)
    n = 6
    probabilities = rng.uniform(0.0, 1.0, (n, n)) ** 3
    np.fill_diagonal(probabilities, 0.0)
    return Supports([f"b{k}" for k in range(n)], probabilities, hidden_load=rng.uniform(0.0, 1.0, n))


@pytest.mark.parametrize("cost", ["load", "count"])
def test_every_box_gets_its_expected_cost_as_expected_moves(random_supports: Supports, cost: str) -> None:
    decision = decide(random_supports, cost=cost)
    assert [reason["box"] for reason in decision.reasons] == list(decision.objects)
    for reason, expected in zip(decision.reasons, decision.expected_costs, strict=True):
        assert reason["expected_moves"] == pytest.approx(expected, abs=1e-4)


def test_the_relations_named_are_the_strongest_conditional_ones(random_supports: Supports) -> None:
    decision = decide(random_supports)
    for k, reason in enumerate(decision.reasons):
        named = reason["holds_up"]
        assert len(named) <= REASONS_PER_BOX
        assert [p for _, p in named] == sorted((p for _, p in named), reverse=True)
        row = {box: decision.marginals[k, j] for j, box in enumerate(decision.objects) if j != k}
        for box, p in named:
            assert p == pytest.approx(row[box], abs=1e-3) and p >= REASON_MIN_PROBABILITY
        strong = sorted(value for value in row.values() if value >= REASON_MIN_PROBABILITY)
        assert [p for _, p in named] == pytest.approx(sorted(strong, reverse=True)[:REASONS_PER_BOX], abs=1e-3)


@pytest.mark.parametrize("seed", range(4))
def test_a_box_with_no_relation_to_name_names_its_likeliest_and_how_many(seed: int) -> None:
    rng = np.random.default_rng(seed)
    n = 7
    marginals = rng.uniform(0.0, 0.19, (n, n)) * (rng.uniform(size=(n, n)) < 0.5)
    np.fill_diagonal(marginals, 0.0)
    marginals[0] = 0.0  # a box that holds nothing up at all
    reasons = pick_reasons(Supports([f"b{k}" for k in range(n)], marginals), marginals, marginals.sum(axis=1))
    assert "may_hold_up" not in reasons[0] and reasons[0]["holds_up"] == []
    for k, reason in enumerate(reasons[1:], start=1):
        row = np.delete(marginals[k], k)
        others = [f"b{j}" for j in range(n) if j != k]
        if row.max() < MAY_HOLD_PROBABILITY:
            assert "may_hold_up" not in reason
            continue
        box, p, count = reason["may_hold_up"]
        assert box == others[int(np.argmax(row))] and p == pytest.approx(row.max(), abs=1e-3)
        assert count == int(np.sum(row >= MAY_HOLD_PROBABILITY))


def test_a_box_with_a_relation_to_name_has_no_likeliest_besides() -> None:
    marginals = np.array([[0.0, 0.5], [0.1, 0.0]])
    reasons = pick_reasons(Supports(["a", "b"], marginals), marginals, np.array([0.5, 0.1]))
    assert reasons[0]["holds_up"] == [["b", 0.5]] and "may_hold_up" not in reasons[0]
    assert reasons[1]["may_hold_up"] == ["a", 0.1, 1]


def test_the_mass_cost_counts_kilograms_and_gives_no_reasons() -> None:
    supports = Supports(["top", "bottom"], [[0.0, 0.1], [0.9, 0.0]], masses=[5.0, 20.0])
    decision = decide(supports, cost="mass")
    assert decision.reasons == () and "reasons" not in decision.to_dict()


def test_the_box_holding_a_pick_up_is_named() -> None:
    supports = Supports(["top", "bottom"], [[0.0, 0.1], [0.9, 0.0]])
    reasons = pick_reasons(supports, np.array([[0.0, 0.1], [0.9, 0.0]]), np.array([0.1, 0.9]))
    assert reasons[0]["held_by"] == ["bottom", 0.9] and reasons[1]["holds_up"] == [["top", 0.9]]
    assert reasons[0]["hidden_load"] == 0.0


def test_the_decision_document_with_reasons_follows_the_schema(random_supports: Supports) -> None:
    document = json.loads(json.dumps(decide(random_supports).to_dict()))
    jsonschema.validate(document, load_schema("unstack.decision/1"))
    assert len(document["reasons"]) == len(document["objects"]) and "disturbance_model" not in document
