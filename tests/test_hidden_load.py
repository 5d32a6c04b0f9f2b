"""The hidden-load estimate sees undetected boxes on detected ones, on both kinds of cloud."""

from __future__ import annotations

import numpy as np
import pytest

from unstack.clouds import surface_cloud, vary_cloud
from unstack.hidden_load import hidden_load
from unstack.scene import Box, Scene


def _loaded_and_free(rng: np.random.Generator) -> list[Box]:
    under = rng.uniform([0.3, 0.3, 0.2], [0.5, 0.45, 0.35])
    on_top = rng.uniform([0.3, 0.3, 0.2], [0.5, 0.45, 0.35])
    free = rng.uniform([0.3, 0.3, 0.2], [0.5, 0.45, 0.35])
    return [
        Box("loaded", under, [1.2, -0.35, under[2] / 2]),
        Box("unseen", on_top, [1.2, -0.35, under[2] + on_top[2] / 2 + 0.001]),
        Box("free", free, [1.2, 0.35, free[2] / 2]),
    ]


@pytest.mark.parametrize("seed", range(6))
def test_an_undetected_box_on_a_detected_one_counts_about_one_box(seed: int) -> None:
    rng = np.random.default_rng(seed)
    boxes = _loaded_and_free(rng)
    cloud = surface_cloud(boxes, viewpoint=[-2.0, rng.uniform(-0.5, 0.5), 1.5], spacing=0.02, seed=seed)
    load = hidden_load(Scene(boxes, cloud, ["loaded", "free"]))
    assert load[0] == pytest.approx(1.0, abs=0.45)
    assert load[1] == 0.0


def test_a_detected_load_is_explained_and_counts_nothing() -> None:
    boxes = _loaded_and_free(np.random.default_rng(1))
    cloud = surface_cloud(boxes, viewpoint=[-2.0, 0.0, 1.5], seed=1)
    assert hidden_load(Scene(boxes, cloud, ["loaded", "unseen", "free"])).tolist() == [0.0, 0.0, 0.0]


def test_a_sparser_noisier_cloud_still_shows_the_load() -> None:
    boxes = _loaded_and_free(np.random.default_rng(2))
    cloud = surface_cloud(boxes, viewpoint=[-2.0, 0.0, 1.5], spacing=0.01, seed=2)
    rng = np.random.default_rng(3)
    sparse = vary_cloud(cloud, rng, keep_range=(0.2, 0.2), max_depth_noise=0.003, max_holes=0)
    assert hidden_load(Scene(boxes, sparse, ["loaded", "free"]))[0] > 0.5


def test_without_a_cloud_nothing_is_hidden() -> None:
    boxes = _loaded_and_free(np.random.default_rng(0))
    assert hidden_load(Scene(boxes, np.zeros((0, 3)), ["loaded"])).tolist() == [0.0]
