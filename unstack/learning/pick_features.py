"""What the robot sees of each candidate pick: the inputs of the pick-disturbance model.

One row per detected box, from what a robot knows only -- the detected boxes' poses, the
point cloud, and the reasoner's output on them (expected costs and conditional marginals)
-- never the poses of boxes nobody detected. The columns (:data:`PICK_FEATURES`):

* where the box is: the height it rests at and its top, its own height, its depth from the
  door, how far below the highest detected box it rests and tops out, the share of detected
  boxes resting higher, whether it stands on the floor, its tilt, its footprint;
* what the reasoner believes: its expected cost (:mod:`unstack.reasoner.costs`), the
  expected number of detected boxes it supports and the largest such marginal, how much the
  detected boxes hold it up, the hidden load the cloud shows on it
  (:mod:`unstack.understanding.hidden_load`);
* what touches it: detected boxes resting on it and under it, detected boxes beside it
  (a gap under :data:`CONTACT_GAP` and a shared height band), the share of its top they cover;
* what the cloud shows around it: points over its top (all, and those no detected box
  explains), how high they reach, points just behind its back face and beside its sides
  (a neighbour a removal may drag by friction) -- counts on a log scale.

Examples
--------
>>> from unstack.scene import Box, Scene
>>> from unstack.supports import Supports
>>> boxes = [Box("low", [0.4, 0.4, 0.3], [1.0, 0.0, 0.15]), Box("top", [0.4, 0.4, 0.3], [1.0, 0.0, 0.45])]
>>> scene = Scene(boxes, np.zeros((0, 3)), ["low", "top"])
>>> supports = Supports(["low", "top"], [[0.0, 0.9], [0.05, 0.0]], hidden_load=[0.0, 0.0])
>>> rows = pick_features(scene, supports, np.array([[0.0, 0.9], [0.05, 0.0]]), np.array([0.9, 0.05]))
>>> rows.shape == (2, len(PICK_FEATURES))
True
>>> float(rows[0, PICK_FEATURES.index("detected_on_top")]), float(rows[1, PICK_FEATURES.index("detected_below")])
(1.0, 1.0)
"""

from __future__ import annotations

import numpy as np

from unstack.errors import InvalidArgument
from unstack.geometry import bounding_boxes, points_in_box, tilt_deg
from unstack.scene import Scene
from unstack.supports import Supports

__all__ = ["CONTACT_GAP", "PICK_FEATURES", "pick_features"]

#: The columns of :func:`pick_features`, in order.
PICK_FEATURES = (
    "resting_height",
    "top_height",
    "own_height",
    "door_distance",
    "below_highest_resting",
    "below_highest_top",
    "share_resting_higher",
    "on_floor",
    "tilt_deg",
    "footprint_area",
    "detected_boxes",
    "expected_cost",
    "expected_supported",
    "largest_support_marginal",
    "held_by_detected",
    "hidden_load",
    "detected_on_top",
    "detected_below",
    "detected_beside",
    "top_covered_share",
    "log_points_over_top",
    "log_unexplained_over_top",
    "rise_over_top",
    "log_points_behind",
    "log_points_beside",
)
#: Two boxes closer than this (metres) touch.
CONTACT_GAP = 0.02
#: How far above a top, behind a back face and beside a side the cloud is looked at (metres).
CLOUD_REACH = (1.5, 0.05, 0.04)
#: A box resting lower than this (metres) stands on the floor.
FLOOR_HEIGHT = 0.03
#: Width of the cloud's columns for box queries (metres).
COLUMN_WIDTH = 0.1
#: Points inside a detected box grown by this (metres) are explained by it.
EXPLAINED_MARGIN = 0.02


class _Columns:
    """The cloud binned into vertical columns of :data:`COLUMN_WIDTH` for fast box queries.

    Points are sorted by column (x index major, y index minor), so the points under an
    x-y rectangle are one contiguous run per x index.
    """

    def __init__(self, points: np.ndarray) -> None:
        self.points = points
        cells = np.floor(points[:, :2] / COLUMN_WIDTH).astype(np.int64) if len(points) else np.zeros((0, 2), np.int64)
        self.low = cells.min(axis=0) if len(points) else np.zeros(2, np.int64)
        cells -= self.low
        self.span = int(cells[:, 1].max()) + 1 if len(points) else 1
        keys = cells[:, 0] * self.span + cells[:, 1]
        self.order = np.argsort(keys, kind="stable")
        self.keys = keys[self.order]

    def within(self, bound: np.ndarray, margin: float, above: float = 0.0) -> np.ndarray:
        """Indices of the points inside ``bound`` grown by ``margin`` (and ``above`` more over its top)."""
        low = bound[:3] - margin
        high = bound[3:] + margin + np.array([0.0, 0.0, above])
        if len(self.points) == 0:
            return np.zeros(0, dtype=np.int64)
        first = np.floor(low[:2] / COLUMN_WIDTH).astype(np.int64) - self.low
        last = np.floor(high[:2] / COLUMN_WIDTH).astype(np.int64) - self.low
        first_y, last_y = max(int(first[1]), 0), min(int(last[1]), self.span - 1)
        runs = []
        for x in range(max(int(first[0]), 0), int(last[0]) + 1):
            start, stop = np.searchsorted(self.keys, [x * self.span + first_y, x * self.span + last_y + 1])
            runs.append(self.order[start:stop])
        near = np.concatenate(runs) if runs else np.zeros(0, dtype=np.int64)
        inside = np.all((self.points[near] >= low) & (self.points[near] <= high), axis=1)
        return np.sort(near[inside])


def _overlap(first: np.ndarray, second: np.ndarray, axes: tuple[int, ...]) -> float:
    """Length, area or volume of the overlap of two bounds along ``axes``."""
    return float(np.prod([max(0.0, min(first[3 + a], second[3 + a]) - max(first[a], second[a])) for a in axes]))


def _contacts(bounds: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Per box: detected boxes resting on it, under it, beside it, and the share of its top covered."""
    n = len(bounds)
    on_top, below, beside, covered = (np.zeros(n) for _ in range(4))
    for i in range(n):
        area = _overlap(bounds[i], bounds[i], (0, 1))
        for j in range(n):
            if i == j:
                continue
            shared = _overlap(bounds[i], bounds[j], (0, 1))
            smaller = min(area, _overlap(bounds[j], bounds[j], (0, 1)))
            if shared > 0.2 * smaller and abs(bounds[j, 2] - bounds[i, 5]) < CONTACT_GAP:
                on_top[i] += 1
                covered[i] += shared / area
            if shared > 0.2 * smaller and abs(bounds[i, 2] - bounds[j, 5]) < CONTACT_GAP:
                below[i] += 1
            gaps = np.maximum(bounds[j, :2] - bounds[i, 3:5], bounds[i, :2] - bounds[j, 3:5])
            if _overlap(bounds[i], bounds[j], (2,)) > 0.05 and gaps.max() < CONTACT_GAP and shared < 0.2 * smaller:
                beside[i] += 1
    return on_top, below, beside, np.minimum(covered, 1.0)


def _cloud_columns(
    points: np.ndarray, bound: np.ndarray, explained: np.ndarray
) -> tuple[float, float, float, float, float]:
    """Points over the top (all, unexplained), how high they rise, behind the back face, beside the sides."""
    above_reach, behind_reach, side_reach = CLOUD_REACH
    inside_xy = np.all((points[:, :2] >= bound[:2] - 0.02) & (points[:, :2] <= bound[3:5] + 0.02), axis=1)
    over = inside_xy & (points[:, 2] > bound[5] + 0.01) & (points[:, 2] < bound[5] + above_reach)
    band_z = (points[:, 2] > bound[2] + 0.02) & (points[:, 2] < bound[5] - 0.02)
    in_y = (points[:, 1] > bound[1]) & (points[:, 1] < bound[4])
    in_x = (points[:, 0] > bound[0]) & (points[:, 0] < bound[3])
    behind = band_z & in_y & (points[:, 0] > bound[3]) & (points[:, 0] < bound[3] + behind_reach)
    left = (points[:, 1] < bound[1]) & (points[:, 1] > bound[1] - side_reach)
    right = (points[:, 1] > bound[4]) & (points[:, 1] < bound[4] + side_reach)
    beside = band_z & in_x & (left | right)
    rise = float(points[over, 2].max() - bound[5]) if over.any() else 0.0
    return (
        float(np.log1p(over.sum())),
        float(np.log1p((over & ~explained).sum())),
        rise,
        float(np.log1p((behind & ~explained).sum())),
        float(np.log1p((beside & ~explained).sum())),
    )


def pick_features(scene: Scene, supports: Supports, marginals: np.ndarray, expected_costs: np.ndarray) -> np.ndarray:
    """One row of :data:`PICK_FEATURES` per object of ``supports`` (detected boxes of ``scene``).

    Parameters
    ----------
    scene : Scene
        The detected boxes' poses and the point cloud are read; other boxes are not.
    supports : Supports
        The support probabilities of the scene's detected boxes (their ``objects`` order the
        rows) with their hidden load.
    marginals : numpy.ndarray, shape (n, n)
        The reasoner's conditional marginals ``P(S_ij | consistent)``.
    expected_costs : numpy.ndarray, shape (n,)
        The reasoner's expected cost of each box.

    Returns
    -------
    numpy.ndarray, shape (n, len(PICK_FEATURES)), float64

    Raises
    ------
    InvalidArgument
        Arrays whose shapes do not match the supports.
    """
    objects = list(supports.objects)
    n = len(objects)
    marginals = np.asarray(marginals, dtype=np.float64)
    expected_costs = np.asarray(expected_costs, dtype=np.float64)
    if marginals.shape != (n, n) or expected_costs.shape != (n,):
        raise InvalidArgument(
            f"expected marginals of shape ({n}, {n}) and expected costs of shape ({n},) for {n} objects, "
            f"got {marginals.shape} and {expected_costs.shape}"
        )
    boxes = [scene.box(box_id) for box_id in objects]
    bounds = bounding_boxes(boxes)
    points = scene.points
    columns = _Columns(points)
    explained = np.zeros(len(points), dtype=bool)
    for box, bound in zip(boxes, bounds, strict=True):
        near = columns.within(bound, EXPLAINED_MARGIN)
        explained[near[points_in_box(points[near], box, margin=EXPLAINED_MARGIN)]] = True
    on_top, below, beside, covered = _contacts(bounds)
    hidden = np.zeros(n) if supports.hidden_load is None else np.asarray(supports.hidden_load, dtype=np.float64)
    off_diagonal = marginals * (1.0 - np.eye(n))
    rows = np.zeros((n, len(PICK_FEATURES)))
    for k, box in enumerate(boxes):
        bound = bounds[k]
        reach = columns.within(bound, max(CLOUD_REACH[1:]) + 0.01, above=CLOUD_REACH[0])
        cloud = _cloud_columns(points[reach], bound, explained[reach]) if len(reach) else (0.0,) * 5
        rows[k] = (
            bound[2],
            bound[5],
            bound[5] - bound[2],
            bound[0],
            bounds[:, 2].max() - bound[2],
            bounds[:, 5].max() - bound[5],
            float(np.mean(bounds[:, 2] > bound[2] + 0.01)),
            float(bound[2] < FLOOR_HEIGHT),
            tilt_deg(box),
            (bound[3] - bound[0]) * (bound[4] - bound[1]),
            float(n),
            expected_costs[k],
            off_diagonal[k].sum(),
            off_diagonal[k].max(initial=0.0),
            off_diagonal[:, k].sum(),
            hidden[k],
            on_top[k],
            below[k],
            beside[k],
            covered[k],
            *cloud,
        )
    return rows
