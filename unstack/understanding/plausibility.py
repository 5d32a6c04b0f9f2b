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
within :data:`FLOAT_GAP`: no box, no floor, no point of the cloud) or are smaller than a carton
(no edge reaching :data:`SMALL_BOX`), and a cloud that is empty or lies far from the boxes.

Examples
--------
>>> from unstack.scene import Box, Scene
>>> floating = Scene([Box("a", [0.4, 0.4, 0.3], [1.0, 0.0, 0.8])], [[1.0, 0.0, 0.95]], ["a"])
>>> scene_warnings(floating)[0]
"<array>: box 'a' floats: its bottom is 0.65 m above the floor with no box or point of the cloud under it"
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from unstack.checks import MAX_BOX_EDGE, MAX_COORDINATE, MIN_BOX_EDGE, REFUSED_OVERLAP, light_boxes
from unstack.geometry import (
    bounding_boxes,
    box_corners,
    footprint,
    footprint_overlap_area,
    overlap_share,
    overlapping_pairs,
)

if TYPE_CHECKING:
    from unstack.scene import Box, Scene

__all__ = [
    "BELOW_FLOOR",
    "FLOAT_GAP",
    "MAX_BOX_EDGE",
    "MAX_COORDINATE",
    "MIN_BOX_EDGE",
    "REFUSED_OVERLAP",
    "SMALL_BOX",
    "WARNED_OVERLAP",
    "overlap_share",
    "overlapping_pairs",
    "scene_warnings",
    "standing_doubts",
]

#: More than this share of the smaller box's volume shared with another is warned about (the
#: refused share is :data:`unstack.checks.REFUSED_OVERLAP`) (a few millimetres of interpenetration of
#: simulated or measured poses stay below it).
WARNED_OVERLAP = 0.05
#: A detected box whose bottom has nothing under it within this gap floats (metres).
FLOAT_GAP = 0.05
#: A box reaching deeper than this below the floor (z = 0) is warned about (metres).
BELOW_FLOOR = 0.02
#: A detected box no edge of which reaches this is smaller than a carton (metres): a sign of
#: sizes or depths in another unit (centimetres read as millimetres).
SMALL_BOX = 0.08
#: A cloud whose points are mostly farther than this from every box is "far" (metres) ...
FAR_CLOUD = 0.5
#: ... when less than this share of its points is nearer.
NEAR_CLOUD_SHARE = 0.05
#: ... and fewer than half the boxes have this many points within :data:`FACE_GAP` of their
#: bounds (a box fitted to the cloud, one alone in a container's view, shows its faces in it).
FACE_POINTS = 10
FACE_GAP = 0.05


def _share_within(points: np.ndarray, low: np.ndarray, high: np.ndarray, enough: float) -> float:
    """Share of the points within ``[low, high]``, counted a slice of the cloud at a time and
    stopped once it reaches ``enough`` (then a share of at least ``enough``, not the whole one).

    Examples
    --------
    >>> points = np.array([[0.0, 0.0, 0.0], [5.0, 0.0, 0.0]])
    >>> _share_within(points, np.full(3, -1.0), np.full(3, 1.0), 0.9)
    0.5
    """
    step = max(1, len(points) // 16)
    inside = 0
    for start in range(0, len(points), step):
        part = points[start : start + step]
        inside += int(np.count_nonzero(np.all((part >= low) & (part <= high), axis=1)))
        if inside >= enough * len(points):
            break
    return inside / len(points)


def _boxes_in_cloud(points: np.ndarray, bounds: np.ndarray) -> float:
    """Share of the boxes (their axis-aligned ``bounds``, rows ``low, high``) with
    :data:`FACE_POINTS` points or more within :data:`FACE_GAP` of their sides or top (not under
    them: the floor under a box detected where nothing is shows no face of it).

    Examples
    --------
    >>> points = np.array([[0.0, 0.0, 0.21]] * 10)
    >>> _boxes_in_cloud(points, np.array([[-0.2, -0.2, 0.0, 0.2, 0.2, 0.2], [5.0, 5.0, 0.0, 5.4, 5.4, 0.4]]))
    0.5
    >>> floor = np.array([[0.0, 0.0, 0.0]] * 10)
    >>> _boxes_in_cloud(floor, np.array([[-0.2, -0.2, 0.0, 0.2, 0.2, 0.2]]))
    0.0
    """
    if len(bounds) == 0:
        return 0.0
    lows, highs = bounds[:, :3] - FACE_GAP, bounds[:, 3:] + FACE_GAP
    lows[:, 2] = bounds[:, 2] + FACE_GAP  # above the bottom: not the surface the box stands on
    near = points[np.all((points >= lows.min(axis=0)) & (points <= highs.max(axis=0)), axis=1)]
    shown = [
        np.count_nonzero(np.all((near >= low) & (near <= high), axis=1)) >= FACE_POINTS
        for low, high in zip(lows, highs, strict=True)
    ]
    return float(np.mean(shown))


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
    poses = _unstandable(scene)
    warnings = [
        f"{source}: boxes {scene.boxes[i].id!r} and {scene.boxes[j].id!r} overlap by {100 * share:.0f} % of the "
        "smaller one's volume; check their poses"
        for i, j, share in poses.overlaps
    ]
    for box, low, high in poses.sunk:
        where = "lies wholly below" if high < 0 else f"reaches {-low:.2f} m into"
        warnings.append(f"{source}: box {box.id!r} {where} the floor (z = 0); check its pose and the frame")
    for box_id in scene.detected:
        size = scene.box(box_id).size
        if size.max() < SMALL_BOX:
            warnings.append(
                f"{source}: box {box_id!r} is {' x '.join(f'{100 * edge:.1f}' for edge in size)} cm, smaller than a "
                "carton; are its size and the cloud in metres?"
            )
        height = poses.floating.get(box_id)
        if height is not None:
            warnings.append(
                f"{source}: box {box_id!r} floats: its bottom is {height:.2f} m above the floor with no box or "
                "point of the cloud under it"
            )
    weighed = [box for box in scene.boxes if box.mass is not None]
    light = light_boxes([box.id for box in weighed], [box.mass for box in weighed])
    if light is not None:
        warnings.append(f"{source}: {light}")
    if len(scene.points) == 0:
        warnings.append(f"{source}: the point cloud is empty; undetected load and cloud features cannot be seen")
    else:
        low, high = poses.bounds[:, :3].min(axis=0) - FAR_CLOUD, poses.bounds[:, 3:].max(axis=0) + FAR_CLOUD
        near = _share_within(scene.points, low, high, NEAR_CLOUD_SHARE)
        if near < NEAR_CLOUD_SHARE and _boxes_in_cloud(scene.points, poses.bounds) < 0.5:
            warnings.append(
                f"{source}: only {100 * near:.1f} % of the cloud's points lie within {FAR_CLOUD} m of the boxes; "
                "is the cloud in the same frame and unit (metres) as the boxes?"
            )
    return warnings


def standing_doubts(scene: Scene) -> list[str]:
    """The poses of a scene that cannot stand as reported, briefly (empty when all can): boxes
    overlapping by more than :data:`WARNED_OVERLAP`, reaching more than :data:`BELOW_FLOOR`
    into the floor, or detected boxes floating (the warnings of :func:`scene_warnings` that a
    physics engine would act out: such boxes move whatever is taken).

    Examples
    --------
    >>> from unstack.scene import Box, Scene
    >>> lifted = Box("lifted", [0.4, 0.4, 0.4], [1.0, 0.0, 0.6])
    >>> standing_doubts(Scene([lifted], np.zeros((0, 3)), ["lifted"]))
    ["'lifted' floats 0.40 m up"]
    """
    poses = _unstandable(scene)
    return [
        *(
            f"{scene.boxes[i].id!r} and {scene.boxes[j].id!r} overlap ({100 * share:.0f} %)"
            for i, j, share in poses.overlaps
        ),
        *(f"{box.id!r} reaches {-low:.2f} m into the floor" for box, low, _ in poses.sunk),
        *(f"{box_id!r} floats {height:.2f} m up" for box_id, height in poses.floating.items()),
    ]


@dataclass(frozen=True)
class _Unstandable:
    """A scene's poses that cannot stand as reported: overlapping pairs ``(i, j, share)``, boxes
    reaching into the floor ``(box, low, high)`` and floating detected boxes (id: height), with
    the boxes' axis-aligned bounds they were found from."""

    bounds: np.ndarray
    overlaps: list[tuple[int, int, float]]
    sunk: list[tuple[Box, float, float]]
    floating: dict[str, float]


def _unstandable(scene: Scene) -> _Unstandable:
    """What :func:`scene_warnings` and :func:`standing_doubts` say of a scene's poses, found once."""
    bounds = bounding_boxes(scene.boxes)
    sunk = [
        (box, float(low), float(high))
        for box, (low, high) in zip(scene.boxes, bounds[:, [2, 5]], strict=True)
        if low < -BELOW_FLOOR
    ]
    index = {box.id: k for k, box in enumerate(scene.boxes)}
    heights = {box_id: _floating(scene, bounds, index[box_id]) for box_id in scene.detected}
    return _Unstandable(
        bounds,
        overlapping_pairs(scene.boxes, WARNED_OVERLAP),
        sunk,
        {box_id: height for box_id, height in heights.items() if height is not None},
    )
