"""Is this scene physical? Refuse what cannot be, warn about what is doubtful.

A scene in millimetres (600 m boxes) or with two boxes in one place would otherwise be
decided like any other. The hard limits are checked when a :class:`~unstack.scene.Box` or a
:class:`~unstack.scene.Scene` is built (an :class:`~unstack.errors.InvalidScene` naming the
file and the JSON path): box edges between :data:`MIN_BOX_EDGE` and :data:`MAX_BOX_EDGE`
metres, coordinates within :data:`MAX_COORDINATE` metres of the origin, and no two boxes
sharing more than :data:`REFUSED_OVERLAP` of the smaller one's volume.

:func:`scene_warnings` lists what is doubtful but possible, one line each: boxes that
overlap by more than :data:`WARNED_OVERLAP` of the smaller volume, boxes that reach
more than :data:`BELOW_FLOOR` into the floor, detected boxes that float (nothing under them
within :data:`FLOAT_GAP`: no box, no floor, no point of the cloud), and a cloud that is empty or
lies far from the boxes.

Examples
--------
>>> from unstack.scene import Box, Scene
>>> floating = Scene([Box("a", [0.4, 0.4, 0.3], [1.0, 0.0, 0.8])], [[1.0, 0.0, 0.95]], ["a"])
>>> scene_warnings(floating)[0]
"<array>: box 'a' floats: its bottom is 0.65 m above the floor with no box or point of the cloud under it"
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from unstack.geometry import bounding_boxes, box_corners, footprint, footprint_overlap_area, rotation_matrix

if TYPE_CHECKING:
    from unstack.scene import Box, Scene

__all__ = [
    "BELOW_FLOOR",
    "FLOAT_GAP",
    "MAX_BOX_EDGE",
    "MAX_COORDINATE",
    "MIN_BOX_EDGE",
    "REFUSED_OVERLAP",
    "WARNED_OVERLAP",
    "overlap_share",
    "overlapping_pairs",
    "scene_warnings",
]

#: Shortest box edge accepted (metres): smaller is not a carton, or the unit is not metres.
MIN_BOX_EDGE = 0.02
#: Longest box edge accepted (metres): longer is not a carton, or the unit is millimetres.
MAX_BOX_EDGE = 5.0
#: Farthest coordinate accepted, boxes and cloud (metres from the origin along any axis).
MAX_COORDINATE = 100.0
#: Two boxes sharing more than this share of the smaller one's volume are refused ...
REFUSED_OVERLAP = 0.5
#: ... and more than this share is warned about (a few millimetres of interpenetration of
#: simulated or measured poses stay below it).
WARNED_OVERLAP = 0.05
#: A detected box whose bottom has nothing under it within this gap floats (metres).
FLOAT_GAP = 0.05
#: A box reaching deeper than this below the floor (z = 0) is warned about (metres).
BELOW_FLOOR = 0.02
#: A cloud whose points are mostly farther than this from every box is "far" (metres).
FAR_CLOUD = 0.5
#: Grid steps per axis when measuring the overlap of two boxes whose axes are not parallel.
_OVERLAP_STEPS = 12


def overlap_share(first: Box, second: Box) -> float:
    """Share of the smaller box's volume that lies inside the other: exact when the two boxes'
    axes are parallel (every pile of cartons, up to a swap of axes), a grid estimate otherwise.

    Examples
    --------
    >>> from unstack.scene import Box
    >>> overlap_share(Box("a", [1, 1, 1], [0, 0, 0.5]), Box("b", [1, 1, 1], [0.5, 0, 0.5]))
    0.5
    >>> overlap_share(Box("a", [0.4, 0.4, 0.4], [0, 0, 0.2]), Box("b", [0.4, 0.4, 0.4], [0.22, 0, 0.2]))
    0.45
    """
    small, large = (first, second) if np.prod(first.size) <= np.prod(second.size) else (second, first)
    to_large = rotation_matrix(large.orientation_xyzw)
    relative = to_large.T @ rotation_matrix(small.orientation_xyzw)  # the small box's axes in the large one's frame
    axes = np.round(np.abs(relative))  # a rotation whose entries are 0 or +-1 permutes the axes
    if np.allclose(np.abs(relative), axes, atol=1e-6):
        centre = to_large.T @ (np.asarray(small.position) - large.position)
        half = axes @ (np.asarray(small.size) / 2.0)
        low = np.maximum(centre - half, -np.asarray(large.size) / 2.0)
        high = np.minimum(centre + half, np.asarray(large.size) / 2.0)
        return round(float(np.prod(np.clip(high - low, 0.0, None)) / np.prod(small.size)), 12)
    steps = (np.arange(_OVERLAP_STEPS) + 0.5) / _OVERLAP_STEPS - 0.5
    grid = np.stack(np.meshgrid(steps, steps, steps, indexing="ij"), axis=-1).reshape(-1, 3) * small.size
    points = grid @ rotation_matrix(small.orientation_xyzw).T + small.position
    local = (points - large.position) @ rotation_matrix(large.orientation_xyzw)
    return float(np.mean(np.all(np.abs(local) <= large.size / 2.0, axis=1)))


def overlapping_pairs(boxes: Sequence[Box], threshold: float) -> list[tuple[int, int, float]]:
    """Pairs of box indices whose overlap share exceeds ``threshold``, with the share."""
    bounds = bounding_boxes(boxes)
    result = []
    for i in range(len(boxes)):
        meets = np.all(bounds[i + 1 :, :3] < bounds[i, 3:], axis=1) & np.all(
            bounds[i + 1 :, 3:] > bounds[i, :3], axis=1
        )
        for j in np.flatnonzero(meets) + i + 1:
            share = overlap_share(boxes[i], boxes[int(j)])
            if share > threshold:
                result.append((i, int(j), share))
    return result


def _floating(scene: Scene, bounds: np.ndarray, index: int) -> float | None:
    """How high box ``index`` floats (metres), or None when something is under it."""
    box = scene.boxes[index]
    bottom = float(box_corners(box)[:, 2].min())
    if bottom <= FLOAT_GAP:
        return None
    polygon = footprint(box)
    for other_index, other in enumerate(scene.boxes):
        if other_index == index:
            continue
        top = bounds[other_index, 5]
        if (
            top >= bottom - FLOAT_GAP
            and bounds[other_index, 2] < bottom
            and footprint_overlap_area(polygon, footprint(other)) > 0
        ):
            return None
    low, high = bounds[index, :2], bounds[index, 3:5]
    points = scene.points
    under = (
        np.all((points[:, :2] >= low) & (points[:, :2] <= high), axis=1)
        & (points[:, 2] < bottom - 0.005)
        & (points[:, 2] >= bottom - FLOAT_GAP)
    )
    return None if np.any(under) else bottom


def scene_warnings(scene: Scene) -> list[str]:
    """What is doubtful about a scene, one line each (an empty list when nothing is).

    Parameters
    ----------
    scene : Scene

    Returns
    -------
    list of str
        Each names the scene's source and the boxes concerned.
    """
    source = scene.source
    warnings = [
        f"{source}: boxes {scene.boxes[i].id!r} and {scene.boxes[j].id!r} overlap by {100 * share:.0f} % of the "
        "smaller one's volume; check their poses"
        for i, j, share in overlapping_pairs(scene.boxes, WARNED_OVERLAP)
    ]
    bounds = bounding_boxes(scene.boxes)
    for box, (low, high) in zip(scene.boxes, bounds[:, [2, 5]], strict=True):
        if low < -BELOW_FLOOR:
            where = "lies wholly below" if high < 0 else f"reaches {-low:.2f} m into"
            warnings.append(f"{source}: box {box.id!r} {where} the floor (z = 0); check its pose and the frame")
    index = {box.id: k for k, box in enumerate(scene.boxes)}
    for box_id in scene.detected:
        height = _floating(scene, bounds, index[box_id])
        if height is not None:
            warnings.append(
                f"{source}: box {box_id!r} floats: its bottom is {height:.2f} m above the floor with no box or "
                "point of the cloud under it"
            )
    if len(scene.points) == 0:
        warnings.append(f"{source}: the point cloud is empty; undetected load and cloud features cannot be seen")
    else:
        low, high = bounds[:, :3].min(axis=0) - FAR_CLOUD, bounds[:, 3:].max(axis=0) + FAR_CLOUD
        near = np.mean(np.all((scene.points >= low) & (scene.points <= high), axis=1))
        if near < 0.05:
            warnings.append(
                f"{source}: only {100 * near:.1f} % of the cloud's points lie within {FAR_CLOUD} m of the boxes; "
                "is the cloud in the same frame and unit (metres) as the boxes?"
            )
    return warnings
