"""Unloading plans: a permutation of the boxes, each step the decision on the boxes left."""

from __future__ import annotations

import json
from pathlib import Path

import jsonschema
import numpy as np
import pytest

from tests.conftest import random_probabilities, supports_of, unstack
from unstack.jsonio import load_schema
from unstack.reasoner.decision import decide
from unstack.reasoner.plan import unloading_plan


@pytest.mark.parametrize("n", [1, 3, 6])
def test_each_step_is_the_decision_on_the_boxes_left(n: int, rng: np.random.Generator) -> None:
    supports = supports_of(random_probabilities(n, rng))
    plan = unloading_plan(supports)
    assert sorted(plan.order) == sorted(supports.objects)
    remaining = list(supports.objects)
    for step in plan.steps:
        decision = decide(supports.subset(remaining))
        assert step.choice == decision.choice and list(step.remaining) == remaining
        remaining.remove(step.choice)
    assert plan.steps[-1].expected_cost == 0.0


def test_a_column_is_unloaded_from_the_top() -> None:
    column = np.array([[0, 0.9, 0.9, 0.9], [0.02, 0, 0.9, 0.9], [0.02, 0.02, 0, 0.9], [0.02, 0.02, 0.02, 0]])
    assert unloading_plan(supports_of(column)).order == ["b3", "b2", "b1", "b0"]


@pytest.mark.slow
def test_plan_command(tmp_path: Path) -> None:
    result = unstack("plan", "examples/stack5.supports.json", "--json", "-o", str(tmp_path / "plan.json"))
    assert result.returncode == 0, result.stderr
    document = json.loads(result.stdout)
    jsonschema.validate(document, load_schema("unstack.plan/1"))
    assert document == json.loads((tmp_path / "plan.json").read_text())
    assert len(document["order"]) == 5 and document["order"][0] == "top_left"
    table = unstack("plan", "examples/pile5.scene.json")
    assert table.returncode == 0 and "Unloading plan" in table.stdout
