"""Compiled kernels of the sampling engine (see :mod:`unstack.reasoner.sampling`).

A chain's state is a preorder on boxes ``0..n-1`` (``n <= 63``) kept as two arrays of bit
masks: ``successors[i]`` (the boxes ``i`` supports) and ``predecessors[i]`` (the boxes that
support ``i``). One move re-inserts one box ``x``: the relations of ``x`` are removed, a new
set ``A`` of boxes that ``x`` supports and a set ``B`` of boxes that support ``x`` are
proposed, and Metropolis-Hastings accepts or keeps the old ones.

The proposal walks the other boxes in a random order and decides each one in turn. A box
is *forced* when an earlier decision and transitivity leave one value only (``A`` must be
closed under "supports", ``B`` under "is supported by", and every member of ``B`` must
support every other member of ``A``); every other box is *free* and joins with its own
probability ``p``. So the proposal is the target itself except at the forced boxes, and
the Metropolis-Hastings ratio is the product of the forced boxes' factors (``p`` when
forced in, ``1 - p`` when forced out) of the new insertion over the old one. Any order of
the boxes gives a consistent result, and drawing the order before the move keeps detailed
balance.

After each sweep (``n`` moves) every ordered pair adds its Rao-Blackwellised value: the
probability of ``S_ij = 1`` given every other relation of the state, which is ``p_ij``
when both values keep the world transitive and the current value when only one does.

The random numbers come from one xorshift64* stream per chain so that results do not
depend on how the chains are spread over threads.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

_MULTIPLIER = np.uint64(0x2545F4914F6CDD1D)
_SHIFT_A = np.uint64(12)
_SHIFT_B = np.uint64(25)
_SHIFT_C = np.uint64(27)
_SHIFT_FLOAT = np.uint64(11)
_TO_UNIT = 1.0 / 9007199254740992.0  # 2**-53


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
def _log_factor(probability: float, member: bool) -> float:
    """``log p`` for a relation that holds, ``log(1 - p)`` for one that does not."""
    value = probability if member else 1.0 - probability
    if value <= 0.0:
        return -np.inf
    return float(np.log(value))


@njit(cache=True, nogil=True)
def _insertion(
    x: int,
    order: np.ndarray,
    probabilities: np.ndarray,
    successors: np.ndarray,
    predecessors: np.ndarray,
    rng: np.ndarray,
    chain: int,
    replay_supported: np.int64,
    replay_supporters: np.int64,
    replay: bool,
) -> tuple[np.int64, np.int64, float]:
    """Propose (or, with ``replay``, re-trace) an insertion of ``x``: ``(A, B, log ratio)``.

    ``A``: boxes ``x`` supports; ``B``: boxes supporting ``x``; the log ratio is the sum of
    the forced decisions' log factors (target over proposal).
    """
    supported_in = np.int64(0)
    supported_out = np.int64(0)
    log_ratio = 0.0
    for k in order:
        bit = np.int64(1) << k
        p = probabilities[x, k]
        if predecessors[k] & supported_in:
            supported_in |= bit
            log_ratio += _log_factor(p, True)
        elif successors[k] & supported_out:
            supported_out |= bit
            log_ratio += _log_factor(p, False)
        else:
            member = (replay_supported & bit) != 0 if replay else _uniform(rng, chain) < p
            if member:
                supported_in |= bit
            else:
                supported_out |= bit
    supporters_in = np.int64(0)
    supporters_out = np.int64(0)
    for k in order:
        bit = np.int64(1) << k
        p = probabilities[k, x]
        allowed = (supported_in & ~bit & ~successors[k]) == 0
        if successors[k] & supporters_in:
            supporters_in |= bit
            log_ratio += _log_factor(p, True)
        elif (not allowed) or (predecessors[k] & supporters_out):
            supporters_out |= bit
            log_ratio += _log_factor(p, False)
        else:
            member = (replay_supporters & bit) != 0 if replay else _uniform(rng, chain) < p
            if member:
                supporters_in |= bit
            else:
                supporters_out |= bit
    return supported_in, supporters_in, log_ratio


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
    successors: np.ndarray,
    predecessors: np.ndarray,
    order: np.ndarray,
    rng: np.ndarray,
    chain: int,
    tries: int,
    candidates_supported: np.ndarray,
    candidates_supporters: np.ndarray,
    log_ratios: np.ndarray,
    row_sums: np.ndarray,
    column_sums: np.ndarray,
    record: bool,
) -> bool:
    """One ensemble move on the relations of box ``x``; True when the relations changed.

    Candidates: the current insertion and ``tries`` proposals; the next insertion is drawn
    among them with weights ``target / proposal`` (Barker's rule over an ensemble of
    independent proposals keeps the target invariant), and with ``record`` the
    weighted mean of the candidates' relations is added to ``row_sums[x]`` (boxes ``x``
    supports) and ``column_sums[:, x]`` (boxes supporting ``x``).
    """
    n = probabilities.shape[0]
    old_supported = successors[x]
    old_supporters = predecessors[x]
    _set_relations(x, n, np.int64(0), np.int64(0), successors, predecessors)
    # the other boxes in a random order (Fisher-Yates over the first n - 1 slots)
    m = 0
    for k in range(n):
        if k != x:
            order[m] = k
            m += 1
    for i in range(m - 1, 0, -1):
        j = int(_uniform(rng, chain) * (i + 1))
        order[i], order[j] = order[j], order[i]
    walk = order[:m]
    a, b, log_ratio = _insertion(
        x, walk, probabilities, successors, predecessors, rng, chain, old_supported, old_supporters, True
    )
    candidates_supported[0] = a
    candidates_supporters[0] = b
    log_ratios[0] = log_ratio
    largest = log_ratio
    for t in range(1, tries + 1):
        a, b, log_ratio = _insertion(
            x, walk, probabilities, successors, predecessors, rng, chain, np.int64(0), np.int64(0), False
        )
        candidates_supported[t] = a
        candidates_supporters[t] = b
        log_ratios[t] = log_ratio
        if log_ratio > largest:
            largest = log_ratio
    total = 0.0
    for t in range(tries + 1):
        log_ratios[t] = np.exp(log_ratios[t] - largest)
        total += log_ratios[t]
    if record:
        for t in range(tries + 1):
            weight = log_ratios[t] / total
            if weight == 0.0:
                continue
            a = candidates_supported[t]
            b = candidates_supporters[t]
            for k in walk:
                bit = np.int64(1) << k
                if a & bit:
                    row_sums[x, k] += weight
                if b & bit:
                    column_sums[k, x] += weight
    u = _uniform(rng, chain) * total
    pick = tries
    for t in range(tries + 1):
        u -= log_ratios[t]
        if u < 0.0:
            pick = t
            break
    _set_relations(x, n, candidates_supported[pick], candidates_supporters[pick], successors, predecessors)
    return pick != 0


@njit(cache=True, nogil=True)
def _add_conditionals(
    probabilities: np.ndarray, successors: np.ndarray, predecessors: np.ndarray, sums: np.ndarray
) -> None:
    """Add ``P(S_ij = 1 | every other relation)`` of the current state to ``sums``."""
    n = probabilities.shape[0]
    for i in range(n):
        ibit = np.int64(1) << i
        for j in range(n):
            if i == j:
                continue
            jbit = np.int64(1) << j
            if successors[i] & jbit:
                # may S_ij be dropped? only if no k has i -> k -> j
                if successors[i] & predecessors[j] & ~ibit & ~jbit:
                    sums[i, j] += 1.0
                else:
                    sums[i, j] += probabilities[i, j]
            else:
                # may S_ij be added? everything j supports, i must support; everything
                # supporting i must support j
                missing_below = successors[j] & ~ibit & ~successors[i]
                missing_above = predecessors[i] & ~jbit & ~predecessors[j]
                if missing_below == 0 and missing_above == 0:
                    sums[i, j] += probabilities[i, j]


@njit(cache=True, nogil=True)
def _run_chain(
    chain: int,
    probabilities: np.ndarray,
    successors: np.ndarray,
    predecessors: np.ndarray,
    rng: np.ndarray,
    sweeps: int,
    tries: int,
    record: bool,
    pair_sums: np.ndarray,
    row_sums: np.ndarray,
    column_sums: np.ndarray,
) -> int:
    """Run ``sweeps`` sweeps of one chain; add the estimates when ``record``."""
    n = probabilities.shape[0]
    order = np.empty(n, dtype=np.int64)
    candidates_supported = np.empty(tries + 1, dtype=np.int64)
    candidates_supporters = np.empty(tries + 1, dtype=np.int64)
    log_ratios = np.empty(tries + 1)
    accepted = 0
    for _ in range(sweeps):
        for x in range(n):
            if _reinsert(
                x,
                probabilities,
                successors,
                predecessors,
                order,
                rng,
                chain,
                tries,
                candidates_supported,
                candidates_supporters,
                log_ratios,
                row_sums,
                column_sums,
                record,
            ):
                accepted += 1
        if record:
            _add_conditionals(probabilities, successors, predecessors, pair_sums)
    return accepted


@njit(cache=True, nogil=True, parallel=True)
def run_chains(
    probabilities: np.ndarray,
    successors: np.ndarray,
    predecessors: np.ndarray,
    rng: np.ndarray,
    sweeps: int,
    tries: int,
    record: bool,
    pair_sums: np.ndarray,
    row_sums: np.ndarray,
    column_sums: np.ndarray,
    accepted: np.ndarray,
) -> None:
    """Advance every chain by ``sweeps`` sweeps (chains run in parallel).

    ``successors``/``predecessors``: ``(chains, n)`` bit masks, updated in place;
    ``rng``: ``(chains,)`` uint64 states; ``pair_sums``, ``row_sums``, ``column_sums``:
    ``(chains, n, n)`` sums of the three estimators over the recorded sweeps;
    ``accepted``: ``(chains,)`` counts of moves that changed the state.
    """
    for c in prange(successors.shape[0]):
        accepted[c] += _run_chain(
            c,
            probabilities,
            successors[c],
            predecessors[c],
            rng,
            sweeps,
            tries,
            record,
            pair_sums[c],
            row_sums[c],
            column_sums[c],
        )
