"""The point cloud binned into vertical columns, to find the points over a rectangle fast.

A depth image of a container holds a few hundred thousand points, and scene understanding
asks, box by box, for the points near one box (the points a detected box explains, the points
just under it). :class:`CloudColumns` sorts the points once by the square column of the floor
they stand over (:data:`COLUMN` metres across); the points over a rectangle are then the
columns it touches, a few contiguous runs of that order, checked exactly.

Examples
--------
>>> points = np.array([[0.05, 0.05, 0.0], [0.5, 0.5, 1.0], [0.52, 0.48, 0.2], [1.5, -0.5, 0.3]])
>>> CloudColumns(points).indices_over([0.4, 0.4], [0.6, 0.6]).tolist()
[1, 2]
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["COLUMN", "CloudColumns", "columns_of"]

#: Edge of the square columns (metres): about a quarter of a carton's side.
COLUMN = 0.1


class CloudColumns:
    """Points sorted by the column of the floor they stand over.

    Parameters
    ----------
    points : array_like, shape (m, 3)
    column : float
        Edge of the columns (metres).
    """

    def __init__(self, points: Any, column: float = COLUMN) -> None:
        self.points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        self.column = float(column)
        if len(self.points) == 0:
            self._first = np.zeros(2, dtype=np.int64)
            self._shape = (0, 0)
            self._order = np.zeros(0, dtype=np.int64)
            self._starts = np.zeros(1, dtype=np.int64)
            return
        across, along = (np.floor(self.points[:, axis] / self.column).astype(np.int64) for axis in (0, 1))
        self._first = np.array([across.min(), along.min()])
        self._shape = (int(across.max() - self._first[0]) + 1, int(along.max() - self._first[1]) + 1)
        keys = (across - self._first[0]) * self._shape[1] + (along - self._first[1])
        if self._shape[0] * self._shape[1] <= np.iinfo(np.uint16).max:
            keys = keys.astype(np.uint16)  # numpy sorts 16-bit keys stably by radix: one pass
        self._order = np.argsort(keys, kind="stable")
        self._starts = np.searchsorted(keys[self._order], np.arange(self._shape[0] * self._shape[1] + 1))

    def _cells(self, xy: np.ndarray) -> np.ndarray:
        cells: np.ndarray = np.floor(xy / self.column).astype(np.int64) - self._first
        return cells

    def indices_over(self, low: Any, high: Any) -> np.ndarray:
        """Indices of the points whose ``x, y`` lie in ``[low, high]`` (both ends in), ascending.

        Parameters
        ----------
        low, high : array_like, shape (2,)
            Corners of the rectangle on the floor.

        Returns
        -------
        numpy.ndarray of int64
        """
        low_xy, high_xy = np.asarray(low, dtype=np.float64)[:2], np.asarray(high, dtype=np.float64)[:2]
        if len(self.points) == 0 or np.any(high_xy < low_xy):
            return np.zeros(0, dtype=np.int64)
        first = np.maximum(self._cells(low_xy[None])[0], 0)
        last = np.minimum(self._cells(high_xy[None])[0], np.array(self._shape) - 1)
        if np.any(last < first):
            return np.zeros(0, dtype=np.int64)
        # a column strictly between the rectangle's first and last (both ways) lies wholly in
        # it: only the points of the border columns are checked
        edge, inner = [], []
        for across in range(first[0], last[0] + 1):
            row = across * self._shape[1]
            start, stop = self._starts[row + first[1]], self._starts[row + last[1] + 1]
            if across in (first[0], last[0]) or last[1] - first[1] < 2:
                edge.append(self._order[start:stop])
                continue
            inner_start, inner_stop = self._starts[row + first[1] + 1], self._starts[row + last[1]]
            edge += [self._order[start:inner_start], self._order[inner_stop:stop]]
            inner.append(self._order[inner_start:inner_stop])
        near = np.concatenate(edge)
        xy = self.points[near, :2]
        inside = np.all((xy >= low_xy) & (xy <= high_xy), axis=1)
        return np.sort(np.concatenate([near[inside], *inner]))


def columns_of(points: Any, columns: CloudColumns | None = None) -> CloudColumns:
    """``columns`` when it bins ``points`` (the same array), else ``points`` binned now.

    Lets the steps of one scene's pipeline share one binning of its cloud.

    Raises
    ------
    ValueError
        ``columns`` bins another cloud.

    Examples
    --------
    >>> points = np.zeros((4, 3))
    >>> shared = CloudColumns(points)
    >>> columns_of(points, shared) is shared, columns_of(points) is shared
    (True, False)
    """
    if columns is None:
        return CloudColumns(points)
    given = np.asarray(points)
    same = columns.points is given or (columns.points.shape == given.shape and np.array_equal(columns.points, given))
    if not same:
        raise ValueError("the binned columns are of another point cloud")
    return columns
