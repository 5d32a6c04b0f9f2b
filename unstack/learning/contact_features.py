"""Contact features of a pair of boxes: how X and Y touch, and what the cloud shows around them.

The paper's 19 numbers (:mod:`unstack.learning.features`) hold only *differences* of the
two bounding boxes and the cloud density one metre away from each centroid. They cannot say
how far Y's bottom is above X's top (that needs the boxes' heights), how much of Y's
footprint lies over X, or whether the cloud shows something stacked between or on them.
``feature_set="extended"`` appends these 17 numbers to ``F_XY``, from the same inputs (the
two boxes and the scene's cloud), for the pair (X, Y) of "does X support Y":

* ``overlap_x``, ``overlap_y``: signed overlap of the two axis-aligned bounding boxes
  along x and y (metres; negative: the gap between them);
* ``overlap_share_x``, ``overlap_share_y``: the area of the footprints' overlap over X's
  and over Y's footprint area;
* ``footprint_gap``: the horizontal distance between the footprints (0 when they overlap);
* ``vertical_gap``: Y's bottom minus X's top;
* ``height_x``, ``height_y``, ``bottom_x``, ``bottom_y``: the boxes' vertical extents and
  the heights of their bottoms (the floor is z = 0);
* ``cloud_between``: share of the cloud's points in the column over the footprints'
  overlap (widened by :data:`COLUMN_MARGIN`) between X's top and Y's bottom -- something
  hidden between them;
* ``rise_above_x``, ``rise_above_y``: how far the highest cloud point over each box's
  footprint is above its top (0 when none is), and ``cloud_above_x``, ``cloud_above_y``:
  the share of the cloud's points there -- what rests on each box;
* ``cloud_in_pair_box``, ``pair_box_volume``: share of the cloud inside the smallest
  axis-aligned box holding both boxes, and that box's volume.

Shares of points (not counts) keep the features from scaling with the sensor's resolution.
An empty cloud gives zeros for the cloud features.

Examples
--------
>>> from unstack.scene import Box
>>> floor_box = Box("a", [0.6, 0.4, 0.4], [1.0, 0.0, 0.2])
>>> top_box = Box("b", [0.4, 0.3, 0.3], [1.0, 0.0, 0.55])
>>> features = contact_features([floor_box, top_box], np.zeros((0, 3)), [(0, 1)])
>>> named = dict(zip(CONTACT_FEATURE_NAMES, features[0].round(3).tolist()))
>>> named["overlap_share_y"], named["vertical_gap"], named["bottom_y"]
(1.0, 0.0, 0.4)
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from unstack.geometry import bounding_box_overlap_xy
from unstack.scene import Box

__all__ = ["COLUMN_MARGIN", "CONTACT_FEATURE_NAMES", "contact_features"]

#: Names of the contact features, in order.
CONTACT_FEATURE_NAMES: tuple[str, ...] = (
    "overlap_x",
    "overlap_y",
    "overlap_share_x",
    "overlap_share_y",
    "footprint_gap",
    "vertical_gap",
    "height_x",
    "height_y",
    "bottom_x",
    "bottom_y",
    "cloud_between",
    "rise_above_x",
    "rise_above_y",
    "cloud_above_x",
    "cloud_above_y",
    "cloud_in_pair_box",
    "pair_box_volume",
)
#: Widening of the column between two boxes in which cloud points count as "between" (metres).
COLUMN_MARGIN = 0.05
#: Side of the square xy columns the cloud is bucketed into for counting (metres; any value
#: gives the same counts, this one the fastest measured on container clouds).
GRID_CELL = 0.05
#: Points closer than this to a box's top or bottom face belong to the face (metres).
FACE_TOLERANCE = 0.01


def _geometry(bb_x: np.ndarray, bb_y: np.ndarray) -> np.ndarray:
    """The ten box-only columns for rows of bounding boxes ``[min xyz, max xyz]``."""
    overlap = bounding_box_overlap_xy(bb_x, bb_y)
    area = np.prod(np.clip(overlap, 0.0, None), axis=1)
    area_x = np.prod(bb_x[:, 3:5] - bb_x[:, :2], axis=1)
    area_y = np.prod(bb_y[:, 3:5] - bb_y[:, :2], axis=1)
    footprint_gap = np.hypot(*np.clip(-overlap, 0.0, None).T)
    return np.column_stack(
        [
            overlap,
            area / area_x,
            area / area_y,
            footprint_gap,
            bb_y[:, 2] - bb_x[:, 5],
            bb_x[:, 5] - bb_x[:, 2],
            bb_y[:, 5] - bb_y[:, 2],
            bb_x[:, 2],
            bb_y[:, 2],
        ]
    )


def _cloud_queries(
    bounds: np.ndarray, x: np.ndarray, y: np.ndarray, pair_box: tuple[np.ndarray, np.ndarray]
) -> tuple[np.ndarray, np.ndarray]:
    """Closed query boxes ``low <= p <= high``: over each box, then between and around each pair.

    Open bounds (strictly above a top, strictly between two faces) become closed ones by
    moving them to the next float, so the counts are exact.
    """
    up, down = np.inf, -np.inf
    above_low = np.column_stack([bounds[:, :2], np.nextafter(bounds[:, 5] + FACE_TOLERANCE, up)])
    above_high = np.column_stack([bounds[:, 3:5], np.full(len(bounds), up)])
    bb_x, bb_y = bounds[x], bounds[y]
    between_low = np.column_stack(
        [np.maximum(bb_x[:, :2], bb_y[:, :2]) - COLUMN_MARGIN, np.nextafter(bb_x[:, 5] + FACE_TOLERANCE, up)]
    )
    between_high = np.column_stack(
        [np.minimum(bb_x[:, 3:5], bb_y[:, 3:5]) + COLUMN_MARGIN, np.nextafter(bb_y[:, 2] - FACE_TOLERANCE, down)]
    )
    pair_low, pair_high = pair_box
    return (
        np.ascontiguousarray(np.vstack([above_low, between_low, pair_low])),
        np.ascontiguousarray(np.vstack([above_high, between_high, pair_high])),
    )


def contact_features(boxes: Sequence[Box], points: np.ndarray, pairs: Sequence[tuple[int, int]]) -> np.ndarray:
    """The contact features of each ordered pair ``(X, Y)`` of box indices, shape (len(pairs), 17)."""
    from unstack.geometry import bounding_boxes

    index = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
    used = np.unique(index)
    row_of = {int(box): row for row, box in enumerate(used)}
    bounds = bounding_boxes([boxes[int(box)] for box in used])
    x = np.array([row_of[int(value)] for value in index[:, 0]], dtype=np.int64)
    y = np.array([row_of[int(value)] for value in index[:, 1]], dtype=np.int64)
    geometry = _geometry(bounds[x], bounds[y])
    pair_box = np.minimum(bounds[x, :3], bounds[y, :3]), np.maximum(bounds[x, 3:], bounds[y, 3:])
    points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    cloud = np.zeros((len(index), 7))
    if len(points):
        from unstack.learning._contact_kernel import column_index, counts_in_boxes

        low, high = _cloud_queries(bounds, x, y, pair_box)
        columns = column_index(points, GRID_CELL)
        counts, highest = counts_in_boxes(columns, low, high)
        shares = counts / len(points)
        n_boxes, n_pairs = len(bounds), len(index)
        above_share = shares[:n_boxes]
        rise = np.where(counts[:n_boxes] > 0, highest[:n_boxes] - bounds[:, 5], 0.0)
        cloud[:, 0] = shares[n_boxes : n_boxes + n_pairs]  # empty queries (low > high) count nothing
        cloud[:, 1], cloud[:, 2] = rise[x], rise[y]
        cloud[:, 3], cloud[:, 4] = above_share[x], above_share[y]
        cloud[:, 5] = shares[n_boxes + n_pairs :]
    cloud[:, 6] = np.prod(pair_box[1] - pair_box[0], axis=1)
    return np.column_stack([geometry, cloud])
