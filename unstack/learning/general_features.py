"""Features that do not depend on how the cloud was sampled: the ``general`` feature set.

The paper's DBAF (Eq. 4) sums Gaussian weights over the cloud's points, and the contact
features of the ``extended`` set count *shares* of the cloud; both change with the sensor's
resolution, its distance, the walls it sees and how much of the scene was scanned. A model
trained on one simulator's clouds then says little on a cloud made otherwise. The
``general`` set keeps to what is invariant:

* geometry of the pair (X, Y) from their poses -- oriented footprints, not axis-aligned
  boxes: ``vertical_gap`` (Y's lowest corner minus X's highest), ``overlap_share_x`` and
  ``overlap_share_y`` (the footprints' common area over X's and over Y's), ``footprint_gap``
  (distance between the footprints), ``height_x``, ``height_y``, ``bottom_x``, ``bottom_y``,
  ``z_overlap_share`` (common height over the lower of the two heights: side by side),
  ``centre_dz``, ``tilt_x``, ``tilt_y`` (degrees from upright), ``centre_over_x`` (how far
  Y's centroid lies inside X's footprint, negative outside: is Y's weight over X),
  ``separation`` (the smallest distance from the corners, edge midpoints and face centres
  of either box to the other box: 0 when they touch, whatever the direction) and
  ``lean_towards_x`` (how far Y's upper half leans over towards X: the horizontal offset of
  Y's highest corner from its centroid along the direction to X's centroid);
* what the cloud shows, as *coverage* -- the share of :data:`COVERAGE_BIN`-wide bins across
  a box's width (world y, across the container, as the sensor at the door sees it) that hold
  at least one point -- which is the same for a dense and a sparse scan:
  ``between_coverage`` (points in the column over the footprints' overlap, between X's top
  and Y's bottom: something between them), ``load_coverage_x`` and ``load_coverage_y``
  (points resting on the box, within :data:`LOAD_BAND` above its top and over its
  footprint), ``under_coverage_y`` (points within the band under Y's bottom and under its
  footprint: Y rests on something), and ``rise_above_x`` (how high the material stacked
  on X reaches: points over X's footprint going up from its top without a gap wider than
  :data:`STACK_GAP`, at most :data:`RISE_BAND`).

Examples
--------
>>> from unstack.scene import Box
>>> floor_box = Box("a", [0.6, 0.4, 0.4], [1.0, 0.0, 0.2])
>>> top_box = Box("b", [0.4, 0.3, 0.3], [1.0, 0.0, 0.55])
>>> features = general_features([floor_box, top_box], np.zeros((0, 3)), [(0, 1)])
>>> named = dict(zip(GENERAL_FEATURE_NAMES, features[0].round(3).tolist()))
>>> named["vertical_gap"], named["overlap_share_y"], named["centre_over_x"]
(0.0, 1.0, 0.2)
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from unstack.geometry import (
    bounding_boxes,
    box_corners,
    footprint,
    footprint_overlap_area,
    polygon_area,
    polygon_distance,
    rotation_matrix,
    tilt_deg,
)
from unstack.scene import Box

__all__ = ["COVERAGE_BIN", "GENERAL_FEATURE_NAMES", "LOAD_BAND", "RISE_BAND", "general_features"]

#: Names of the general features, in order.
GENERAL_FEATURE_NAMES: tuple[str, ...] = (
    "vertical_gap",
    "overlap_share_x",
    "overlap_share_y",
    "footprint_gap",
    "height_x",
    "height_y",
    "bottom_x",
    "bottom_y",
    "z_overlap_share",
    "centre_dz",
    "tilt_x",
    "tilt_y",
    "centre_over_x",
    "separation",
    "lean_towards_x",
    "between_coverage",
    "load_coverage_x",
    "load_coverage_y",
    "under_coverage_y",
    "rise_above_x",
)
#: Width of the bins across a box in which coverage is counted (metres): wider than the
#: point spacing of any usable scan, narrower than a box.
COVERAGE_BIN = 0.04
#: Points this far above a top face (or below a bottom face) count as resting on it (metres).
LOAD_BAND = 0.25
#: Points up to this far above a box's top count for ``rise_above_x`` (metres).
RISE_BAND = 1.0
#: A vertical gap wider than this (metres) ends the material stacked on a box.
STACK_GAP = 0.08
#: Points closer than this to a face belong to the face, not to what rests on it (metres).
FACE_TOLERANCE = 0.015
#: Footprints farther apart than this are measured by their bounding boxes only (metres).
FAR = 0.3


def _coverage(y_values: np.ndarray, low: float, high: float) -> float:
    """Share of the ``COVERAGE_BIN`` bins of ``[low, high]`` that hold a value."""
    if high - low <= 0:
        return 0.0
    bins = max(1, int(np.ceil((high - low) / COVERAGE_BIN)))
    if len(y_values) == 0:
        return 0.0
    index = np.clip(((y_values - low) / (high - low) * bins).astype(np.int64), 0, bins - 1)
    return float(len(np.unique(index)) / bins)


#: Surface samples of a unit cube: 8 corners, 12 edge midpoints, 6 face centres.
_SURFACE = (
    np.array(
        [[a, b, c] for a in (-1, 0, 1) for b in (-1, 0, 1) for c in (-1, 0, 1) if (a, b, c) != (0, 0, 0)],
        dtype=np.float64,
    )
    / 2.0
)


def _separation(first: _BoxFrame, second: _BoxFrame) -> float:
    """Smallest distance from a surface sample of either box to the other box."""
    distances = []
    for source, target in ((first, second), (second, first)):
        samples = (_SURFACE * source.box.size) @ source.rotation.T + source.box.position
        local = (samples - target.box.position) @ target.rotation
        outside = np.maximum(np.abs(local) - target.box.size / 2.0, 0.0)
        distances.append(float(np.min(np.linalg.norm(outside, axis=1))))
    return min(distances)


def _lean_towards(leaning: _BoxFrame, other: _BoxFrame) -> float:
    """Horizontal offset of ``leaning``'s highest corner from its centroid, towards ``other``."""
    direction = other.box.position[:2] - leaning.box.position[:2]
    length = float(np.linalg.norm(direction))
    if length < 1e-9:
        return 0.0
    highest = leaning.corners[int(np.argmax(leaning.corners[:, 2]))]
    return float(np.dot(highest[:2] - leaning.box.position[:2], direction / length))


class _BoxFrame:
    """A box with what the features need of it: corners, footprint, frame, the points over it."""

    def __init__(self, box: Box, points: np.ndarray) -> None:
        corners = box_corners(box)
        self.corners = corners
        self.box = box
        self.top = float(corners[:, 2].max())
        self.bottom = float(corners[:, 2].min())
        self.footprint = footprint(box)
        self.area = polygon_area(self.footprint)
        self.rotation = rotation_matrix(box.orientation_xyzw)
        self.tilt = tilt_deg(box)
        self.bounds = bounding_boxes([box])[0]
        low, high = self.bounds[:2], self.bounds[3:5]
        column = np.all((points[:, :2] >= low) & (points[:, :2] <= high), axis=1)
        candidates = points[column]
        self.column = candidates[self._over_footprint(candidates)]

    def _over_footprint(self, points: np.ndarray) -> np.ndarray:
        """Points whose vertical projection falls on the footprint (convex polygon test)."""
        polygon = self.footprint
        if len(points) == 0 or len(polygon) < 3:
            return np.zeros(len(points), dtype=bool)
        edges = np.roll(polygon, -1, axis=0) - polygon
        offsets = points[None, :, :2] - polygon[:, None, :]
        cross = edges[:, None, 0] * offsets[..., 1] - edges[:, None, 1] * offsets[..., 0]
        inside: np.ndarray = np.all(cross >= -1e-9, axis=0)
        return inside

    def over(self, points: np.ndarray) -> np.ndarray:
        """The points over this box's footprint."""
        selected: np.ndarray = points[self._over_footprint(points)]
        return selected

    def load_coverage(self) -> float:
        band = self.column[
            (self.column[:, 2] > self.top + FACE_TOLERANCE) & (self.column[:, 2] <= self.top + LOAD_BAND)
        ]
        return _coverage(band[:, 1], self.bounds[1], self.bounds[4])

    def under_coverage(self) -> float:
        low = self.bottom - LOAD_BAND
        band = self.column[(self.column[:, 2] < self.bottom - FACE_TOLERANCE) & (self.column[:, 2] >= low)]
        return _coverage(band[:, 1], self.bounds[1], self.bounds[4])

    def rise(self) -> float:
        """Height above the top of the material stacked on it: points over the footprint going
        up from the top face without a vertical gap wider than :data:`STACK_GAP`."""
        heights = np.sort(self.column[:, 2][self.column[:, 2] > self.top + FACE_TOLERANCE]) - self.top
        heights = heights[heights <= RISE_BAND]
        if len(heights) == 0 or heights[0] > STACK_GAP:
            return 0.0
        jumps = np.flatnonzero(np.diff(heights) > STACK_GAP)
        return float(heights[jumps[0]] if len(jumps) else heights[-1])

    def centre_inside(self, point: np.ndarray) -> float:
        """Signed distance of a point's projection to the footprint's boundary (positive inside)."""
        polygon = self.footprint
        edges = np.roll(polygon, -1, axis=0) - polygon
        lengths = np.maximum(np.linalg.norm(edges, axis=1), 1e-12)
        offsets = point[:2] - polygon
        signed = (edges[:, 0] * offsets[:, 1] - edges[:, 1] * offsets[:, 0]) / lengths
        if np.all(signed >= 0):
            return float(signed.min())
        along = np.clip(np.einsum("ij,ij->i", offsets, edges) / lengths**2, 0.0, 1.0)
        nearest = polygon + along[:, None] * edges
        return -float(np.min(np.linalg.norm(point[:2] - nearest, axis=1)))


def general_features(boxes: Sequence[Box], points: np.ndarray, pairs: Sequence[tuple[int, int]]) -> np.ndarray:
    """The general features of each ordered pair ``(X, Y)`` of box indices, shape (len(pairs), 20)."""
    index = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
    cloud = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    frames = {int(k): _BoxFrame(boxes[int(k)], cloud) for k in np.unique(index)}
    per_box = {k: (frame.load_coverage(), frame.under_coverage(), frame.rise()) for k, frame in frames.items()}
    result = np.zeros((len(index), len(GENERAL_FEATURE_NAMES)))
    for row, (a, b) in enumerate(index):
        x, y = frames[int(a)], frames[int(b)]
        aabb_gap = np.maximum(np.maximum(x.bounds[:2], y.bounds[:2]) - np.minimum(x.bounds[3:5], y.bounds[3:5]), 0)
        if np.hypot(*aabb_gap) > FAR:
            overlap, gap = 0.0, float(np.hypot(*aabb_gap))
        else:
            overlap = footprint_overlap_area(x.footprint, y.footprint)
            gap = 0.0 if overlap > 0 else polygon_distance(x.footprint, y.footprint)
        height_x, height_y = x.top - x.bottom, y.top - y.bottom
        z_overlap = max(0.0, min(x.top, y.top) - max(x.bottom, y.bottom)) / max(min(height_x, height_y), 1e-9)
        between = 0.0
        if overlap > 0 and y.bottom - x.top > 2 * FACE_TOLERANCE:
            column = y.over(x.column)
            inside = column[(column[:, 2] > x.top + FACE_TOLERANCE) & (column[:, 2] < y.bottom - FACE_TOLERANCE)]
            low, high = max(x.bounds[1], y.bounds[1]), min(x.bounds[4], y.bounds[4])
            between = _coverage(inside[:, 1], low, high)
        result[row] = (
            y.bottom - x.top,
            overlap / max(x.area, 1e-12),
            overlap / max(y.area, 1e-12),
            gap,
            height_x,
            height_y,
            x.bottom,
            y.bottom,
            z_overlap,
            float(y.box.position[2] - x.box.position[2]),
            x.tilt,
            y.tilt,
            x.centre_inside(y.box.position) if gap <= FAR else -gap,
            _separation(x, y) if gap <= FAR else gap,
            _lean_towards(y, x),
            between,
            per_box[int(a)][0],
            per_box[int(b)][0],
            per_box[int(b)][1],
            per_box[int(a)][2],
        )
    return result
