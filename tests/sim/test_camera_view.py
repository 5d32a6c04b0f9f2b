"""The simulator's sensor as camera files: the same points, and scenes built back from them."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from unstack.camera import depth_points, scene_from_depth
from unstack.dataset_folders import list_configurations
from unstack.scene import load_scene
from unstack.sim.camera_view import camera_view

pytestmark = pytest.mark.slow  # renders piles


def test_the_intrinsics_and_pose_give_back_the_scan_points(small_dataset: Path) -> None:
    scene = load_scene(list_configurations(small_dataset)[0])
    view = camera_view(scene)
    points = depth_points(view.depth_m, view.intrinsics, view.camera_to_world)
    assert len(points) == len(scene.points)
    assert np.abs(np.sort(points, axis=0) - np.sort(scene.points, axis=0)).max() < 1e-4


@pytest.mark.parametrize("pile", [1, 2])
def test_most_boxes_come_back_within_a_centimetre_and_gravity_within_a_fifth_of_a_degree(
    small_dataset: Path, pile: int
) -> None:
    scene = load_scene(list_configurations(small_dataset)[pile])
    view = camera_view(scene)
    ids = sorted(view.masks)
    sizes = sorted({tuple(np.sort(box.size)) for box in scene.boxes})
    built = scene_from_depth(view.depth_m, view.intrinsics, view.camera_to_world, [view.masks[i] for i in ids],
                             ids=ids, known_sizes=sizes, door=[-1.0, 0.0, 0.0])  # fmt: skip
    assert built.frame.tilt_deg < 0.2
    assert len(built.fitted) >= len(ids) - 2
    errors = [np.linalg.norm(item.box.position - scene.box(item.box.id).position) for item in built.fitted]
    assert np.median(errors) < 0.01


@pytest.mark.parametrize(
    ("key", "value", "message"),
    [
        ("sensor_position", "door", r"\$\.metadata\.simulation\.sensor_position: expected 3 numbers"),
        ("sensor_target", [1.0, float("nan"), 0.9], r"\$\.metadata\.simulation\.sensor_target\[1\]: expected a finite"),
    ],
)
def test_a_bad_sensor_pose_in_the_metadata_names_its_json_path(
    small_dataset: Path, key: str, value: object, message: str
) -> None:
    from unstack.errors import InvalidScene
    from unstack.scene import Scene
    from unstack.sim.camera_view import scene_sensor

    scene = load_scene(list_configurations(small_dataset)[0])
    metadata = {
        **scene.metadata,
        "simulation": {
            **scene.metadata.get("simulation", {}),
            "sensor_position": [-2.8, 0.0, 1.3],
            "sensor_target": [1.0, 0.0, 0.9],
        },
    }
    metadata["simulation"][key] = value
    with pytest.raises(InvalidScene, match=message):  # NaN: the scene refuses it; a word: the sensor's reader
        scene_sensor(Scene(scene.boxes, scene.points, scene.detected, metadata=metadata, source=scene.source))
