"""Load that nobody detected: what the point cloud shows resting on a detected box.

Eq. 11 counts only detected boxes, so a detected box carrying an undetected one costs as
little as a free box -- although the cloud shows the load. For each detected box X this
module estimates the expected number of undetected boxes resting on it, from the points
over X's footprint that no detected box explains (points inside a detected box grown by
:data:`EXPLAINED_MARGIN` are explained; the container's walls and ceiling -- planes no box is -- are dropped first,
:func:`container_planes`):

* the points over X's footprint swept :data:`FRONT_REACH` towards the door (a box resting
  on X that is deeper than X shows its front face in front of X's footprint) and grown by
  :data:`SIDE_REACH` on every side (a box as wide as X shows its side faces on the edge of
  X's footprint, and depth noise scatters them to either side of it);
* the lowest unexplained point above X's top must lie within one typical box height (plus
  :data:`STACK_GAP`) of it -- a box resting on X whose front face is not seen still shows
  its top there;
* ``coverage``: the share of :data:`COVERAGE_BIN`-wide bins across X's width (world y, as
  the sensor at the door sees it) holding an unexplained point within one layer (a typical
  box height plus :data:`STACK_GAP`) of the lowest one -- how much of X's top carries
  something, from its front face, its top face or both;
* ``rise``: how high the unexplained material reaches, going up without a vertical gap
  wider than :data:`STACK_GAP`;
* the estimate ``coverage * max(1, rise / typical box height)``, the typical height being
  the median height of the detected boxes: one layer of load per box height.

It is geometric and needs no model; what it measures on simulated piles is on the
generalisation page of the docs.

Examples
--------
>>> from unstack.scene import Box, Scene
>>> from unstack.understanding.clouds import surface_cloud
>>> boxes = [Box("loaded", [0.4, 0.4, 0.3], [1.0, -0.4, 0.15]), Box("unseen", [0.4, 0.4, 0.3], [1.0, -0.4, 0.45]),
...          Box("free", [0.4, 0.4, 0.3], [1.0, 0.4, 0.15])]
>>> scene = Scene(boxes, surface_cloud(boxes, viewpoint=[-2.0, 0.0, 1.5], seed=0), ["loaded", "free"])
>>> hidden_load(scene).round(1).tolist()
[1.0, 0.0]
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from unstack.geometry import bounding_boxes, box_corners, convex_hull_2d, footprint, points_in_box
from unstack.scene import Box, Scene
from unstack.understanding.cloud_columns import CloudColumns, columns_of

__all__ = ["EXPLAINED_MARGIN", "SIDE_REACH", "STACK_GAP", "container_planes", "hidden_load", "unexplained_points"]

#: Points within this distance of a detected box belong to it (metres).
EXPLAINED_MARGIN = 0.02
#: A vertical gap wider than this ends the material stacked on a box (metres).
STACK_GAP = 0.08
#: Points closer than this to a box's top belong to the top face (metres).
FACE_TOLERANCE = 0.015
#: Unexplained material higher than this above a box is not counted (metres).
MAX_RISE = 1.5
#: Width of the bins across a box in which coverage is counted (metres).
COVERAGE_BIN = 0.04
#: The footprint is swept this far towards the door (-x) before looking for load (metres).
FRONT_REACH = 0.08
#: ... and grown this far on every side (metres): a range sensor's depth noise.
SIDE_REACH = 0.02
#: The cloud's extreme points on one side (top, back, left, right) are a container plane when
#: they spread over more than this (metres) in both directions of the plane (a 1 m deep
#: section's side walls, not the face of a carton of up to 0.7 m) ...
PLANE_SPREAD = 0.8
#: ... within this distance of the extreme (metres).
PLANE_THICKNESS = 0.05
#: A wall is looked for this far inside the cloud's extreme on its side (metres): a door
#: frame or the floor outside can reach beyond the walls.
PLANE_SEARCH_DEPTH = 0.3
#: Points this close to the cloud's lowest point are floor: no wall is looked for among them
#: (the floor in front of the door can reach wider than the walls).
FLOOR_BAND = 0.05
#: The sides a container plane can stand on: (axis, +1 for the highest coordinate, -1 for the
#: lowest). The door side (-x) is open and the floor lies under every box.
PLANE_SIDES = ((2, 1), (0, 1), (1, -1), (1, 1))


#: The footprint grown by :data:`SIDE_REACH`: its corners moved diagonally (a square's Minkowski sum).
_SIDE_OFFSETS = SIDE_REACH * np.array([[1.0, 1.0], [1.0, -1.0], [-1.0, 1.0], [-1.0, -1.0]])


def _over(polygon: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Points whose vertical projection falls on a convex counter-clockwise polygon."""
    edges = np.roll(polygon, -1, axis=0) - polygon
    offsets = points[None, :, :2] - polygon[:, None, :]
    cross = edges[:, None, 0] * offsets[..., 1] - edges[:, None, 1] * offsets[..., 0]
    inside: np.ndarray = np.all(cross >= -1e-9, axis=0)
    return inside


def container_planes(points: np.ndarray) -> np.ndarray:
    """Which points belong to a container's ceiling, back wall or side walls.

    On each side of :data:`PLANE_SIDES`, the cloud above the floor (:data:`FLOOR_BAND`) is cut
    into slabs :data:`PLANE_THICKNESS` thick from its extreme coordinate inwards, down to
    :data:`PLANE_SEARCH_DEPTH`; the first slab whose points spread over more than
    :data:`PLANE_SPREAD` in both other directions -- a plane no carton is -- holds a wall: the
    points within half a slab of its median and every point beyond are dropped. A box
    standing against a wall otherwise carries the wall as load.

    Parameters
    ----------
    points : numpy.ndarray, shape (m, 3)

    Returns
    -------
    numpy.ndarray of bool, shape (m,)

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> back_wall = np.column_stack([np.full(200, 2.0), rng.uniform(-1.2, 1.2, 200), rng.uniform(0.1, 2.4, 200)])
    >>> carton_top = np.column_stack([rng.uniform(0.8, 1.2, 50), rng.uniform(-0.2, 0.2, 50), np.full(50, 0.4)])
    >>> floor = np.column_stack([rng.uniform(-0.5, 2.0, 300), rng.uniform(-1.5, 1.5, 300), np.zeros(300)])
    >>> container_planes(np.vstack([back_wall, carton_top, floor])).sum()  # the wall only
    np.int64(200)
    """
    planes = np.zeros(len(points), dtype=bool)
    if len(points) == 0:
        return planes
    floor = points[:, 2] <= points[:, 2].min() + FLOOR_BAND
    for axis, direction in PLANE_SIDES:
        candidates = np.flatnonzero(~planes & ~floor)
        if len(candidates) == 0:
            break
        coordinate = direction * points[candidates, axis]
        others = [other for other in range(3) if other != axis]
        extreme = coordinate.max()
        depths = np.arange(0.0, PLANE_SEARCH_DEPTH, PLANE_THICKNESS)
        searched = np.flatnonzero(coordinate > extreme - depths[-1] - PLANE_THICKNESS)  # every slab's points
        near = coordinate[searched]
        for inside in depths:
            slab = searched[(near > extreme - inside - PLANE_THICKNESS) & (near <= extreme - inside)]
            if len(slab) and np.all(np.ptp(points[candidates[slab]][:, others], axis=0) > PLANE_SPREAD):
                wall = float(np.median(coordinate[slab]))  # a noisy wall straddles two slabs
                planes[candidates[coordinate > wall - PLANE_THICKNESS / 2]] = True  # the wall and beyond
                break
    return planes


def _load_on(column: np.ndarray, top: float, low_y: float, high_y: float, typical_height: float) -> float:
    """The estimate for one box from the unexplained points over it (see the module docstring)."""
    heights = column[:, 2] - top
    above = np.sort(heights[(heights > FACE_TOLERANCE) & (heights <= MAX_RISE)])
    if len(above) == 0 or above[0] > typical_height + STACK_GAP:
        return 0.0  # nothing over the box, or only far above it (not resting on it)
    jumps = np.flatnonzero(np.diff(above) > STACK_GAP)
    rise = float(above[jumps[0]] if len(jumps) else above[-1])
    first = float(above[0])
    band = column[(heights >= first) & (heights <= first + typical_height + STACK_GAP)]
    bins = max(1, int(np.ceil((high_y - low_y) / COVERAGE_BIN)))
    occupied = np.unique(np.clip(((band[:, 1] - low_y) / (high_y - low_y) * bins).astype(int), 0, bins - 1))
    return len(occupied) / bins * max(1.0, rise / typical_height)


def _explained(points: np.ndarray, boxes: Sequence[Box], bounds: np.ndarray, columns: CloudColumns) -> np.ndarray:
    """Points inside a detected box grown by :data:`EXPLAINED_MARGIN` (boolean mask).

    Each box tests only the points over its footprint's bounding rectangle (``columns``, the
    cloud binned once), so a cloud of a few hundred thousand points costs one sort, not one
    pass per box.
    """
    explained = np.zeros(len(points), dtype=bool)
    for box, bound in zip(boxes, bounds, strict=True):
        near = columns.indices_over(bound[:2] - EXPLAINED_MARGIN, bound[3:5] + EXPLAINED_MARGIN)
        heights = points[near, 2]
        near = near[(heights >= bound[2] - EXPLAINED_MARGIN) & (heights <= bound[5] + EXPLAINED_MARGIN)]
        explained[near[points_in_box(points[near], box, margin=EXPLAINED_MARGIN)]] = True
    return explained


def unexplained_points(points: np.ndarray, boxes: Sequence[Box], *, columns: CloudColumns | None = None) -> np.ndarray:
    """Which points no box of ``boxes`` explains and no container plane holds (boolean mask).

    A point is explained when it lies inside one of the boxes grown by
    :data:`EXPLAINED_MARGIN`; the container's walls and ceiling are :func:`container_planes`.
    ``columns``: the same points binned already (:func:`~unstack.understanding.cloud_columns.columns_of`).

    Examples
    --------
    >>> box = Box("a", [0.4, 0.4, 0.4], [1.0, 0.0, 0.2])
    >>> unexplained_points(np.array([[1.0, 0.0, 0.41], [1.0, 0.0, 0.7]]), [box]).tolist()
    [False, True]
    """
    points = np.asarray(points, dtype=np.float64)
    if len(points) == 0:
        return np.zeros(0, dtype=bool)
    free = ~container_planes(points)
    if boxes:
        free &= ~_explained(points, boxes, bounding_boxes(list(boxes)), columns_of(points, columns))
    return free


def hidden_load(
    scene: Scene, detected: Sequence[str] | None = None, *, columns: CloudColumns | None = None
) -> np.ndarray:
    """Expected number of undetected boxes resting on each detected box, in ``scene.detected`` order.

    Parameters
    ----------
    scene : Scene
        Its detected boxes' poses and its point cloud are used; undetected boxes' poses
        are not (a robot does not know them).
    detected : sequence of str, optional
        Box ids to treat as the detected ones instead of ``scene.detected`` (an ISet).
    columns : CloudColumns, optional
        The scene's points binned already (one binning serves the whole pipeline).

    Returns
    -------
    numpy.ndarray, shape (len(detected),)
        Non-negative; 0 where the cloud shows nothing unexplained on a box.
    """
    boxes = [scene.box(box_id) for box_id in (scene.detected if detected is None else detected)]
    points = scene.points
    result = np.zeros(len(boxes))
    if len(points) == 0 or not boxes:
        return result
    bounds = bounding_boxes(boxes)
    binned = columns_of(points, columns)
    free = unexplained_points(points, boxes, columns=binned)
    free &= points[:, 2] > bounds[:, 5].min() + FACE_TOLERANCE  # nothing lower lies on any box
    typical_height = float(np.median([np.ptp(box_corners(box)[:, 2]) for box in boxes]))
    for k, box in enumerate(boxes):
        low, high = bounds[k, :2] - [FRONT_REACH + SIDE_REACH, SIDE_REACH], bounds[k, 3:5] + SIDE_REACH
        over = binned.indices_over(low, high)  # ascending: the cloud's order
        column = points[over[free[over]]]
        if len(column) == 0:
            continue
        polygon = np.vstack([footprint(box) + offset for offset in _SIDE_OFFSETS])
        swept = convex_hull_2d(np.vstack([polygon, polygon - [FRONT_REACH, 0.0]]))
        result[k] = _load_on(column[_over(swept, column)], bounds[k, 5], low[1], high[1], typical_height)
    return result
