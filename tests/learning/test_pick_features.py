"""The robot's view of each candidate pick: detected boxes and the cloud only."""

from __future__ import annotations

import numpy as np
import pytest

from unstack.errors import InvalidArgument
from unstack.learning.pick_features import PICK_FEATURES, pick_features
from unstack.scene import Box, Scene
from unstack.supports import Supports
from unstack.understanding.clouds import surface_cloud


def column(rows: np.ndarray, name: str) -> np.ndarray:
    return rows[:, PICK_FEATURES.index(name)]


@pytest.fixture
def stack() -> list[Box]:
    """Two boxes side by side on the floor, a third on the first, a fourth (undetected) on the third."""
    return [
        Box("base", [0.4, 0.4, 0.3], [1.0, -0.3, 0.15]),
        Box("free", [0.4, 0.4, 0.3], [1.0, 0.105, 0.15]),  # 5 mm beside the base
        Box("middle", [0.4, 0.4, 0.3], [1.0, -0.3, 0.45]),
        Box("hidden", [0.4, 0.4, 0.3], [1.0, -0.3, 0.75]),
    ]


def features_of(scene: Scene) -> np.ndarray:
    n = len(scene.detected)
    marginals = np.full((n, n), 0.1) * (1 - np.eye(n))
    supports = Supports(list(scene.detected), marginals, hidden_load=np.zeros(n))
    return pick_features(scene, supports, marginals, marginals.sum(axis=1))


def test_one_row_of_every_feature_per_detected_box(stack: list[Box]) -> None:
    scene = Scene(stack, surface_cloud(stack, viewpoint=[-2.0, 0.0, 1.5], seed=0), ["base", "free", "middle"])
    rows = features_of(scene)
    assert rows.shape == (3, len(PICK_FEATURES)) and rows.dtype == np.float64 and np.isfinite(rows).all()


def test_contacts_count_detected_boxes_on_top_and_below(stack: list[Box]) -> None:
    scene = Scene(stack, np.zeros((0, 3)), ["base", "free", "middle"])
    rows = features_of(scene)
    assert column(rows, "detected_on_top").tolist() == [1.0, 0.0, 0.0]  # the hidden box is not seen as a box
    assert column(rows, "detected_below").tolist() == [0.0, 0.0, 1.0]
    assert column(rows, "on_floor").tolist() == [1.0, 1.0, 0.0]
    assert column(rows, "detected_beside").tolist() == [1.0, 1.0, 0.0]


def test_the_cloud_over_a_box_shows_load_nobody_detected(stack: list[Box]) -> None:
    cloud = surface_cloud(stack, viewpoint=[-2.0, 0.0, 1.5], seed=0)
    rows = features_of(Scene(stack, cloud, ["base", "free", "middle"]))
    unexplained = column(rows, "log_unexplained_over_top")
    # the middle box carries the hidden one; over the free box only the hidden box's edge shows
    assert unexplained[2] > unexplained[1] + 1.0


def test_undetected_poses_are_never_read(stack: list[Box], rng: np.random.Generator) -> None:
    cloud = surface_cloud(stack, viewpoint=[-2.0, 0.0, 1.5], seed=0)
    moved = [*stack[:3], Box("hidden", [0.3, 0.3, 0.3], [1.0 + rng.uniform(0.5, 1.0), 0.9, 0.15])]
    first = features_of(Scene(stack, cloud, ["base", "free", "middle"]))
    second = features_of(Scene(moved, cloud, ["base", "free", "middle"]))
    np.testing.assert_array_equal(first, second)


def test_arrays_that_do_not_match_the_supports_are_refused(stack: list[Box]) -> None:
    scene = Scene(stack, np.zeros((0, 3)), ["base", "free"])
    supports = Supports(["base", "free"], [[0, 0.1], [0.1, 0]])
    with pytest.raises(InvalidArgument, match=r"marginals of shape \(2, 2\).*got \(3, 3\)"):
        pick_features(scene, supports, np.zeros((3, 3)), np.zeros(2))
