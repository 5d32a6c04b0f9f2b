"""A synthetic pile of 40 detected boxes with seeded expected costs, for the pictures' tests."""

from __future__ import annotations

import numpy as np
import pytest

from unstack.pictures.values import DecisionValues
from unstack.scene import Box, Scene


def wall_scene(columns: int = 8, rows: int = 5, *, seed: int = 0) -> Scene:
    """A wall of ``columns`` x ``rows`` boxes facing the door, all detected, with a cloud on the front faces."""
    rng = np.random.default_rng(seed)
    boxes = []
    for row in range(rows):
        for column in range(columns):
            size = np.array([0.4, 0.3, 0.3])
            position = np.array([1.2, (column - (columns - 1) / 2) * 0.31, 0.15 + 0.305 * row])
            boxes.append(Box(f"b{row * columns + column:02d}", size, position))
    points = np.concatenate(
        [
            np.column_stack(
                [
                    np.full(50, box.position[0] - 0.2),
                    box.position[1] + rng.uniform(-0.14, 0.14, 50),
                    box.position[2] + rng.uniform(-0.14, 0.14, 50),
                ]
            )
            for box in boxes
        ]
    )
    truth = np.zeros((len(boxes), len(boxes)), dtype=np.int64)
    for k in range(len(boxes) - columns):
        truth[k, k + columns] = 1
    return Scene(boxes, points=points, detected=[box.id for box in boxes], ground_truth=truth)


def wall_values(scene: Scene, *, seed: int = 0, order: bool = False) -> DecisionValues:
    """Seeded costs (higher low in the wall), some sampled errors, probabilities from the truth plus noise."""
    rng = np.random.default_rng(seed)
    n = len(scene.boxes)
    heights = np.array([box.position[2] for box in scene.boxes])
    costs = (heights.max() - heights) * 3.0 + rng.uniform(0.0, 0.3, n)
    errors = np.where(rng.random(n) < 0.5, rng.uniform(0.01, 0.1, n), 0.0)
    assert scene.ground_truth is not None
    probabilities = np.clip(scene.ground_truth * 0.9 + rng.uniform(0.0, 0.3, (n, n)), 0.0, 1.0)
    np.fill_diagonal(probabilities, 0.0)
    ids = [box.id for box in scene.boxes]
    choice = ids[int(np.argmin(costs))]
    plan = [ids[i] for i in np.argsort(costs, kind="stable")] if order else None
    return DecisionValues(ids, costs, errors, choice=choice, order=plan, probabilities=probabilities)


@pytest.fixture
def wall() -> Scene:
    return wall_scene()


@pytest.fixture
def wall_decision(wall: Scene) -> DecisionValues:
    return wall_values(wall, seed=3, order=True)
