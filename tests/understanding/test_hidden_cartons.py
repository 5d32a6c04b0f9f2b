"""Whole hidden cartons drawn into the space the sensor cannot see (unstack.understanding.hidden_cartons)."""

from __future__ import annotations

import functools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from unstack.geometry import bounding_boxes
from unstack.scene import Box
from unstack.understanding.clouds import surface_cloud
from unstack.understanding.hidden_cartons import (
    CARTON_REACH,
    GAP,
    carton_extents,
    draw_hidden_cartons,
)
from unstack.understanding.occlusion import REACH, OccludedBlocks, occluded_space, occlusion_grid

VIEWPOINT = [-2.8, 0.0, 1.3]
INTERIOR = [[0.0, -1.175, 0.0], [2.0, 1.175, 2.39]]
DENSE = 0.005


def _grid(cloud: np.ndarray, seen: list[Box], reach: float = CARTON_REACH):  # type: ignore[no-untyped-def]
    return occlusion_grid(cloud, seen, viewpoint=VIEWPOINT, interior=INTERIOR, reach=reach)


@functools.cache
def _pile(seed: int) -> tuple[list[Box], list[Box], np.ndarray]:
    """Rows of columns two boxes high, some hidden; the cloud and the boxes seen."""
    rng = np.random.default_rng(seed)
    boxes = []
    for k, (x, y) in enumerate([(x, y) for x in (0.5, 1.0, 1.5) for y in (-0.6, 0.0, 0.6)]):
        height = float(rng.uniform(0.2, 0.5))
        boxes.append(Box(f"b{k}", [0.45, 0.5, height], [x, y, height / 2]))
        if rng.random() < 0.5:
            on = float(rng.uniform(0.2, 0.4))
            boxes.append(Box(f"b{k}u", [0.45, 0.5, on], [x + rng.uniform(-0.03, 0.03), y, height + on / 2]))
    cloud = surface_cloud(boxes, viewpoint=VIEWPOINT, spacing=DENSE, seed=seed)
    seen = [box for box in boxes if box.position[0] < 0.7 or rng.random() < 0.4]
    return boxes, seen, cloud


def test_the_grid_joined_into_runs_is_the_occluded_space(hidden_step: list[Box]) -> None:
    cloud = surface_cloud(hidden_step, viewpoint=VIEWPOINT, spacing=DENSE, seed=0)
    seen = [hidden_step[0], hidden_step[2]]
    grid = _grid(cloud, seen, reach=REACH)
    blocks = occluded_space(cloud, seen, viewpoint=VIEWPOINT, interior=INTERIOR)
    assert grid is not None
    centres = np.stack(np.meshgrid(*grid.axes, indexing="ij"), axis=-1)[grid.occluded]
    # every occluded cell's centre lies in a block, or was cut back out of a seen box
    in_block = np.all(np.abs(centres[:, None, :] - blocks.centers[None]) <= blocks.sizes[None] / 2 + 1e-9, axis=2)
    assert in_block.any(axis=1).mean() > 0.9
    assert grid.distance.shape == grid.occluded.shape and np.all(grid.distance[grid.occluded] < REACH)


def test_a_carton_is_drawn_where_the_hidden_box_is_and_none_in_seen_space(hidden_step: list[Box]) -> None:
    cloud = surface_cloud(hidden_step, viewpoint=VIEWPOINT, spacing=DENSE, seed=0)
    front, _, up = hidden_step
    rng = np.random.default_rng(0)
    hits = 0
    for _ in range(10):
        cartons = draw_hidden_cartons(_grid(cloud, [front, up]), [front, up], interior=INTERIOR, share=1.0, rng=rng)
        low, high = cartons.centers - cartons.sizes / 2, cartons.centers + cartons.sizes / 2
        hits += bool(np.any(np.all((low <= [1.0, 0.0, 0.15]) & (high >= [1.0, 0.0, 0.15]), axis=1)))
        assert not np.any(high[:, 0] < 0.4)  # nothing in front of the pile, where the sensor sees air
    assert hits >= 5  # a hypothesis each time; the hidden box's space is often in it


@pytest.mark.parametrize("seed", range(4))
def test_cartons_stay_inside_overlap_nothing_and_stand_on_something(seed: int) -> None:
    _, seen, cloud = _pile(seed)
    rng = np.random.default_rng(seed)
    cartons = draw_hidden_cartons(_grid(cloud, seen), seen, interior=INTERIOR, share=0.5, rng=rng)
    assert len(cartons) > 0
    low, high = cartons.centers - cartons.sizes / 2, cartons.centers + cartons.sizes / 2
    assert np.all(low[:, 1:] >= np.array(INTERIOR[0])[1:] - 1e-9) and np.all(high <= np.array(INTERIOR[1]) + 1e-9)
    everything = np.vstack([bounding_boxes(seen), np.hstack([low, high])])
    for k in range(len(cartons)):
        others = np.delete(everything, len(seen) + k, axis=0)
        overlap = np.minimum(high[k], others[:, 3:]) - np.maximum(low[k], others[:, :3])
        assert not np.any(np.all(overlap > 0, axis=1))
        # on the floor, or on the top of a seen box or another carton under its footprint
        under = np.all(others[:, :2] < high[k, :2], axis=1) & np.all(others[:, 3:5] > low[k, :2], axis=1)
        tops = others[under, 5]
        assert low[k, 2] <= 2 * GAP or np.any(np.abs(tops - low[k, 2]) <= 2 * GAP)


def test_cartons_take_the_sizes_of_the_seen_boxes_turned_or_not() -> None:
    _, seen, cloud = _pile(1)
    cartons = draw_hidden_cartons(_grid(cloud, seen), seen, interior=INTERIOR, share=0.5, rng=np.random.default_rng(1))
    extents = carton_extents(seen)
    turned = extents[:, [1, 0, 2]]
    for size in cartons.sizes:
        assert np.any(np.all(np.isclose(extents, size), axis=1) | np.all(np.isclose(turned, size), axis=1))


def test_a_larger_share_draws_more_cartons_and_the_same_seed_the_same_ones() -> None:
    _, seen, cloud = _pile(2)
    grid = _grid(cloud, seen)

    def drawn(share: float, seed: int) -> OccludedBlocks:
        return draw_hidden_cartons(grid, seen, interior=INTERIOR, share=share, rng=np.random.default_rng(seed))

    assert len(drawn(0.0, 0)) == 0
    assert sum(len(drawn(0.6, seed)) for seed in range(3)) > sum(len(drawn(0.1, seed)) for seed in range(3))
    assert np.array_equal(drawn(0.3, 5).centers, drawn(0.3, 5).centers)


def test_nothing_seen_or_no_unseen_space_draws_nothing(hidden_step: list[Box]) -> None:
    cloud = surface_cloud(hidden_step, viewpoint=VIEWPOINT, spacing=DENSE, seed=0)
    rng = np.random.default_rng(0)
    assert len(draw_hidden_cartons(_grid(cloud, []), [], interior=INTERIOR, share=1.0, rng=rng)) == 0
    assert len(draw_hidden_cartons(None, hidden_step, interior=INTERIOR, share=1.0, rng=rng)) == 0


@settings(max_examples=25, deadline=None)
@given(
    size=st.tuples(*[st.floats(0.1, 0.8)] * 3),
    yaw=st.sampled_from([0.0, 90.0, 180.0, 270.0]),
)
def test_extents_of_a_box_turned_by_quarters_are_its_size_permuted(
    size: tuple[float, float, float], yaw: float
) -> None:
    from scipy.spatial.transform import Rotation

    quaternion = Rotation.from_euler("z", yaw, degrees=True).as_quat()
    extents = carton_extents([Box("a", list(size), [1.0, 0.0, 0.5], quaternion.tolist())])[0]
    expected = np.array(size) if yaw in (0.0, 180.0) else np.array([size[1], size[0], size[2]])
    assert np.allclose(extents, expected)
