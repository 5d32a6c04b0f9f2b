"""DecisionValues: the plain numbers a picture shows, and stored decision files."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import unstack
from unstack.errors import InvalidArgument, InvalidFile
from unstack.pictures.values import DecisionValues, check_threshold, read_decision_values


def test_values_are_checked() -> None:
    with pytest.raises(InvalidArgument, match="expected 2 expected costs and errors, got 3 and 2"):
        DecisionValues(["a", "b"], [1, 2, 3])
    with pytest.raises(InvalidArgument, match="the choice 'c' is not one of the boxes"):
        DecisionValues(["a", "b"], [1, 2], choice="c")
    with pytest.raises(InvalidArgument, match="the order must list distinct boxes"):
        DecisionValues(["a", "b"], [1, 2], order=["a", "a"])
    with pytest.raises(InvalidArgument, match=r"expected a 2 x 2 probability matrix, got shape \(3, 3\)"):
        DecisionValues(["a", "b"], [1, 2], probabilities=np.zeros((3, 3)))


@pytest.mark.parametrize("threshold", [-0.1, 1.01, float("nan")])
def test_a_threshold_is_a_probability(threshold: float) -> None:
    with pytest.raises(InvalidArgument, match=r"threshold must be a probability in \[0, 1\]"):
        check_threshold(threshold)


def test_arrows_strongest_and_text(rng: np.random.Generator) -> None:
    probabilities = rng.uniform(0, 1, (4, 4))
    np.fill_diagonal(probabilities, 0)
    values = DecisionValues(list("abcd"), [0, 1, 2, 3], [0, 0.1, 0, 0], probabilities=probabilities, order="dcba")
    arrows = values.arrows(0.5)
    assert len(arrows) == int(((probabilities >= 0.5) & ~np.eye(4, dtype=bool)).sum())
    assert [p for _, _, p in arrows] == sorted(p for _, _, p in arrows)
    assert values.arrows(1.0) == [] or all(p == 1.0 for _, _, p in values.arrows(1.0))
    strongest = values.strongest("a", limit=3)
    assert len(strongest) == 3 and strongest[0][2] == max(probabilities[0].max(), probabilities[:, 0].max())
    assert values.cost_text("b") == "EC 1.00 ± 0.10" and values.cost_text("a") == "EC 0.00"
    assert values.plan_number("d") == 1 and values.sampled


def test_a_stored_decision_is_read(tmp_path: Path, examples: Path) -> None:
    decision = unstack.decide(unstack.load_supports(examples / "pile31.supports.json"), seed=0)
    path = tmp_path / "decision.json"
    path.write_text(json.dumps(decision.to_dict()))
    values = read_decision_values(path)
    assert values.choice == decision.choice and values.objects == decision.objects
    np.testing.assert_array_equal(values.expected_cost_errors, decision.expected_cost_errors)
    np.testing.assert_array_equal(values.probabilities, decision.marginals)
    with pytest.raises(InvalidArgument, match=r"decision\.json: the decision's boxes do not match scene\.json"):
        values.check_boxes(["b00"], "scene.json")


def test_a_wrong_decision_file_is_refused(tmp_path: Path, examples: Path) -> None:
    with pytest.raises(InvalidFile, match=r"expected unstack\.decision/1"):
        read_decision_values(examples / "stack5.supports.json")
    path = tmp_path / "bad.json"
    document = unstack.decide(unstack.load_supports(examples / "stack5.supports.json")).to_dict()
    document["expected_costs"] = document["expected_costs"][:2]
    path.write_text(json.dumps(document))
    with pytest.raises(InvalidFile, match=r"\$\.expected_costs: expected 5 numbers"):
        read_decision_values(path)
