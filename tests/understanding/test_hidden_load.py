"""The hidden-load estimate sees undetected boxes on detected ones, on both kinds of cloud."""

from __future__ import annotations

import numpy as np
import pytest

from unstack.scene import Box, Scene
from unstack.understanding.clouds import surface_cloud, vary_cloud
from unstack.understanding.hidden_load import container_planes, hidden_load


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


def _container_walls(
    rng: np.random.Generator, depth: float = 2.0, width: float = 2.35, height: float = 2.39
) -> np.ndarray:
    """Points on a container's back wall, side walls and ceiling, with a few millimetres of noise."""
    count = 3000
    back = np.column_stack(
        [np.full(count, depth), rng.uniform(-width / 2, width / 2, count), rng.uniform(0, height, count)]
    )
    left = np.column_stack([rng.uniform(0, depth, count), np.full(count, -width / 2), rng.uniform(0, height, count)])
    right = np.column_stack([rng.uniform(0, depth, count), np.full(count, width / 2), rng.uniform(0, height, count)])
    ceiling = np.column_stack(
        [rng.uniform(0, depth, count), rng.uniform(-width / 2, width / 2, count), np.full(count, height)]
    )
    walls = np.vstack([back, left, right, ceiling])
    return walls + rng.normal(0.0, 0.004, walls.shape)


def _inside_container(cloud: np.ndarray, depth: float = 2.0, width: float = 2.35) -> np.ndarray:
    """The cloud without the floor beyond the walls (a sensor inside a container sees none)."""
    return cloud[(cloud[:, 0] <= depth) & (np.abs(cloud[:, 1]) <= width / 2)]


@pytest.mark.parametrize("seed", range(4))
def test_the_container_walls_behind_and_beside_a_box_are_not_load(seed: int) -> None:
    rng = np.random.default_rng(seed)
    size = rng.uniform([0.3, 0.3, 0.2], [0.6, 0.45, 0.4])
    against_back = Box("against_back", size, [2.0 - size[0] / 2, 0.2, size[2] / 2])
    in_corner = Box("in_corner", size, [2.0 - size[0] / 2, -2.35 / 2 + size[1] / 2, size[2] / 2])
    boxes = [against_back, in_corner]
    cloud = np.vstack(
        [_inside_container(surface_cloud(boxes, viewpoint=[-2.0, 0.0, 1.5], seed=seed)), _container_walls(rng)]
    )
    assert hidden_load(Scene(boxes, cloud, ["against_back", "in_corner"])).tolist() == [0.0, 0.0]


def test_an_undetected_box_against_the_back_wall_still_counts() -> None:
    rng = np.random.default_rng(5)
    under = Box("under", [0.5, 0.4, 0.3], [1.75, 0.2, 0.15])
    unseen = Box("unseen", [0.4, 0.4, 0.3], [1.8, 0.2, 0.451])
    cloud = surface_cloud([under, unseen], viewpoint=[-2.0, 0.0, 1.5], seed=5)
    cloud = np.vstack([_inside_container(cloud), _container_walls(rng)])
    assert hidden_load(Scene([under, unseen], cloud, ["under"]))[0] == pytest.approx(1.0, abs=0.45)


def test_container_planes_finds_walls_and_ceiling_but_not_a_carton() -> None:
    rng = np.random.default_rng(0)
    walls = _container_walls(rng)
    carton = surface_cloud([Box("c", [0.5, 0.4, 0.3], [1.0, 0.0, 0.15])], viewpoint=[-2.0, 0.0, 1.5], seed=0)
    inside = _inside_container(carton)
    planes = container_planes(np.vstack([walls, inside]))
    assert planes[: len(walls)].mean() > 0.95
    assert not planes[len(walls) :][inside[:, 2] > 0.01].any()  # the carton's faces (the floor meets the walls)
    assert not container_planes(carton).any()  # in the open: nothing is dropped


def test_the_walls_of_a_narrow_section_are_found_behind_a_wider_floor_and_door_frame() -> None:
    rng = np.random.default_rng(3)
    walls = _container_walls(rng, depth=1.0, width=1.2, height=2.3)
    floor = np.column_stack([rng.uniform(-0.7, 1.0, 4000), rng.uniform(-0.7, 0.7, 4000), np.zeros(4000)])
    door_frame = np.column_stack([np.zeros(400), rng.choice([-0.7, 0.7], 400), rng.uniform(0.0, 2.0, 400)])
    planes = container_planes(np.vstack([walls, floor, door_frame]))
    assert planes[: len(walls)].mean() > 0.95
    assert not planes[len(walls) : len(walls) + len(floor)].any()
