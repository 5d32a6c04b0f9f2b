"""Compiled kernels of the sampling engine (see :mod:`unstack.reasoner.sampling`).

A chain's state is a preorder on boxes ``0..n-1`` (``n <= 63``) kept as two arrays of bit
masks: ``successors[i]`` (the boxes ``i`` supports) and ``predecessors[i]`` (the boxes that
support ``i``). One move re-inserts one box ``x``: new sets ``A`` of boxes that ``x``
supports and ``B`` of boxes that support ``x`` replace its relations, or the old ones stay.

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
"""

from __future__ import annotations

import numpy as np
from numba import njit

from unstack.reasoner._chain_arrays import BlockArrays, ChainArrays

_MULTIPLIER = np.uint64(0x2545F4914F6CDD1D)
_SHIFT_A = np.uint64(12)
_SHIFT_B = np.uint64(25)
_SHIFT_C = np.uint64(27)
_SHIFT_FLOAT = np.uint64(11)
_TO_UNIT = 1.0 / 9007199254740992.0  # 2**-53
_STRIDE = 5  # unstack.reasoner.block_gibbs.BLOCK_STRIDE: bit a * 5 + b of a block's table mask


@njit(cache=True, nogil=True)
def _uniform(rng: np.ndarray, chain: int) -> float:
    """A uniform number in ``[0, 1)`` from the chain's xorshift64* stream."""
    x = rng[chain]
    x ^= x >> _SHIFT_A
    x ^= x << _SHIFT_B
    x ^= x >> _SHIFT_C
    rng[chain] = x
    return float((x * _MULTIPLIER) >> _SHIFT_FLOAT) * _TO_UNIT


@njit(cache=True, nogil=True)
def _decide_side(
    x: int,
    order: np.ndarray,
    log_present: np.ndarray,
    log_absent: np.ndarray,
    probabilities: np.ndarray,
    forward: np.ndarray,
    backward: np.ndarray,
    other_side: np.int64,
    rng: np.ndarray,
    chain: int,
    replay: np.int64,
    replaying: bool,
) -> tuple[np.int64, float, float]:
    """Decide the boxes that ``x`` supports, given the boxes ``other_side`` that support it
    (0 when undecided).

    Called with the transposed probability tables and ``forward``/``backward`` swapped, the
    same walk decides the boxes that support ``x`` given those it supports. ``forward[k]``:
    the boxes ``k`` supports; ``backward[k]``: the boxes supporting ``k``. Returns
    ``(set, log proposal, log forced)``: the log probability of the free decisions and the log
    factors of the forced ones (their sum is the log target of this side of ``x``).
    """
    inside = np.int64(0)
    outside = np.int64(0)
    log_proposal = 0.0
    log_forced = 0.0
    for k in order:
        bit = np.int64(1) << k
        allowed = (other_side & ~bit & ~backward[k]) == 0
        if backward[k] & inside:
            inside |= bit
            log_forced += log_present[x, k]
        elif (not allowed) or (forward[k] & outside):
            outside |= bit
            log_forced += log_absent[x, k]
        else:
            member = (replay & bit) != 0 if replaying else _uniform(rng, chain) < probabilities[x, k]
            if member:
                inside |= bit
                log_proposal += log_present[x, k]
            else:
                outside |= bit
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
    replay_supported: np.int64,
    replay_supporters: np.int64,
    replaying: bool,
) -> tuple[np.int64, np.int64, float, float]:
    """Propose (or, with ``replaying``, re-trace) an insertion of ``x``.

    ``A`` (boxes ``x`` supports) is decided before ``B`` (boxes supporting ``x``), or after
    with ``supporters_first``. Returns ``(A, B, log proposal, log target)``. The relations
    of ``x`` itself in ``successors``/``predecessors`` are never read: every mask they meet
    excludes ``x``.
    """
    # the supporters of x are the boxes x supports in the transposed relation
    p_t, present_t, absent_t = probabilities.T, log_present.T, log_absent.T
    if supporters_first:
        supporters, log_q1, log_f1 = _decide_side(
            x,
            order,
            present_t,
            absent_t,
            p_t,
            predecessors,
            successors,
            np.int64(0),
            rng,
            chain,
            replay_supporters,
            replaying,
        )
        supported, log_q2, log_f2 = _decide_side(
            x,
            order,
            log_present,
            log_absent,
            probabilities,
            successors,
            predecessors,
            supporters,
            rng,
            chain,
            replay_supported,
            replaying,
        )
    else:
        supported, log_q1, log_f1 = _decide_side(
            x,
            order,
            log_present,
            log_absent,
            probabilities,
            successors,
            predecessors,
            np.int64(0),
            rng,
            chain,
            replay_supported,
            replaying,
        )
        supporters, log_q2, log_f2 = _decide_side(
            x,
            order,
            present_t,
            absent_t,
            p_t,
            predecessors,
            successors,
            supported,
            rng,
            chain,
            replay_supporters,
            replaying,
        )
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
    supported: np.int64,
    supporters: np.int64,
    log_proposal: float,
    log_target: float,
    supporters_first: bool,
) -> float:
    """``log(target / proposal)`` of an insertion under the even mixture of both phase orders.

    ``log_proposal``/``log_target`` come from the order that drew (or replayed) it; the other
    order is replayed here.
    """
    _, _, other_proposal, _ = _insertion(
        x,
        order,
        probabilities,
        log_present,
        log_absent,
        successors,
        predecessors,
        rng,
        chain,
        not supporters_first,
        supported,
        supporters,
        True,
    )
    if log_proposal >= other_proposal:
        mixture = log_proposal + np.log1p(np.exp(other_proposal - log_proposal))
    else:
        mixture = other_proposal + np.log1p(np.exp(log_proposal - other_proposal))
    return float(log_target - mixture)


@njit(cache=True, nogil=True)
def _set_relations(
    x: int, n: int, supported: np.int64, supporters: np.int64, successors: np.ndarray, predecessors: np.ndarray
) -> None:
    """Give box ``x`` the relations ``x -> supported`` and ``supporters -> x``."""
    bit = np.int64(1) << x
    successors[x] = supported
    predecessors[x] = supporters
    for k in range(n):
        if k == x:
            continue
        kbit = np.int64(1) << k
        if supported & kbit:
            predecessors[k] |= bit
        else:
            predecessors[k] &= ~bit
        if supporters & kbit:
            successors[k] |= bit
        else:
            successors[k] &= ~bit


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
) -> bool:
    """One ensemble move on the relations of box ``x``; True when the relations changed.

    With ``scatter`` the first proposal is taken whatever its weight (if not 0): used once
    to spread the chains' starting worlds, never while recording.

    Candidates: the current insertion and ``tries`` proposals; the next insertion is drawn
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
    old_supported = successors[x]
    old_supporters = predecessors[x]
    _, _, log_q, log_t = _insertion(
        x,
        walk,
        probabilities,
        log_present,
        log_absent,
        successors,
        predecessors,
        rng,
        chain,
        False,
        old_supported,
        old_supporters,
        True,
    )
    candidates_supported[0] = old_supported
    candidates_supporters[0] = old_supporters
    log_ratios[0] = _log_weight(
        x,
        walk,
        probabilities,
        log_present,
        log_absent,
        successors,
        predecessors,
        rng,
        chain,
        old_supported,
        old_supporters,
        log_q,
        log_t,
        False,
    )
    largest = log_ratios[0]
    for t in range(1, tries + 1):
        supporters_first = _uniform(rng, chain) < 0.5
        a, b, log_q, log_t = _insertion(
            x,
            walk,
            probabilities,
            log_present,
            log_absent,
            successors,
            predecessors,
            rng,
            chain,
            supporters_first,
            np.int64(0),
            np.int64(0),
            False,
        )
        candidates_supported[t] = a
        candidates_supporters[t] = b
        log_ratios[t] = _log_weight(
            x,
            walk,
            probabilities,
            log_present,
            log_absent,
            successors,
            predecessors,
            rng,
            chain,
            a,
            b,
            log_q,
            log_t,
            supporters_first,
        )
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
    _set_relations(x, n, candidates_supported[pick], candidates_supporters[pick], successors, predecessors)
    return True


@njit(cache=True, nogil=True)
def _pair_is_free(i: int, j: int, successors: np.ndarray, predecessors: np.ndarray) -> bool:
    """Whether both values of ``S_ij`` keep the world transitive, the other relations fixed.

    Dropping a present ``S_ij`` needs no ``k`` with ``i -> k -> j``; adding an absent one
    needs ``i`` to support everything ``j`` supports and ``j`` to be supported by everything
    supporting ``i``.
    """
    ibit = np.int64(1) << i
    jbit = np.int64(1) << j
    if successors[i] & jbit:
        return bool((successors[i] & predecessors[j] & ~ibit & ~jbit) == 0)
    return bool((successors[j] & ~ibit & ~successors[i]) == 0 and (predecessors[i] & ~jbit & ~predecessors[j]) == 0)


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
            if _uniform(rng, chain) < probabilities[i, j]:
                successors[i] |= np.int64(1) << j
                predecessors[j] |= np.int64(1) << i
            else:
                successors[i] &= ~(np.int64(1) << j)
                predecessors[j] &= ~(np.int64(1) << i)


@njit(cache=True, nogil=True)
def _block_update(
    members: np.ndarray,
    size: int,
    count: int,
    masks: np.ndarray,
    log_weights: np.ndarray,
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
    cache_key: np.ndarray,
    cache_sums: np.ndarray,
) -> None:
    """Redraw the relations inside one block from their exact conditional (block Gibbs).

    The relations across the block forbid or force relations inside it (see
    :mod:`unstack.reasoner.block_gibbs`); the block's preorders that respect them are weighed
    by ``log_weights`` and one is drawn. With ``record`` the conditional marginal of every
    pair inside the block is added to ``sums``. A block with no relation across draws from
    ``cumulative`` and records ``clean_marginals`` (no pass over its table). ``pair_table``:
    the table's masks as 0/1 floats, one row per preorder. ``cache_key`` /
    ``cache_sums``: the chain's last sums of a linked block (``(state, forbidden, forced)``,
    state 0 none, 1 the total, 2 also the pair sums; the 25 pair sums, the total, ``top``),
    reused while the relations across impose the same constraints.
    """
    inside = np.int64(0)
    for a in range(size):
        inside |= np.int64(1) << members[a]
    forbidden = np.int64(0)
    forced = np.int64(0)
    linked = False
    for a in range(size):
        u = members[a]
        if (predecessors[u] | successors[u]) & ~inside:
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
        # the sums depend only on (forbidden, forced), which change only when a relation
        # across the block does: the chain's last sums for the same constraints are reused
        # (the very same numbers, so the results do not change)
        known = cache_key[1] == forbidden and cache_key[2] == forced and cache_key[0] >= (2 if record else 1)
        if known:
            top = cache_sums[_STRIDE * _STRIDE + 1]
            total = cache_sums[_STRIDE * _STRIDE]
            pair_sums[:] = cache_sums[: _STRIDE * _STRIDE]
        else:
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
                    w = np.exp(log_weights[t] - top)
                    total += w
                    if record:
                        row = pair_table[t]
                        for k in range(_STRIDE * _STRIDE):  # vectorised: no branch on the bits
                            pair_sums[k] += w * row[k]
            cache_key[0] = 2 if record else 1
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
                target -= np.exp(log_weights[t] - top)
                if target < 0.0:
                    break
    for a in range(size):
        u = members[a]
        for b in range(size):
            if a == b:
                continue
            v = members[b]
            if pick & (np.int64(1) << (a * _STRIDE + b)):
                successors[u] |= np.int64(1) << v
                predecessors[v] |= np.int64(1) << u
            else:
                successors[u] &= ~(np.int64(1) << v)
                predecessors[v] &= ~(np.int64(1) << u)


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
            elif successors[i] & (np.int64(1) << j):
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
    cache_keys = np.zeros((blocks.sizes.shape[0], 3), dtype=np.int64)
    cache_sums = np.zeros((blocks.sizes.shape[0], _STRIDE * _STRIDE + 2))
    accepted = 0
    for _sweep in range(sweeps):
        _flip_pairs(probabilities, successors, predecessors, rng, chain)
        for _ in range(moves):
            x = schedule[cursors[chain]]
            cursors[chain] = (cursors[chain] + 1) % schedule.shape[0]
            if _reinsert(
                x,
                probabilities,
                log_present,
                log_absent,
                successors,
                predecessors,
                order,
                rng,
                chain,
                tries,
                candidates_supported,
                candidates_supporters,
                log_ratios,
                scatter,
            ):
                accepted += 1
        for k in range(blocks.sizes.shape[0]):
            _block_update(
                blocks.members[k],
                blocks.sizes[k],
                blocks.counts[k],
                blocks.masks[k],
                blocks.log_weights[k],
                blocks.cumulative[k],
                blocks.marginals[k],
                blocks.pairs[k],
                successors,
                predecessors,
                rng,
                chain,
                record,
                sums,
                pair_sums,
                cache_keys[k],
                cache_sums[k],
            )
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
    every chain's state (:class:`~unstack.reasoner._chain_arrays.ChainArrays`, ``(chains, n)``
    bit masks, updated in place; the conditionals of every recorded sweep of round ``r`` are
    added to ``chains.sums[:, r]``); ``blocks``: the blocks redrawn exactly after every sweep
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
