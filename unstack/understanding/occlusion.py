"""The space a sensor cannot see: behind the surface its point cloud shows.

A robot that scans a container from the door sees the front faces and tops of the pile;
what lies behind them -- boxes deeper in the container, boxes under others -- it does not
see. Boxes are packed from the back wall forwards and stand on one another, so the unseen
space next to a box the robot sees is mostly filled. This module finds that space from the
cloud and the sensor's position alone:

* the cloud's points are binned by direction from the sensor (:data:`DIRECTION_BIN` radians
  of azimuth and of elevation); in each direction the nearest point is the visible surface;
* the container's interior is cut into cells :data:`CELL` metres across, near the given
  boxes (within :data:`REACH`: only what they could touch matters to them);
* a cell is **occluded** when its centre lies farther from the sensor, in its direction,
  than the visible surface (by more than three quarters of a cell), and its centre is not
  inside one of the given boxes;
* occluded cells are joined into runs along the container's depth, each run cut back
  where it would overlap a given box (on the axis of the smallest overlap, with
  :data:`CLEARANCE`): blocks of unseen material that touch the given boxes without
  entering them.

The cloud must be as dense as a depth image (a point in every direction bin, as the
simulator's sensor gives); a direction in which the cloud has no point says nothing, and its
cells are not occluded. The physics on the belief (:mod:`unstack.sim.belief`) puts these blocks in as fixed bodies.

Examples
--------
>>> import numpy as np
>>> from unstack.scene import Box
>>> from unstack.understanding.clouds import surface_cloud
>>> front = Box("front", [0.4, 0.4, 0.4], [1.0, 0.0, 0.2])
>>> behind = Box("behind", [0.4, 0.4, 0.4], [1.4, 0.0, 0.2])   # hidden by front, seen by nobody
>>> cloud = surface_cloud([front, behind], viewpoint=[-2.0, 0.0, 0.3], spacing=0.005, seed=0)
>>> blocks = occluded_space(cloud, [front], viewpoint=[-2.0, 0.0, 0.3], interior=[[0, -1, 0], [2, 1, 2]])
>>> def unseen(point):
...     return bool(np.all(np.abs(blocks.centers - point) <= blocks.sizes / 2, axis=1).any())
>>> unseen([1.3, 0.0, 0.2]), unseen([1.0, 0.0, 0.2]), unseen([1.0, 0.0, 0.6])   # behind, inside, above
(True, False, False)
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from unstack.scene import Box

__all__ = [
    "CELL",
    "CLEARANCE",
    "DIRECTION_BIN",
    "REACH",
    "OccludedBlocks",
    "OcclusionGrid",
    "occluded_space",
    "occlusion_grid",
]

#: Edge of the cells the container's interior is cut into (metres).
CELL = 0.06
#: Only cells within this distance of a given box are considered (metres).
REACH = 0.2
#: Width of the direction bins of the visible surface (radians of azimuth and of elevation):
#: about three pixels of the simulator's 640 x 480 sensor at 43 degrees.
DIRECTION_BIN = 0.005
#: Gap left between a block and a given box it would overlap (metres).
CLEARANCE = 0.003
#: Thinner blocks than this are dropped (metres).
THINNEST = 0.005


@dataclass(frozen=True)
class OccludedBlocks:
    """Axis-aligned blocks of unseen material: ``sizes`` and ``centers``, shape (k, 3) each."""

    sizes: np.ndarray
    centers: np.ndarray

    def __len__(self) -> int:
        return int(self.sizes.shape[0])


def _direction_keys(offsets: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Direction bin of each offset from the sensor, as one integer, and its range."""
    ranges = np.linalg.norm(offsets, axis=1)
    azimuth = np.floor(np.arctan2(offsets[:, 1], offsets[:, 0]) / DIRECTION_BIN).astype(np.int64)
    elevation = np.arcsin(np.clip(offsets[:, 2] / np.maximum(ranges, 1e-12), -1.0, 1.0))
    return azimuth * 1_000_003 + np.floor(elevation / DIRECTION_BIN).astype(np.int64), ranges


def _visible_surface(points: np.ndarray, viewpoint: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Sorted direction keys and the nearest range in each."""
    keys, ranges = _direction_keys(points - viewpoint)
    order = np.lexsort((ranges, keys))
    keys, ranges = keys[order], ranges[order]
    first = np.r_[True, keys[1:] != keys[:-1]]
    return keys[first], ranges[first]


def _clipped(low: np.ndarray, high: np.ndarray, bounds: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The blocks ``[low, high]`` (rows) cut back out of every box bound they overlap, box by box."""
    for bound in bounds:
        overlap = np.minimum(high, bound[3:]) - np.maximum(low, bound[:3])
        hit = np.flatnonzero(np.all(overlap > 0, axis=1))
        if len(hit) == 0:
            continue
        axis = np.argmin(overlap[hit], axis=1)
        before = (low[hit, axis] + high[hit, axis]) / 2 < (bound[axis] + bound[3 + axis]) / 2
        high[hit[before], axis[before]] = bound[axis[before]] - CLEARANCE
        low[hit[~before], axis[~before]] = bound[3 + axis[~before]] + CLEARANCE
    return low, high


@dataclass(frozen=True)
class OcclusionGrid:
    """The cells near some boxes and which of them the sensor cannot see.

    Attributes
    ----------
    axes : tuple of numpy.ndarray
        The cells' centre coordinates along x, y and z (metres).
    occluded : numpy.ndarray of bool, shape (len(axes[0]), len(axes[1]), len(axes[2]))
        Behind the visible surface and outside every box.
    distance : numpy.ndarray of float, the same shape
        How far each cell's centre lies outside the nearest box's bounds (metres, 0 inside).
    cell : float
        Edge of the cells (metres).
    """

    axes: tuple[np.ndarray, np.ndarray, np.ndarray]
    occluded: np.ndarray
    distance: np.ndarray
    cell: float


def occlusion_grid(
    points: Any, boxes: Sequence[Box], *, viewpoint: Any, interior: Any, cell: float = CELL, reach: float = REACH
) -> OcclusionGrid | None:
    """The cells within ``reach`` of ``boxes`` and which the sensor cannot see (the module
    docstring; :func:`occluded_space` joins them into blocks); None when there are none.

    Parameters
    ----------
    points, boxes, viewpoint, interior, cell
        As in :func:`occluded_space`.
    reach : float
        Only cells within this distance of a box's bounds are considered (metres).

    Examples
    --------
    >>> from unstack.understanding.clouds import surface_cloud
    >>> front = Box("front", [0.4, 0.4, 0.4], [1.0, 0.0, 0.2])
    >>> cloud = surface_cloud([front], viewpoint=[-2.0, 0.0, 0.3], spacing=0.005, seed=0)
    >>> grid = occlusion_grid(cloud, [front], viewpoint=[-2.0, 0.0, 0.3], interior=[[0, -1, 0], [2, 1, 2]])
    >>> bool(grid.occluded.any()), grid.occluded.shape == grid.distance.shape
    (True, True)
    """
    from unstack.geometry import bounding_boxes

    cloud = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    origin = np.asarray(viewpoint, dtype=np.float64)
    inside_low, inside_high = np.asarray(interior, dtype=np.float64)
    if len(cloud) == 0 or not boxes:
        return None
    keys, surface = _visible_surface(cloud, origin)
    bounds = bounding_boxes(list(boxes))
    low = np.maximum(bounds[:, :3].min(axis=0) - reach, inside_low)
    high = np.minimum(bounds[:, 3:].max(axis=0) + reach, inside_high)
    axes = tuple(np.arange(start + cell / 2, stop, cell) for start, stop in zip(low, high, strict=True))
    if any(len(axis) == 0 for axis in axes):
        return None
    centres = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    distance = np.full(len(centres), np.inf)
    inside = np.zeros(len(centres), dtype=bool)
    for bound in bounds:
        outside = np.maximum(np.maximum(bound[:3] - centres, centres - bound[3:]), 0.0)
        distance = np.minimum(distance, np.max(outside, axis=1))
        inside |= np.all((centres > bound[:3]) & (centres < bound[3:]), axis=1)
    near = distance < reach
    cell_keys, cell_ranges = _direction_keys(centres - origin)
    slot = np.minimum(np.searchsorted(keys, cell_keys), len(keys) - 1)
    behind = (keys[slot] == cell_keys) & (cell_ranges > surface[slot] + 0.75 * cell)
    shape = tuple(len(axis) for axis in axes)
    occluded = (near & ~inside & behind).reshape(shape)
    return OcclusionGrid(axes, occluded, distance.reshape(shape), cell)  # type: ignore[arg-type]


def occluded_space(
    points: Any, boxes: Sequence[Box], *, viewpoint: Any, interior: Any, cell: float = CELL
) -> OccludedBlocks:
    """The unseen space near ``boxes``, as blocks (see the module docstring).

    Parameters
    ----------
    points : array_like, shape (m, 3)
        The point cloud.
    boxes : sequence of Box
        The boxes the robot sees (their space is never occluded).
    viewpoint : array_like, shape (3,)
        The sensor's position.
    interior : array_like, shape (2, 3)
        The lowest and highest corner of the space boxes can be in (the container's inside).
    cell : float
        Edge of the cells (metres).

    Returns
    -------
    OccludedBlocks
    """
    from unstack.geometry import bounding_boxes

    empty = OccludedBlocks(np.zeros((0, 3)), np.zeros((0, 3)))
    grid = occlusion_grid(points, boxes, viewpoint=viewpoint, interior=interior, cell=cell)
    if grid is None:
        return empty
    bounds = bounding_boxes(list(boxes))
    axes, occluded = grid.axes, grid.occluded
    padded = np.zeros((occluded.shape[0] + 2, *occluded.shape[1:]), dtype=bool)
    padded[1:-1] = occluded
    starts = np.argwhere(padded[1:-1] & ~padded[:-2])  # (depth index, j, k) of each run's first cell
    stops = np.argwhere(~padded[2:] & padded[1:-1])  # ... and of its last; both in (j, k, depth) order below
    starts = starts[np.lexsort((starts[:, 0], starts[:, 2], starts[:, 1]))]
    stops = stops[np.lexsort((stops[:, 0], stops[:, 2], stops[:, 1]))]
    if len(starts) == 0:
        return empty
    half = cell / 2
    block_low = np.column_stack([axes[0][starts[:, 0]], axes[1][starts[:, 1]], axes[2][starts[:, 2]]]) - half
    block_high = np.column_stack([axes[0][stops[:, 0]], axes[1][stops[:, 1]], axes[2][stops[:, 2]]]) + half
    block_low, block_high = _clipped(block_low, block_high, bounds)
    block_low, block_high = _clipped(block_low, block_high, bounds)  # a cut may meet a second box
    kept = np.all(block_high - block_low > THINNEST, axis=1)
    if not kept.any():
        return empty
    return OccludedBlocks((block_high - block_low)[kept], ((block_high + block_low) / 2)[kept])
