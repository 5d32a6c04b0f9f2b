"""Compiled kernels of the contact features' cloud counts (see :mod:`unstack.learning.contact_features`).

The cloud is bucketed once into square columns of the xy plane, each column's points sorted
by z. A query box then visits only the columns its xy-range touches: a column wholly inside
the range answers by two binary searches on z; a column on the range's edge checks its
points one by one. Counts are exact (no point is dropped or counted twice).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from unstack.threads import run_in_ranges


class PointColumns(NamedTuple):
    """A cloud bucketed into square columns of the xy plane (:func:`column_index`)."""

    points: np.ndarray
    """The points sorted by (column, z)."""
    starts: np.ndarray
    """The first row of each column (and one past the last)."""
    origin: np.ndarray
    """The grid's lowest corner in x and y."""
    shape: np.ndarray
    """Columns along x and y."""
    cell: float
    """A column's side (metres)."""


def column_index(points: np.ndarray, cell: float) -> PointColumns:
    """The points bucketed into columns of side ``cell``."""
    origin = points[:, :2].min(axis=0)
    cells = np.floor((points[:, :2] - origin) / cell).astype(np.int64)
    shape = cells.max(axis=0) + 1
    column = cells[:, 0] * shape[1] + cells[:, 1]
    order = np.lexsort((points[:, 2], column))
    starts = np.searchsorted(column[order], np.arange(shape[0] * shape[1] + 1))
    return PointColumns(
        np.ascontiguousarray(points[order]), starts.astype(np.int64), origin, shape.astype(np.int64), cell
    )


@njit(cache=True, nogil=True)
def _counts_in_boxes(
    points: np.ndarray,
    starts: np.ndarray,
    origin: np.ndarray,
    shape: np.ndarray,
    cell: float,
    low: np.ndarray,
    high: np.ndarray,
    first: int,
    last: int,
    counts: np.ndarray,
    top: np.ndarray,
) -> None:  # pragma: no cover
    """Points with ``low <= p <= high`` in the query boxes ``first`` to ``last - 1``, and the highest z
    among them (-inf if none), into ``counts`` and ``top``."""
    for q in range(first, last):
        if low[q, 0] > high[q, 0] or low[q, 1] > high[q, 1] or low[q, 2] > high[q, 2]:
            continue
        first_x = max(int(np.floor((low[q, 0] - origin[0]) / cell)), 0)
        last_x = min(int(np.floor((high[q, 0] - origin[0]) / cell)), shape[0] - 1)
        first_y = max(int(np.floor((low[q, 1] - origin[1]) / cell)), 0)
        last_y = min(int(np.floor((high[q, 1] - origin[1]) / cell)), shape[1] - 1)
        count = 0
        highest = -np.inf
        for ix in range(first_x, last_x + 1):
            inside_x = origin[0] + ix * cell >= low[q, 0] and origin[0] + (ix + 1) * cell <= high[q, 0]
            for iy in range(first_y, last_y + 1):
                begin = starts[ix * shape[1] + iy]
                end = starts[ix * shape[1] + iy + 1]
                if begin == end:
                    continue
                inside = inside_x and origin[1] + iy * cell >= low[q, 1] and origin[1] + (iy + 1) * cell <= high[q, 1]
                if inside:  # z-sorted: two binary searches
                    zs = points[begin:end, 2]
                    lo = np.searchsorted(zs, low[q, 2], side="left")
                    hi = np.searchsorted(zs, high[q, 2], side="right")
                    if hi > lo:
                        count += hi - lo
                        highest = max(highest, zs[hi - 1])
                    continue
                for k in range(begin, end):
                    x, y, z = points[k, 0], points[k, 1], points[k, 2]
                    if low[q, 0] <= x <= high[q, 0] and low[q, 1] <= y <= high[q, 1] and low[q, 2] <= z <= high[q, 2]:
                        count += 1
                        highest = max(highest, z)
        counts[q] = count
        top[q] = highest


def counts_in_boxes(columns: PointColumns, low: np.ndarray, high: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The compiled counts of every query box, the boxes shared out over
    :func:`unstack.threads.thread_count` threads (each box counted whole by one thread)."""
    boxes = low.shape[0]
    counts = np.zeros(boxes, dtype=np.int64)
    top = np.full(boxes, -np.inf)
    run_in_ranges(
        lambda first, last: _counts_in_boxes(*columns, low, high, first, last, counts, top),
        boxes,
    )
    return counts, top
