"""Box geometry in the world frame: rotations, corners, bounding boxes, footprints.

Part of the data model: the learning features, the plausibility checks, the hidden-load
estimate and the synthetic clouds all measure boxes with these functions. A box's
*footprint* is the convex polygon its corners cover seen from above (a rectangle for an
upright box, a hexagon for a tilted one).

Examples
--------
>>> from unstack.scene import Box
>>> floor_box = Box("a", [0.6, 0.4, 0.4], [1.0, 0.0, 0.2])
>>> top_box = Box("b", [0.4, 0.3, 0.3], [1.0, 0.1, 0.55])
>>> round(footprint_overlap_area(footprint(floor_box), footprint(top_box)), 4)
0.1
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from unstack.scene import Box

__all__ = [
    "BOX_FACES",
    "axis_error_deg",
    "bounding_box_overlap_xy",
    "bounding_boxes",
    "box_corners",
    "convex_hull_2d",
    "convex_overlap",
    "footprint",
    "footprint_overlap_area",
    "overlap_share",
    "overlapping_pairs",
    "points_in_box",
    "polygon_area",
    "polygon_distance",
    "rotation_angles_deg",
    "rotation_matrix",
    "rotation_tilt_deg",
    "tilt_deg",
]

#: The six faces of a cuboid as cycles of indices into :func:`box_corners` (each face fixes
#: one bit of the corner index).
BOX_FACES = ((0, 1, 3, 2), (4, 5, 7, 6), (0, 1, 5, 4), (2, 3, 7, 6), (0, 2, 6, 4), (1, 3, 7, 5))
#: Corner signs of a cuboid, in a fixed order (x fastest).
_CORNER_SIGNS = np.array([[sx, sy, sz] for sz in (-1, 1) for sy in (-1, 1) for sx in (-1, 1)], dtype=np.float64)


def rotation_matrix(orientation_xyzw: np.ndarray) -> np.ndarray:
    """The 3 x 3 rotation of a unit quaternion ``[x, y, z, w]``.

    Examples
    --------
    >>> rotation_matrix(np.array([0.0, 0.0, 0.0, 1.0])).tolist()
    [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
    """
    x, y, z, w = (float(value) for value in orientation_xyzw)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def box_corners(box: Box) -> np.ndarray:
    """The eight corners of a box in the world frame, shape (8, 3).

    Examples
    --------
    >>> from unstack.scene import Box
    >>> box_corners(Box("a", [2, 2, 2], [0, 0, 1]))[:, 2].tolist()
    [0.0, 0.0, 0.0, 0.0, 2.0, 2.0, 2.0, 2.0]
    """
    local = _CORNER_SIGNS * (box.size / 2.0)
    corners: np.ndarray = local @ rotation_matrix(box.orientation_xyzw).T + box.position
    return corners


def bounding_boxes(boxes: Sequence[Box]) -> np.ndarray:
    """``[x_min, y_min, z_min, x_max, y_max, z_max]`` of each rotated cuboid, shape (n, 6).

    Examples
    --------
    >>> from unstack.scene import Box
    >>> quarter_turn = [0, 0, np.sin(np.pi / 4), np.cos(np.pi / 4)]
    >>> bounding_boxes([Box("a", [2, 1, 1], [0, 0, 0], quarter_turn)]).round(6).tolist()
    [[-0.5, -1.0, -0.5, 0.5, 1.0, 0.5]]
    """
    result = np.empty((len(boxes), 6))
    for row, box in enumerate(boxes):
        half_extent = np.abs(rotation_matrix(box.orientation_xyzw)) @ (box.size / 2.0)
        result[row, :3] = box.position - half_extent
        result[row, 3:] = box.position + half_extent
    return result


def bounding_box_overlap_xy(first: np.ndarray, second: np.ndarray) -> np.ndarray:
    """Signed overlap along x and y of axis-aligned bounding boxes ``[min xyz, max xyz]``, row by row.

    Negative where the footprints are apart (minus the gap along that axis).

    Examples
    --------
    >>> a = np.array([[0.0, 0.0, 0.0, 1.0, 1.0, 1.0]])
    >>> b = np.array([[0.5, 1.5, 0.0, 2.0, 2.0, 1.0]])
    >>> bounding_box_overlap_xy(a, b).tolist()
    [[0.5, -0.5]]
    """
    first, second = np.atleast_2d(first), np.atleast_2d(second)
    overlap: np.ndarray = np.minimum(first[:, 3:5], second[:, 3:5]) - np.maximum(first[:, :2], second[:, :2])
    return overlap


def rotation_angles_deg(before_xyzw: np.ndarray, after_xyzw: np.ndarray) -> np.ndarray:
    """Angle of the rotation between two orientations (quaternions ``x, y, z, w``), per row, in degrees.

    Examples
    --------
    >>> half_turn = np.array([[0.0, 0.0, 1.0, 0.0]])
    >>> rotation_angles_deg(np.array([[0.0, 0.0, 0.0, 1.0]]), half_turn).round(6).tolist()
    [180.0]
    """
    dots = np.abs(np.sum(before_xyzw * after_xyzw, axis=-1))
    angles: np.ndarray = np.degrees(2.0 * np.arccos(np.clip(dots, 0.0, 1.0)))
    return angles


def rotation_tilt_deg(rotation: np.ndarray) -> float:
    """The angle between the world's z axis and the nearest axis of a rotation matrix's frame
    (degrees, 0 for a frame standing upright, up to about 54.7).

    Examples
    --------
    >>> round(rotation_tilt_deg(rotation_matrix(np.array([np.sin(0.1), 0.0, 0.0, np.cos(0.1)]))), 2)
    11.46
    """
    cosine = float(np.max(np.abs(np.asarray(rotation)[2, :])))
    return float(np.degrees(np.arccos(np.clip(cosine, -1.0, 1.0))))


def tilt_deg(box: Box) -> float:
    """How far the box is from standing on a face: the angle between the world's z axis and
    the nearest of the box's axes (degrees, 0 for an upright box, up to about 54.7).

    Examples
    --------
    >>> from unstack.scene import Box
    >>> tilt_deg(Box("a", [1, 1, 1], [0, 0, 0]))
    0.0
    """
    return rotation_tilt_deg(rotation_matrix(box.orientation_xyzw))


def axis_error_deg(truth_xyzw: np.ndarray, fitted_xyzw: np.ndarray) -> float:
    """The largest angle between an axis of the fitted orientation and the nearest axis of the
    true one (degrees: 0 when the two frames' axes are the same lines, whatever their order and
    signs).

    Examples
    --------
    >>> quarter_turn = np.array([0.0, 0.0, np.sin(np.pi / 4), np.cos(np.pi / 4)])
    >>> round(axis_error_deg(np.array([0.0, 0.0, 0.0, 1.0]), quarter_turn), 6)
    0.0
    """
    dots = np.abs(rotation_matrix(np.asarray(truth_xyzw)).T @ rotation_matrix(np.asarray(fitted_xyzw)))
    return float(np.degrees(np.arccos(min(1.0, float(dots.max(axis=0).min())))))


def convex_hull_2d(points: np.ndarray) -> np.ndarray:
    """Counter-clockwise convex hull of 2-D points (Andrew's monotone chain), shape (k, 2).

    Examples
    --------
    >>> convex_hull_2d(np.array([[0, 0], [1, 0], [1, 1], [0, 1], [0.5, 0.5]])).tolist()
    [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]
    """
    unique = np.unique(np.round(np.asarray(points, dtype=np.float64), 12), axis=0)
    if len(unique) <= 2:
        return unique

    def cross(o: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
        return float((a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]))

    lower: list[np.ndarray] = []
    for point in unique:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], point) <= 0:
            lower.pop()
        lower.append(point)
    upper: list[np.ndarray] = []
    for point in unique[::-1]:
        while len(upper) >= 2 and cross(upper[-2], upper[-1], point) <= 0:
            upper.pop()
        upper.append(point)
    return np.array(lower[:-1] + upper[:-1])


def footprint(box: Box) -> np.ndarray:
    """The convex polygon a box covers seen from above, counter-clockwise, shape (k, 2)."""
    return convex_hull_2d(box_corners(box)[:, :2])


def polygon_area(polygon: np.ndarray) -> float:
    """Area of a simple polygon (shoelace formula); 0 for fewer than three vertices.

    Examples
    --------
    >>> polygon_area(np.array([[0, 0], [2, 0], [2, 1], [0, 1]]))
    2.0
    """
    if len(polygon) < 3:
        return 0.0
    x, y = polygon[:, 0], polygon[:, 1]
    return float(abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))) / 2.0)


def _clip(subject: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Sutherland-Hodgman: the part of ``subject`` left of the directed edge a -> b."""
    if len(subject) == 0:
        return subject
    edge = b - a
    side = edge[0] * (subject[:, 1] - a[1]) - edge[1] * (subject[:, 0] - a[0])
    output: list[np.ndarray] = []
    for k in range(len(subject)):
        current, previous = subject[k], subject[k - 1]
        side_current, side_previous = side[k], side[k - 1]
        if side_current >= 0:
            if side_previous < 0:
                output.append(previous + (current - previous) * side_previous / (side_previous - side_current))
            output.append(current)
        elif side_previous >= 0:
            output.append(previous + (current - previous) * side_previous / (side_previous - side_current))
    return np.array(output).reshape(-1, 2)


def convex_overlap(first: np.ndarray, second: np.ndarray) -> np.ndarray:
    """The intersection of two convex counter-clockwise polygons, counter-clockwise, shape (k, 2)
    (no rows where they do not meet).

    Examples
    --------
    >>> square = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=float)
    >>> convex_overlap(square, square + 0.5).tolist()
    [[0.5, 0.5], [1.0, 0.5], [1.0, 1.0], [0.5, 1.0]]
    """
    clipped = np.asarray(first, dtype=np.float64).reshape(-1, 2)
    for k in range(len(second)):
        clipped = _clip(clipped, second[k - 1], second[k])
        if len(clipped) == 0:
            break
    return clipped


def footprint_overlap_area(first: np.ndarray, second: np.ndarray) -> float:
    """Area of the intersection of two convex counter-clockwise polygons.

    Examples
    --------
    >>> square = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=float)
    >>> footprint_overlap_area(square, square + 0.5)
    0.25
    """
    return polygon_area(convex_overlap(first, second))


def _point_segment_distances(points: np.ndarray, starts: np.ndarray, ends: np.ndarray) -> np.ndarray:
    edges = ends - starts
    lengths = np.maximum(np.einsum("ij,ij->i", edges, edges), 1e-18)
    offsets = points[:, None, :] - starts[None, :, :]
    along = np.clip(np.einsum("pij,ij->pi", offsets, edges) / lengths, 0.0, 1.0)
    nearest = starts[None, :, :] + along[..., None] * edges[None, :, :]
    distances: np.ndarray = np.linalg.norm(points[:, None, :] - nearest, axis=-1)
    return distances


def polygon_distance(first: np.ndarray, second: np.ndarray) -> float:
    """Distance between two convex polygons (0 when they overlap or touch).

    Examples
    --------
    >>> square = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=float)
    >>> polygon_distance(square, square + [3.0, 0.0])
    2.0
    """
    if footprint_overlap_area(first, second) > 0.0:
        return 0.0
    distances = [
        _point_segment_distances(a, b, np.roll(b, -1, axis=0)).min() for a, b in ((first, second), (second, first))
    ]
    return float(min(distances))


def points_in_box(points: np.ndarray, box: Box, *, margin: float = 0.0) -> np.ndarray:
    """Which points lie inside the box grown by ``margin`` on every side (boolean mask).

    Examples
    --------
    >>> from unstack.scene import Box
    >>> points_in_box(np.array([[0, 0, 0.5], [0, 0, 1.2]]), Box("a", [1, 1, 1], [0, 0, 0.5])).tolist()
    [True, False]
    """
    local = (np.asarray(points, dtype=np.float64) - box.position) @ rotation_matrix(box.orientation_xyzw)
    inside: np.ndarray = np.all(np.abs(local) <= box.size / 2.0 + margin, axis=1)
    return inside


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


def _overlap_bound(small: Box, small_rotation: np.ndarray, large: Box, large_rotation: np.ndarray) -> float:
    """At least :func:`overlap_share` of the pair: the share of ``small``'s volume that its
    bounding box in ``large``'s frame shares with ``large`` (the share itself when the axes are
    parallel)."""
    relative = large_rotation.T @ small_rotation
    centre = large_rotation.T @ (small.position - large.position)
    half = np.abs(relative) @ (small.size / 2.0)
    low = np.maximum(centre - half, -large.size / 2.0)
    high = np.minimum(centre + half, large.size / 2.0)
    return float(np.prod(np.clip(high - low, 0.0, None)) / np.prod(small.size))


def overlapping_pairs(boxes: Sequence[Box], threshold: float) -> list[tuple[int, int, float]]:
    """Pairs of box indices whose overlap share exceeds ``threshold``, with the share.

    Two boxes share at most what the smaller one's bounding box in the larger one's frame shares
    with the larger one: a pair whose bound is below ``threshold`` is passed over unmeasured
    (boxes that touch, as in every pile, share a few millimetres' slab), and so is a pair whose
    bounding boxes do not meet.

    Examples
    --------
    >>> from unstack.scene import Box
    >>> overlapping_pairs([Box("a", [1, 1, 1], [0, 0, 0.5]), Box("b", [1, 1, 1], [0.5, 0, 0.5])], 0.2)
    [(0, 1, 0.5)]
    >>> overlapping_pairs([Box("a", [1, 1, 1], [0, 0, 0.5]), Box("b", [1, 1, 1], [0.99, 0, 0.5])], 0.2)
    []
    """
    bounds = bounding_boxes(boxes)
    rotations = [rotation_matrix(box.orientation_xyzw) for box in boxes]
    volumes = [float(np.prod(box.size)) for box in boxes]
    result = []
    for i in range(len(boxes)):
        meets = np.all(bounds[i + 1 :, :3] < bounds[i, 3:], axis=1) & np.all(
            bounds[i + 1 :, 3:] > bounds[i, :3], axis=1
        )
        for j in (int(j) for j in np.flatnonzero(meets) + i + 1):
            small, large = (i, j) if volumes[i] <= volumes[j] else (j, i)
            if _overlap_bound(boxes[small], rotations[small], boxes[large], rotations[large]) < threshold - 1e-9:
                continue
            share = overlap_share(boxes[i], boxes[j])
            if share > threshold:
                result.append((i, j, share))
    return result
