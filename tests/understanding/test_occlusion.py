"""The space the sensor cannot see (unstack.understanding.occlusion)."""

from __future__ import annotations

import numpy as np
import pytest

from unstack.geometry import bounding_boxes
from unstack.scene import Box
from unstack.understanding.clouds import surface_cloud
from unstack.understanding.occlusion import CLEARANCE, OccludedBlocks, occluded_space

VIEWPOINT = [-2.8, 0.0, 1.3]
INTERIOR = [[0.0, -1.175, 0.0], [2.0, 1.175, 2.39]]
#: Point spacing of a depth image at the pile's range (about a pixel of the simulated sensor).
DENSE = 0.005


def _unseen(blocks: OccludedBlocks, point: list[float]) -> bool:
    return bool(np.all(np.abs(blocks.centers - point) <= blocks.sizes / 2, axis=1).any())


def test_a_box_hidden_behind_a_seen_one_is_unseen_space_and_seen_space_is_not(hidden_step: list[Box]) -> None:
    cloud = surface_cloud(hidden_step, viewpoint=VIEWPOINT, spacing=DENSE, seed=0)
    front, _, up = hidden_step
    blocks = occluded_space(cloud, [front, up], viewpoint=VIEWPOINT, interior=INTERIOR)
    assert _unseen(blocks, [1.0, 0.0, 0.15])  # where the hidden box is
    assert not _unseen(blocks, [0.6, 0.0, 0.2])  # inside a seen box
    assert not _unseen(blocks, [0.6, 0.0, 0.55])  # open air above the front box, seen through
    assert not _unseen(blocks, [0.2, 0.0, 0.2])  # in front of the pile


def test_no_points_or_no_boxes_give_no_unseen_space(hidden_step: list[Box]) -> None:
    cloud = surface_cloud(hidden_step, viewpoint=VIEWPOINT, spacing=DENSE, seed=0)
    assert len(occluded_space(np.zeros((0, 3)), hidden_step, viewpoint=VIEWPOINT, interior=INTERIOR)) == 0
    assert len(occluded_space(cloud, [], viewpoint=VIEWPOINT, interior=INTERIOR)) == 0


@pytest.mark.parametrize("seed", range(3))
def test_blocks_stay_inside_the_container_and_out_of_every_seen_box(seed: int) -> None:
    rng = np.random.default_rng(seed)
    boxes = []
    for k, (x, y) in enumerate([(x, y) for x in (0.5, 1.0, 1.5) for y in (-0.6, 0.0, 0.6)]):
        height = float(rng.uniform(0.2, 0.5))
        boxes.append(Box(f"b{k}", [0.45, 0.5, height], [x, y, height / 2]))
        if rng.random() < 0.5:  # a second box on it
            on = float(rng.uniform(0.2, 0.4))
            boxes.append(Box(f"b{k}u", [0.45, 0.5, on], [x + rng.uniform(-0.03, 0.03), y, height + on / 2]))
    cloud = surface_cloud(boxes, viewpoint=VIEWPOINT, spacing=DENSE, seed=seed)
    seen = [box for box in boxes if rng.random() < 0.6] or boxes[:1]
    blocks = occluded_space(cloud, seen, viewpoint=VIEWPOINT, interior=INTERIOR)
    assert len(blocks) > 0
    low, high = blocks.centers - blocks.sizes / 2, blocks.centers + blocks.sizes / 2
    assert np.all(low >= np.array(INTERIOR[0]) - 1e-9) and np.all(high <= np.array(INTERIOR[1]) + 1e-9)
    for bound in bounding_boxes(seen):
        overlap = np.minimum(high, bound[3:]) - np.maximum(low, bound[:3])
        assert not np.any(np.all(overlap > CLEARANCE / 2, axis=1))


@pytest.mark.parametrize("seed", range(3))
def test_blocks_are_runs_along_the_depth_that_never_overlap_one_another(seed: int) -> None:
    rng = np.random.default_rng(seed)
    boxes = [
        Box(f"b{k}", [0.4, 0.45, 0.3], [float(rng.uniform(0.3, 1.7)), float(rng.uniform(-0.9, 0.9)), 0.15])
        for k in range(6)
    ]
    boxes = [
        box
        for k, box in enumerate(boxes)
        if not any(np.all(np.abs(box.position[:2] - other.position[:2]) < [0.4, 0.45]) for other in boxes[:k])
    ]
    cloud = surface_cloud(boxes, viewpoint=VIEWPOINT, spacing=DENSE, seed=seed)
    blocks = occluded_space(cloud, boxes, viewpoint=VIEWPOINT, interior=INTERIOR)
    low, high = blocks.centers - blocks.sizes / 2, blocks.centers + blocks.sizes / 2
    overlap = np.minimum(high[:, None], high[None]) - np.maximum(low[:, None], low[None])
    overlapping = np.all(overlap > 1e-9, axis=2)
    np.fill_diagonal(overlapping, False)
    assert len(blocks) > 0 and not overlapping.any()
    assert np.all(blocks.sizes[:, 1:] <= 0.06 + 1e-9)  # one cell across, any length along the depth
