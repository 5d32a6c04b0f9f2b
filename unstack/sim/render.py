"""Pictures of a pile: an oblique view of the boxes and the range sensor's view.

Boxes are coloured by how many boxes they support in the ground truth (grey when the
scene has none); detected boxes get a black outline and their id. The sensor view shows
the scene's point cloud as the sensor at the door saw it, coloured the same way (points
on the container are light grey).

Examples
--------
>>> import tempfile, pathlib
>>> from unstack.scene import Box, Scene
>>> scene = Scene([Box("a", [0.6, 0.4, 0.4], [1.0, 0.0, 0.2]), Box("b", [0.4, 0.3, 0.3], [1.0, 0.0, 0.55])],
...               points=[[0.7, 0.0, 0.5]], detected=["a", "b"], ground_truth=[[0, 1], [0, 0]])
>>> target = pathlib.Path(tempfile.mkdtemp()) / "pile.png"
>>> render_scene(scene, target)
>>> target.stat().st_size > 1000
True
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np

from unstack.errors import UnstackError
from unstack.geometry import BOX_FACES, box_corners
from unstack.scene import Scene
from unstack.sim.settings import SensorSettings, SimulationSettings

__all__ = ["render_scene"]


def _support_counts(scene: Scene) -> np.ndarray | None:
    if scene.ground_truth is None:
        return None
    return np.asarray(scene.ground_truth.sum(axis=1), dtype=np.int64)


def _sensor(scene: Scene) -> SensorSettings:
    """The sensor that scanned a simulated scene (the default sensor for other scenes)."""
    data = scene.metadata.get("settings")
    if not isinstance(data, dict):
        return SensorSettings()
    try:
        return SimulationSettings.from_dict(data).sensor
    except (KeyError, TypeError, ValueError, UnstackError):
        return SensorSettings()


def _point_boxes(scene: Scene, base_dir: Path | None) -> np.ndarray | None:
    name = scene.metadata.get("point_boxes_file")
    if not name or base_dir is None:
        return None
    path = base_dir / name
    if not path.is_file():
        return None
    labels = np.load(path, allow_pickle=False)
    return labels if labels.shape == (len(scene.points),) else None


def _project(points: np.ndarray, sensor: SensorSettings) -> tuple[np.ndarray, np.ndarray]:
    """Pixel coordinates (u right, v down) and depth of points seen by the sensor."""
    eye = np.asarray(sensor.position, dtype=np.float64)
    forward = np.asarray(sensor.target, dtype=np.float64) - eye
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    relative = points - eye
    depth = relative @ forward
    focal = sensor.height / 2.0 / np.tan(np.radians(sensor.vertical_fov_deg) / 2.0)
    safe = np.where(depth > 1e-9, depth, np.nan)
    u = sensor.width / 2.0 + focal * (relative @ right) / safe
    v = sensor.height / 2.0 - focal * (relative @ up) / safe
    return np.stack([u, v], axis=1), depth


def _draw_supports(axes: Any, scene: Scene, supports: Any, min_probability: float, sensor: SensorSettings) -> None:
    """Arrows X -> Y in the sensor view for the probable support relations, opacity = probability."""
    for i, supporter in enumerate(supports.objects):
        for j, supported in enumerate(supports.objects):
            probability = float(supports.probabilities[i, j])
            if i == j or probability < min_probability:
                continue
            ends, depths = _project(np.array([scene.box(supporter).position, scene.box(supported).position]), sensor)
            if np.any(depths <= 0):
                continue
            axes.annotate(
                "",
                xy=ends[1],
                xytext=ends[0],
                arrowprops={"arrowstyle": "-|>", "color": "red", "alpha": probability, "lw": 2},
            )
            axes.text(*ends.mean(axis=0), f"{probability:.2f}", color="darkred", fontsize=7, ha="center")


def render_scene(
    scene: Scene,
    output: str | os.PathLike[str],
    *,
    base_dir: str | os.PathLike[str] | None = None,
    title: str | None = None,
    supports: Any = None,
    min_probability: float = 0.1,
) -> None:
    """Draw the oblique view and the sensor view of a scene into a PNG (written atomically).

    Parameters
    ----------
    scene : Scene
    output : path
        The PNG file.
    base_dir : path, optional
        Folder of the scene file, to find its per-point box labels (simulated scenes).
    title : str, optional
    supports : Supports, optional
        Support probabilities of (some of) the scene's boxes: each ordered pair with
        P(SUPP(X, Y)) >= ``min_probability`` is drawn in the sensor view as an arrow from X's
        centroid to Y's, as opaque as it is probable and labelled with the probability.
    min_probability : float
        Smallest probability drawn.
    """
    from unstack.figures import pyplot

    plt = pyplot()
    from matplotlib import colormaps
    from matplotlib.colors import BoundaryNorm
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    counts = _support_counts(scene)
    top = int(counts.max()) if counts is not None and counts.size else 0
    cmap = colormaps["viridis"].resampled(max(top + 1, 2))
    norm = BoundaryNorm(np.arange(-0.5, max(top, 1) + 1.5), cmap.N)
    detected = set(scene.detected)

    def colour(index: int) -> Any:
        return cmap(norm(counts[index])) if counts is not None else (0.7, 0.7, 0.7, 1.0)

    figure = plt.figure(figsize=(13, 5.6))
    oblique = figure.add_subplot(1, 2, 1, projection="3d")
    for index, box in enumerate(scene.boxes):
        corners = box_corners(box)
        faces = [[corners[k] for k in face] for face in BOX_FACES]
        is_detected = box.id in detected
        oblique.add_collection3d(
            Poly3DCollection(
                faces,
                facecolors=[colour(index)],
                edgecolors="black" if is_detected else (0.3, 0.3, 0.3, 0.5),
                linewidths=1.4 if is_detected else 0.4,
                alpha=0.95 if is_detected else 0.45,
            )
        )
        if is_detected:
            label_at = box.position + np.array([0.0, 0.0, box.size.max() / 2.0])
            oblique.text(*label_at, box.id, fontsize=6, zorder=10)
    all_corners = np.concatenate([box_corners(box) for box in scene.boxes])
    low, high = all_corners.min(axis=0), all_corners.max(axis=0)
    low[2] = 0.0
    oblique.set_xlim(low[0] - 0.05, high[0] + 0.05)
    oblique.set_ylim(low[1] - 0.05, high[1] + 0.05)
    oblique.set_zlim(0.0, high[2] + 0.05)
    oblique.set_box_aspect(tuple(np.maximum(high - low + 0.1, 0.2)))
    oblique.set_xlabel("x (into container, m)")
    oblique.set_ylabel("y (m)")
    oblique.set_zlabel("z (m)")
    oblique.view_init(elev=28, azim=-150)  # from the door side
    oblique.set_title("oblique view (outlined: detected)")

    sensor = _sensor(scene)
    view = figure.add_subplot(1, 2, 2)
    points = scene.points
    labels = _point_boxes(scene, Path(base_dir) if base_dir is not None else None)
    image = np.ones((sensor.height, sensor.width, 4))
    if len(points):
        pixels, depth = _project(points, sensor)
        columns = np.round(pixels[:, 0]).astype(np.int64, copy=False)
        rows = np.round(pixels[:, 1]).astype(np.int64, copy=False)
        inside = (depth > 0) & (columns >= 0) & (columns < sensor.width) & (rows >= 0) & (rows < sensor.height)
        shade = 1.0 - 0.5 * (depth - depth.min()) / max(float(np.ptp(depth)), 1e-9)
        if labels is not None:
            palette = np.array([colour(k) for k in range(len(scene.boxes))] + [(0.8, 0.8, 0.8, 1.0)]).reshape(-1, 4)
            colours = palette[np.where(labels >= 0, labels, len(scene.boxes))].copy()
            colours[labels < 0, :3] *= shade[labels < 0, None]
        else:
            colours = np.ones((len(points), 4))
            colours[:, :3] = 0.2 + 0.6 * (1.0 - shade)[:, None]
        order = np.argsort(-depth)  # far points first, near points drawn over them
        order = order[inside[order]]
        image[rows[order], columns[order]] = colours[order]
    view.imshow(image, interpolation="nearest")
    for box in scene.boxes:
        if box.id in detected:
            centre, box_depth = _project(box.position[None, :], sensor)
            if box_depth[0] > 0:
                view.annotate(box.id, centre[0], fontsize=6, ha="center", color="black")
    view.set_xlim(0, sensor.width)
    view.set_ylim(sensor.height, 0)
    view.set_aspect("equal")
    view.set_title(f"sensor view ({len(scene.points):,} points)")
    if supports is not None:
        _draw_supports(view, scene, supports, min_probability, sensor)
        view.set_title(f"sensor view; arrows: learned P(X supports Y) >= {min_probability:g}")
    view.set_xticks([])
    view.set_yticks([])
    if counts is not None:
        mappable = plt.cm.ScalarMappable(norm=norm, cmap=cmap)
        bar = figure.colorbar(mappable, ax=[oblique, view], shrink=0.7, ticks=range(max(top, 1) + 1))
        bar.set_label("boxes supported (ground truth)")
    if title:
        figure.suptitle(title)
    from unstack.figures import save_figure

    save_figure(figure, output)
