"""Exact conditional marginals without listing worlds (the reasoner's fast path).

Because the cost is additive, the decision needs only
``P(S_XY = 1 | consistent)`` for every ordered pair. The consistent worlds are the
preorders on the boxes, and every preorder is built exactly once by inserting the boxes
``0..n-1`` in turn, box ``j`` joining with a down-closed set D of supporters and an
up-closed set U of boxes it supports (see :mod:`unstack.reasoner._insertion_kernels`).
A world's weight is the product of one factor per level -- ``f_j(D) * g_j(U)`` -- so a
depth-first walk of this insertion tree computes the partition function, and per-level
tables indexed by D and U give every marginal at O(1) cost per node. The last two boxes are
summed at each node of level ``n - 2`` by subset and superset sums over that node's
down-sets and up-sets, so the nodes of the last level are never built. The walk is compiled
with numba and the subtrees below the first levels run on one thread each, on all cores.

Each pair's factors are divided by ``max(p, 1 - p)`` so that every factor is at most 1:
no product can overflow and the all-zero or forced-closure world keeps the partition
function away from underflow in practice; a partition function below
:data:`SMALLEST_PARTITION` raises :class:`~unstack.errors.NumericalRangeError`.

Examples
--------
>>> import numpy as np
>>> half = np.full((3, 3), 0.5); np.fill_diagonal(half, 0)
>>> result = exact_marginals(half)
>>> result.consistent_worlds
29
>>> round(float(result.marginals[0, 1]), 6)  # 12 of the 29 preorders on 3 boxes have a -> b
0.413793
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from unstack.errors import NumericalRangeError, TooLarge
from unstack.reasoner.arguments import check_count, check_matrix
from unstack.reasoner.consistency import PREORDER_COUNTS
from unstack.reasoner.small import SMALL_MAX_BOXES, small_marginals
from unstack.threads import map_on_threads

__all__ = ["EXACT_MAX_BOXES", "ExactMarginals", "exact_marginals"]

#: Largest scene the exact engine accepts by default. n = 8 dense takes about a second;
#: n = 9 has 6.3e10 worlds and takes a minute or two (pass ``max_boxes=9`` to run it anyway).
EXACT_MAX_BOXES = 8
#: The engine refuses results whose partition function falls below this.
SMALLEST_PARTITION = 1e-280


@dataclass(frozen=True, eq=False)
class ExactMarginals:
    """Result of the exact engine.

    Attributes
    ----------
    marginals : numpy.ndarray, shape (n, n)
        ``P(S_xy = 1 | consistent)``; diagonal 0.
    consistent_worlds : int
        Number of consistent worlds of non-zero probability.
    log_partition : float
        ``log`` of the sum of the (rescaled) weights of the consistent worlds.
    """

    marginals: np.ndarray
    consistent_worlds: int
    log_partition: float


def _level_weights(probabilities: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Tables ``f[j, D]`` and ``g[j, U]`` (the weight of box j's relations to boxes < j)
    and whether each is allowed at all (no relation of probability exactly 0 or 1 broken).

    The allowed tables keep pruning and counting structural: a product of tiny but
    non-zero factors may underflow to 0.0 without making its worlds impossible.
    """
    n = probabilities.shape[0]
    scale = np.maximum(probabilities, 1.0 - probabilities)
    present = probabilities / scale
    absent = (1.0 - probabilities) / scale
    width = 1 << max(n - 1, 0)
    down_weights = np.zeros((n, width))
    up_weights = np.zeros((n, width))
    down_allowed = np.zeros((n, width), dtype=np.bool_)
    up_allowed = np.zeros((n, width), dtype=np.bool_)
    masks = np.arange(width)
    for j in range(n):
        members = masks[: 1 << j]
        f = np.ones(1 << j)
        g = np.ones(1 << j)
        f_allowed = np.ones(1 << j, dtype=bool)
        g_allowed = np.ones(1 << j, dtype=bool)
        for x in range(j):
            has_x = ((members >> x) & 1).astype(bool)
            f *= np.where(has_x, present[x, j], absent[x, j])
            g *= np.where(has_x, present[j, x], absent[j, x])
            f_allowed &= np.where(has_x, probabilities[x, j] > 0, probabilities[x, j] < 1)
            g_allowed &= np.where(has_x, probabilities[j, x] > 0, probabilities[j, x] < 1)
        down_weights[j, : 1 << j] = f
        up_weights[j, : 1 << j] = g
        down_allowed[j, : 1 << j] = f_allowed
        up_allowed[j, : 1 << j] = g_allowed
    return down_weights, up_weights, down_allowed, up_allowed


def _split_depth(n: int) -> int:
    """Level at which the tree is cut into parallel tasks (A000798(depth) tasks)."""
    if n <= 5:
        return 0
    if n <= 7:
        return 2
    return 4


def exact_marginals(probabilities: np.ndarray, *, max_boxes: int = EXACT_MAX_BOXES) -> ExactMarginals:
    """Exact ``P(S_xy = 1 | consistent)`` for every pair, by weighted counting of preorders.

    Parameters
    ----------
    probabilities : numpy.ndarray, shape (n, n)
        Checked support probabilities; exactly 0 and 1 are hard evidence (propagate them
        first with :func:`~unstack.reasoner.pruning.propagate_evidence` to get conflicts
        reported by name).
    max_boxes : int, optional
        Refuse larger scenes.

    Returns
    -------
    ExactMarginals

    Raises
    ------
    InvalidArgument
        Not a square matrix of probabilities with a zero diagonal, or ``max_boxes`` below 1.
    TooLarge
        More than ``max_boxes`` boxes.
    NumericalRangeError
        No consistent world keeps a representable weight.

    Examples
    --------
    >>> exact_marginals([[0, 0.9], [0.2, 0]]).consistent_worlds
    4
    """
    return _exact_marginals(check_matrix(probabilities), check_count(max_boxes, "max_boxes"))


def _exact_marginals(probabilities: np.ndarray, max_boxes: int = EXACT_MAX_BOXES) -> ExactMarginals:
    """:func:`exact_marginals` on checked arguments: the table path up to
    :data:`~unstack.reasoner.small.SMALL_MAX_BOXES` boxes, the compiled walk above."""
    n = probabilities.shape[0]
    if n > max_boxes:
        next_count = f"{PREORDER_COUNTS[max_boxes + 1]:.2g}" if max_boxes + 1 < len(PREORDER_COUNTS) else "over 1e13"
        raise TooLarge(
            f"{n} boxes: the exact engine is limited to {max_boxes} boxes "
            f"(n = {max_boxes + 1} has {next_count} consistent worlds; "
            f"n = 8 takes about a second, each further box about 100 times longer)"
        )
    if n <= SMALL_MAX_BOXES:
        marginals, worlds, log_partition = small_marginals(probabilities)
        return ExactMarginals(marginals, worlds, log_partition)
    return _compiled_marginals(probabilities)


def _compiled_marginals(probabilities: np.ndarray, collapse: int = 2) -> ExactMarginals:
    """The compiled insertion walk on a checked matrix of ``n >= 2`` boxes (any size the
    tables fit in memory; :func:`exact_marginals` takes it above the table path).

    ``collapse`` is how many of the last levels are summed without building their nodes:
    2 (transforms, the default) or 1 (the direct pair sum, kept as a cross-check).
    """
    from unstack.reasoner import _insertion_kernels as kernels

    n = probabilities.shape[0]
    tables = _level_weights(np.ascontiguousarray(probabilities, dtype=np.float64))
    depth = min(_split_depth(n), n - collapse)
    off_diagonal = probabilities[~np.eye(n, dtype=bool)]
    # Worlds are counted only when some relation is exactly 0 or 1; otherwise every
    # preorder is allowed and the count is A000798(n).
    counting = bool(np.any((off_diagonal == 0.0) | (off_diagonal == 1.0)))
    tasks = kernels.collect_tasks(n, depth, PREORDER_COUNTS[depth], *tables)
    task_weight, task_downs, task_above, task_ups, task_sizes, path_downs, path_ups = tasks

    def run(task: int) -> tuple[float, np.ndarray, np.ndarray, int]:
        return kernels.run_task(
            task, n, depth, collapse, counting, task_weight, task_downs, task_above, task_ups, task_sizes, *tables
        )

    results = map_on_threads(run, range(len(task_weight)))
    subtree_sums = np.array([result[0] for result in results])
    down_table = np.sum([result[1] for result in results], axis=0)
    up_table = np.sum([result[2] for result in results], axis=0)
    world_count = sum(int(result[3]) for result in results)
    if not counting:
        world_count = PREORDER_COUNTS[n] if n < len(PREORDER_COUNTS) else int(world_count)
    contributions = task_weight * subtree_sums
    for level in range(depth):
        np.add.at(down_table[level], path_downs[:, level], contributions)
        np.add.at(up_table[level], path_ups[:, level], contributions)
    partition = float(contributions.sum())
    if not partition > SMALLEST_PARTITION:
        raise NumericalRangeError(
            "the probabilities are too extreme for float64 weighted counting "
            f"(partition function {partition:.3g}); use the SAT method (method 'sat'), which works in log space"
        )
    marginals = np.zeros((n, n))
    for j in range(1, n):
        members = ((np.arange(1 << j)[:, None] >> np.arange(j)[None, :]) & 1).astype(np.float64)
        marginals[:j, j] = members.T @ down_table[j, : 1 << j] / partition
        marginals[j, :j] = members.T @ up_table[j, : 1 << j] / partition
    np.clip(marginals, 0.0, 1.0, out=marginals)
    return ExactMarginals(marginals, int(world_count), float(np.log(partition)))
