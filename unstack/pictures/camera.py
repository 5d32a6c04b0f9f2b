"""The pinhole camera a sensor view is drawn through (plain numbers; the simulator's sensor maps onto it).

Examples
--------
>>> camera = Camera(position=(-2.0, 0.0, 1.0), target=(1.0, 0.0, 1.0))
>>> pixels, depth = camera.project([[1.0, 0.0, 1.0]])
>>> pixels.round(1).tolist(), depth.round(1).tolist()
([[320.0, 240.0]], [3.0])
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from unstack.scene import Scene

__all__ = ["Camera", "point_box_labels"]


@dataclass(frozen=True)
class Camera:
    """Where the sensor sits, where it looks, its vertical field of view and image size."""

    position: tuple[float, float, float] = (-2.8, 0.0, 1.3)
    target: tuple[float, float, float] = (1.0, 0.0, 0.9)
    vertical_fov_deg: float = 43.0
    width: int = 640
    height: int = 480

    def project(self, points: Any) -> tuple[np.ndarray, np.ndarray]:
        """Pixel coordinates (u right, v down) and depth along the view axis of ``points`` (n x 3).

        Points behind the camera get NaN pixels.
        """
        eye = np.asarray(self.position, dtype=np.float64)
        forward = np.asarray(self.target, dtype=np.float64) - eye
        forward /= np.linalg.norm(forward)
        right = np.cross(forward, [0.0, 0.0, 1.0])
        right /= np.linalg.norm(right)
        up = np.cross(right, forward)
        relative = np.asarray(points, dtype=np.float64).reshape(-1, 3) - eye
        depth = relative @ forward
        focal = self.height / 2.0 / np.tan(np.radians(self.vertical_fov_deg) / 2.0)
        safe = np.where(depth > 1e-9, depth, np.nan)
        u = self.width / 2.0 + focal * (relative @ right) / safe
        v = self.height / 2.0 - focal * (relative @ up) / safe
        return np.stack([u, v], axis=1), depth


def point_box_labels(scene: Scene, base_dir: str | os.PathLike[str] | None) -> np.ndarray | None:
    """Per-point box index of a simulated scene (``metadata["point_boxes_file"]``; -1: container), or
    None (no such file, or not one integer from -1 to the number of boxes less one per point).

    Examples
    --------
    >>> from unstack.scene import Box
    >>> point_box_labels(Scene([Box("a", [1, 1, 1], [0, 0, 0.5])], points=[], detected=["a"]), None) is None
    True
    """
    name = scene.metadata.get("point_boxes_file")
    if not name or base_dir is None:
        return None
    path = Path(base_dir) / str(name)
    if not path.is_file():
        return None
    try:
        labels = np.load(path, allow_pickle=False)
    except (OSError, ValueError):
        return None
    if labels.shape != (len(scene.points),) or not np.issubdtype(labels.dtype, np.integer):
        return None
    # -1 the container, else a box's index: other labels are not this scene's
    return labels if labels.size == 0 or (labels.min() >= -1 and labels.max() < len(scene.boxes)) else None
