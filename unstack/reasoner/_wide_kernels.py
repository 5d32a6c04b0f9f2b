"""Compiled kernels of the sampling engine for groups of any size (see :mod:`unstack.reasoner.sampling`).

The moves, the Rao-Blackwellised record and the block updates are those of
:mod:`unstack.reasoner._sampler_kernels`, step for step and with the same random numbers;
only the sets differ. There a set of boxes is one 64-bit integer, which caps a group at 63
boxes; here it is an array of ``words = ceil(n / 64)`` 64-bit words (box ``k`` is bit
``k % 64`` of word ``k // 64``), so ``successors``/``predecessors`` of a chain are
``(n, words)`` arrays. A test runs both kernels on the same small groups and seeds and
requires identical states and sums; the sampler uses these for groups of 64 boxes and more.

Cost: every set operation touches ``words`` words, so a sweep costs about ``n ** 2 * words``
word operations against ``n ** 2`` for the one-word kernels.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from unstack.reasoner._chain_arrays import BlockArrays, ChainArrays
from unstack.reasoner._sampler_kernels import _STRIDE, _uniform

#: Below this a linked block's sum of table weights is redone in scaled log space.
_SMALLEST_TOTAL = 1e-250


@njit(cache=True, nogil=True, inline="always")
def _has(mask: np.ndarray, k: int) -> bool:
    """Whether box ``k`` is in the set ``mask``."""
    return bool(((mask[k >> 6] >> (k & 63)) & 1) != 0)


@njit(cache=True, nogil=True, inline="always")
def _put(mask: np.ndarray, k: int, member: bool) -> None:
    """Add box ``k`` to ``mask`` (``member``) or remove it."""
    bit = np.int64(1) << (k & 63)
    if member:
        mask[k >> 6] |= bit
    else:
        mask[k >> 6] &= ~bit


@njit(cache=True, nogil=True)
def _decide_side(
    x: int,
    order: np.ndarray,
    log_present: np.ndarray,
    log_absent: np.ndarray,
    probabilities: np.ndarray,
    forward: np.ndarray,
    backward: np.ndarray,
    other_side: np.ndarray,
    rng: np.ndarray,
    chain: int,
    replay: np.ndarray,
    replaying: bool,
    inside: np.ndarray,
    outside: np.ndarray,
) -> tuple[float, float]:
    """:func:`unstack.reasoner._sampler_kernels._decide_side` on word arrays; the decided set
    is written to ``inside`` (``outside``: scratch). Returns ``(log proposal, log forced)``."""
    words = inside.shape[0]
    constrained = False  # the other side is decided and not empty
    for w in range(words):
        inside[w] = 0
        outside[w] = 0
        if other_side[w] != 0:
            constrained = True
    log_proposal = 0.0
    log_forced = 0.0
    for k in order:
        word = k >> 6
        bit = np.int64(1) << (k & 63)
        forced_in = False
        for w in range(words):  # direct indexing: no array views in the innermost loop
            if backward[k, w] & inside[w]:
                forced_in = True
                break
        if forced_in:
            inside[word] |= bit
            log_forced += log_present[x, k]
            continue
        excluded = False
        if constrained:
            for w in range(words):
                rest = other_side[w] & ~backward[k, w]
                if w == word:
                    rest &= ~bit
                if rest != 0:
                    excluded = True
                    break
        if not excluded:
            for w in range(words):
                if forward[k, w] & outside[w]:
                    excluded = True
                    break
        if excluded:
            outside[word] |= bit
            log_forced += log_absent[x, k]
            continue
        member = (replay[word] & bit) != 0 if replaying else _uniform(rng, chain) < probabilities[x, k]
        if member:
            inside[word] |= bit
            log_proposal += log_present[x, k]
        else:
            outside[word] |= bit
            log_proposal += log_absent[x, k]
    return log_proposal, log_forced


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
    replay_supported: np.ndarray,
    replay_supporters: np.ndarray,
    replaying: bool,
    supported: np.ndarray,
    supporters: np.ndarray,
    outside: np.ndarray,
    empty: np.ndarray,
) -> tuple[float, float]:
    """:func:`unstack.reasoner._sampler_kernels._insertion` on word arrays: ``A`` goes to
    ``supported``, ``B`` to ``supporters``; returns ``(log proposal, log target)``."""
    p_t, present_t, absent_t = probabilities.T, log_present.T, log_absent.T
    if supporters_first:
        log_q1, log_f1 = _decide_side(
            x, order, present_t, absent_t, p_t, predecessors, successors, empty, rng, chain,
            replay_supporters, replaying, supporters, outside,
        )  # fmt: skip
        log_q2, log_f2 = _decide_side(
            x, order, log_present, log_absent, probabilities, successors, predecessors, supporters, rng, chain,
            replay_supported, replaying, supported, outside,
        )  # fmt: skip
    else:
        log_q1, log_f1 = _decide_side(
            x, order, log_present, log_absent, probabilities, successors, predecessors, empty, rng, chain,
            replay_supported, replaying, supported, outside,
        )  # fmt: skip
        log_q2, log_f2 = _decide_side(
            x, order, present_t, absent_t, p_t, predecessors, successors, supported, rng, chain,
            replay_supporters, replaying, supporters, outside,
        )  # fmt: skip
    log_proposal = log_q1 + log_q2
    return log_proposal, log_proposal + log_f1 + log_f2


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
    supported: np.ndarray,
    supporters: np.ndarray,
    log_proposal: float,
    log_target: float,
    supporters_first: bool,
    scratch: np.ndarray,
) -> float:
    """``log(target / proposal)`` under the even mixture of both phase orders (``scratch``:
    ``(4, words)``)."""
    other_proposal, _ = _insertion(
        x, order, probabilities, log_present, log_absent, successors, predecessors, rng, chain,
        not supporters_first, supported, supporters, True, scratch[0], scratch[1], scratch[2], scratch[3],
    )  # fmt: skip
    if log_proposal >= other_proposal:
        mixture = log_proposal + np.log1p(np.exp(other_proposal - log_proposal))
    else:
        mixture = other_proposal + np.log1p(np.exp(log_proposal - other_proposal))
    return float(log_target - mixture)


@njit(cache=True, nogil=True)
def _set_relations(
    x: int, n: int, supported: np.ndarray, supporters: np.ndarray, successors: np.ndarray, predecessors: np.ndarray
) -> None:
    """Give box ``x`` the relations ``x -> supported`` and ``supporters -> x``."""
    successors[x, :] = supported
    predecessors[x, :] = supporters
    for k in range(n):
        if k == x:
            continue
        _put(predecessors[k], x, _has(supported, k))
        _put(successors[k], x, _has(supporters, k))


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
    scratch: np.ndarray,
) -> bool:
    """:func:`unstack.reasoner._sampler_kernels._reinsert` on word arrays. ``scratch``:
    ``(8, words)``; rows 0-2 serve the replays in the other order, 4-6 this order's sets;
    rows 3 and 7 are never written and stay the empty set."""
    n = probabilities.shape[0]
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
    candidates_supported[0] = successors[x]
    candidates_supporters[0] = predecessors[x]
    log_q, log_t = _insertion(
        x, walk, probabilities, log_present, log_absent, successors, predecessors, rng, chain, False,
        candidates_supported[0], candidates_supporters[0], True, scratch[4], scratch[5], scratch[6], scratch[7],
    )  # fmt: skip
    log_ratios[0] = _log_weight(
        x, walk, probabilities, log_present, log_absent, successors, predecessors, rng, chain,
        candidates_supported[0], candidates_supporters[0], log_q, log_t, False, scratch,
    )  # fmt: skip
    largest = log_ratios[0]
    for t in range(1, tries + 1):
        supporters_first = _uniform(rng, chain) < 0.5
        log_q, log_t = _insertion(
            x, walk, probabilities, log_present, log_absent, successors, predecessors, rng, chain,
            supporters_first, scratch[7], scratch[7], False, candidates_supported[t], candidates_supporters[t],
            scratch[6], scratch[7],
        )  # fmt: skip
        log_ratios[t] = _log_weight(
            x, walk, probabilities, log_present, log_absent, successors, predecessors, rng, chain,
            candidates_supported[t], candidates_supporters[t], log_q, log_t, supporters_first, scratch,
        )  # fmt: skip
        if log_ratios[t] > largest:
            largest = log_ratios[t]
    total = 0.0
    for t in range(tries + 1):
        log_ratios[t] = np.exp(log_ratios[t] - largest)
        total += log_ratios[t]
    pick = tries
    if scatter:
        pick = 1 if log_ratios[1] > 0.0 else 0
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
    """:func:`unstack.reasoner._sampler_kernels._pair_is_free` on word arrays."""
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


@njit(cache=True, nogil=True)
def _flip_pairs(
    probabilities: np.ndarray, successors: np.ndarray, predecessors: np.ndarray, rng: np.ndarray, chain: int
) -> None:
    """One Gibbs pass over the ordered pairs (as in the one-word kernels)."""
    n = probabilities.shape[0]
    for i in range(n):
        for j in range(n):
            if i == j or not _pair_is_free(i, j, successors, predecessors):
                continue
            member = _uniform(rng, chain) < probabilities[i, j]
            _put(successors[i], j, member)
            _put(predecessors[j], i, member)


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
    inside: np.ndarray,
    cache_key: np.ndarray,
    cache_sums: np.ndarray,
) -> None:
    """:func:`unstack.reasoner._sampler_kernels._block_update` on word arrays (``inside``:
    scratch for the block's set of boxes). The block's table masks stay one word.

    One difference: a block linked across sums the table's ``linear_weights``
    (``exp(log_weights)``, computed once) instead of calling ``exp`` for every preorder of the
    table at every update -- 5 to 10 times faster on 150 boxes linked by 1e-2, where most
    blocks are linked -- unless those allowed all underflow. The draws can then differ from
    the one-word kernels' in the last bits of a cumulative sum. And the sums of a linked block
    are kept per chain (``cache_key``: ``(state, forbidden, forced)`` with state 0 none, 1 the
    total, 2 the total and the pair sums; ``cache_sums``: the 25 pair sums and the total) and
    reused while the relations across it impose the same constraints.
    """
    words = successors.shape[1]
    inside[:] = 0
    for a in range(size):
        _put(inside, members[a], True)
    forbidden = np.int64(0)
    forced = np.int64(0)
    linked = False
    for a in range(size):
        u = members[a]
        for w in range(words):
            if (predecessors[u, w] | successors[u, w]) & ~inside[w]:
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
            for b in range(size):
                if a == b:
                    continue
                v = members[b]
                bit = np.int64(1) << (a * _STRIDE + b)
                through = False  # u -> w -> v for an outside w
                excluded = False  # In(u) not in In(v), or Out(v) not in Out(u)
                for w in range(words):
                    outer = ~inside[w]
                    if successors[u, w] & predecessors[v, w] & outer:
                        through = True
                    if (predecessors[u, w] & ~predecessors[v, w] & outer) or (
                        successors[v, w] & ~successors[u, w] & outer
                    ):
                        excluded = True
                if through:
                    forced |= bit
                elif excluded:
                    forbidden |= bit
        # the table's own weights (largest 1) first; exp(log weight - top) only if those
        # allowed here all underflow (extreme probabilities)
        top = 0.0
        scaled = False
        # the sums depend only on (forbidden, forced), which change only when a relation
        # across the block does: reuse the chain's last sums for the same constraints
        known = cache_key[1] == forbidden and cache_key[2] == forced and cache_key[0] >= (2 if record else 1)
        if known:
            total = cache_sums[_STRIDE * _STRIDE]
            pair_sums[:] = cache_sums[: _STRIDE * _STRIDE]
        while not known:
            total = 0.0
            pair_sums[:] = 0.0
            for t in range(count):
                m = masks[t]
                if (m & forbidden) == 0 and (m & forced) == forced:
                    weight = np.exp(log_weights[t] - top) if scaled else linear_weights[t]
                    total += weight
                    if record:
                        row = pair_table[t]
                        for k in range(_STRIDE * _STRIDE):
                            pair_sums[k] += weight * row[k]
            if total > _SMALLEST_TOTAL or scaled:
                break
            scaled = True
            top = -np.inf
            for t in range(count):
                m = masks[t]
                if (m & forbidden) == 0 and (m & forced) == forced and log_weights[t] > top:
                    top = log_weights[t]
            if top == -np.inf:
                return  # cannot happen from a consistent state of non-zero weight
        if not known:
            cache_key[0] = 0 if scaled else (2 if record else 1)
            cache_key[1] = forbidden
            cache_key[2] = forced
            cache_sums[: _STRIDE * _STRIDE] = pair_sums
            cache_sums[_STRIDE * _STRIDE] = total
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
            _put(successors[u], v, member)
            _put(predecessors[v], u, member)


@njit(cache=True, nogil=True)
def _add_conditionals(
    probabilities: np.ndarray, successors: np.ndarray, predecessors: np.ndarray, sums: np.ndarray, block_of: np.ndarray
) -> None:
    """Add ``P(S_ij = 1 | every other relation)`` of the current state to ``sums`` (pairs
    inside a block excepted), as in the one-word kernels."""
    n = probabilities.shape[0]
    for i in range(n):
        for j in range(n):
            if i == j or (block_of[i] >= 0 and block_of[i] == block_of[j]):
                continue
            if _pair_is_free(i, j, successors, predecessors):
                sums[i, j] += probabilities[i, j]
            elif _has(successors[i], j):
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

    A sweep re-inserts ``moves`` boxes, the next ones of ``schedule`` in turn from
    ``cursors[chain]`` (all boxes, in order, when ``moves == n`` and the schedule is every box
    once: the sweep of the one-word kernels). The round's records go to
    ``chains.sums[chain, round_]``."""
    successors, predecessors, rng, cursors = (
        chains.successors[chain],
        chains.predecessors[chain],
        chains.rng,
        chains.cursors,
    )
    sums = chains.sums[chain, round_]
    n = probabilities.shape[0]
    words = successors.shape[1]
    pair_sums = np.zeros(_STRIDE * _STRIDE)
    order = np.empty(n, dtype=np.int64)
    candidates_supported = np.zeros((tries + 1, words), dtype=np.int64)
    candidates_supporters = np.zeros((tries + 1, words), dtype=np.int64)
    log_ratios = np.empty(tries + 1)
    scratch = np.zeros((8, words), dtype=np.int64)
    inside = np.zeros(words, dtype=np.int64)
    cache_keys = np.zeros((blocks.sizes.shape[0], 3), dtype=np.int64)
    cache_sums = np.zeros((blocks.sizes.shape[0], _STRIDE * _STRIDE + 1))
    accepted = 0
    for _ in range(sweeps):
        _flip_pairs(probabilities, successors, predecessors, rng, chain)
        for _ in range(moves):
            x = schedule[cursors[chain]]
            cursors[chain] = (cursors[chain] + 1) % schedule.shape[0]
            if _reinsert(
                x, probabilities, log_present, log_absent, successors, predecessors, order, rng, chain, tries,
                candidates_supported, candidates_supporters, log_ratios, scatter, scratch,
            ):  # fmt: skip
                accepted += 1
        for k in range(blocks.sizes.shape[0]):
            _block_update(
                blocks.members[k], blocks.sizes[k], blocks.counts[k], blocks.masks[k], blocks.log_weights[k],
                blocks.linear_weights[k], blocks.cumulative[k], blocks.marginals[k], blocks.pairs[k], successors,
                predecessors, rng, chain, record, sums, pair_sums, inside, cache_keys[k], cache_sums[k],
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
    """:func:`unstack.reasoner._sampler_kernels.run_chains` (chains ``first`` to ``last - 1``) with
    ``(chains, n, words)`` states in ``chains``; the rest as there."""
    for c in range(first, last):
        for r in range(rounds):
            chains.accepted[c] += _run_chain(
                c, r, probabilities, log_present, log_absent, chains, blocks, sweeps, tries, record, scatter, moves,
                schedule,
            )  # fmt: skip
