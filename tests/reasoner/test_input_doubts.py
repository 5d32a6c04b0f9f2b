"""Arguments a decision takes but cannot have meant are warned about (masses lighter than a carton,
margins above every expected cost the boxes can have), and those no call could use are refused
before any work with the library's own error, never a bare exception from deep inside."""

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


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (
            lambda s: unstack.plan(s, progress=lambda: None),
            r"progress must take two arguments, progress\(done, total\)",
        ),
        (lambda s: unstack.decide(s, physics_veto="yes"), r"physics_veto must be True or False, got 'yes'"),
        (
            lambda s: unstack.decide(s, time_limit=10**400),
            r"time_limit must be a finite number of seconds, got an integer",
        ),
        (
            lambda s: unstack.decide(s, near_tie_margin=10**400),
            r"near_tie_margin must be .* got an integer of about 401",
        ),
    ],
    ids=["progress-arity", "physics-veto-type", "huge-time-limit", "huge-margin"],
)
def test_arguments_no_call_could_use_are_refused_before_any_work(chain: Supports, call: object, message: str) -> None:
    from unstack.errors import InvalidArgument

    with pytest.raises(InvalidArgument, match=message):
        call(chain)  # type: ignore[operator]


@pytest.mark.parametrize("name", ["x" * 5000, "a\0b"], ids=["too-long", "nul"])
def test_a_file_name_the_system_refuses_is_one_invalid_file_error(name: str) -> None:
    from unstack.errors import InvalidFile

    with pytest.raises(
        InvalidFile, match=r"\$: (cannot read the file: File name too long|expected a file name, got one)"
    ):
        unstack.load(name)


def test_a_scene_of_no_list_of_boxes_is_refused_with_its_path() -> None:
    from unstack.errors import InvalidScene

    with pytest.raises(InvalidScene, match=r"\$\.boxes: expected a list of boxes, got NoneType"):
        unstack.Scene(None, [], ["a"])  # type: ignore[arg-type]


def test_more_undetected_boxes_on_a_box_than_a_stack_holds_are_warned_about_with_the_load_cost(chain: Supports) -> None:
    loaded = Supports(chain.objects, chain.probabilities, hidden_load=[1000.0, 0.0, 2.0], source="pile.json")
    assert decide(loaded).warnings == (
        f"pile.json: box {chain.objects[0]!r} carries 1,000 undetected boxes, more than a stack on one carton holds "
        "(50); a count of boxes, not kg?",
    )
    assert decide(loaded, cost="count").warnings == ()


def _ten_boxes_with(entries: dict[tuple[int, int], float]) -> Supports:
    """Ten weakly linked boxes (one sampled group) with ``entries`` set."""
    probabilities = np.full((10, 10), 0.3)
    np.fill_diagonal(probabilities, 0.0)
    for (x, y), value in entries.items():
        probabilities[x, y] = value
    return Supports([f"b{k}" for k in range(10)], probabilities)


@pytest.mark.parametrize(
    ("entries", "named"),
    [
        ({(0, 1): 1 - 1e-9}, "1 relation has a probability within 0.001 of 1 but not 1 (b0 -> b1: 0.999999999)"),
        (
            {(0, 1): 0.9995, (2, 3): 0.99999, (4, 5): 0.9999, (6, 7): 0.9991, (3, 1): 1.0},
            "4 relations have a probability within 0.001 of 1 but not 1 (b0 -> b1: 0.9995, b2 -> b3: 0.99999, "
            "b4 -> b5: 0.9999 and 1 more)",
        ),
    ],
    ids=["one", "four-named-three"],
)
def test_a_sampled_group_with_relations_near_but_not_at_1_is_warned_about(
    entries: dict[tuple[int, int], float], named: str
) -> None:
    decision = decide(_ten_boxes_with(entries), seed=0, samples=200)
    assert decision.component_methods == ("approx",)
    [warning] = [text for text in decision.warnings if "within 0.001 of 1" in text]
    assert warning.startswith(named) and warning.endswith(
        "give 1 where it is meant (hard evidence is counted exactly) or compare two seeds"
    )


@pytest.mark.parametrize(
    ("entries", "method"),
    [({(0, 1): 1.0}, "auto"), ({(0, 1): 0.998}, "auto"), ({(0, 1): 1 - 1e-9}, "exact")],
    ids=["exactly-1", "a-models-highest", "counted-exactly"],
)
def test_relations_at_1_far_from_it_or_counted_exactly_are_not_warned_about(
    entries: dict[tuple[int, int], float], method: str
) -> None:
    supports = _ten_boxes_with(entries)
    if method == "exact":  # a group small enough to count
        supports = Supports(supports.objects[:6], supports.probabilities[:6, :6])
    decision = decide(supports, seed=0, samples=200, method="auto" if method == "exact" else method)
    assert not any("within 0.001 of 1" in text for text in decision.warnings)
