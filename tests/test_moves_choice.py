"""Choosing a pick from expected moves: the fewest and the veto rules (no model loads)."""

from __future__ import annotations

import numpy as np
import pytest

from unstack.errors import InvalidArgument
from unstack.moves import MOVES_VETO, choose_on_moves

OBJECTS = ("low", "mid", "high")
HEIGHTS = np.array([0.0, 0.3, 0.6])


@pytest.mark.parametrize(
    ("moves", "fewest", "veto"),
    [
        ([0.1, 0.2, 0.3], "low", "high"),  # every box allowed: veto takes the highest
        ([0.1, 0.2, MOVES_VETO], "low", "mid"),  # the highest vetoed: the next highest allowed
        ([MOVES_VETO, 2.0, 1.0], "low", "low"),  # none allowed: veto falls back to the fewest
    ],
)
def test_each_rule_picks_its_box(moves: list[float], fewest: str, veto: str) -> None:
    expected = np.array(moves)
    assert choose_on_moves(OBJECTS, expected, HEIGHTS, rule="fewest", margin=0.05)[0] == fewest
    assert choose_on_moves(OBJECTS, expected, HEIGHTS, rule="veto", margin=0.05)[0] == veto


def test_near_ties_on_the_fewest_go_to_the_box_resting_highest() -> None:
    choice, ties = choose_on_moves(OBJECTS, np.array([0.10, 0.14, 0.9]), HEIGHTS, rule="fewest", margin=0.05)
    assert choice == "mid" and ties == ("low", "mid")


def test_an_unknown_rule_is_refused() -> None:
    with pytest.raises(InvalidArgument, match="unknown moves rule 'lowest'; expected one of fewest, veto"):
        choose_on_moves(OBJECTS, np.zeros(3), HEIGHTS, rule="lowest", margin=0.05)
