"""Compiled kernel of the direct DBAF sum (see :mod:`unstack.learning.features`)."""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from unstack.threads import PARALLEL_KERNELS


@njit(cache=True, parallel=True, fastmath=False)
def _gaussian_sums(
    points: np.ndarray, queries: np.ndarray, inverse_two_variance: float
) -> np.ndarray:  # pragma: no cover
    """``sum_k exp(-||q - p_k||^2 * inverse_two_variance)`` for every query point q."""
    sums = np.zeros(queries.shape[0])
    for q in prange(queries.shape[0]):
        qx, qy, qz = queries[q, 0], queries[q, 1], queries[q, 2]
        total = 0.0
        for k in range(points.shape[0]):
            dx = points[k, 0] - qx
            dy = points[k, 1] - qy
            dz = points[k, 2] - qz
            total += np.exp(-(dx * dx + dy * dy + dz * dz) * inverse_two_variance)
        sums[q] = total
    return sums


def gaussian_sums(points: np.ndarray, queries: np.ndarray, inverse_two_variance: float) -> np.ndarray:
    """The compiled sum, holding :data:`unstack.threads.PARALLEL_KERNELS` (safe from any thread)."""
    with PARALLEL_KERNELS:
        sums: np.ndarray = _gaussian_sums(points, queries, inverse_two_variance)
    return sums
