"""Physics on the belief: the unseen material of a cloud as blocks, removals tried on what is seen."""

from __future__ import annotations

import numpy as np
import pytest

from unstack.errors import UnstackError
from unstack.scene import Box, Scene
from unstack.sim.belief import (
    OCCUPANCY_CAP,
    OCCUPANCY_PER_CUBIC_METRE,
    BeliefBlock,
    behind_seen_faces,
    belief_blocks,
    belief_choice,
    belief_removals,
    belief_settings,
    choose_by_expected_moves,
    drawn_worlds,
    occlusion_blocks,
    restless_boxes,
    scaled_occupancy,
)
from unstack.understanding.clouds import surface_cloud

VIEWPOINT = [-2.0, 0.0, 1.5]


def _scene(boxes: list[Box], detected: list[str], seed: int = 0) -> Scene:
    return Scene(boxes, surface_cloud(boxes, viewpoint=VIEWPOINT, seed=seed), detected)


@pytest.fixture
def column() -> list[Box]:
    """Three boxes stacked on the floor and one beside them."""
    return [
        Box("bottom", [0.4, 0.4, 0.3], [1.0, -0.3, 0.15]),
        Box("middle", [0.4, 0.4, 0.3], [1.0, -0.3, 0.45]),
        Box("top", [0.4, 0.4, 0.3], [1.0, -0.3, 0.75]),
        Box("beside", [0.4, 0.4, 0.3], [1.0, 0.3, 0.15]),
    ]


def test_nothing_unseen_when_every_box_is_detected(column: list[Box]) -> None:
    assert belief_blocks(_scene(column, [box.id for box in column])) == []


def test_an_undetected_box_on_a_detected_one_is_its_hidden_load(column: list[Box]) -> None:
    blocks = belief_blocks(_scene(column, ["bottom", "middle", "beside"]))
    assert [block.resting_on for block in blocks] == ["middle"]
    load = blocks[0]
    assert load.center[2] - load.size[2] / 2 == pytest.approx(0.6, abs=0.01)  # on the middle box's top
    assert load.center[2] + load.size[2] / 2 == pytest.approx(0.9, abs=0.03)  # up to the unseen box's top


def test_an_undetected_box_on_the_floor_is_fixed_material(column: list[Box]) -> None:
    blocks = belief_blocks(_scene(column, ["bottom", "middle", "top"]))
    assert blocks and all(block.resting_on is None for block in blocks)
    tops = np.array([block.center[2] + block.size[2] / 2 for block in blocks])
    assert tops.max() == pytest.approx(0.3, abs=0.02)
    assert all(block.center[1] > 0.05 for block in blocks)  # where the beside box stands


def test_an_empty_cloud_has_no_unseen_material(column: list[Box]) -> None:
    assert belief_blocks(Scene(column, np.zeros((0, 3)), ["bottom"])) == []


def test_blocks_are_typed_values(column: list[Box]) -> None:
    block = belief_blocks(_scene(column, ["bottom", "middle", "beside"]))[0]
    assert isinstance(block, BeliefBlock) and block.size.shape == (3,) and np.all(block.size > 0)


@pytest.mark.slow  # physics
def test_removing_a_box_under_others_moves_them_and_the_top_box_moves_nothing(column: list[Box]) -> None:
    outcomes = belief_removals(_scene(column, [box.id for box in column]), worlds=2)
    assert set(outcomes["middle"].moved) == {"top"}
    assert set(outcomes["bottom"].moved) == {"middle", "top"}
    assert outcomes["top"].expected_moved == 0.0 and outcomes["beside"].expected_moved == 0.0


@pytest.mark.slow  # physics
def test_the_hidden_load_falls_with_the_box_that_carries_it(column: list[Box]) -> None:
    outcomes = belief_removals(_scene(column, ["bottom", "middle", "beside"]), worlds=1)
    assert "load:middle" in outcomes["middle"].moved
    assert {"middle", "load:middle"} <= set(outcomes["bottom"].moved)
    assert outcomes["beside"].moved == ()


@pytest.mark.slow  # physics
def test_the_choice_is_a_box_that_moves_nothing_resting_highest(column: list[Box]) -> None:
    assert belief_choice(_scene(column, [box.id for box in column]), worlds=1) == "top"
    assert belief_choice(_scene(column, ["bottom", "middle", "beside"]), worlds=1) == "beside"


@pytest.mark.slow  # physics
def test_the_same_seed_gives_the_same_outcomes(column: list[Box]) -> None:
    scene = _scene(column, ["bottom", "middle", "beside"])
    assert belief_removals(scene, worlds=3, seed=5) == belief_removals(scene, worlds=3, seed=5)


def test_candidates_that_are_not_detected_are_refused(column: list[Box]) -> None:
    with pytest.raises(UnstackError, match=r"candidates \['top'\] are not detected"):
        belief_removals(_scene(column, ["bottom"]), ["top"])


def test_at_least_one_world_is_needed(column: list[Box]) -> None:
    with pytest.raises(UnstackError, match="worlds must be at least 1"):
        belief_removals(_scene(column, ["bottom"]), worlds=0)


def test_an_unknown_rule_is_refused(column: list[Box]) -> None:
    with pytest.raises(UnstackError, match="unknown belief rule 'tallest'"):
        belief_choice(_scene(column, ["bottom"]), rule="tallest")


@pytest.mark.parametrize(
    ("expected", "rule", "choice"),
    [
        ({"low": 0.0, "high": 0.5}, "fewest", "low"),
        ({"low": 0.0, "high": 0.5}, "veto", "high"),
        ({"low": 0.0, "high": 1.0}, "veto", "low"),
        ({"low": 0.0, "high": 0.0}, "fewest", "high"),
    ],
)
def test_the_rules_pick_from_the_expected_moves(expected: dict[str, float], rule: str, choice: str) -> None:
    assert choose_by_expected_moves(expected, {"low": 0.0, "high": 0.3}, rule) == choice


def _seen_from_the_door(boxes: list[Box], detected: list[str]) -> Scene:
    """A dense cloud from the default sensor's position (the belief's occlusion needs it)."""
    return Scene(boxes, surface_cloud(boxes, viewpoint=[-2.8, 0.0, 1.3], spacing=0.005, seed=0), detected)


@pytest.mark.slow  # physics
def test_with_the_unseen_space_filled_a_box_on_a_hidden_one_stands_and_taking_either_moves_nothing(
    hidden_step: list[Box],
) -> None:
    outcomes = belief_removals(_seen_from_the_door(hidden_step, ["front", "up"]), worlds=1, fill="occlusion")
    assert outcomes["front"].moved == () and outcomes["up"].moved == ()


@pytest.mark.slow  # physics
def test_with_the_unseen_space_filled_the_seen_box_under_another_still_moves_it(column: list[Box]) -> None:
    outcomes = belief_removals(_seen_from_the_door(column, [box.id for box in column]), worlds=1, fill="occlusion")
    assert set(outcomes["bottom"].moved) == {"middle", "top"} and outcomes["top"].moved == ()


@pytest.mark.slow  # physics
def test_with_the_unseen_space_sampled_what_needs_nothing_unseen_moves_in_every_world(column: list[Box]) -> None:
    outcomes = belief_removals(_seen_from_the_door(column, [box.id for box in column]), worlds=3, fill="sampled")
    assert outcomes["bottom"].expected_moved == 2.0 and outcomes["top"].expected_moved == 0.0


@pytest.mark.slow  # physics
def test_with_the_unseen_space_sampled_the_same_seed_gives_the_same_outcomes(hidden_step: list[Box]) -> None:
    scene = _seen_from_the_door(hidden_step, ["front", "up"])
    first, second = (belief_removals(scene, worlds=2, fill="sampled", seed=3) for _ in range(2))
    assert first == second


@pytest.mark.parametrize("cubic_metres", [0.0, 0.05, 0.4, 1.0, 2.0, 5.0])
def test_the_scaled_occupancy_grows_with_the_unseen_volume_up_to_its_cap(cubic_metres: float) -> None:
    blocks = [BeliefBlock(np.array([0.5, 0.5, cubic_metres / 0.25]), np.zeros(3), None)] if cubic_metres else []
    expected = min(OCCUPANCY_CAP, OCCUPANCY_PER_CUBIC_METRE * cubic_metres)
    assert scaled_occupancy(blocks) == pytest.approx(expected)


@pytest.mark.slow  # physics
def test_the_scaled_fill_is_the_sampled_fill_at_the_chance_the_unseen_volume_gives(hidden_step: list[Box]) -> None:
    scene = _seen_from_the_door(hidden_step, ["front", "up"])
    chance = scaled_occupancy(occlusion_blocks(scene))
    assert 0.0 < chance < OCCUPANCY_CAP
    scaled = belief_removals(scene, worlds=3, fill="scaled", seed=5)
    assert scaled == belief_removals(scene, worlds=3, fill="sampled", occupancy=chance, seed=5)


def test_no_unseen_space_lies_behind_a_seen_face_when_every_box_is_detected(column: list[Box]) -> None:
    scene = _seen_from_the_door(column, [box.id for box in column])
    blocks = occlusion_blocks(scene)
    assert len(blocks) > 0 and not behind_seen_faces(scene, blocks).any()


def test_the_space_behind_a_missed_box_face_is_behind_a_seen_face(column: list[Box]) -> None:
    scene = _seen_from_the_door(column, ["middle", "top", "beside"])
    blocks = occlusion_blocks(scene)
    behind = behind_seen_faces(scene, blocks)
    inside_bottom = [bool(np.all(np.abs(block.center - [1.0, -0.3, 0.15]) < [0.2, 0.2, 0.15])) for block in blocks]
    assert any(inside_bottom) and all(behind[k] for k, inside in enumerate(inside_bottom) if inside)


@pytest.mark.slow  # physics
def test_with_every_box_detected_the_faces_fill_is_the_scaled_fill(column: list[Box]) -> None:
    scene = _seen_from_the_door(column, [box.id for box in column])
    faces, scaled = (belief_removals(scene, worlds=2, fill=fill, seed=4) for fill in ("faces", "scaled"))
    assert faces == scaled


@pytest.mark.slow  # physics
def test_with_hidden_cartons_the_first_world_rests_and_taking_the_top_box_moves_nothing(hidden_step: list[Box]) -> None:
    scene = _seen_from_the_door(hidden_step, ["front", "up"])
    worlds = drawn_worlds(scene, belief_settings(scene), "cartons", 0.2, 3, np.random.default_rng(0))
    assert all(block.resting_on is None for blocks in worlds for block in blocks)
    assert restless_boxes(scene, fill="cartons") == ()
    outcomes = belief_removals(scene, worlds=3, fill="cartons", seed=0)
    assert outcomes == belief_removals(scene, worlds=3, fill="cartons", seed=0)
    assert outcomes["up"].expected_moved == 0.0  # the top of the pile moves nothing when taken


@pytest.mark.slow  # physics
def test_drawn_masses_keep_the_drawn_space_and_what_needs_no_mass_to_move(column: list[Box]) -> None:
    scene = _seen_from_the_door(column, [box.id for box in column])
    typical = belief_removals(scene, worlds=3, fill="faces", seed=2)
    drawn = belief_removals(scene, worlds=3, fill="faces", seed=2, draw_masses=True)
    assert drawn == belief_removals(scene, worlds=3, fill="faces", seed=2, draw_masses=True)
    for box_id in ("bottom", "top"):  # a column falls, and its top moves nothing, whatever the masses
        assert drawn[box_id].expected_moved == typical[box_id].expected_moved


@pytest.mark.parametrize("fill", ["cloud", "occlusion"])
def test_drawn_masses_are_refused_with_a_fill_whose_worlds_draw_masses_already(column: list[Box], fill: str) -> None:
    with pytest.raises(
        UnstackError, match=f"draw_masses is for the fills that draw the unseen space .* the {fill} fill"
    ):
        belief_removals(_scene(column, ["bottom"]), fill=fill, draw_masses=True)


def test_an_occupancy_outside_zero_to_one_is_refused(column: list[Box]) -> None:
    with pytest.raises(UnstackError, match=r"occupancy must lie between 0 and 1, got 1\.5"):
        belief_removals(_scene(column, ["bottom"]), fill="sampled", occupancy=1.5)


def test_an_unknown_fill_is_refused(column: list[Box]) -> None:
    with pytest.raises(
        UnstackError,
        match="unknown belief fill 'air'; expected one of cloud, occlusion, sampled, scaled, faces, cartons",
    ):
        belief_removals(_scene(column, ["bottom"]), fill="air")


def test_a_box_that_cannot_stand_as_reported_is_restless_and_a_calm_pile_is_not() -> None:
    stack = [Box("base", [0.4, 0.4, 0.3], [1.2, -0.4, 0.151]), Box("top", [0.4, 0.4, 0.3], [1.2, -0.4, 0.452])]
    floating = Box("floating", [0.4, 0.4, 0.3], [1.2, 0.5, 1.75])  # still falling when the world should rest
    calm = Scene(stack, surface_cloud(stack, viewpoint=[-2.0, 0.0, 1.5], seed=0), ["base", "top"])
    assert restless_boxes(calm) == ()
    boxes = [*stack, floating]
    scene = Scene(boxes, surface_cloud(boxes, viewpoint=[-2.0, 0.0, 1.5], seed=0), ["base", "top", "floating"])
    assert restless_boxes(scene) == ("floating",)
    with pytest.raises(UnstackError, match="unknown belief fill 'cloud' for a rest check"):
        restless_boxes(scene, fill="cloud")


def test_net_outcomes_leave_out_what_moves_with_nothing_taken() -> None:
    stack = [Box("base", [0.4, 0.4, 0.3], [1.2, -0.4, 0.151]), Box("top", [0.4, 0.4, 0.3], [1.2, -0.4, 0.452])]
    floating = Box("floating", [0.4, 0.4, 0.3], [1.2, 0.5, 1.75])  # falls whatever is taken
    boxes = [*stack, floating]
    scene = Scene(boxes, surface_cloud(boxes, viewpoint=VIEWPOINT, seed=0), ["base", "top", "floating"])
    gross = belief_removals(scene, ["top", "base"], worlds=2, fill="faces")
    net = belief_removals(scene, ["top", "base"], worlds=2, fill="faces", net=True)
    assert "floating" in gross["top"].moved and gross["top"].expected_moved >= 1.0
    assert net["top"].moved == () and net["top"].expected_moved == 0.0
    assert set(net["base"].moved) == {"top"}  # what the pick itself sets moving is still counted
