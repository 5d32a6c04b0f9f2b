"""Compiled kernels of the exact marginals engine (see :mod:`unstack.reasoner.marginals`).

A consistent world on boxes ``0..n-1`` is a preorder. It is built by inserting the
boxes one at a time: box ``j`` joins the preorder on ``0..j-1`` with

* a *down-set* ``D`` -- the boxes that support ``j`` (closed under "is supported by"),
* an *up-set* ``U`` -- the boxes that ``j`` supports (closed under "supports"),

and the pair is admissible iff every member of ``U`` other than ``x`` is supported by
every ``x`` in ``D`` (``U`` lies inside ``A(D)``, the boxes above every member of ``D``).
Every preorder arises exactly once, so the weighted sum over the insertion tree is the
partition function of the consistent worlds.

A node of the tree keeps three lists, all as bit masks over the boxes already placed:
its admissible down-sets, ``A(D)`` for each of them, and its admissible up-sets. A child's
lists are filtered from the parent's instead of recomputing closures. Each call returns
its subtree's weight sum; times the path weight, that sum is added to per-level tables
indexed by ``D`` and by ``U``, so the marginal bookkeeping costs O(1) per node. The last
box is never expanded into leaves: the admissible ``(D, U)`` pairs are summed directly.

Everything here is plain numeric code compiled with numba; the public wrapper lives in
:mod:`unstack.reasoner.marginals`.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange


@njit(cache=True, nogil=True)
def _child_lists(
    j: int,
    down_set: int,
    up_set: int,
    downs: np.ndarray,
    above: np.ndarray,
    n_downs: int,
    ups: np.ndarray,
    n_ups: int,
    child_downs: np.ndarray,
    child_above: np.ndarray,
    child_ups: np.ndarray,
) -> tuple[int, int]:
    """Write the admissible lists of the child that inserts box ``j`` with ``(D, U)``."""
    bit = np.int64(1) << j
    n_child_downs = 0
    for a in range(n_downs):
        s = downs[a]
        if s & up_set == 0:
            above_s = above[a]
            if s & ~down_set == 0:
                above_s |= bit
            child_downs[n_child_downs] = s
            child_above[n_child_downs] = above_s
            n_child_downs += 1
    for a in range(n_downs):
        s = downs[a]
        if down_set & ~s == 0:
            above_s = above[a]
            if s == down_set:
                above_s |= bit
            child_downs[n_child_downs] = s | bit
            child_above[n_child_downs] = above_s & (up_set | bit)
            n_child_downs += 1
    n_child_ups = 0
    for b in range(n_ups):
        s = ups[b]
        if s & down_set == 0:
            child_ups[n_child_ups] = s
            n_child_ups += 1
    for b in range(n_ups):
        s = ups[b]
        if up_set & ~s == 0:
            child_ups[n_child_ups] = s | bit
            n_child_ups += 1
    return n_child_downs, n_child_ups


@njit(cache=True, nogil=True, fastmath=True)
def _last_level(
    j: int,
    path_weight: float,
    downs: np.ndarray,
    above: np.ndarray,
    n_downs: int,
    ups: np.ndarray,
    n_ups: int,
    down_weights: np.ndarray,
    up_weights: np.ndarray,
    down_allowed: np.ndarray,
    up_allowed: np.ndarray,
    down_table: np.ndarray,
    up_table: np.ndarray,
    scratch_ups: np.ndarray,
    scratch_weights: np.ndarray,
    scratch_sums: np.ndarray,
    world_count: np.ndarray,
) -> float:
    """Sum the last box's admissible ``(D, U)`` pairs without expanding leaves."""
    n_live = 0
    for b in range(n_ups):
        if up_allowed[j, ups[b]]:
            scratch_ups[n_live] = ups[b]
            scratch_weights[n_live] = up_weights[j, ups[b]]
            scratch_sums[n_live] = 0.0
            n_live += 1
    total = 0.0
    count = np.int64(0)
    for a in range(n_downs):
        d = downs[a]
        if not down_allowed[j, d]:
            continue
        f = down_weights[j, d]
        outside = ~above[a]
        up_sum = 0.0
        for b in range(n_live):
            inside = np.int64(scratch_ups[b] & outside == 0)
            up_sum += inside * scratch_weights[b]
            scratch_sums[b] += inside * f
            count += inside
        down_table[j, d] += path_weight * f * up_sum
        total += f * up_sum
    for b in range(n_live):
        if scratch_sums[b] > 0.0:
            up_table[j, scratch_ups[b]] += path_weight * scratch_weights[b] * scratch_sums[b]
    world_count[0] += count
    return total


@njit(cache=True, nogil=True)
def _next_pair(
    j: int,
    a: int,
    b: int,
    downs: np.ndarray,
    above: np.ndarray,
    ups: np.ndarray,
    n_downs: int,
    n_ups: int,
    down_weights: np.ndarray,
    up_weights: np.ndarray,
    down_allowed: np.ndarray,
    up_allowed: np.ndarray,
) -> tuple[int, int]:
    """Return the next admissible non-zero ``(D, U)`` index pair at or after ``(a, b)``.

    Returns ``(n_downs, 0)`` when the node's pairs are exhausted.
    """
    while a < n_downs:
        if down_allowed[j, downs[j, a]]:
            outside = ~above[j, a]
            while b < n_ups:
                u = ups[j, b]
                if u & outside == 0 and up_allowed[j, u]:
                    return a, b
                b += 1
        a += 1
        b = 0
    return n_downs, 0


@njit(cache=True, nogil=True)
def _subtree(
    start: int,
    n: int,
    start_weight: float,
    downs: np.ndarray,
    above: np.ndarray,
    ups: np.ndarray,
    n_downs: np.ndarray,
    n_ups: np.ndarray,
    down_weights: np.ndarray,
    up_weights: np.ndarray,
    down_allowed: np.ndarray,
    up_allowed: np.ndarray,
    down_table: np.ndarray,
    up_table: np.ndarray,
    scratch_ups: np.ndarray,
    scratch_weights: np.ndarray,
    scratch_sums: np.ndarray,
    world_count: np.ndarray,
) -> float:
    """Weight sum of all completions of the node at level ``start`` (lists in its row).

    An explicit depth-first walk (numba's on-disk cache mishandles recursive functions):
    row ``j`` of ``downs``/``above``/``ups`` holds the lists of the current node at level
    ``j`` and ``n_downs[j]``/``n_ups[j]`` their lengths.
    """
    if start == n - 1:
        return _last_level(
            start,
            start_weight,
            downs[start],
            above[start],
            n_downs[start],
            ups[start],
            n_ups[start],
            down_weights,
            up_weights,
            down_allowed,
            up_allowed,
            down_table,
            up_table,
            scratch_ups,
            scratch_weights,
            scratch_sums,
            world_count,
        )
    cursor_down = np.zeros(n, dtype=np.int64)
    cursor_up = np.zeros(n, dtype=np.int64)
    chosen_weight = np.zeros(n)
    path_weight = np.zeros(n)
    subtotal = np.zeros(n)
    path_weight[start] = start_weight
    level = start
    while True:
        j = level
        a, b = _next_pair(
            j,
            cursor_down[j],
            cursor_up[j],
            downs,
            above,
            ups,
            n_downs[j],
            n_ups[j],
            down_weights,
            up_weights,
            down_allowed,
            up_allowed,
        )
        if a < n_downs[j]:
            d = downs[j, a]
            u = ups[j, b]
            w = down_weights[j, d] * up_weights[j, u]
            cursor_down[j] = a
            cursor_up[j] = b + 1
            chosen_weight[j] = w
            n_downs[j + 1], n_ups[j + 1] = _child_lists(
                j,
                d,
                u,
                downs[j],
                above[j],
                n_downs[j],
                ups[j],
                n_ups[j],
                downs[j + 1],
                above[j + 1],
                ups[j + 1],
            )
            if j + 1 < n - 1:
                level = j + 1
                cursor_down[level] = 0
                cursor_up[level] = 0
                path_weight[level] = path_weight[j] * w
                subtotal[level] = 0.0
                continue
            sub = _last_level(
                j + 1,
                path_weight[j] * w,
                downs[j + 1],
                above[j + 1],
                n_downs[j + 1],
                ups[j + 1],
                n_ups[j + 1],
                down_weights,
                up_weights,
                down_allowed,
                up_allowed,
                down_table,
                up_table,
                scratch_ups,
                scratch_weights,
                scratch_sums,
                world_count,
            )
        else:
            if j == start:
                return float(subtotal[j])
            sub = subtotal[j]
            j -= 1
            level = j
        if sub != 0.0:
            w = chosen_weight[j]
            contribution = path_weight[j] * w * sub
            down_table[j, downs[j, cursor_down[j]]] += contribution
            up_table[j, ups[j, cursor_up[j] - 1]] += contribution
            subtotal[j] += w * sub


@njit(cache=True, nogil=True)
def collect_tasks(
    n: int,
    depth: int,
    max_tasks: int,
    down_weights: np.ndarray,
    up_weights: np.ndarray,
    down_allowed: np.ndarray,
    up_allowed: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Split the insertion tree at level ``depth`` into independent subtrees.

    Each task is a node of level ``depth``: its path weight, its three lists and the
    ``(D, U)`` masks chosen on the way to it (one per level above it).
    """
    width = 1 << max(n - 1, 0)
    downs = np.zeros((n + 1, width + 1), dtype=np.int64)
    above = np.zeros((n + 1, width + 1), dtype=np.int64)
    ups = np.zeros((n + 1, width + 1), dtype=np.int64)
    n_downs = np.zeros(n + 1, dtype=np.int64)
    n_ups = np.zeros(n + 1, dtype=np.int64)
    task_width = 1 << depth
    path_columns = max(depth, 1)
    task_weight = np.zeros(max_tasks)
    task_downs = np.zeros((max_tasks, task_width), dtype=np.int64)
    task_above = np.zeros((max_tasks, task_width), dtype=np.int64)
    task_ups = np.zeros((max_tasks, task_width), dtype=np.int64)
    task_sizes = np.zeros((max_tasks, 2), dtype=np.int64)
    task_path_downs = np.zeros((max_tasks, path_columns), dtype=np.int64)
    task_path_ups = np.zeros((max_tasks, path_columns), dtype=np.int64)
    cursor_down = np.zeros(n + 1, dtype=np.int64)
    cursor_up = np.zeros(n + 1, dtype=np.int64)
    path_weight = np.ones(n + 1)
    # The root: no box placed; the only down-set and up-set is the empty one.
    n_downs[0] = 1
    n_ups[0] = 1
    t = 0
    level = 0
    while True:
        j = level
        if j == depth:
            task_weight[t] = path_weight[j]
            task_sizes[t, 0] = n_downs[j]
            task_sizes[t, 1] = n_ups[j]
            task_downs[t, : n_downs[j]] = downs[j, : n_downs[j]]
            task_above[t, : n_downs[j]] = above[j, : n_downs[j]]
            task_ups[t, : n_ups[j]] = ups[j, : n_ups[j]]
            for parent in range(depth):
                task_path_downs[t, parent] = downs[parent, cursor_down[parent]]
                task_path_ups[t, parent] = ups[parent, cursor_up[parent] - 1]
            t += 1
            if j == 0:
                break
            level = j - 1
            continue
        a, b = _next_pair(
            j,
            cursor_down[j],
            cursor_up[j],
            downs,
            above,
            ups,
            n_downs[j],
            n_ups[j],
            down_weights,
            up_weights,
            down_allowed,
            up_allowed,
        )
        if a == n_downs[j]:
            if j == 0:
                break
            level = j - 1
            continue
        d = downs[j, a]
        u = ups[j, b]
        cursor_down[j] = a
        cursor_up[j] = b + 1
        n_downs[j + 1], n_ups[j + 1] = _child_lists(
            j,
            d,
            u,
            downs[j],
            above[j],
            n_downs[j],
            ups[j],
            n_ups[j],
            downs[j + 1],
            above[j + 1],
            ups[j + 1],
        )
        level = j + 1
        cursor_down[level] = 0
        cursor_up[level] = 0
        path_weight[level] = path_weight[j] * down_weights[j, d] * up_weights[j, u]
    return (
        task_weight[:t],
        task_downs[:t],
        task_above[:t],
        task_ups[:t],
        task_sizes[:t],
        task_path_downs[:t],
        task_path_ups[:t],
    )


@njit(cache=True, parallel=True)
def run_tasks(
    n: int,
    depth: int,
    task_weight: np.ndarray,
    task_downs: np.ndarray,
    task_above: np.ndarray,
    task_ups: np.ndarray,
    task_sizes: np.ndarray,
    down_weights: np.ndarray,
    up_weights: np.ndarray,
    down_allowed: np.ndarray,
    up_allowed: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """Expand every task's subtree in parallel.

    Returns each task's subtree weight sum, the per-level ``D`` and ``U`` tables (summed
    over the tasks) and the number of worlds of non-zero weight.
    """
    n_tasks = task_weight.shape[0]
    width = 1 << max(n - 1, 0)
    # One table per task (numba's thread id would keep this function out of the cache);
    # callers keep the task count in the hundreds, so this stays a few megabytes.
    down_tables = np.zeros((n_tasks, n, width))
    up_tables = np.zeros((n_tasks, n, width))
    subtree_sums = np.zeros(n_tasks)
    world_counts = np.zeros((n_tasks, 1), dtype=np.int64)
    for t in prange(n_tasks):
        downs = np.zeros((n + 1, width + 1), dtype=np.int64)
        above = np.zeros((n + 1, width + 1), dtype=np.int64)
        ups = np.zeros((n + 1, width + 1), dtype=np.int64)
        scratch_ups = np.zeros(width + 1, dtype=np.int64)
        scratch_weights = np.zeros(width + 1)
        scratch_sums = np.zeros(width + 1)
        n_downs = np.zeros(n + 1, dtype=np.int64)
        n_ups = np.zeros(n + 1, dtype=np.int64)
        n_downs[depth] = task_sizes[t, 0]
        n_ups[depth] = task_sizes[t, 1]
        for a in range(n_downs[depth]):
            downs[depth, a] = task_downs[t, a]
            above[depth, a] = task_above[t, a]
        for b in range(n_ups[depth]):
            ups[depth, b] = task_ups[t, b]
        subtree_sums[t] = _subtree(
            depth,
            n,
            task_weight[t],
            downs,
            above,
            ups,
            n_downs,
            n_ups,
            down_weights,
            up_weights,
            down_allowed,
            up_allowed,
            down_tables[t],
            up_tables[t],
            scratch_ups,
            scratch_weights,
            scratch_sums,
            world_counts[t],
        )
    return subtree_sums, down_tables.sum(axis=0), up_tables.sum(axis=0), world_counts.sum()
