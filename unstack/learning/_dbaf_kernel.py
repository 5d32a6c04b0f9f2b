"""Compiled kernel of the direct DBAF sum (see :mod:`unstack.learning.features`)."""

from __future__ import annotations

import numpy as np
from numba import njit

from unstack.threads import run_in_ranges


@njit(cache=True, nogil=True, fastmath=False)
def _gaussian_sums(
    points: np.ndarray, queries: np.ndarray, inverse_two_variance: float, first: int, last: int, sums: np.ndarray
) -> None:  # pragma: no cover
    """``sums[q] = sum_k exp(-||q - p_k||^2 * inverse_two_variance)`` for the query points ``first`` to ``last - 1``."""
    for q in range(first, last):
        qx, qy, qz = queries[q, 0], queries[q, 1], queries[q, 2]
        total = 0.0
        for k in range(points.shape[0]):
            dx = points[k, 0] - qx
            dy = points[k, 1] - qy
            dz = points[k, 2] - qz
            total += np.exp(-(dx * dx + dy * dy + dz * dz) * inverse_two_variance)
        sums[q] = total


def gaussian_sums(points: np.ndarray, queries: np.ndarray, inverse_two_variance: float) -> np.ndarray:
    """The compiled sum for every query point, the queries shared out over :func:`unstack.threads.thread_count`
    threads (each sum is computed whole by one thread: the same numbers on any number of threads)."""
    sums = np.zeros(queries.shape[0])
    run_in_ranges(
        lambda first, last: _gaussian_sums(points, queries, inverse_two_variance, first, last, sums), len(sums)
    )
    return sums
