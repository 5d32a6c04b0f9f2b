"""The range sensor: points lie on the boxes they are labelled with, noise is seeded."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from unstack.sim.sensor import scan_pile
from unstack.sim.settings import SensorSettings, SimulationSettings
from unstack.sim.world import PhysicsWorld

pytestmark = pytest.mark.slow  # renders range images

BOXES = [  # centre, size: in view of the default sensor at the door
    ([0.5, 0.3, 0.2], [0.6, 0.4, 0.4]),
    ([0.7, -0.4, 0.55], [0.4, 0.3, 0.3]),
    ([0.9, 0.0, 0.3], [0.3, 0.3, 0.6]),
]


def scene(settings: SimulationSettings, sensor: SensorSettings, seed: int | None = None) -> tuple[np.ndarray, ...]:
    with PhysicsWorld(settings, door=False) as world:
        for centre, size in BOXES:
            world.add_box(size, centre, [0, 0, 0, 1], mass=5.0)
        scan = scan_pile(world, sensor, seed=seed)
    return scan.points, scan.point_boxes, scan.pixel_counts


def outside_distance(points: np.ndarray, centre: list[float], size: list[float]) -> np.ndarray:
    return np.max(np.abs(points - np.asarray(centre)) - np.asarray(size) / 2.0, axis=1)


@pytest.mark.parametrize("resolution", [(96, 72), (640, 480)])
def test_every_point_lies_on_its_box(settings: SimulationSettings, resolution: tuple[int, int]) -> None:
    sensor = replace(settings.sensor, width=resolution[0], height=resolution[1])
    points, point_boxes, counts = scene(settings, sensor)
    assert points.shape == (len(point_boxes), 3) and np.all(np.isfinite(points))
    for index, (centre, size) in enumerate(BOXES):
        on_box = points[point_boxes == index]
        assert len(on_box) == counts[index] > 0
        # the renderer's pixel convention (integer coordinates, rows flipped): within 1 mm;
        # sampling at pixel centres would put points 3-7 mm outside
        assert outside_distance(on_box, centre, size).max() < 1e-3


def test_container_points_are_labelled_minus_one(settings: SimulationSettings) -> None:
    points, point_boxes, _ = scene(settings, settings.sensor)
    floor = points[point_boxes == -1]
    assert len(floor) > 0 and np.all(point_boxes >= -1)


def test_depth_noise_is_seeded_and_grows_with_depth(settings: SimulationSettings) -> None:
    noisy = replace(settings.sensor, noise=True)
    clean, _, _ = scene(settings, settings.sensor)
    first, _, _ = scene(settings, noisy, seed=4)
    again, _, _ = scene(settings, noisy, seed=4)
    other, _, _ = scene(settings, noisy, seed=5)
    assert np.array_equal(first, again) and not np.array_equal(first, other)
    errors = np.linalg.norm(first - clean, axis=1)
    depth = np.linalg.norm(clean - np.asarray(settings.sensor.position), axis=1)
    near, far = errors[depth < np.median(depth)], errors[depth >= np.median(depth)]
    assert 0 < near.std() < far.std() < 0.05


def test_detectable_needs_enough_pixels(settings: SimulationSettings) -> None:
    _, _, counts = scene(settings, settings.sensor)
    assert np.all(counts >= settings.sensor.min_pixels)
    strict = replace(settings.sensor, min_pixels=int(counts.max()) + 1)
    assert not np.any(counts >= strict.min_pixels)
