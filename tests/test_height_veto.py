"""The hybrid pick: the highest box unstack does not believe holds anything up."""

from __future__ import annotations

import numpy as np
import pytest

from unstack.errors import InvalidArgument
from unstack.height_veto import HYBRID_MAX_COST, highest_free_box, hybrid_choice
from unstack.scene import Box, Scene


@pytest.fixture
def three_heights() -> Scene:
    boxes = [
        Box("floor", [0.4, 0.4, 0.3], [1.0, -0.5, 0.15]),
        Box("middle", [0.4, 0.4, 0.3], [1.0, 0.0, 0.45]),
        Box("top", [0.4, 0.4, 0.3], [1.0, 0.5, 0.75]),
    ]
    return Scene(boxes, np.zeros((0, 3)), ["floor", "middle", "top"])


@pytest.mark.parametrize(
    ("costs", "expected"),
    [
        ({"floor": 0.0, "middle": 0.1, "top": 0.2}, "top"),  # every box free: the highest
        ({"floor": 0.0, "middle": 0.1, "top": HYBRID_MAX_COST}, "middle"),  # the highest is vetoed
        ({"floor": 0.3, "middle": 1.0, "top": 2.0}, "floor"),
        ({"floor": 1.5, "middle": 0.9, "top": 2.0}, "middle"),  # none free: the lowest expected cost
    ],
)
def test_the_highest_free_box_is_taken(three_heights: Scene, costs: dict[str, float], expected: str) -> None:
    assert highest_free_box(three_heights, costs) == expected


def test_a_lower_bound_vetoes_more(three_heights: Scene) -> None:
    costs = {"floor": 0.0, "middle": 0.1, "top": 0.2}
    assert highest_free_box(three_heights, costs, max_cost=0.15) == "middle"


def test_a_detected_box_without_a_cost_is_refused(three_heights: Scene) -> None:
    with pytest.raises(InvalidArgument, match=r"missing \['top'\]"):
        highest_free_box(three_heights, {"floor": 0.0, "middle": 0.1})


@pytest.mark.parametrize("candidates", [None, ["floor", "middle"]])
def test_the_hybrid_choice_reads_a_decisions_costs(three_heights: Scene, candidates: list[str] | None) -> None:
    from types import SimpleNamespace

    decision = SimpleNamespace(objects=("floor", "middle", "top"), expected_costs=np.array([0.0, 0.1, 0.9]))
    expected = "middle"  # "top" is vetoed; among the candidates "middle" is the highest free box
    assert hybrid_choice(three_heights, decision, candidates=candidates) == expected
