"""Whole cartons nobody sees: one hypothesis of the boxes hidden behind and under the boxes in view.

The ``sampled``, ``scaled`` and ``faces`` fills of the physics on the belief
(:mod:`unstack.sim.belief`) keep runs of the space the sensor cannot see solid, each on its
own: a porous scatter of bars that holds a seen box up in some cells and not in others. A
container is packed with cartons, and a hidden carton is a whole box resting on something.
:func:`draw_hidden_cartons` draws such a hypothesis:

* the cells the sensor cannot see (:func:`unstack.understanding.occlusion.occlusion_grid`)
  within :data:`CARTON_REACH` of the boxes in view are where a hidden carton may stand;
* a carton takes the extents of a box in view, drawn at random (the cartons of a container
  are alike; the robot sees some of them), turned a quarter about the vertical half the time;
* it is placed over a randomly drawn unseen cell (its footprint drawn to cover it) and
  dropped onto what is under it there -- the floor, a box in view, a carton drawn before --;
  where it enters a neighbour it is slid out of it sideways, where it enters what stands over
  it it is cut down (to :data:`MIN_HEIGHT` of itself at least), and it is kept only if it then
  overlaps nothing already placed and at most :data:`SEEN_SLACK` of its cells lie where the
  sensor sees (a fitted box's guessed extent is not exact);
* cartons are drawn until they cover ``share`` of the unseen cells within
  :data:`~unstack.understanding.occlusion.REACH` of the boxes in view (the band the other fills
  sample), or :data:`ATTEMPTS` draws were made.

It is geometry only: the belief puts the cartons into its physics worlds as fixed blocks.

Examples
--------
>>> import numpy as np
>>> from unstack.scene import Box
>>> from unstack.understanding.clouds import surface_cloud
>>> from unstack.understanding.occlusion import occlusion_grid
>>> front = Box("front", [0.4, 0.4, 0.4], [0.6, 0.0, 0.2])
>>> behind = Box("behind", [0.4, 0.4, 0.4], [1.0, 0.0, 0.2])   # hidden by front
>>> cloud = surface_cloud([front, behind], viewpoint=[-2.0, 0.0, 0.3], spacing=0.005, seed=0)
>>> inside = [[0, -1, 0], [2, 1, 2]]
>>> grid = occlusion_grid(cloud, [front], viewpoint=[-2.0, 0.0, 0.3], interior=inside, reach=CARTON_REACH)
>>> cartons = draw_hidden_cartons(grid, [front], interior=inside, share=1.0, rng=np.random.default_rng(0))
>>> len(cartons) > 0, bool(np.all(cartons.centers[:, 0] > 0.8))   # behind the front box, none in front
(True, True)
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from unstack.scene import Box
from unstack.understanding.occlusion import OccludedBlocks, OcclusionGrid

__all__ = ["ATTEMPTS", "CARTON_REACH", "GAP", "MIN_HEIGHT", "SEEN_SLACK", "carton_extents", "draw_hidden_cartons"]

#: Hidden cartons stand within this distance of a box in view (metres).
CARTON_REACH = 0.6
#: A carton may have at most this share of its cells where the sensor sees (or outside the cells).
SEEN_SLACK = 0.1
#: Draws of a carton per hypothesis.
ATTEMPTS = 300
#: Gap kept between a carton and what it stands on or beside (metres).
GAP = 0.005
#: A carton under something may be cut down to this share of its height to fit (a box of
#: the same footprint, lower).
MIN_HEIGHT = 0.5


def carton_extents(boxes: Sequence[Box]) -> np.ndarray:
    """Each box's extents along the world's x, y and z: its own size, axes matched to the
    world's by its orientation (a tilted box keeps its size, not its bounding box's).

    Examples
    --------
    >>> standing = Box("a", [0.2, 0.3, 0.4], [1.0, 0.0, 0.2], [0.0, 0.0, 0.7071068, 0.7071068])   # a quarter turn
    >>> carton_extents([standing]).round(3).tolist()
    [[0.3, 0.2, 0.4]]
    """
    from unstack.geometry import rotation_matrix

    rows = []
    for box in boxes:
        rotation = np.abs(rotation_matrix(box.orientation_xyzw))  # columns: the box's axes in the world
        order = np.argsort(-rotation, axis=1)[:, 0]
        size = np.asarray(box.size, dtype=np.float64)
        rows.append(size[order] if len(set(order.tolist())) == 3 else np.sort(size))
    return np.array(rows, dtype=np.float64).reshape(-1, 3)


def _resting_height(foot_low: np.ndarray, foot_high: np.ndarray, below: float, taken: np.ndarray) -> float:
    """Where a footprint dropped from ``below`` comes to rest: on the highest top of ``taken``
    under it no higher than ``below``, else on the floor (:data:`GAP` above either)."""
    under = np.all(taken[:, :2] < foot_high - GAP, axis=1) & np.all(taken[:, 3:5] > foot_low + GAP, axis=1)
    under &= taken[:, 5] <= below + GAP
    return (float(taken[under, 5].max()) if under.any() else 0.0) + GAP


def _overlapping(low: np.ndarray, high: np.ndarray, taken: np.ndarray) -> np.ndarray:
    """The rows of ``taken`` (bounds) that ``[low, high]`` enters."""
    return np.flatnonzero(np.all((taken[:, :3] < high) & (taken[:, 3:] > low), axis=1))


def _fitted(low: np.ndarray, high: np.ndarray, taken: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """A carton ``[low, high]`` moved out of what it enters: slid sideways out of a neighbour by
    the shorter way, or cut down under what stands over it (to no less than :data:`MIN_HEIGHT` of
    itself), twice at most; None where it still enters something."""
    height = high[2] - low[2]
    for attempt in range(3):
        hit = _overlapping(low, high, taken)
        if len(hit) == 0:
            return low, high
        if attempt == 2:
            return None
        for row in taken[hit]:
            depth = np.minimum(high, row[3:]) - np.maximum(low, row[:3])
            if depth[2] <= 0 or depth[0] <= 0 or depth[1] <= 0:
                continue
            above = row[2] > low[2] + GAP
            if above and depth[2] < min(depth[0], depth[1]):
                high = high.copy()
                high[2] = row[2] - GAP
                if high[2] - low[2] < MIN_HEIGHT * height:
                    return None
                continue
            axis = int(np.argmin(depth[:2]))
            shift = depth[axis] + GAP
            if (low[axis] + high[axis]) / 2 < (row[axis] + row[3 + axis]) / 2:
                shift = -shift
            low, high = low.copy(), high.copy()
            low[axis] += shift
            high[axis] += shift
    return None


def _cell_span(axis: np.ndarray, low: float, high: float) -> slice:
    """The indices of the cells of ``axis`` whose centres lie within ``[low, high]``."""
    return slice(int(np.searchsorted(axis, low)), int(np.searchsorted(axis, high, side="right")))


def draw_hidden_cartons(
    grid: OcclusionGrid | None,
    boxes: Sequence[Box],
    *,
    interior: Any,
    share: float,
    rng: np.random.Generator,
    obstacles: np.ndarray | None = None,
    attempts: int = ATTEMPTS,
) -> OccludedBlocks:
    """One hypothesis of the hidden cartons next to ``boxes`` (the module docstring).

    Parameters
    ----------
    grid : OcclusionGrid or None
        The cells near ``boxes`` the sensor cannot see, within :data:`CARTON_REACH`
        (:func:`unstack.understanding.occlusion.occlusion_grid` with ``reach=CARTON_REACH``).
    boxes : sequence of Box
        The boxes in view.
    interior : array_like, shape (2, 3)
        The lowest and highest corner of the container's inside.
    share : float
        The share of the unseen cells near the boxes in view to cover with cartons.
    rng : numpy.random.Generator
        Draws the cartons.
    obstacles : numpy.ndarray, shape (k, 6), optional
        Bounds (low corner, high corner) of what stands there already besides ``boxes``.
    attempts : int
        Draws of a carton at most.

    Returns
    -------
    OccludedBlocks
        The cartons' extents and centres (axis-aligned).
    """
    from unstack.geometry import bounding_boxes
    from unstack.understanding.occlusion import REACH

    empty = OccludedBlocks(np.zeros((0, 3)), np.zeros((0, 3)))
    if not boxes or share <= 0.0 or grid is None or not grid.occluded.any():
        return empty
    band = grid.occluded & (grid.distance < REACH)
    target = share * float(band.sum())
    extents = carton_extents(boxes)
    placed = [bounding_boxes(list(boxes))]
    if obstacles is not None and len(obstacles):
        placed.append(np.asarray(obstacles, dtype=np.float64).reshape(-1, 6))
    taken = np.concatenate(placed)
    inside_low, inside_high = np.asarray(interior, dtype=np.float64)
    covered = np.zeros_like(grid.occluded)
    cell = grid.cell
    unseen_cells = np.argwhere(grid.occluded)
    band_covered = 0.0
    sizes, centers = [], []
    for _ in range(attempts):
        if band_covered >= target:
            break
        anchor_index = unseen_cells[rng.integers(len(unseen_cells))]
        if covered[tuple(anchor_index)]:
            continue
        anchor = np.array([grid.axes[axis][anchor_index[axis]] for axis in range(3)])
        size = extents[rng.integers(len(extents))].copy()
        if rng.random() < 0.5:
            size[[0, 1]] = size[[1, 0]]
        slack = np.maximum(size[:2] / 2 - cell / 2, 0.0)
        middle = anchor[:2] + rng.uniform(-slack, slack)
        foot_low, foot_high = middle - size[:2] / 2, middle + size[:2] / 2
        bottom = _resting_height(foot_low, foot_high, anchor[2] + cell / 2, taken)
        fitted = _fitted(np.array([*foot_low, bottom]), np.array([*foot_high, bottom + size[2]]), taken)
        if fitted is None:
            continue
        low, high = fitted  # slid sideways, it may stand over something lower: dropped again
        drop = low[2] - _resting_height(low[:2], high[:2], low[2], taken)
        low, high = low - [0.0, 0.0, drop], high - [0.0, 0.0, drop]
        if len(_overlapping(low, high, taken)):
            continue
        if np.any(low[1:] < inside_low[1:]) or np.any(high > inside_high):
            continue
        spans = tuple(_cell_span(grid.axes[axis], low[axis], high[axis]) for axis in range(3))
        expected_cells = np.prod(np.maximum(np.round((high - low) / cell), 1.0))
        if float(grid.occluded[spans].sum()) < (1.0 - SEEN_SLACK) * expected_cells:
            continue
        band_covered += float((band[spans] & ~covered[spans]).sum())
        covered[spans] = True
        taken = np.vstack([taken, np.concatenate([low, high])])
        sizes.append(high - low)
        centers.append((high + low) / 2)
    if not sizes:
        return empty
    return OccludedBlocks(np.array(sizes), np.array(centers))
