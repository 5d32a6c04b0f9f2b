"""Features of box poses alone, for piles and sensors unlike the simulator's: the ``general`` set.

The paper's DBAF (Eq. 4) sums Gaussian weights over the cloud's points, and the contact
features of the ``extended`` set count *shares* of the cloud; both change with the sensor's
resolution, its distance, the walls it sees and how much of the scene was scanned. A model
trained on one simulator's clouds then says little on a cloud made otherwise. The
``general`` set keeps to the geometry of the pair (X, Y) from their poses -- oriented
footprints, not axis-aligned boxes:

* ``vertical_gap`` (Y's lowest corner minus X's highest), ``overlap_share_x`` and
  ``overlap_share_y`` (the footprints' common area over X's and over Y's), ``footprint_gap``
  (distance between the footprints), ``height_x``, ``height_y``, ``bottom_x``, ``bottom_y``,
  ``z_overlap_share`` (common height over the lower of the two heights: side by side),
  ``centre_dz``, ``tilt_x``, ``tilt_y`` (degrees from upright), ``centre_over_x`` (how far
  Y's centroid lies inside X's footprint, negative outside: is Y's weight over X),
  ``separation`` (the smallest distance from the corners, edge midpoints and face centres
  of either box to the other box: 0 when they touch, whatever the direction) and
  ``lean_towards_x`` (how far Y's upper half leans over towards X: the horizontal offset of
  Y's highest corner from its centroid along the direction to X's centroid).

The cloud is left out on purpose. Coverage features of the cloud (the share of bins across
a box holding points between the two boxes, resting on each box, under Y; the height of the
material stacked on X) were measured against the generalisation suite
(``unstack experiment generalisation``): models trained with them picked right as often but
kept the suite's cost bounds less often (37 of 64 decisions against 46-58 of 64 without
them, trained on the same piles); what the cloud alone can tell -- load nobody detected --
is counted by :mod:`unstack.understanding.hidden_load` in the decision's cost instead.

Examples
--------
>>> from unstack.scene import Box
>>> floor_box = Box("a", [0.6, 0.4, 0.4], [1.0, 0.0, 0.2])
>>> top_box = Box("b", [0.4, 0.3, 0.3], [1.0, 0.0, 0.55])
>>> features = general_features([floor_box, top_box], [(0, 1)])
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

__all__ = ["GENERAL_FEATURE_NAMES", "general_features"]

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
)
#: Footprints farther apart than this are measured by their bounding boxes only (metres).
FAR = 0.3


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
    """A box with what the features need of it: corners, extent, footprint, frame, tilt."""

    def __init__(self, box: Box) -> None:
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


def general_features(boxes: Sequence[Box], pairs: Sequence[tuple[int, int]]) -> np.ndarray:
    """The general features of each ordered pair ``(X, Y)`` of box indices, shape (len(pairs), 15)."""
    index = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
    frames = {int(k): _BoxFrame(boxes[int(k)]) for k in np.unique(index)}
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
        )
    return result
