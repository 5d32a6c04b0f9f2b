"""The simulator's sensor as a camera's files: depth image, intrinsics, pose, one mask per box.

What a robot's depth camera and box detector hand over, rendered from a simulated scene, so
that :func:`unstack.camera.scene_from_depth` can be tried against the truth. The sensor is the
one the scene was scanned with (its jittered viewpoint when the data set moved it); a box is
given a mask when the sensor sees at least ``min_pixels`` of it, the data sets' detection rule.

Examples
--------
>>> from unstack.scene import Box, Scene
>>> from unstack.sim.settings import SensorSettings, SimulationSettings
>>> settings = SimulationSettings(boxes=(1, 1), sensor=SensorSettings(width=80, height=60, min_pixels=5))
>>> box = Box("b00", [0.6, 0.4, 0.4], [1.0, 0.0, 0.2])
>>> scene = Scene([box], [], ["b00"], metadata={"settings": settings.to_dict()})
>>> view = camera_view(scene)
>>> view.depth_m.shape, sorted(view.masks)
((60, 80), ['b00'])
"""

from __future__ import annotations

import dataclasses
import io
import json
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from unstack.errors import UnstackError
from unstack.scene import Scene

__all__ = ["CameraView", "camera_view", "save_camera_files", "scene_sensor"]


@dataclass(frozen=True)
class CameraView:
    """One rendered frame: depth (metres, 0 where nothing was hit), intrinsics, pose, masks by box id."""

    depth_m: np.ndarray
    intrinsics: Any
    camera_to_world: np.ndarray
    masks: dict[str, np.ndarray]


def scene_sensor(scene: Scene) -> Any:
    """The sensor a simulated scene was scanned with (its viewpoint moved as the data set moved it)."""
    from unstack.sim.settings import scene_settings

    settings = scene_settings(scene)
    if settings is None:
        raise UnstackError(f"{scene.source}: $.metadata.settings: rendering a camera view needs a simulated scene")
    sensor = dataclasses.replace(settings.sensor, position_jitter=0.0)
    simulation = scene.metadata.get("simulation", {})
    if "sensor_position" in simulation:
        from unstack.checks import check_vector

        position, target = (
            check_vector(simulation.get(key), 3, source=scene.source, path=f"$.metadata.simulation.{key}")
            for key in ("sensor_position", "sensor_target")
        )
        x, y, z = (float(value) for value in position)
        aim_x, aim_y, aim_z = (float(value) for value in target)
        sensor = dataclasses.replace(sensor, position=(x, y, z), target=(aim_x, aim_y, aim_z))
    return sensor


def camera_view(scene: Scene, *, noise_seed: int | None = None) -> CameraView:
    """Render the scene's boxes with its sensor: depth, intrinsics, pose and the masks of the seen boxes.

    ``noise_seed``: with the sensor's depth noise on (its ``noise`` setting), the seed of the noise.
    """
    from unstack.sim.sensor import scan_pile, sensor_intrinsics, sensor_pose
    from unstack.sim.settings import SimulationSettings, scene_settings
    from unstack.sim.world import PhysicsWorld

    sensor = scene_sensor(scene)
    settings = scene_settings(scene) or SimulationSettings()
    with PhysicsWorld(settings, door=False) as world:
        for box in scene.boxes:
            world.add_box(box.size, box.position, box.orientation_xyzw, mass=1.0)
        scan = scan_pile(world, sensor, seed=noise_seed)
    hit = scan.box_image >= -1
    depth = np.where(hit, scan.depth_image, 0.0)
    masks = {
        box.id: scan.box_image == k for k, box in enumerate(scene.boxes) if scan.pixel_counts[k] >= sensor.min_pixels
    }
    return CameraView(depth, sensor_intrinsics(sensor), sensor_pose(sensor), masks)


def save_camera_files(view: CameraView, folder: str | os.PathLike[str]) -> list[Path]:
    """Write a view as a camera's files: ``depth.png`` (16-bit, mm), ``intrinsics.json``,
    ``pose.json`` (camera to world) and ``mask-<id>.png`` per seen box; the paths written."""
    from PIL import Image

    from unstack.atomic import atomic_write_bytes, atomic_write_text

    target = Path(folder)
    target.mkdir(parents=True, exist_ok=True)

    def png(path: Path, array: np.ndarray) -> Path:
        buffer = io.BytesIO()
        Image.fromarray(array).save(buffer, format="PNG")
        atomic_write_bytes(path, buffer.getvalue())
        return path

    millimetres = np.round(view.depth_m * 1000.0)
    written = [png(target / "depth.png", np.clip(millimetres, 0, 65535).astype(np.uint16))]
    intrinsics = {name: getattr(view.intrinsics, name) for name in ("fx", "fy", "cx", "cy", "width", "height")}
    atomic_write_text(target / "intrinsics.json", json.dumps(intrinsics, indent=2) + "\n")
    atomic_write_text(target / "pose.json", json.dumps({"camera_to_world": view.camera_to_world.tolist()}) + "\n")
    written += [target / "intrinsics.json", target / "pose.json"]
    for box_id, mask in view.masks.items():
        written.append(png(target / f"mask-{box_id}.png", mask.astype(np.uint8) * 255))
    return written
