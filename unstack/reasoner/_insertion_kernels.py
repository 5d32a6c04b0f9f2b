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
indexed by ``D`` and by ``U``, so the marginal bookkeeping costs O(1) per node.

The last levels are summed without building their nodes (``collapse``):

* ``collapse=1``: the last box's admissible ``(D, U)`` pairs are summed directly
  (:func:`_last_level`, O(#D x #U) per node of level ``n - 1``);
* ``collapse=2`` (the default): the last *two* boxes are summed at each node of level
  ``n - 2`` with subset sums (zeta transforms) and superset sums over the lattices of that
  node's up-sets and down-sets (:func:`_last_two_levels`), so the ``A000798(n - 1)`` nodes
  of the last level are never built.

Everything here is plain numeric code compiled with numba; the public wrapper lives in
:mod:`unstack.reasoner.marginals`.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def _child_lists(
    j: int, down_set: int, up_set: int, lists: tuple[np.ndarray, np.ndarray, np.ndarray], n_downs: int, n_ups: int
) -> tuple[int, int]:
    """Write the admissible lists of the child that inserts box ``j`` with ``(D, U)``: from row
    ``j`` of ``lists`` (``downs``, ``above``, ``ups``, one row per level) into row ``j + 1``."""
    downs, above, ups = lists[0][j], lists[1][j], lists[2][j]
    child_downs, child_above, child_ups = lists[0][j + 1], lists[1][j + 1], lists[2][j + 1]
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
    node: tuple[np.ndarray, np.ndarray, int, np.ndarray, int],
    weights: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray],
    tables: tuple[np.ndarray, np.ndarray],
    scratch: np.ndarray,
    index_scratch: np.ndarray,
    world_count: np.ndarray,
) -> float:
    """Sum the last box's admissible ``(D, U)`` pairs without expanding leaves.

    ``node``: the node's ``downs``, ``above``, their number, ``ups`` and theirs; ``weights``:
    ``down_weights``, ``up_weights``, ``down_allowed``, ``up_allowed``; ``tables``: the per-level
    ``D`` and ``U`` tables.
    """
    downs, above, n_downs, ups, n_ups = node
    down_weights, up_weights, down_allowed, up_allowed = weights
    down_table, up_table = tables
    scratch_ups, scratch_weights, scratch_sums = index_scratch[0], scratch[0], scratch[1]
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


@njit(cache=True, nogil=True, fastmath=True)
def _lattice_sums(masks: np.ndarray, n: int, values: np.ndarray, out: np.ndarray, upward: bool) -> None:
    """``out[j]`` = sum of ``values[i]`` over ``masks[i] ⊆ masks[j]`` (``masks[i] ⊇ masks[j]`` if ``upward``).

    The zeta transform of a lattice given as a list of masks, O(n^2) and branch-free.
    """
    for j in range(n):
        mask_j = masks[j]
        acc = 0.0
        if upward:
            for i in range(n):
                acc += np.float64(mask_j & ~masks[i] == 0) * values[i]
        else:
            for i in range(n):
                acc += np.float64(masks[i] & ~mask_j == 0) * values[i]
        out[j] = acc


@njit(cache=True, nogil=True, fastmath=True)
def _lattice_sums2(
    masks: np.ndarray, n: int, x: np.ndarray, y: np.ndarray, x_out: np.ndarray, y_out: np.ndarray, upward: bool
) -> None:
    """:func:`_lattice_sums` of two value lists at once."""
    for j in range(n):
        mask_j = masks[j]
        acc_x = 0.0
        acc_y = 0.0
        if upward:
            for i in range(n):
                inside = np.float64(mask_j & ~masks[i] == 0)
                acc_x += inside * x[i]
                acc_y += inside * y[i]
        else:
            for i in range(n):
                inside = np.float64(masks[i] & ~mask_j == 0)
                acc_x += inside * x[i]
                acc_y += inside * y[i]
        x_out[j] = acc_x
        y_out[j] = acc_y


@njit(cache=True, nogil=True, fastmath=True)
def _weights_of_sets(
    sets: np.ndarray,
    n: int,
    weights: np.ndarray,
    m: int,
    a_bit: np.int64,
    own: np.ndarray,
    next_own: np.ndarray,
    next_with_a: np.ndarray,
) -> None:
    """For each of the ``n`` sets: its weight for box ``m`` (``own``), for box ``m + 1``
    (``next_own``) and for box ``m + 1`` with box ``m`` added to it (``next_with_a``)."""
    for k in range(n):
        mask = sets[k]
        own[k] = weights[m, mask]
        next_own[k] = weights[m + 1, mask]
        next_with_a[k] = weights[m + 1, mask | a_bit]


@njit(cache=True, nogil=True, fastmath=True)
def _sums_over_inside(
    ups: np.ndarray, n_ups: int, above: np.ndarray, n_downs: int, up_values: np.ndarray, out: np.ndarray
) -> None:
    """``out[s]``: ``up_values`` summed over the up-sets inside ``A(D_s)`` (``above[s]``)."""
    for s in range(n_downs):
        a_s = above[s]
        acc = 0.0
        for t in range(n_ups):
            acc += np.float64(ups[t] & ~a_s == 0) * up_values[t]
        out[s] = acc


@njit(cache=True, nogil=True, fastmath=True)
def _sums_over_containing(
    ups: np.ndarray, n_ups: int, above: np.ndarray, n_downs: int, down_values: np.ndarray, out: np.ndarray
) -> None:
    """``out[t]``: ``down_values`` summed over the down-sets ``D`` with ``ups[t]`` inside ``A(D)``."""
    for t in range(n_ups):
        u = ups[t]
        acc = 0.0
        for s in range(n_downs):
            acc += np.float64(u & ~above[s] == 0) * down_values[s]
        out[t] = acc


@njit(cache=True, nogil=True, fastmath=True)
def _last_two_levels(
    m: int,
    path_weight: float,
    node: tuple[np.ndarray, np.ndarray, int, np.ndarray, int],
    node_weights: tuple[np.ndarray, np.ndarray],
    tables: tuple[np.ndarray, np.ndarray],
    with_tables: bool,
    scratch: np.ndarray,
    index_scratch: np.ndarray,
) -> float:
    """Weight sum of the completions of a node at level ``m = n - 2`` (the last two boxes).

    Box ``a = m`` joins with ``(D_a, U_a)`` and box ``b = m + 1`` with ``(D_b, U_b)``
    (``D_b``, ``U_b`` the sets of earlier boxes, without ``a``), in one of four ways:

    * **unrelated**: ``U_a`` and ``D_b`` disjoint, ``U_b`` and ``D_a`` disjoint. For fixed
      ``D_a`` and ``D_b`` the up-sets are independent: ``U_a`` ranges over the up-sets inside
      ``A(D_a) \\ D_b``, ``U_b`` over those inside ``A(D_b) \\ D_a``, so the sum is
      ``f_a(D_a) f_b(D_b) G_a(A(D_a) \\ D_b) G_b(A(D_b) \\ D_a)`` with ``G`` the subset sums
      (zeta transform) of ``g`` over the up-sets: O(#D^2) per node;
    * **a under b** (``a`` supports ``b``): ``D_b`` contains ``D_a``; ``U_b`` lies in
      ``A(D_b)``, in ``U_a`` and outside ``D_a``: per admissible ``(D_a, U_a)`` and ``D_b``,
      ``f_b(D_b + a) G_b(A(D_b) & U_a \\ D_a)``. Where ``U_a`` lies inside ``D_a`` this is
      ``g_b(empty)`` times the superset sum of ``f_b(. + a)`` at ``D_a``; where ``D_a`` is
      empty it is a subset sum over ``U_a`` of ``g_b(U) psi(U)``, ``psi(U)`` the sum of
      ``f_b(D + a)`` over the down-sets ``D`` with ``U`` inside ``A(D)``;
    * **b under a**, the mirror image with ``B(U)``, the largest down-set ``D`` with ``U``
      inside ``A(D)``: ``g_b(U_b + a) F_b(B(U_b) & D_a \\ U_a)`` for ``U_b`` containing ``U_a``;
    * **a and b mutual**: ``D_b = D_a``, ``U_b = U_a``.

    Every argument of a subset or superset sum is an up-set (or a down-set) of the node, so
    the sums run over the node's lists, O(#U^2) and branch-free, instead of over all
    ``2^m`` masks; arrays indexed by mask are read and written at those masks only. The
    per-level tables of ``a`` and ``b`` come from the same loops: where a term is a subset
    sum, its marginal contribution is scattered at the sum's argument and gathered back by
    the opposite (superset) sum.

    ``node``, ``tables``: as for :func:`_last_level`; ``node_weights``: ``down_weights`` and
    ``up_weights``. With ``with_tables`` false only the sum is returned (the world count uses
    0/1 weights).
    """
    downs, above, n_downs, ups, n_ups = node
    down_weights, up_weights = node_weights
    down_table, up_table = tables
    a_bit = np.int64(1) << m
    b = m + 1
    # cube arrays, indexed by a mask of the m earlier boxes (only up-set or down-set masks used)
    g1_at = scratch[0]
    g2_at = scratch[1]
    f2_at = scratch[2]
    x_at = scratch[3]
    y_at = scratch[4]
    z_at = scratch[5]
    # lists over the up-sets (t) and the down-sets (s) of the node
    g1 = scratch[6]
    g2 = scratch[7]
    g2a = scratch[8]
    f1 = scratch[9]
    f2 = scratch[10]
    f2a = scratch[11]
    t_a = scratch[12]
    t_b = scratch[13]
    t_c = scratch[14]
    t_d = scratch[15]
    s_a = scratch[16]
    s_c = scratch[18]
    s_d = scratch[19]
    up_m = scratch[20]
    up_ba = scratch[21]
    down_m = scratch[22]
    down_b = scratch[23]
    down_ba = scratch[24]
    wc2 = scratch[25]
    wc3 = scratch[26]
    omega = scratch[27]
    omega2 = scratch[28]
    psi = scratch[29]
    psi2 = scratch[30]
    q = scratch[31]
    q2 = scratch[32]
    r_above = scratch[33]
    r2_below = scratch[34]
    g2a_sup = scratch[35]
    f2a_sup = scratch[36]
    same_down = scratch[37]
    same_up = scratch[38]
    below = index_scratch[0]
    # the weights of a (level m) and b (m + 1, with a or without) at each set; sums cleared
    _weights_of_sets(ups, n_ups, up_weights, m, a_bit, g1, g2, g2a)
    _weights_of_sets(downs, n_downs, down_weights, m, a_bit, f1, f2, f2a)
    for t in range(n_ups):
        x_at[ups[t]] = 0.0
        z_at[ups[t]] = 0.0
    for s in range(n_downs):
        y_at[downs[s]] = 0.0
    up_m[:n_ups] = 0.0
    up_ba[:n_ups] = 0.0
    wc2[:n_ups] = 0.0
    same_up[:n_ups] = 0.0
    down_m[:n_downs] = 0.0
    down_b[:n_downs] = 0.0
    down_ba[:n_downs] = 0.0
    wc3[:n_downs] = 0.0
    same_down[:n_downs] = 0.0
    # below[t]: the largest down-set D with ups[t] inside A(D); psi[t]: sum of f2a over the
    # down-sets D with ups[t] inside A(D); psi2[s]: sum of g2a over the up-sets inside A(D_s)
    for t in range(n_ups):
        u = ups[t]
        union = np.int64(0)
        for s in range(n_downs):
            union |= downs[s] * np.int64(u & ~above[s] == 0)
        below[t] = union
    _sums_over_containing(ups, n_ups, above, n_downs, f2a, psi)
    _sums_over_inside(ups, n_ups, above, n_downs, g2a, psi2)
    # subset sums over the up-sets (g1, g2) and down-sets (f2), placed at their masks
    _lattice_sums2(ups, n_ups, g1, g2, t_a, t_b, False)
    for t in range(n_ups):
        g1_at[ups[t]] = t_a[t]
        g2_at[ups[t]] = t_b[t]
    _lattice_sums(downs, n_downs, f2, s_a, False)
    for s in range(n_downs):
        f2_at[downs[s]] = s_a[s]
    # superset sums: g2a and g1 over the up-sets, f2a and f1 over the down-sets
    _lattice_sums2(ups, n_ups, g2a, g1, g2a_sup, omega, True)
    _lattice_sums2(downs, n_downs, f2a, f1, f2a_sup, omega2, True)
    f1_empty = f1[0]
    g1_empty = g1[0]
    for t in range(n_ups):
        t_c[t] = g2[t] * psi[t]
        t_d[t] = g2[t] * f1_empty * omega[t]
    for s in range(n_downs):
        s_c[s] = f2[s] * psi2[s]
        s_d[s] = f2[s] * g1_empty * omega2[s]
    _lattice_sums(ups, n_ups, t_c, q, False)
    _lattice_sums(downs, n_downs, s_c, q2, False)
    # r_above[s]: t_d summed over the up-sets inside A(D_s); r2_below[t]: s_d over D inside below[t]
    _sums_over_inside(ups, n_ups, above, n_downs, t_d, r_above)
    _sums_over_containing(ups, n_ups, above, n_downs, s_d, r2_below)
    total = 0.0
    # a and b unrelated: any two down-sets; each box's up-sets summed by the subset sums
    for i in range(n_downs):
        d1 = downs[i]
        a1 = above[i]
        w1 = f1[i]
        row_sum = 0.0
        for s in range(n_downs):
            mask_a = a1 & ~downs[s]
            mask_b = above[s] & ~d1
            ga = g1_at[mask_a]
            gb = g2_at[mask_b]
            wf = w1 * f2[s]
            v = wf * ga * gb
            row_sum += v
            down_b[s] += v
            z_at[mask_a] += wf * gb
            x_at[mask_b] += wf * ga
        down_m[i] += row_sum
        total += row_sum
    # the admissible (D_a, U_a) pairs: a and b mutual, a under b, b under a
    x_empty = 0.0
    y_empty = 0.0
    g2_empty = g2_at[0]
    f2_empty = f2_at[0]
    for i in range(n_downs):
        d1 = downs[i]
        if f1[i] == 0.0:
            continue
        a1 = above[i]
        for k in range(n_ups):
            u1 = ups[k]
            if u1 & ~a1 != 0 or g1[k] == 0.0:
                continue
            w1 = f1[i] * g1[k]
            same = f2a[i] * g2a[k]
            sub = same
            same_down[i] += w1 * same
            same_up[k] += w1 * same
            # a under b
            outside = u1 & ~d1
            if d1 == 0:
                sub += q[k]
            elif outside == 0:
                sub += g2_empty * f2a_sup[i]
                wc3[i] += w1
                x_empty += w1 * f2a_sup[i]
            else:
                for s in range(n_downs):
                    mask = above[s] & outside
                    fa = np.float64(d1 & ~downs[s] == 0) * f2a[s]
                    va = fa * g2_at[mask]
                    sub += va
                    down_ba[s] += w1 * va
                    x_at[mask] += w1 * fa
            # b under a
            inside = d1 & ~u1
            if u1 == 0:
                sub += q2[i]
            elif inside == 0:
                sub += f2_empty * g2a_sup[k]
                wc2[k] += w1
                y_empty += w1 * g2a_sup[k]
            else:
                for t in range(n_ups):
                    ga = np.float64(u1 & ~ups[t] == 0) * g2a[t]
                    mask = below[t] & inside
                    v = ga * f2_at[mask]
                    sub += v
                    up_ba[t] += w1 * v
                    y_at[mask] += w1 * ga
            down_m[i] += w1 * sub
            up_m[k] += w1 * sub
            total += w1 * sub
    if not with_tables:
        return total
    x_at[0] += x_empty
    y_at[0] += y_empty
    for t in range(n_ups):
        t_a[t] = x_at[ups[t]]
        t_b[t] = z_at[ups[t]]
    _lattice_sums2(ups, n_ups, t_a, t_b, t_c, t_d, True)  # t_c: x summed upward, t_d: z
    _lattice_sums(ups, n_ups, wc2, t_a, False)
    for s in range(n_downs):
        s_a[s] = y_at[downs[s]]
    _lattice_sums(downs, n_downs, s_a, s_c, True)  # s_c: y summed upward
    _lattice_sums(downs, n_downs, wc3, s_d, False)
    for t in range(n_ups):
        u = ups[t]
        up_table[m, u] += path_weight * (up_m[t] + g1[t] * t_d[t])
        up_table[b, u] += path_weight * g2[t] * (t_c[t] + psi[t] * f1_empty * omega[t])
        up_table[b, u | a_bit] += path_weight * (same_up[t] + up_ba[t] + g2a[t] * (r2_below[t] + f2_empty * t_a[t]))
    for s in range(n_downs):
        d = downs[s]
        down_table[m, d] += path_weight * down_m[s]
        down_table[b, d] += path_weight * (down_b[s] + f2[s] * (s_c[s] + psi2[s] * g1_empty * omega2[s]))
        down_table[b, d | a_bit] += path_weight * (
            same_down[s] + down_ba[s] + f2a[s] * (r_above[s] + g2_empty * s_d[s])
        )
    return total


@njit(cache=True, nogil=True)
def _next_pair(
    j: int,
    a: int,
    b: int,
    lists: tuple[np.ndarray, np.ndarray, np.ndarray],
    n_downs: int,
    n_ups: int,
    weights: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray],
) -> tuple[int, int]:
    """Return the next admissible non-zero ``(D, U)`` index pair of level ``j`` at or after ``(a, b)``.

    Returns ``(n_downs, 0)`` when the node's pairs are exhausted.
    """
    downs, above, ups = lists
    down_allowed, up_allowed = weights[2], weights[3]
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
def _finish(
    j: int,
    n: int,
    path_weight: float,
    lists: tuple[np.ndarray, np.ndarray, np.ndarray],
    n_downs: int,
    n_ups: int,
    weights: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray],
    ones: tuple[np.ndarray, np.ndarray],
    tables: tuple[np.ndarray, np.ndarray],
    scratch: np.ndarray,
    index_scratch: np.ndarray,
    world_count: np.ndarray,
    counting: bool,
) -> float:
    """Weight sum of the completions of the node at level ``j`` (row ``j`` of ``lists``), one of
    the last two levels.

    Level ``n - 1``: the last box's pairs directly; level ``n - 2``: the last two boxes
    by transforms, and (``counting``) their worlds again with 0/1 weights (``ones``).
    """
    node = (lists[0][j], lists[1][j], n_downs, lists[2][j], n_ups)
    if j == n - 1:
        return _last_level(j, path_weight, node, weights, tables, scratch, index_scratch, world_count)
    if counting:
        worlds = _last_two_levels(j, 1.0, node, ones, tables, False, scratch, index_scratch)
        world_count[0] += np.int64(worlds + 0.5)
    return _last_two_levels(j, path_weight, node, (weights[0], weights[1]), tables, True, scratch, index_scratch)


@njit(cache=True, nogil=True)
def _subtree(
    start: int,
    n: int,
    collapse: int,
    start_weight: float,
    lists: tuple[np.ndarray, np.ndarray, np.ndarray],
    n_downs: np.ndarray,
    n_ups: np.ndarray,
    weights: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray],
    ones: tuple[np.ndarray, np.ndarray],
    tables: tuple[np.ndarray, np.ndarray],
    scratch: np.ndarray,
    index_scratch: np.ndarray,
    world_count: np.ndarray,
    counting: bool,
) -> float:
    """Weight sum of all completions of the node at level ``start`` (lists in its row).

    An explicit depth-first walk (numba's on-disk cache mishandles recursive functions):
    row ``j`` of ``lists`` (``downs``, ``above``, ``ups``) holds the lists of the current node
    at level ``j`` and ``n_downs[j]``/``n_ups[j]`` their lengths. Nodes of level
    ``n - collapse`` are not expanded (:func:`_finish`); ``start`` must not be deeper.
    """
    downs, _, ups = lists
    down_weights, up_weights = weights[0], weights[1]
    down_table, up_table = tables
    finishing = (weights, ones, tables, scratch, index_scratch, world_count, counting)
    last = n - collapse
    if start == last:
        return _finish(start, n, start_weight, lists, n_downs[start], n_ups[start], *finishing)
    cursor_down = np.zeros(n, dtype=np.int64)
    cursor_up = np.zeros(n, dtype=np.int64)
    chosen_weight = np.zeros(n)
    path_weight = np.zeros(n)
    subtotal = np.zeros(n)
    path_weight[start] = start_weight
    level = start
    while True:
        j = level
        a, b = _next_pair(j, cursor_down[j], cursor_up[j], lists, n_downs[j], n_ups[j], weights)
        if a < n_downs[j]:
            d = downs[j, a]
            u = ups[j, b]
            w = down_weights[j, d] * up_weights[j, u]
            cursor_down[j] = a
            cursor_up[j] = b + 1
            chosen_weight[j] = w
            n_downs[j + 1], n_ups[j + 1] = _child_lists(j, d, u, lists, n_downs[j], n_ups[j])
            if j + 1 < last:
                level = j + 1
                cursor_down[level] = 0
                cursor_up[level] = 0
                path_weight[level] = path_weight[j] * w
                subtotal[level] = 0.0
                continue
            sub = _finish(j + 1, n, path_weight[j] * w, lists, n_downs[j + 1], n_ups[j + 1], *finishing)
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
    lists = (downs, above, ups)
    weights = (down_weights, up_weights, down_allowed, up_allowed)
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
        a, b = _next_pair(j, cursor_down[j], cursor_up[j], lists, n_downs[j], n_ups[j], weights)
        if a == n_downs[j]:
            if j == 0:
                break
            level = j - 1
            continue
        d = downs[j, a]
        u = ups[j, b]
        cursor_down[j] = a
        cursor_up[j] = b + 1
        n_downs[j + 1], n_ups[j + 1] = _child_lists(j, d, u, lists, n_downs[j], n_ups[j])
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


@njit(cache=True, nogil=True)
def run_task(
    t: int,
    n: int,
    depth: int,
    collapse: int,
    counting: bool,
    task_weight: np.ndarray,
    task_downs: np.ndarray,
    task_above: np.ndarray,
    task_ups: np.ndarray,
    task_sizes: np.ndarray,
    down_weights: np.ndarray,
    up_weights: np.ndarray,
    down_allowed: np.ndarray,
    up_allowed: np.ndarray,
) -> tuple[float, np.ndarray, np.ndarray, int]:
    """Expand task ``t``'s subtree, without the GIL (the caller runs tasks on threads).

    ``collapse`` (1 or 2) last levels are summed without building their nodes, and
    ``depth`` must be at most ``n - collapse``. Returns the subtree's weight sum, its
    per-level ``D`` and ``U`` tables and the number of worlds whose relations are all
    allowed -- counted only if ``counting`` with ``collapse=2`` (when every relation is
    allowed, the count is the number of preorders and the caller knows it).

    A plain serial kernel rather than a ``parallel=True`` loop: numba's parallel lowering
    tripled the compile time of this walk (about 60 s in a fresh process), and threads the
    caller owns need no threading layer and no process-wide lock.
    """
    width = 1 << max(n - 1, 0)
    weights = (down_weights, up_weights, down_allowed, up_allowed)
    down_ones = down_allowed.astype(np.float64)
    up_ones = up_allowed.astype(np.float64)
    down_table = np.zeros((n, width))
    up_table = np.zeros((n, width))
    world_count = np.zeros(1, dtype=np.int64)
    downs = np.zeros((n + 1, width + 1), dtype=np.int64)
    above = np.zeros((n + 1, width + 1), dtype=np.int64)
    ups = np.zeros((n + 1, width + 1), dtype=np.int64)
    scratch = np.zeros((39, width + 1))
    index_scratch = np.zeros((1, width + 1), dtype=np.int64)
    n_downs = np.zeros(n + 1, dtype=np.int64)
    n_ups = np.zeros(n + 1, dtype=np.int64)
    n_downs[depth] = task_sizes[t, 0]
    n_ups[depth] = task_sizes[t, 1]
    for a in range(n_downs[depth]):
        downs[depth, a] = task_downs[t, a]
        above[depth, a] = task_above[t, a]
    for b in range(n_ups[depth]):
        ups[depth, b] = task_ups[t, b]
    subtree_sum = _subtree(
        depth, n, collapse, task_weight[t], (downs, above, ups), n_downs, n_ups, weights, (down_ones, up_ones),
        (down_table, up_table), scratch, index_scratch, world_count, counting,
    )  # fmt: skip
    return subtree_sum, down_table, up_table, world_count[0]
