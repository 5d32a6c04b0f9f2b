"""Arguments a decision takes but cannot have meant are warned about: masses lighter than a carton,
margins above every expected cost the boxes can have."""

from __future__ import annotations

import re

import numpy as np
import pytest

import unstack
from unstack.reasoner.costs import largest_expected_cost
from unstack.reasoner.decision import decide
from unstack.supports import Supports


@pytest.fixture
def chain() -> Supports:
    """'bottom' holds 'middle', which holds 'top'; heights so that near ties can be broken."""
    probabilities = [[0, 0.9, 0.8], [0.05, 0, 0.9], [0.01, 0.05, 0]]
    return Supports(["bottom", "middle", "top"], probabilities, masses=[12.0, 8.0, 5.0], heights=[0.2, 0.6, 1.0])


@pytest.mark.parametrize(("cost", "largest"), [("count", 2.0), ("mass", 20.0), ("load", 2.0)])
def test_the_largest_expected_cost_is_every_other_box_held_up(chain: Supports, cost: str, largest: float) -> None:
    assert largest_expected_cost(chain, cost) == largest
    costs = decide(chain, cost=cost).expected_costs
    assert np.all(costs <= largest)


@pytest.mark.parametrize("cost", ["count", "mass"])
def test_a_near_tie_margin_above_every_cost_is_warned_about(chain: Supports, cost: str) -> None:
    decision = decide(chain, cost=cost, near_tie_margin=1e300)
    assert decision.choice == "top"
    assert decision.warnings == (
        f"near_tie_margin 1e+300 is above any expected cost these boxes can have "
        f"({largest_expected_cost(chain, cost):.3g} for the {cost} cost): every box is a near tie whatever it holds "
        "up, and the highest is taken",
    )


def test_a_margin_within_the_costs_and_the_default_are_not_warned_about(chain: Supports) -> None:
    assert decide(chain, near_tie_margin=1.5).warnings == ()
    assert decide(chain).warnings == ()


def test_a_free_cost_above_every_cost_is_warned_about_in_decisions_and_plans() -> None:
    scene = unstack.load("examples/pile5.scene.json")
    decision = unstack.decide(scene, free_cost=1e300, seed=0)
    plan = unstack.plan(scene, free_cost=1e300, seed=0)
    doubt = r"pile5.scene.json: free_cost 1e\+300 is above any expected cost these boxes can have \([\d.]+ for the load"
    assert any(re.match(r".*" + doubt, line) for line in decision.warnings)
    assert any(re.match(r".*" + doubt, line) for line in plan.warnings)
    assert not any("free_cost" in line for line in unstack.decide(scene, free_cost=0.5, seed=0).warnings)


def test_masses_lighter_than_a_carton_are_warned_about_with_the_mass_cost_only(chain: Supports) -> None:
    feathers = Supports(chain.objects, chain.probabilities, masses=[1e-9, 8.0, 5.0], source="pile.json")
    assert decide(feathers, cost="mass").warnings == (
        "pile.json: box 'bottom' (1e-09 kg) weighs less than 0.01 kg, lighter than a carton; masses in kg?",
    )
    assert decide(feathers, cost="count").warnings == ()
