"""The generalisation suite: the default model's decisions on hand-made scenes, two clouds each."""

from __future__ import annotations

import pytest

from unstack.experiments.canonical_scenes import CANONICAL_KINDS, build_case
from unstack.experiments.generalisation import CLOUDS, canonical_scene, check_decision, physical_check
from unstack.learning.model_file import default_model_path, load_model
from unstack.pipeline import scene_support_probabilities
from unstack.reasoner.decision import decide

pytestmark = pytest.mark.slow  # decides every canonical scene with the shipped model


@pytest.fixture(scope="module")
def default_model():  # type: ignore[no-untyped-def]
    return load_model(default_model_path())


#: Seeds of the scenes the tests draw: not the seeds (0-2) the shipped model was chosen on.
SEEDS = (7, 8)


@pytest.mark.parametrize("cloud", CLOUDS)
@pytest.mark.parametrize("kind", list(CANONICAL_KINDS))
def test_the_default_model_picks_a_box_that_holds_up_nothing(default_model, kind: str, cloud: str) -> None:  # type: ignore[no-untyped-def]
    from unstack.height_veto import free_highest

    for seed in SEEDS:
        case = build_case(kind, seed=seed)
        scene = canonical_scene(case, cloud=cloud, seed=seed)
        decision = decide(scene_support_probabilities(scene, default_model))
        assert decision.choice in case.pickable, (seed, decision.choice, case.pickable)  # the reasoner's own
        default = free_highest(decision, scene).choice  # unstack.decide's on a scene
        assert default in case.pickable, (seed, default, case.pickable)


#: TipSupport scenes on which near ties by the box centre's height took the box leant on (the
#: model gave it EC 0.056 against the free box's 0.019; seeds 0-99 of the suite, before the
#: leaning box was made to touch the box it leans on).
LEANT_ON_BEFORE = (17, 50, 63, 69, 80)


@pytest.mark.parametrize("seed", LEANT_ON_BEFORE)
def test_a_box_leant_on_is_not_taken_for_being_taller(default_model, seed: int) -> None:  # type: ignore[no-untyped-def]
    case = build_case("leaning", seed=seed)
    scene = canonical_scene(case, cloud="surface", seed=seed)
    for statics in (False, True):  # the model alone, and with statics
        decision = decide(scene_support_probabilities(scene, default_model, statics=statics))
        assert decision.choice == "free"  # the taller box leant on is not taken
    from unstack.height_veto import free_highest

    default = free_highest(decide(scene_support_probabilities(scene, default_model)), scene).choice
    assert default in case.pickable and default != "upright"  # statics price the box leant on above the free cost


@pytest.mark.parametrize("cloud", CLOUDS)
def test_with_statics_the_box_leant_on_costs_what_it_holds_up(default_model, cloud: str) -> None:  # type: ignore[no-untyped-def]
    from unstack.understanding.statics import TIP_SUPPORT_PROBABILITY

    for seed in SEEDS:
        scene = canonical_scene(build_case("leaning", seed=seed), cloud=cloud, seed=seed)
        supports = scene_support_probabilities(scene, default_model)
        costs = dict(zip(*(lambda d: (d.objects, d.expected_costs))(decide(supports)), strict=True))
        assert costs["upright"] >= TIP_SUPPORT_PROBABILITY - 0.01 > 0.5 > costs["free"]
        assert any("without 'upright'" in warning for warning in supports.metadata["warnings"])
        assert supports.metadata["tip_supports"][0]["supporter"] == "upright"


@pytest.mark.parametrize("cloud", CLOUDS)
@pytest.mark.parametrize("kind", ["hidden_load", "hidden_middle"])
def test_a_box_under_undetected_load_costs_at_least_half_a_box_more_than_a_free_one(
    default_model,
    kind: str,
    cloud: str,  # type: ignore[no-untyped-def]
) -> None:
    for seed in SEEDS:
        case = build_case(kind, seed=seed)
        decision = decide(scene_support_probabilities(canonical_scene(case, cloud=cloud, seed=seed), default_model))
        costs = dict(zip(decision.objects, decision.expected_costs, strict=True))
        loaded = list(case.holds)
        assert loaded and all(costs[box] >= costs["free"] + 0.5 for box in loaded), costs


@pytest.mark.parametrize("seed", SEEDS)
def test_the_container_walls_are_not_load_on_the_boxes_against_them(seed: int) -> None:
    from unstack.understanding.hidden_load import hidden_load

    case = build_case("against_the_walls", seed=seed, in_container=True)
    scene = canonical_scene(case, cloud="sensor", seed=seed)
    assert hidden_load(scene).max() < 0.05


def test_eq_11_alone_does_not_see_the_hidden_load(default_model) -> None:  # type: ignore[no-untyped-def]
    case = build_case("hidden_load", seed=7)
    supports = scene_support_probabilities(canonical_scene(case, cloud="sensor", seed=7), default_model)
    counted = decide(supports, cost="count")
    assert dict(zip(counted.objects, counted.expected_costs, strict=True))["loaded"] < 0.5


def test_a_wrong_pick_is_reported() -> None:
    case = build_case("plain_stack", seed=0)
    costs = {box.id: 0.0 for box in case.boxes}
    problems = check_decision(case, "s0", costs)
    assert problems[0].startswith("picked 's0', which holds up")


@pytest.mark.parametrize("kind", ["plain_stack", "bridge", "leaning", "side_by_side"])
def test_the_labels_of_a_case_agree_with_the_physics_engine(kind: str) -> None:
    assert physical_check(build_case(kind, seed=7)) == []


def test_an_unknown_pick_is_refused() -> None:
    from unstack.errors import UnstackError
    from unstack.experiments.generalisation import picked

    case = build_case("plain_stack", seed=0)
    scene = canonical_scene(case, cloud="surface", seed=0)
    with pytest.raises(
        UnstackError, match="unknown pick 'tallest'; expected one of default, near-ties, min-cost, hybrid"
    ):
        picked(None, scene, "tallest")


@pytest.mark.parametrize(
    ("pick", "expected"), [("default", "high"), ("near-ties", "high"), ("min-cost", "low"), ("hybrid", "high")]
)
def test_the_suite_can_pick_by_each_rule(pick: str, expected: str) -> None:
    import numpy as np

    from unstack.experiments.generalisation import picked
    from unstack.scene import Box, Scene
    from unstack.supports import Supports

    boxes = [Box("low", [0.4, 0.4, 0.3], [1.0, 0.0, 0.15]), Box("high", [0.4, 0.4, 0.3], [1.0, 0.5, 0.45])]
    scene = Scene(boxes, np.zeros((0, 3)), ["low", "high"])  # 'high' rests at 0.3 m (on a box nobody detected)
    decision = decide(Supports(["low", "high"], [[0.0, 0.01], [0.03, 0.0]], heights=[0.0, 0.3]))
    chosen = picked(decision, scene, pick)
    assert chosen.choice == expected
    assert chosen.expected_costs.tolist() == decision.expected_costs.tolist()
