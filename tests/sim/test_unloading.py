"""Executing unloading orders in the simulator."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from unstack.dataset_folders import list_configurations
from unstack.errors import UnstackError
from unstack.scene import Scene, load_scene
from unstack.sim.unloading import IN_VIEW, execute_policy, execute_unloading, reachable_boxes, unload_container

pytestmark = pytest.mark.slow  # executes unloading orders in the physics engine


@pytest.fixture
def pile(small_dataset: Path) -> Scene:
    return load_scene(list_configurations(small_dataset)[0])


def test_top_down_disturbs_less_than_bottom_up(pile: Scene) -> None:
    by_height = sorted(pile.box_ids, key=lambda box_id: -pile.box(box_id).position[2])
    top_down = execute_unloading(pile, by_height)
    bottom_up = execute_unloading(pile, by_height[::-1])
    assert [step.box for step in top_down.steps] == by_height
    assert top_down.resettle_drift_m < 0.01
    assert top_down.boxes_moved < bottom_up.boxes_moved
    assert bottom_up.steps[0].boxes_moved > 0  # the lowest box holds others up
    assert all(box not in step.moved for step in top_down.steps for box in by_height[: by_height.index(step.box) + 1])


def test_repeating_an_order_repeats_the_measurement(pile: Scene) -> None:
    order = list(pile.detected)
    assert execute_unloading(pile, order).to_dict() == execute_unloading(pile, order).to_dict()


@pytest.mark.parametrize("order", [["nope"], ["b00", "b00"]])
def test_bad_orders_are_refused(pile: Scene, order: list[str]) -> None:
    with pytest.raises(UnstackError, match="the order names unknown or repeated boxes"):
        execute_unloading(pile, order)


def test_a_scene_without_simulation_settings(repo: Path) -> None:
    with pytest.raises(UnstackError, match=r"\$\.metadata\.settings: executing an order needs a simulated scene"):
        execute_unloading(load_scene(repo / "examples" / "scene3.json"), [])


def test_a_closed_loop_senses_the_pile_before_each_pick(pile: Scene) -> None:
    seen: list[Scene] = []

    def lowest_first(current: Scene) -> str:
        seen.append(current)
        return min(current.detected, key=lambda box_id: current.box(box_id).position[2])

    run = execute_policy(pile, lowest_first, pile.detected)
    assert sorted(run.order) == sorted(pile.detected) and len(seen) == len(pile.detected)
    for number, current in enumerate(seen):
        assert set(current.detected) == set(pile.detected) - set(run.order[:number])  # boxes left to unload
        assert len(current.boxes) == len(pile.boxes) - number and len(current.points) > 1000  # a new scan
    taken = run.order[0]
    assert not any(box.id == taken for box in seen[1].boxes)


def test_the_next_scan_shows_where_a_disturbed_box_went(pile: Scene) -> None:
    assert pile.ground_truth is not None
    supporters = [box for box in pile.detected if pile.ground_truth[pile.box_ids.index(box)].any()]
    assert supporters, "the fixture pile has a detected box that holds another up"
    seen: list[Scene] = []

    def supporter_first(current: Scene) -> str:
        seen.append(current)
        return supporters[0] if len(seen) == 1 else sorted(current.detected)[0]

    run = execute_policy(pile, supporter_first, pile.detected)
    assert run.steps[0].moved  # removing a supporter disturbs what it held up
    moved_box = run.steps[0].moved[0]
    assert not (seen[1].box(moved_box).position == pile.box(moved_box).position).all()


def test_a_policy_must_pick_a_box_left_to_unload(pile: Scene) -> None:
    with pytest.raises(UnstackError, match="the policy picked 'nope', not one of the boxes left to unload"):
        execute_policy(pile, lambda current: "nope", pile.detected)


def highest_first(current: Scene) -> str:
    return max(current.detected, key=lambda box_id: (current.box(box_id).position[2], box_id))


@pytest.fixture
def pile_with_a_hidden_box(small_dataset: Path) -> Scene:
    """The first pile of the small data set in which the sensor cannot see every box."""
    for path in list_configurations(small_dataset):
        scene = load_scene(path)
        if len(scene.detected) < len(scene.boxes):
            return scene
    raise AssertionError("the small data set has no pile with a hidden box")


def test_unloading_a_container_detects_again_after_every_pick(pile_with_a_hidden_box: Scene) -> None:
    pile = pile_with_a_hidden_box
    seen: list[Scene] = []

    def recording(current: Scene) -> str:
        seen.append(current)
        return highest_first(current)

    run = unload_container(pile, recording)
    assert run.stopped in ("container empty", "nothing detected and reachable")
    if run.stopped == "container empty":
        assert sorted(run.order) == sorted(pile.box_ids)
    assert len(run.order) == len(seen) == len(run.steps) and len(set(run.order)) == len(run.order)
    candidates = set().union(*(set(current.detected) for current in seen))
    assert set(run.order) <= candidates
    hidden = set(pile.box_ids) - set(pile.detected)
    assert hidden & candidates  # a box the first scan could not see is found once the boxes before it are gone
    for number, current in enumerate(seen):
        assert len(current.boxes) == len(pile.boxes) - number
        assert set(current.detected) <= {box.id for box in current.boxes}


def test_a_box_that_leaves_the_container_leaves_the_pile(pile: Scene) -> None:
    """A box falling off the apron (or through the floor) is lost: never scanned into a scene again."""
    from dataclasses import replace

    from unstack.sim.unloading import LOST_BELOW_FLOOR

    outside = replace(pile.boxes[-1], position=np.array([-2.5, 0.0, 0.4]))  # beyond the apron, in the air
    scene = Scene([*pile.boxes[:-1], outside], pile.points, pile.detected, metadata=pile.metadata, source="test")
    seen: list[Scene] = []

    def recording(current: Scene) -> str:
        seen.append(current)
        return highest_first(current)

    run = unload_container(scene, recording)
    assert [step.lost for step in run.steps if step.lost] == [(outside.id,)]
    lost_at = next(number for number, step in enumerate(run.steps) if step.lost)
    assert outside.id in run.steps[lost_at].fallen
    assert all(outside.id not in {box.id for box in current.boxes} for current in seen[lost_at + 1 :])
    assert outside.id not in run.order and run.stopped == "container empty"
    assert seen[lost_at].box(outside.id).position[2] >= -LOST_BELOW_FLOOR  # in place until the step that lost it
    again = execute_unloading(scene, [*run.order, outside.id])  # a fixed order skips the box it lost
    assert again.order == run.order and any(outside.id in step.lost for step in again.steps)


def test_a_pick_limit_stops_the_run_and_says_so(pile: Scene) -> None:
    run = unload_container(pile, highest_first, max_picks=2)
    assert len(run.order) == 2 and run.stopped == "pick limit"
    assert run.to_dict()["stopped"] == "pick limit"


def test_a_watched_run_says_its_picks_and_the_boxes_left(pile: Scene) -> None:
    from unstack.sim.progress import watching_picks

    seen: list[tuple[int, int]] = []

    def watched_highest(current: Scene) -> str:
        seen.append((watch.picks, watch.left))
        return highest_first(current)

    with watching_picks() as watch:
        unload_container(pile, watched_highest, max_picks=2)
    assert seen[0] == (0, len(pile.boxes))  # the policy is asked with the pile whole
    assert seen[1][0] == 1 and seen[1][1] <= len(pile.boxes) - 1  # one box out (and any lost with it)
    assert len(seen) == 2 and watch.picks == 2


def test_detector_noise_moves_the_reported_boxes_reproducibly(pile: Scene) -> None:
    reported: list[list[np.ndarray]] = []

    def recording(current: Scene) -> str:
        reported.append([box.position.copy() for box in current.boxes])
        return highest_first(current)

    first = unload_container(pile, recording, detector_noise=0.01, max_picks=1, seed=4)
    again = unload_container(pile, recording, detector_noise=0.01, max_picks=1, seed=4)
    assert first.to_dict() == again.to_dict()
    np.testing.assert_array_equal(reported[0], reported[1])
    unload_container(pile, recording, max_picks=1, seed=4)  # the true poses
    errors = np.linalg.norm(np.array(reported[0]) - np.array(reported[2]), axis=1)
    assert 0 < errors.max() < 0.1


def test_the_policy_is_told_every_box_in_view_but_the_missed_ones(pile: Scene) -> None:
    told: dict[float, tuple[set[str], set[str]]] = {}

    def telling(misses: float):  # type: ignore[no-untyped-def]
        def policy(current: Scene) -> str:
            told[misses] = (set(current.metadata[IN_VIEW]), set(current.detected))
            return highest_first(current)

        return policy

    for misses in (0.0, 0.6):  # the first scan of the same pile, every box reported, then some missed
        unload_container(pile, telling(misses), detector_misses=misses, max_picks=1, seed=4)
    (in_view, candidates), (in_view_missing, candidates_missing) = told[0.0], told[0.6]
    assert candidates <= in_view <= set(pile.box_ids) and candidates_missing < candidates
    assert in_view_missing == in_view - (candidates - candidates_missing)


def test_a_detector_that_misses_boxes_offers_fewer_candidates_reproducibly(pile: Scene) -> None:
    offered: dict[float, list[int]] = {}

    def recording(share: float):  # type: ignore[no-untyped-def]
        def policy(current: Scene) -> str:
            offered.setdefault(share, []).append(len(current.detected))
            return highest_first(current)

        return policy

    for share in (0.0, 0.6):
        unload_container(pile, recording(share), detector_misses=share, max_picks=3, seed=4)
    first = offered[0.6]
    offered.pop(0.6)
    unload_container(pile, recording(0.6), detector_misses=0.6, max_picks=3, seed=4)
    assert offered[0.6] == first  # the same misses for the same seed
    assert all(count >= 1 for count in first)  # at least one box is found at every scan
    assert sum(first) < sum(offered[0.0])


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        ({"reach": "roof"}, "unknown reach rule 'roof'; expected one of door, any"),
        ({"detector_misses": 1.0}, r"detector_misses must be a share in \[0, 1\), got 1.0"),
        ({"detector_noise": -0.1}, "detector_noise must be a finite number of metres >= 0, got -0.1"),
        ({"max_picks": -1}, "max_picks must be at least 0, got -1"),
    ],
)
def test_bad_unloading_settings_are_refused(pile: Scene, arguments: dict[str, object], message: str) -> None:
    with pytest.raises(UnstackError, match=message):
        unload_container(pile, highest_first, **arguments)  # type: ignore[arg-type]


def test_a_box_blocked_in_front_and_on_top_is_out_of_reach() -> None:
    from unstack.scene import Box

    blocked = Box("blocked", [0.4, 0.4, 0.4], [0.6, 0.0, 0.2])
    in_front = Box("in_front", [0.4, 0.4, 0.4], [0.19, 0.0, 0.2])
    on_top = Box("on_top", [0.4, 0.4, 0.4], [0.6, 0.0, 0.61])
    beside = Box("beside", [0.4, 0.4, 0.4], [0.6, 0.41, 0.2])
    boxes = [blocked, in_front, on_top, beside]
    assert reachable_boxes(boxes, ["blocked", "in_front", "on_top", "beside"]) == ["in_front", "on_top", "beside"]
    assert reachable_boxes(boxes, ["blocked"], "any") == ["blocked"]


def test_a_rebuilt_pile_moves_what_the_ground_truth_says_a_removal_moves(pile: Scene) -> None:
    from unstack.sim.unloading import rebuilt_removals

    outcomes = rebuilt_removals(pile, pile.box_ids)
    assert set(outcomes) == set(pile.box_ids)
    truth = pile.ground_truth
    assert truth is not None and truth.any(), "the fixture pile has a box that holds another up"
    for i, box_id in enumerate(pile.box_ids):
        held_up = {pile.box_ids[j] for j in np.flatnonzero(truth[i])}
        assert held_up <= set(outcomes[box_id].moved), (box_id, held_up, outcomes[box_id].moved)
    typical = rebuilt_removals(pile, pile.box_ids, masses={box_id: 10.0 for box_id in pile.box_ids})
    assert set(typical) == set(pile.box_ids)


def test_rebuilding_names_only_boxes_of_the_scene(pile: Scene) -> None:
    from unstack.sim.unloading import rebuilt_removals

    with pytest.raises(UnstackError, match=r"candidates \['nowhere'\] are not boxes of the scene"):
        rebuilt_removals(pile, ["nowhere"])
