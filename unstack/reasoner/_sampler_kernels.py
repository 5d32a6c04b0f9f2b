"""Compiled kernels of the sampling engine, one family for every group size (see :mod:`unstack.reasoner.sampling`).

A chain's state is a preorder on boxes ``0..n-1`` kept as two relations of sets of boxes:
``successors[i]`` (the boxes ``i`` supports) and ``predecessors[i]`` (the boxes that support
``i``). One move re-inserts one box ``x``: new sets ``A`` of boxes that ``x`` supports and
``B`` of boxes that support ``x`` replace its relations, or the old ones stay.

The proposal walks the other boxes in an order drawn at random and decides each one in
turn, first all of ``A`` then all of ``B`` or the other way round (a coin decides). A box
is *forced* when an earlier decision and transitivity leave one value only (``A`` must be
closed under "supports", ``B`` under "is supported by", and every member of ``B`` must
support every other member of ``A``); every other box is *free* and joins with its own
probability ``p``. So the proposal is the target itself except at the forced boxes. Its
probability under the even mixture of both phase orders is computed by replaying the
candidate in the other order, and the move draws the next insertion among the current one
and ``tries`` proposals with weights ``target / proposal`` (an ensemble of independent
proposals, which keeps the target invariant). Any order of the boxes gives a consistent
result, and drawing the order before the move keeps detailed balance.

A sweep is a pass over the pairs and ``moves`` re-insertions (the next boxes in turn); after
each sweep every ordered pair adds its Rao-Blackwellised value: the
probability of ``S_ij = 1`` given every other relation of the state, which is ``p_ij``
when both values keep the world transitive and the current value when only one does.

The random numbers come from one xorshift64* stream per chain so that results do not
depend on how the chains are spread over threads.

Two layouts of a set, one code
------------------------------
In a group of up to 63 boxes a set of boxes is one 64-bit integer (``successors`` of a chain is
an ``(n,)`` array of bit masks); above, it is an array of ``words = ceil(n / 64)`` 64-bit words
(box ``k`` is bit ``k % 64`` of word ``k // 64``; ``successors`` is ``(n, words)``). The kernels
are written once, over a few set operations (:func:`_has`, :func:`_with`, :func:`_row_meets`,
:func:`_pair_is_free`, ...): each is a stub with one version per layout, and a
``numba.extending.overload`` picks the version from the types the kernel is compiled for, so
numba compiles every kernel once per layout -- plain ``int64`` arithmetic for one word, loops
over the words (direct 2-D indexing, no views) for word arrays.

A set in the kernels is an ``int64`` in both layouts: the bit mask itself, or, for word arrays,
the row of the chain's ``work`` array that holds its words (``work`` is the integer 0 for one
word). So no array is ever rebound in a hot loop. Measured while writing this (2 cores, numba
0.68): rebinding word arrays made numba count references at every step (sweeps of 80 boxes
2-3 times longer), and the overloads inlined in numba's IR (``inline="always"``) counted
references to every array passed in (the one-word record 6 times longer); compiled as
functions, LLVM inlines them with no counting.

Both layouts draw the same random numbers, so a group sampled in either gives the same states
and estimates (``tests/reasoner/test_wide.py``) -- except for blocks linked across
(:func:`_block_update`), which the word-array layout sums from precomputed linear weights.

Cost: every set operation of the word arrays touches ``words`` words, so a sweep costs about
``n ** 2 * words`` word operations against ``n ** 2`` for one word.
"""

from __future__ import annotations

import inspect
from collections.abc import Callable
from typing import Any

import numpy as np
from numba import njit, types
from numba.extending import overload

from unstack.reasoner._chain_arrays import BlockArrays, ChainArrays

_MULTIPLIER = np.uint64(0x2545F4914F6CDD1D)
_SHIFT_A = np.uint64(12)
_SHIFT_B = np.uint64(25)
_SHIFT_C = np.uint64(27)
_SHIFT_FLOAT = np.uint64(11)
_TO_UNIT = 1.0 / 9007199254740992.0  # 2**-53
_STRIDE = 5  # unstack.reasoner.block_gibbs.BLOCK_STRIDE: bit a * 5 + b of a block's table mask
#: Below this a linked block's sum of linear table weights is redone in scaled log space.
_SMALLEST_TOTAL = 1e-250
#: Rows of ``work`` (word arrays): 0-7 the re-insertion's sets (0-2 the replays in the other order,
#: 4-6 this order's; 3 and 7 never written: the empty set), 8 a block's boxes, then the candidates'
#: sets ``A`` (row ``_CANDIDATES + t``) and ``B`` (row ``_CANDIDATES + tries + 1 + t``).
_BLOCK_ROW = 8
_CANDIDATES = 9
_COMPILED_ONLY = "a set operation of the compiled kernels: numba compiles the version of the layout"


@njit(cache=True, nogil=True)
def _uniform(rng: np.ndarray, chain: int) -> float:
    """A uniform number in ``[0, 1)`` from the chain's xorshift64* stream."""
    x = rng[chain]
    x ^= x >> _SHIFT_A
    x ^= x << _SHIFT_B
    x ^= x >> _SHIFT_C
    rng[chain] = x
    return float((x * _MULTIPLIER) >> _SHIFT_FLOAT) * _TO_UNIT


# --- set operations ---------------------------------------------------------------------------
# Each: a stub (never called from Python), the version of each layout (``*_one_word``,
# ``*_words``) and a :func:`_by_layout` line naming the argument whose layout picks one from
# (one word: ``work`` an integer, a relation of rank 1). A set is an int64 (the mask, or the
# row of ``work``); ``relation[i]`` is the set of box ``i`` (an int64 of an ``(n,)`` array, or
# row ``i`` of an ``(n, words)`` array). The two versions take the same parameters, annotations
# included.


def _one_word(value: Any) -> bool:
    """Whether ``work`` or a relation (a numba type) is of the one-word layout: ``work`` an
    integer (no rows: a set is its own bit mask), a relation of rank 1."""
    return isinstance(value, types.Integer) or bool(value.ndim == 1)


def _by_layout(
    operation: Callable[..., Any], one_word: Callable[..., Any], words: Callable[..., Any], decided_by: str
) -> None:
    """Compile ``operation`` in a kernel as ``one_word`` or ``words``, by the layout of its
    argument ``decided_by`` (``work`` or a relation).

    numba calls the overload with the argument types and requires its signature to be the
    versions' own, so the overload takes theirs.
    """
    parameters = inspect.signature(one_word)
    position = list(parameters.parameters).index(decided_by)

    def layout(*argument_types: Any) -> Any:
        return one_word if _one_word(argument_types[position]) else words

    layout.__signature__ = parameters  # type: ignore[attr-defined]
    overload(operation)(layout)


def _work(successors: np.ndarray, tries: int) -> Any:
    """The rows that hold the sets of one chain's moves: a ``(_CANDIDATES + 2 * (tries + 1),
    words)`` array for word arrays; 0 for one word (nothing to pass, nothing to count)."""
    raise NotImplementedError(_COMPILED_ONLY)


def _work_one_word(successors: Any, tries: Any) -> Any:
    return np.int64(0)


def _work_words(successors: Any, tries: Any) -> Any:
    return np.zeros((_CANDIDATES + 2 * (tries + 1), successors.shape[1]), dtype=np.int64)


_by_layout(_work, _work_one_word, _work_words, "successors")


def _set(work: Any, row: int) -> int:
    """The set held in row ``row`` of ``work`` (word arrays); the empty set for one word."""
    raise NotImplementedError(_COMPILED_ONLY)


def _set_one_word(work: Any, row: Any) -> Any:
    return np.int64(0)


def _set_words(work: Any, row: Any) -> Any:
    return row


_by_layout(_set, _set_one_word, _set_words, "work")


def _emptied(work: Any, row: int) -> int:
    """The empty set, in row ``row`` of ``work`` (word arrays: cleared)."""
    raise NotImplementedError(_COMPILED_ONLY)


def _emptied_one_word(work: Any, row: Any) -> Any:
    return np.int64(0)


def _emptied_words(work: Any, row: Any) -> Any:
    for w in range(work.shape[1]):
        work[row, w] = 0
    return row


_by_layout(_emptied, _emptied_one_word, _emptied_words, "work")


def _copied(work: Any, row: int, relation: np.ndarray, x: int) -> int:
    """The set of box ``x``, copied into row ``row`` of ``work`` (word arrays)."""
    raise NotImplementedError(_COMPILED_ONLY)


def _copied_one_word(work: Any, row: Any, relation: Any, x: Any) -> Any:
    return relation[x]


def _copied_words(work: Any, row: Any, relation: Any, x: Any) -> Any:
    for w in range(work.shape[1]):
        work[row, w] = relation[x, w]
    return row


_by_layout(_copied, _copied_one_word, _copied_words, "work")


def _set_row(relation: np.ndarray, x: int, work: Any, members: int) -> None:
    """Make ``members`` the set of box ``x``."""
    raise NotImplementedError(_COMPILED_ONLY)


def _set_row_one_word(relation: Any, x: Any, work: Any, members: Any) -> Any:
    relation[x] = members


def _set_row_words(relation: Any, x: Any, work: Any, members: Any) -> Any:
    for w in range(work.shape[1]):
        relation[x, w] = work[members, w]


_by_layout(_set_row, _set_row_one_word, _set_row_words, "work")


def _is_empty(work: Any, members: int) -> bool:
    """Whether ``members`` is empty."""
    raise NotImplementedError(_COMPILED_ONLY)


def _is_empty_one_word(work: Any, members: Any) -> Any:
    return members == 0


def _is_empty_words(work: Any, members: Any) -> Any:
    for w in range(work.shape[1]):  # noqa: SIM110 (a plain loop in numba, no generator)
        if work[members, w] != 0:
            return False
    return True


_by_layout(_is_empty, _is_empty_one_word, _is_empty_words, "work")


def _has(work: Any, members: int, k: int) -> bool:
    """Whether box ``k`` is in ``members``."""
    raise NotImplementedError(_COMPILED_ONLY)


def _has_one_word(work: Any, members: Any, k: Any) -> Any:
    return (members & (np.int64(1) << k)) != 0


def _has_words(work: Any, members: Any, k: Any) -> Any:
    return ((work[members, k >> 6] >> (k & 63)) & 1) != 0


_by_layout(_has, _has_one_word, _has_words, "work")


def _with(work: Any, members: int, k: int) -> int:
    """``members`` with box ``k`` added (word arrays: in place)."""
    raise NotImplementedError(_COMPILED_ONLY)


def _with_one_word(work: Any, members: Any, k: Any) -> Any:
    return members | (np.int64(1) << k)


def _with_words(work: Any, members: Any, k: Any) -> Any:
    work[members, k >> 6] |= np.int64(1) << (k & 63)
    return members


_by_layout(_with, _with_one_word, _with_words, "work")


def _row_meets(work: Any, relation: np.ndarray, k: int, members: int) -> bool:
    """Whether the set of box ``k`` and ``members`` share a box."""
    raise NotImplementedError(_COMPILED_ONLY)


def _row_meets_one_word(work: Any, relation: Any, k: Any, members: Any) -> Any:
    return (relation[k] & members) != 0


def _row_meets_words(work: Any, relation: Any, k: Any, members: Any) -> Any:
    for w in range(work.shape[1]):  # noqa: SIM110 (a plain loop in numba, no generator)
        if relation[k, w] & work[members, w]:
            return True
    return False


_by_layout(_row_meets, _row_meets_one_word, _row_meets_words, "work")


def _within_row(work: Any, members: int, relation: np.ndarray, k: int, constrained: bool) -> bool:
    """Whether every box of ``members`` but ``k`` is in the set of box ``k`` (``constrained``:
    ``members`` is not empty; the word arrays skip their loop without it)."""
    raise NotImplementedError(_COMPILED_ONLY)


def _within_row_one_word(work: Any, members: Any, relation: Any, k: Any, constrained: Any) -> Any:
    return (members & ~(np.int64(1) << k) & ~relation[k]) == 0


def _within_row_words(work: Any, members: Any, relation: Any, k: Any, constrained: Any) -> Any:
    if not constrained:
        return True
    word = k >> 6
    bit = np.int64(1) << (k & 63)
    for w in range(work.shape[1]):
        rest = work[members, w] & ~relation[k, w]
        if w == word:
            rest &= ~bit
        if rest != 0:
            return False
    return True


_by_layout(_within_row, _within_row_one_word, _within_row_words, "work")


def _linked(work: Any, successors: np.ndarray, predecessors: np.ndarray, u: int, members: int) -> bool:
    """Whether box ``u`` has a relation to a box outside ``members``."""
    raise NotImplementedError(_COMPILED_ONLY)


def _linked_one_word(work: Any, successors: Any, predecessors: Any, u: Any, members: Any) -> Any:
    return ((predecessors[u] | successors[u]) & ~members) != 0


def _linked_words(work: Any, successors: Any, predecessors: Any, u: Any, members: Any) -> Any:
    for w in range(work.shape[1]):  # noqa: SIM110 (a plain loop in numba, no generator)
        if (predecessors[u, w] | successors[u, w]) & ~work[members, w]:
            return True
    return False


_by_layout(_linked, _linked_one_word, _linked_words, "work")


def _constraints(
    work: Any, successors: np.ndarray, predecessors: np.ndarray, members: np.ndarray, size: int, inside: int
) -> tuple[int, int]:
    """What the relations across make of the pairs of a block (boxes ``members[:size]``, the set
    ``inside``): ``(forbidden, forced)`` as table masks (bit ``a * 5 + b`` for the pair ``a, b``).

    ``S_uv`` is forced by ``u -> w -> v`` for an outside ``w``, and forbidden by a supporter
    of ``u`` that does not support ``v`` or a box ``v`` supports that ``u`` does not.
    """
    raise NotImplementedError(_COMPILED_ONLY)


def _constraints_one_word(work: Any, successors: Any, predecessors: Any, members: Any, size: Any, inside: Any) -> Any:
    forbidden = np.int64(0)
    forced = np.int64(0)
    for a in range(size):
        u = members[a]
        in_u = predecessors[u] & ~inside
        out_u = successors[u] & ~inside
        for b in range(size):
            if a == b:
                continue
            v = members[b]
            in_v = predecessors[v] & ~inside
            out_v = successors[v] & ~inside
            bit = np.int64(1) << (a * _STRIDE + b)
            if out_u & in_v:
                forced |= bit
            elif (in_u & ~in_v) or (out_v & ~out_u):
                forbidden |= bit
    return forbidden, forced


def _constraints_words(work: Any, successors: Any, predecessors: Any, members: Any, size: Any, inside: Any) -> Any:
    forbidden = np.int64(0)
    forced = np.int64(0)
    for a in range(size):
        u = members[a]
        for b in range(size):
            if a == b:
                continue
            v = members[b]
            bit = np.int64(1) << (a * _STRIDE + b)
            through = False  # u -> w -> v for an outside w
            excluded = False  # In(u) not in In(v), or Out(v) not in Out(u)
            for w in range(work.shape[1]):
                outer = ~work[inside, w]
                if successors[u, w] & predecessors[v, w] & outer:
                    through = True
                if (predecessors[u, w] & ~predecessors[v, w] & outer) or (successors[v, w] & ~successors[u, w] & outer):
                    excluded = True
            if through:
                forced |= bit
            elif excluded:
                forbidden |= bit
    return forbidden, forced


_by_layout(_constraints, _constraints_one_word, _constraints_words, "work")


def _in_row(relation: np.ndarray, i: int, j: int) -> bool:
    """Whether box ``j`` is in the set of box ``i``."""
    raise NotImplementedError(_COMPILED_ONLY)


def _in_row_one_word(relation: Any, i: Any, j: Any) -> Any:
    return (relation[i] & (np.int64(1) << j)) != 0


def _in_row_words(relation: Any, i: Any, j: Any) -> Any:
    return ((relation[i, j >> 6] >> (j & 63)) & 1) != 0


_by_layout(_in_row, _in_row_one_word, _in_row_words, "relation")


def _put(relation: np.ndarray, i: int, j: int, member: bool) -> None:
    """Add box ``j`` to the set of box ``i`` (``member``) or remove it."""
    raise NotImplementedError(_COMPILED_ONLY)


def _put_one_word(relation: Any, i: Any, j: Any, member: Any) -> Any:
    if member:
        relation[i] |= np.int64(1) << j
    else:
        relation[i] &= ~(np.int64(1) << j)


def _put_words(relation: Any, i: Any, j: Any, member: Any) -> Any:
    bit = np.int64(1) << (j & 63)
    if member:
        relation[i, j >> 6] |= bit
    else:
        relation[i, j >> 6] &= ~bit


_by_layout(_put, _put_one_word, _put_words, "relation")


def _pair_is_free(i: int, j: int, successors: np.ndarray, predecessors: np.ndarray) -> bool:
    """Whether both values of ``S_ij`` keep the world transitive, the other relations fixed.

    Dropping a present ``S_ij`` needs no ``k`` with ``i -> k -> j``; adding an absent one
    needs ``i`` to support everything ``j`` supports and ``j`` to be supported by everything
    supporting ``i``. (The innermost test of the pair pass and the record, so a set operation
    of its own: written over the others, LLVM did not inline it there and the word arrays' pair
    pass and record took 4-9 times longer.)
    """
    raise NotImplementedError(_COMPILED_ONLY)


def _pair_is_free_one_word(i: Any, j: Any, successors: Any, predecessors: Any) -> Any:
    ibit = np.int64(1) << i
    jbit = np.int64(1) << j
    if successors[i] & jbit:
        return bool((successors[i] & predecessors[j] & ~ibit & ~jbit) == 0)
    return bool((successors[j] & ~ibit & ~successors[i]) == 0 and (predecessors[i] & ~jbit & ~predecessors[j]) == 0)


def _pair_is_free_words(i: Any, j: Any, successors: Any, predecessors: Any) -> Any:
    words = successors.shape[1]
    i_word, i_bit = i >> 6, np.int64(1) << (i & 63)
    j_word, j_bit = j >> 6, np.int64(1) << (j & 63)
    if successors[i, j_word] & j_bit:
        for w in range(words):
            between = successors[i, w] & predecessors[j, w]
            if w == i_word:
                between &= ~i_bit
            if w == j_word:
                between &= ~j_bit
            if between != 0:
                return False
        return True
    for w in range(words):
        missing = successors[j, w] & ~successors[i, w]
        if w == i_word:
            missing &= ~i_bit
        if missing != 0:
            return False
        missing = predecessors[i, w] & ~predecessors[j, w]
        if w == j_word:
            missing &= ~j_bit
        if missing != 0:
            return False
    return True


_by_layout(_pair_is_free, _pair_is_free_one_word, _pair_is_free_words, "successors")


# --- the kernels, written once -------------------------------------------------------------


@njit(cache=True, nogil=True)
def _decide_side(
    x: int,
    order: np.ndarray,
    log_present: np.ndarray,
    log_absent: np.ndarray,
    probabilities: np.ndarray,
    forward: np.ndarray,
    backward: np.ndarray,
    other_side: int,
    rng: np.ndarray,
    chain: int,
    replay: int,
    replaying: bool,
    work: Any,
    inside_row: int,
    outside_row: int,
) -> tuple[int, float, float]:
    """Decide the boxes that ``x`` supports, given the boxes ``other_side`` that support it
    (empty when undecided).

    Called with the transposed probability tables and ``forward``/``backward`` swapped, the
    same walk decides the boxes that support ``x`` given those it supports. ``forward[k]``:
    the boxes ``k`` supports; ``backward[k]``: the boxes supporting ``k``; the decided sets are
    kept in rows ``inside_row`` and ``outside_row`` of ``work`` (word arrays). Returns ``(set,
    log proposal, log forced)``: the log probability of the free decisions and the log factors
    of the forced ones (their sum is the log target of this side of ``x``).
    """
    inside = _emptied(work, inside_row)
    outside = _emptied(work, outside_row)
    constrained = not _is_empty(work, other_side)  # the other side is decided and not empty
    log_proposal = 0.0
    log_forced = 0.0
    for k in order:
        if _row_meets(work, backward, k, inside):
            inside = _with(work, inside, k)
            log_forced += log_present[x, k]
        elif not _within_row(work, other_side, backward, k, constrained) or _row_meets(work, forward, k, outside):
            outside = _with(work, outside, k)
            log_forced += log_absent[x, k]
        else:
            member = _has(work, replay, k) if replaying else _uniform(rng, chain) < probabilities[x, k]
            if member:
                inside = _with(work, inside, k)
                log_proposal += log_present[x, k]
            else:
                outside = _with(work, outside, k)
                log_proposal += log_absent[x, k]
    return inside, log_proposal, log_forced


@njit(cache=True, nogil=True)
def _insertion(
    x: int,
    order: np.ndarray,
    probabilities: np.ndarray,
    log_present: np.ndarray,
    log_absent: np.ndarray,
    successors: np.ndarray,
    predecessors: np.ndarray,
    rng: np.ndarray,
    chain: int,
    supporters_first: bool,
    replay_supported: int,
    replay_supporters: int,
    replaying: bool,
    work: Any,
    supported_row: int,
    supporters_row: int,
    outside_row: int,
    empty: int,
) -> tuple[int, int, float, float]:
    """Propose (or, with ``replaying``, re-trace) an insertion of ``x``.

    ``A`` (boxes ``x`` supports) is decided before ``B`` (boxes supporting ``x``), or after
    with ``supporters_first``; they are kept in rows ``supported_row`` and ``supporters_row`` of
    ``work`` (``outside_row``: scratch; ``empty``: the empty set). Returns ``(A, B, log
    proposal, log target)``. The relations of ``x`` itself in ``successors``/``predecessors``
    are never read: every set they meet excludes ``x``.
    """
    # the supporters of x are the boxes x supports in the transposed relation
    p_t, present_t, absent_t = probabilities.T, log_present.T, log_absent.T
    if supporters_first:
        supporters, log_q1, log_f1 = _decide_side(
            x, order, present_t, absent_t, p_t, predecessors, successors, empty, rng, chain,
            replay_supporters, replaying, work, supporters_row, outside_row,
        )  # fmt: skip
        supported, log_q2, log_f2 = _decide_side(
            x, order, log_present, log_absent, probabilities, successors, predecessors, supporters, rng, chain,
            replay_supported, replaying, work, supported_row, outside_row,
        )  # fmt: skip
    else:
        supported, log_q1, log_f1 = _decide_side(
            x, order, log_present, log_absent, probabilities, successors, predecessors, empty, rng, chain,
            replay_supported, replaying, work, supported_row, outside_row,
        )  # fmt: skip
        supporters, log_q2, log_f2 = _decide_side(
            x, order, present_t, absent_t, p_t, predecessors, successors, supported, rng, chain,
            replay_supporters, replaying, work, supporters_row, outside_row,
        )  # fmt: skip
    log_proposal = log_q1 + log_q2
    return supported, supporters, log_proposal, log_proposal + log_f1 + log_f2


@njit(cache=True, nogil=True)
def _log_weight(
    x: int,
    order: np.ndarray,
    probabilities: np.ndarray,
    log_present: np.ndarray,
    log_absent: np.ndarray,
    successors: np.ndarray,
    predecessors: np.ndarray,
    rng: np.ndarray,
    chain: int,
    supported: int,
    supporters: int,
    log_proposal: float,
    log_target: float,
    supporters_first: bool,
    work: Any,
) -> float:
    """``log(target / proposal)`` of an insertion under the even mixture of both phase orders.

    ``log_proposal``/``log_target`` come from the order that drew (or replayed) it; the other
    order is replayed here (in rows 0-3 of ``work``).
    """
    _, _, other_proposal, _ = _insertion(
        x, order, probabilities, log_present, log_absent, successors, predecessors, rng, chain,
        not supporters_first, supported, supporters, True, work, 0, 1, 2, _set(work, 3),
    )  # fmt: skip
    if log_proposal >= other_proposal:
        mixture = log_proposal + np.log1p(np.exp(other_proposal - log_proposal))
    else:
        mixture = other_proposal + np.log1p(np.exp(log_proposal - other_proposal))
    return float(log_target - mixture)


@njit(cache=True, nogil=True)
def _set_relations(
    x: int,
    n: int,
    supported: int,
    supporters: int,
    successors: np.ndarray,
    predecessors: np.ndarray,
    work: Any,
) -> None:
    """Give box ``x`` the relations ``x -> supported`` and ``supporters -> x``."""
    _set_row(successors, x, work, supported)
    _set_row(predecessors, x, work, supporters)
    for k in range(n):
        if k == x:
            continue
        _put(predecessors, k, x, _has(work, supported, k))
        _put(successors, k, x, _has(work, supporters, k))


@njit(cache=True, nogil=True)
def _reinsert(
    x: int,
    probabilities: np.ndarray,
    log_present: np.ndarray,
    log_absent: np.ndarray,
    successors: np.ndarray,
    predecessors: np.ndarray,
    order: np.ndarray,
    rng: np.ndarray,
    chain: int,
    tries: int,
    candidates_supported: np.ndarray,
    candidates_supporters: np.ndarray,
    log_ratios: np.ndarray,
    scatter: bool,
    work: Any,
) -> bool:
    """One ensemble move on the relations of box ``x``; True when the relations changed.

    With ``scatter`` the first proposal is taken whatever its weight (if not 0): used once
    to spread the chains' starting worlds, never while recording.

    Candidates: the current insertion and ``tries`` proposals (their sets in
    ``candidates_supported`` / ``candidates_supporters``); the next insertion is drawn
    among them with weights ``target / proposal`` (Barker's rule over an ensemble of
    independent proposals keeps the target invariant).
    """
    n = probabilities.shape[0]
    # the other boxes from a random start, in a random direction (any order drawn
    # independently of the state keeps detailed balance)
    first = int(_uniform(rng, chain) * n)
    step = 1 if _uniform(rng, chain) < 0.5 else n - 1
    m = 0
    k = first
    for _ in range(n):
        if k != x:
            order[m] = k
            m += 1
        k = (k + step) % n
    walk = order[:m]
    empty = _set(work, 7)
    old_supported = _copied(work, _CANDIDATES, successors, x)
    old_supporters = _copied(work, _CANDIDATES + tries + 1, predecessors, x)
    _, _, log_q, log_t = _insertion(
        x, walk, probabilities, log_present, log_absent, successors, predecessors, rng, chain, False,
        old_supported, old_supporters, True, work, 4, 5, 6, empty,
    )  # fmt: skip
    candidates_supported[0] = old_supported
    candidates_supporters[0] = old_supporters
    log_ratios[0] = _log_weight(
        x, walk, probabilities, log_present, log_absent, successors, predecessors, rng, chain,
        old_supported, old_supporters, log_q, log_t, False, work,
    )  # fmt: skip
    largest = log_ratios[0]
    for t in range(1, tries + 1):
        supporters_first = _uniform(rng, chain) < 0.5
        a, b, log_q, log_t = _insertion(
            x, walk, probabilities, log_present, log_absent, successors, predecessors, rng, chain,
            supporters_first, empty, empty, False, work, _CANDIDATES + t, _CANDIDATES + tries + 1 + t, 6, empty,
        )  # fmt: skip
        candidates_supported[t] = a
        candidates_supporters[t] = b
        log_ratios[t] = _log_weight(
            x, walk, probabilities, log_present, log_absent, successors, predecessors, rng, chain,
            a, b, log_q, log_t, supporters_first, work,
        )  # fmt: skip
        if log_ratios[t] > largest:
            largest = log_ratios[t]
    total = 0.0
    for t in range(tries + 1):
        log_ratios[t] = np.exp(log_ratios[t] - largest)
        total += log_ratios[t]
    pick = tries
    if scatter:
        pick = 1 if log_ratios[1] > 0.0 else 0  # any proposal of non-zero weight
    else:
        u = _uniform(rng, chain) * total
        for t in range(tries + 1):
            u -= log_ratios[t]
            if u < 0.0:
                pick = t
                break
    if pick == 0:
        return False
    _set_relations(x, n, candidates_supported[pick], candidates_supporters[pick], successors, predecessors, work)
    return True


@njit(cache=True, nogil=True)
def _flip_pairs(
    probabilities: np.ndarray, successors: np.ndarray, predecessors: np.ndarray, rng: np.ndarray, chain: int
) -> None:
    """One Gibbs pass over the ordered pairs: a pair whose both values keep the world
    transitive is redrawn with its own probability; the others keep their value.

    Local moves like these keep the chain moving where every re-insertion proposal is far
    less probable than the current state (dense matrices of 20 boxes and more).
    """
    n = probabilities.shape[0]
    for i in range(n):
        for j in range(n):
            if i == j or not _pair_is_free(i, j, successors, predecessors):
                continue
            member = _uniform(rng, chain) < probabilities[i, j]
            _put(successors, i, j, member)
            _put(predecessors, j, i, member)


@njit(cache=True, nogil=True)
def _block_update(
    members: np.ndarray,
    size: int,
    count: int,
    masks: np.ndarray,
    log_weights: np.ndarray,
    linear_weights: np.ndarray,
    cumulative: np.ndarray,
    clean_marginals: np.ndarray,
    pair_table: np.ndarray,
    successors: np.ndarray,
    predecessors: np.ndarray,
    rng: np.ndarray,
    chain: int,
    record: bool,
    sums: np.ndarray,
    pair_sums: np.ndarray,
    work: Any,
    cache_key: np.ndarray,
    cache_sums: np.ndarray,
) -> None:
    """Redraw the relations inside one block from their exact conditional (block Gibbs).

    The relations across the block forbid or force relations inside it (see
    :mod:`unstack.reasoner.block_gibbs`); the block's preorders that respect them are weighed
    by ``log_weights`` and one is drawn. With ``record`` the conditional marginal of every
    pair inside the block is added to ``sums``. A block with no relation across draws from
    ``cumulative`` and records ``clean_marginals`` (no pass over its table). ``pair_table``:
    the table's masks as 0/1 floats, one row per preorder (a block's table masks are one word
    in both layouts). The block's set of boxes is kept in row 8 of ``work`` (word arrays).

    A linked block's weights: the one-word layout sums ``exp(log_weights - top)`` (``top`` the
    largest allowed); the word-array layout sums the table's ``linear_weights``
    (``exp(log_weights)``, computed once) -- 5 to 10 times faster on 150 boxes linked by 1e-2,
    where most blocks are linked -- unless those allowed all underflow, and then as the one-word
    layout does. So the two layouts can differ in the last bits of a cumulative sum; each keeps
    its own numbers. ``cache_key`` / ``cache_sums``: the chain's last sums of a linked block
    (``(state, forbidden, forced)``, state 0 none, 1 the total, 2 also the pair sums; the 25
    pair sums, the total, ``top``), reused while the relations across impose the same
    constraints (the very same numbers, so the results do not change).
    """
    linear = successors.ndim == 2  # a constant of the compiled layout: the word arrays
    inside = _emptied(work, _BLOCK_ROW)
    for a in range(size):
        inside = _with(work, inside, members[a])
    linked = False
    for a in range(size):
        u = members[a]
        if _linked(work, successors, predecessors, u, inside):
            linked = True
    if not linked:
        target = _uniform(rng, chain) * cumulative[count - 1]
        low, high = 0, count - 1
        while low < high:
            middle = (low + high) // 2
            if cumulative[middle] > target:
                high = middle
            else:
                low = middle + 1
        pick = masks[low]
        if record:
            for a in range(size):
                for b in range(size):
                    if a != b:
                        sums[members[a], members[b]] += clean_marginals[a * _STRIDE + b]
    else:
        forbidden, forced = _constraints(work, successors, predecessors, members, size, inside)
        top = 0.0
        scaled = not linear
        known = cache_key[1] == forbidden and cache_key[2] == forced and cache_key[0] >= (2 if record else 1)
        if known:
            total = cache_sums[_STRIDE * _STRIDE]
            top = cache_sums[_STRIDE * _STRIDE + 1]
            pair_sums[:] = cache_sums[: _STRIDE * _STRIDE]
        while not known:
            if scaled:
                top = -np.inf
                for t in range(count):
                    m = masks[t]
                    if (m & forbidden) == 0 and (m & forced) == forced and log_weights[t] > top:
                        top = log_weights[t]
                if top == -np.inf:
                    return  # cannot happen from a consistent state of non-zero weight
            total = 0.0
            pair_sums[:] = 0.0
            for t in range(count):
                m = masks[t]
                if (m & forbidden) == 0 and (m & forced) == forced:
                    weight = np.exp(log_weights[t] - top) if scaled else linear_weights[t]
                    total += weight
                    if record:
                        row = pair_table[t]
                        for k in range(_STRIDE * _STRIDE):  # vectorised: no branch on the bits
                            pair_sums[k] += weight * row[k]
            if scaled or total > _SMALLEST_TOTAL:
                break
            scaled = True  # the linear weights allowed here all underflow
        if not known:
            cache_key[0] = 0 if scaled and linear else (2 if record else 1)
            cache_key[1] = forbidden
            cache_key[2] = forced
            cache_sums[: _STRIDE * _STRIDE] = pair_sums
            cache_sums[_STRIDE * _STRIDE] = total
            cache_sums[_STRIDE * _STRIDE + 1] = top
        if record:
            for a in range(size):
                for b in range(size):
                    if a != b:
                        sums[members[a], members[b]] += pair_sums[a * _STRIDE + b] / total
        target = _uniform(rng, chain) * total
        pick = np.int64(-1)
        for t in range(count):
            m = masks[t]
            if (m & forbidden) == 0 and (m & forced) == forced:
                pick = m
                target -= np.exp(log_weights[t] - top) if scaled else linear_weights[t]
                if target < 0.0:
                    break
    for a in range(size):
        u = members[a]
        for b in range(size):
            if a == b:
                continue
            v = members[b]
            member = (pick & (np.int64(1) << (a * _STRIDE + b))) != 0
            _put(successors, u, v, member)
            _put(predecessors, v, u, member)


@njit(cache=True, nogil=True)
def _add_conditionals(
    probabilities: np.ndarray,
    successors: np.ndarray,
    predecessors: np.ndarray,
    sums: np.ndarray,
    block_of: np.ndarray,
) -> None:
    """Add ``P(S_ij = 1 | every other relation)`` of the current state to ``sums``: ``p_ij``
    for a free pair, else its current value. Pairs inside a block are skipped (the block
    update adds their conditional given the relations across)."""
    n = probabilities.shape[0]
    for i in range(n):
        for j in range(n):
            if i == j or (block_of[i] >= 0 and block_of[i] == block_of[j]):
                continue
            if _pair_is_free(i, j, successors, predecessors):
                sums[i, j] += probabilities[i, j]
            elif _in_row(successors, i, j):
                sums[i, j] += 1.0


@njit(cache=True, nogil=True)
def _run_chain(
    chain: int,
    round_: int,
    probabilities: np.ndarray,
    log_present: np.ndarray,
    log_absent: np.ndarray,
    chains: ChainArrays,
    blocks: BlockArrays,
    sweeps: int,
    tries: int,
    record: bool,
    scatter: bool,
    moves: int,
    schedule: np.ndarray,
) -> int:
    """Run ``sweeps`` sweeps of one chain; add the estimates when ``record``.

    A sweep re-inserts ``moves`` boxes, the next ones of ``schedule`` (each box once, in
    order, unless some are visited more often) in turn from ``cursors[chain]`` (every box
    when ``moves == n`` and the schedule is every box once). The round's records go to
    ``chains.sums[chain, round_]``."""
    successors, predecessors, rng, cursors = (
        chains.successors[chain],
        chains.predecessors[chain],
        chains.rng,
        chains.cursors,
    )
    sums = chains.sums[chain, round_]
    n = probabilities.shape[0]
    pair_sums = np.zeros(_STRIDE * _STRIDE)
    order = np.empty(n, dtype=np.int64)
    candidates_supported = np.empty(tries + 1, dtype=np.int64)
    candidates_supporters = np.empty(tries + 1, dtype=np.int64)
    log_ratios = np.empty(tries + 1)
    work = _work(successors, tries)
    cache_keys = np.zeros((blocks.sizes.shape[0], 3), dtype=np.int64)
    cache_sums = np.zeros((blocks.sizes.shape[0], _STRIDE * _STRIDE + 2))
    accepted = 0
    for _sweep in range(sweeps):
        _flip_pairs(probabilities, successors, predecessors, rng, chain)
        for _ in range(moves):
            x = schedule[cursors[chain]]
            cursors[chain] = (cursors[chain] + 1) % schedule.shape[0]
            if _reinsert(
                x, probabilities, log_present, log_absent, successors, predecessors, order, rng, chain, tries,
                candidates_supported, candidates_supporters, log_ratios, scatter, work,
            ):  # fmt: skip
                accepted += 1
        for k in range(blocks.sizes.shape[0]):
            _block_update(
                blocks.members[k], blocks.sizes[k], blocks.counts[k], blocks.masks[k], blocks.log_weights[k],
                blocks.linear_weights[k], blocks.cumulative[k], blocks.marginals[k], blocks.pairs[k], successors,
                predecessors, rng, chain, record, sums, pair_sums, work, cache_keys[k], cache_sums[k],
            )  # fmt: skip
        if record:
            _add_conditionals(probabilities, successors, predecessors, sums, blocks.block_of)
    return accepted


@njit(cache=True, nogil=True)
def run_chains(
    first: int,
    last: int,
    probabilities: np.ndarray,
    log_present: np.ndarray,
    log_absent: np.ndarray,
    chains: ChainArrays,
    blocks: BlockArrays,
    sweeps: int,
    rounds: int,
    tries: int,
    record: bool,
    scatter: bool,
    moves: int,
    schedule: np.ndarray,
) -> None:
    """Advance chains ``first`` to ``last - 1`` by ``rounds`` times ``sweeps`` sweeps, one chain after
    the other.

    A plain ``nogil`` kernel: the sampler runs one range of chains per thread of its own call
    (:mod:`unstack.threads`), not numba's parallel loop, whose OpenMP workers spin while they
    wait (a 31-box plan took 1.4-2.1 s instead of 0.8-0.9 s beside a busy core).

    ``log_present``/``log_absent``: ``log p`` and ``log(1 - p)`` (``-inf`` at 0); ``chains``:
    every chain's state (:class:`~unstack.reasoner._chain_arrays.ChainArrays`: ``(chains, n)``
    one-word sets or ``(chains, n, words)`` word arrays -- numba compiles one version for each
    -- updated in place; the conditionals of every recorded sweep of round ``r`` are added to
    ``chains.sums[:, r]``); ``blocks``: the blocks redrawn exactly after every sweep
    (:class:`~unstack.reasoner._chain_arrays.BlockArrays`; no blocks: zero rows); ``rounds``
    rounds of ``sweeps`` sweeps each; ``scatter``: take every first proposal (to spread the
    starting worlds of the chains); a sweep re-inserts ``moves`` boxes, the next ones of
    ``schedule`` in turn from ``chains.cursors``.
    """
    for c in range(first, last):
        for r in range(rounds):
            chains.accepted[c] += _run_chain(
                c, r, probabilities, log_present, log_absent, chains, blocks, sweeps, tries, record, scatter, moves,
                schedule,
            )  # fmt: skip
