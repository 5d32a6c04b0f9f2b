"""Compiled sum of one box's insertion over a free set (see :mod:`unstack.reasoner.insertion`).

The same dynamic programme as :class:`unstack.reasoner.insertion._Insertion`, for a chain
state of the one-word sampler (bit masks of up to 63 boxes, ``int64``) and restricted to a
*free set* ``F`` of boxes: the insertions summed are those whose supporters ``U`` and
supported boxes ``D`` both lie inside ``F``. For a fixed ``F`` these insertions, for each
preorder of the other boxes, form one cell of a partition of the worlds (every other world
is a cell of its own), so the average of a box's row over its cell, recorded at every sweep,
is an unbiased estimate of the row of the marginals (the tower rule); ``F`` only trades the
size of the sum against how much spread it removes.

The memo is an open-addressing hash table in a preallocated array (one :func:`workspace`
per chain, emptied from call to call by a generation stamp): a key is two masks, ``(A, -1)``
for ``G`` (down-sets inside ``A``), ``(S, -2)`` for ``H`` (up-sets inside ``S``) and
``(S, A)`` for the joint sum ``F``. Each stored state is a slot with, per box, the weight of
the insertions holding it and, last, their total weight. The recursion passes four arrays
only (masks, factors, table, slots): numba counts references to every array argument of
every call, which dominated the time with a dozen separate arrays. A sum that needs more slots than the
workspace has is abandoned (:func:`insertion_row` returns ``False``); whether that happens
depends only on the other boxes' preorder, so it defines cells too.
"""

from __future__ import annotations

import numpy as np
from numba import njit

#: A bit mask of boxes, or an index, as numba sees it (``int64``).
Mask = int | np.int64

_EMPTY = np.int64(-1)
_ROW_TAG = np.int64(-1)
_COLUMN_TAG = np.int64(-2)
_DE_BRUIJN = np.uint64(0x03F79D71B4CB0A89)
_DE_BRUIJN_INDEX = np.array(
    [
        0, 1, 48, 2, 57, 49, 28, 3, 61, 58, 50, 42, 38, 29, 17, 4,
        62, 55, 59, 36, 53, 51, 43, 22, 45, 39, 33, 30, 24, 18, 12, 5,
        63, 47, 56, 27, 60, 41, 37, 16, 54, 35, 52, 21, 44, 32, 23, 11,
        46, 26, 40, 15, 34, 20, 31, 10, 25, 14, 19, 9, 13, 8, 7, 6,
    ],
    dtype=np.int64,
)  # fmt: skip


def workspace(n: int, slots: int = 2048) -> tuple[np.ndarray, ...]:
    """Arrays for one box's sums: ``(masks, factors, table, state, store)``.

    ``masks``: successors, predecessors, closures and co-closures of the other boxes;
    ``factors``: ``p`` and ``1 - p`` of the box's row and column; ``table``: hash entries
    ``(key, key, slot, generation)``, twice ``slots``; ``state``: the generation and the slots
    used by the last sum; ``store``: ``slots`` states (per box held, then the total)."""
    return (
        np.zeros((4, n), dtype=np.int64),
        np.zeros((4, n)),
        np.zeros((2 * slots, 4), dtype=np.int64),
        np.zeros(2, dtype=np.int64),
        np.zeros((slots, n + 1)),
    )


def chain_workspaces(chains: int, n: int, slots: int = 2048) -> tuple[np.ndarray, ...]:
    """One :func:`workspace` per chain, plus a row, each array with a leading chain axis."""
    one = (*workspace(n, slots), np.zeros(n))
    return tuple(np.repeat(array[None], chains, axis=0) for array in one)


@njit(cache=True, nogil=True, inline="always")
def _lowest(mask: Mask) -> Mask:
    """Index of the lowest set bit of a non-zero mask."""
    low = np.uint64(mask & -mask)
    return int(_DE_BRUIJN_INDEX[np.int64((low * _DE_BRUIJN) >> np.uint64(58))])


@njit(cache=True, nogil=True, inline="always")
def _count(mask: Mask) -> Mask:
    """Number of set bits."""
    v = np.uint64(mask)
    v = v - ((v >> np.uint64(1)) & np.uint64(0x5555555555555555))
    v = (v & np.uint64(0x3333333333333333)) + ((v >> np.uint64(2)) & np.uint64(0x3333333333333333))
    v = (v + (v >> np.uint64(4))) & np.uint64(0x0F0F0F0F0F0F0F0F)
    return int((v * np.uint64(0x0101010101010101)) >> np.uint64(56))


@njit(cache=True, nogil=True, inline="always")
def _product(factors: np.ndarray, which: int, mask: Mask) -> float:
    result = 1.0
    while mask:
        result *= factors[which, _lowest(mask)]
        mask &= mask - 1
    return result


@njit(cache=True, nogil=True, inline="always")
def _mix(store: np.ndarray, slot: Mask, first: Mask, first_scale: float, second: Mask, second_scale: float) -> None:
    """``store[slot] = first_scale * store[first] + second_scale * store[second]`` (totals too)."""
    for y in range(store.shape[1]):
        store[slot, y] = first_scale * store[first, y] + second_scale * store[second, y]


@njit(cache=True, nogil=True, inline="always")
def _find(table: np.ndarray, generation: Mask, first: Mask, second: Mask) -> Mask:
    """The entry of key ``(first, second)``: its own, or the empty one where it would go."""
    mask = table.shape[0] - 1
    h = np.uint64(first) * np.uint64(0x9E3779B97F4A7C15) ^ np.uint64(second) * np.uint64(0xC2B2AE3D27D4EB4F)
    entry = np.int64((h ^ (h >> np.uint64(29))) & np.uint64(mask))
    while table[entry, 3] == generation:
        if table[entry, 0] == first and table[entry, 1] == second:
            return entry
        entry = (entry + 1) & mask
    return entry


@njit(cache=True, nogil=True, inline="always")
def _new_slot(state: np.ndarray, store: np.ndarray) -> Mask:
    """A fresh slot, or -1 when the workspace is full."""
    slot = int(state[1])
    if slot >= store.shape[0]:
        return _EMPTY
    state[1] = slot + 1
    return slot


@njit(cache=True, nogil=True, inline="always")
def _store(table: np.ndarray, state: np.ndarray, first: Mask, second: Mask, slot: Mask) -> None:
    entry = _find(table, state[0], first, second)  # found again: the recursion may have filled the old one
    table[entry, 0] = first
    table[entry, 1] = second
    table[entry, 2] = slot
    table[entry, 3] = state[0]


@njit(cache=True, nogil=True)
def _extreme(mask: Mask, masks: np.ndarray, later: int) -> Mask:
    """A box of ``mask`` with nothing of ``mask`` strictly after it, the most boxes before it
    (``later`` 0: a sink, after = supported; 1: a source)."""
    earlier = 1 - later
    best: Mask = _EMPTY
    reach: Mask = np.int64(-1)
    left = mask
    while left:
        y = _lowest(left)
        left &= left - 1
        if masks[later, y] & mask & ~(masks[0, y] & masks[1, y]) == 0:
            before = _count(masks[earlier, y] & mask)
            if before > reach:
                best = y
                reach = before
    return best


@njit(cache=True, nogil=True)
def _component(mask: Mask, masks: np.ndarray) -> Mask:
    """The comparability component of ``mask``'s lowest box."""
    component = mask & -mask
    frontier = component
    while frontier:
        reached = np.int64(0)
        while frontier:
            y = _lowest(frontier)
            frontier &= frontier - 1
            reached |= (masks[0, y] | masks[1, y]) & mask
        frontier = reached & ~component
        component |= frontier
    return component


@njit(cache=True, nogil=True)
def _side(
    mask: Mask,
    side: int,
    masks: np.ndarray,
    factors: np.ndarray,
    table: np.ndarray,
    state: np.ndarray,
    store: np.ndarray,
) -> Mask:
    """The slot of the sum over one side alone (-1: out of slots): ``side`` 0 is ``G``, the
    down-sets inside ``mask`` (the boxes the box supports, with the weight holding each box),
    1 is ``H``, the up-sets inside ``mask`` (the boxes supporting it, total weight only)."""
    if mask == 0:
        return np.int64(0)
    tag = _ROW_TAG if side == 0 else _COLUMN_TAG
    entry = _find(table, state[0], mask, tag)
    if table[entry, 3] == state[0]:
        return int(table[entry, 2])
    n = masks.shape[1]
    part = _component(mask, masks)
    if part != mask:
        first = _side(part, side, masks, factors, table, state, store)
        if first < 0:
            return _EMPTY
        second = _side(mask & ~part, side, masks, factors, table, state, store)
        if second < 0:
            return _EMPTY
        slot = _new_slot(state, store)
        if slot < 0:
            return _EMPTY
        if side == 0:
            _mix(store, slot, first, store[second, n], second, store[first, n])
        store[slot, n] = store[first, n] * store[second, n]
    else:
        y = _extreme(mask, masks, 1 - side)  # G: a source, H: a sink
        taken = masks[2 + side, y] & mask  # its closure (G) or co-closure (H) joins
        equivalent = taken & masks[3 - side, y]  # or it leaves with the boxes equivalent to it
        inside = _product(factors, 2 * side, taken)
        outside = _product(factors, 2 * side + 1, equivalent)
        with_y = _side(mask & ~taken, side, masks, factors, table, state, store)
        if with_y < 0:
            return _EMPTY
        without_y = _side(mask & ~equivalent, side, masks, factors, table, state, store)
        if without_y < 0:
            return _EMPTY
        slot = _new_slot(state, store)
        if slot < 0:
            return _EMPTY
        if side == 0:
            _mix(store, slot, with_y, inside, without_y, outside)
            bits = taken
            while bits:
                store[slot, _lowest(bits)] += inside * store[with_y, n]
                bits &= bits - 1
        store[slot, n] = inside * store[with_y, n] + outside * store[without_y, n]
    _store(table, state, mask, tag, slot)
    return slot


@njit(cache=True, nogil=True)
def _joint(
    candidates: Mask,
    allowed: Mask,
    root_allowed: Mask,
    masks: np.ndarray,
    factors: np.ndarray,
    table: np.ndarray,
    state: np.ndarray,
    store: np.ndarray,
) -> Mask:
    """``F``: the slot of the sum over the up-sets inside ``candidates`` and the down-sets inside
    ``allowed`` and the closure of every box of the up-set (boxes of ``root_allowed`` outside
    ``allowed`` counted absent)."""
    entry = _find(table, state[0], candidates, allowed)
    if table[entry, 3] == state[0]:
        return int(table[entry, 2])
    n = masks.shape[1]
    unconstrained = True
    left = candidates
    while left and allowed:
        if allowed & ~masks[2, _lowest(left)]:
            unconstrained = False
            break
        left &= left - 1
    if unconstrained:
        up = _side(candidates, 1, masks, factors, table, state, store)
        if up < 0:
            return _EMPTY
        down = _side(allowed, 0, masks, factors, table, state, store)
        if down < 0:
            return _EMPTY
        slot = _new_slot(state, store)
        if slot < 0:
            return _EMPTY
        _mix(store, slot, down, store[up, n] * _product(factors, 1, root_allowed & ~allowed), 0, 0.0)
    else:
        y = _extreme(candidates, masks, 0)
        taken = masks[3, y] & candidates
        equivalent = taken & masks[2, y]
        inside = _product(factors, 2, taken)
        outside = _product(factors, 3, equivalent)
        with_y = _joint(candidates & ~taken, allowed & masks[2, y], root_allowed, masks, factors, table, state, store)
        if with_y < 0:
            return _EMPTY
        without_y = _joint(candidates & ~equivalent, allowed, root_allowed, masks, factors, table, state, store)
        if without_y < 0:
            return _EMPTY
        slot = _new_slot(state, store)
        if slot < 0:
            return _EMPTY
        _mix(store, slot, with_y, inside, without_y, outside)
    _store(table, state, candidates, allowed, slot)
    return slot


@njit(cache=True, nogil=True)
def insertion_row(
    box: int,
    free: Mask,
    probabilities: np.ndarray,
    successors: np.ndarray,
    predecessors: np.ndarray,
    masks: np.ndarray,
    factors: np.ndarray,
    table: np.ndarray,
    state: np.ndarray,
    store: np.ndarray,
    row: np.ndarray,
) -> bool:
    """``P(box supports y | the world's cell)`` into ``row`` when the world's insertion of
    ``box`` lies inside ``free``; ``False`` (``row`` untouched) when it does not or the sum
    outgrows the workspace.

    ``successors``/``predecessors``: the chain state (bit masks, ``box``'s own bits ignored);
    the other arrays: one :func:`workspace`.
    """
    n = probabilities.shape[0]
    bit = np.int64(1) << box
    free &= ~bit
    if (successors[box] | predecessors[box]) & ~bit & ~free:
        return False
    for y in range(n):
        own = np.int64(1) << y
        masks[0, y] = successors[y] & ~bit & ~own
        masks[1, y] = predecessors[y] & ~bit & ~own
        masks[2, y] = masks[0, y] | own
        masks[3, y] = masks[1, y] | own
        factors[0, y] = probabilities[box, y]
        factors[1, y] = 1.0 - probabilities[box, y]
        factors[2, y] = probabilities[y, box]
        factors[3, y] = 1.0 - probabilities[y, box]
    candidates = np.int64(0)
    allowed = np.int64(0)
    left: Mask = free
    while left:
        lowest = _lowest(left)
        left &= left - 1
        if masks[3, lowest] & ~free == 0:
            candidates |= np.int64(1) << lowest
        if masks[2, lowest] & ~free == 0:
            allowed |= np.int64(1) << lowest
    state[0] += 1  # a new generation: every entry of the table is empty again
    state[1] = 1
    store[0] = 0.0
    store[0, n] = 1.0
    slot = _joint(candidates, allowed, allowed, masks, factors, table, state, store)
    if slot < 0 or not store[slot, n] > 0.0:
        return False
    for y in range(n):
        row[y] = store[slot, y] / store[slot, n]
    row[box] = 0.0
    return True
