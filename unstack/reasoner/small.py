"""Exact marginals of small groups from a table of every preorder (pure numpy).

Up to :data:`SMALL_MAX_BOXES` boxes the consistent worlds are few (6,942 for five boxes):
a table of all preorders on ``n`` labelled boxes, built once per process, turns the
weighted count into two matrix products in log space. No compiled kernel is loaded and no
thread pool is woken, so a decision on a handful of boxes takes tens of microseconds.

The table of ``n`` boxes is built from the table of ``n - 1``: box ``n - 1`` joins every
preorder with every set of supporters and supported boxes, and the transitive candidates
are kept (each preorder arises exactly once, since removing the last box recovers it).

Examples
--------
>>> import numpy as np
>>> preorders(3).shape
(29, 3, 3)
>>> half = np.full((3, 3), 0.5); np.fill_diagonal(half, 0)
>>> marginals, worlds, _ = small_marginals(half)
>>> worlds, round(float(marginals[0, 1]), 6)
(29, 0.413793)
"""

from __future__ import annotations

import threading

import numpy as np

from unstack.errors import InvalidArgument, TooLarge

__all__ = ["SMALL_MAX_BOXES", "preorders", "small_marginals"]

#: Largest group the table path takes (n = 6 would hold 209,527 worlds, 50 MB).
SMALL_MAX_BOXES = 5

_TABLES: dict[int, np.ndarray] = {}
_FLAT: dict[int, np.ndarray] = {}
_LOCK = threading.Lock()
_OFF_DIAGONAL = {n: ~np.eye(n, dtype=bool) for n in range(SMALL_MAX_BOXES + 1)}


def _extend(worlds: np.ndarray) -> np.ndarray:
    """Every preorder on one more box whose restriction to the first boxes is in ``worlds``.

    The new box joins with a set D of supporters and a set U of boxes it supports. The
    result is transitive iff D is closed under supporters, U is closed under supported
    boxes, and every box of D supports every other box of U (checked on bit masks).
    """
    count, m, _ = worlds.shape
    n = m + 1
    bits = np.left_shift(1, np.arange(m))
    successors = (worlds * bits[None, None, :]).sum(axis=2)  # (count, m): boxes x supports
    predecessors = (worlds * bits[None, :, None]).sum(axis=1)  # (count, m): boxes supporting x
    masks = np.arange(1 << m)
    member = ((masks[:, None] >> np.arange(m)[None, :]) & 1).astype(bool)  # (2^m, m)
    # down[w, D]: D holds every supporter of its members; up[w, U]: every box its members support
    down = ~np.any(member[None] & ((predecessors[:, None, :] & ~masks[None, :, None]) != 0), axis=2)
    up = ~np.any(member[None] & ((successors[:, None, :] & ~masks[None, :, None]) != 0), axis=2)
    # cross[w, D, U]: each x in D supports each y != x in U
    reach = successors | bits[None, :]  # (count, m)
    blocked = np.zeros((count, 1 << m, 1 << m), dtype=bool)
    for x in range(m):
        outside = ~reach[:, x][:, None] & masks[None, :]  # (count, 2^m): boxes of U x does not reach
        blocked |= member[None, :, x, None] & (outside[:, None, :] != 0)
    keep = down[:, :, None] & up[:, None, :] & ~blocked
    world, d, u = np.nonzero(keep)
    extended = np.zeros((len(world), n, n), dtype=bool)
    extended[:, :m, :m] = worlds[world]
    extended[:, :m, m] = member[d]
    extended[:, m, :m] = member[u]
    return extended


def preorders(n: int) -> np.ndarray:
    """Every consistent world on ``n`` boxes as a boolean array ``(worlds, n, n)`` (cached).

    Parameters
    ----------
    n : int
        Number of boxes, ``0 <= n <=`` :data:`SMALL_MAX_BOXES`.

    Returns
    -------
    numpy.ndarray, shape (A000798(n), n, n), bool
        ``[w, i, j]``: box i supports box j in world w. Read-only.

    Examples
    --------
    >>> [len(preorders(n)) for n in range(5)]
    [1, 1, 4, 29, 355]
    """
    if isinstance(n, bool) or not isinstance(n, int | np.integer) or not 0 <= n <= SMALL_MAX_BOXES:
        raise InvalidArgument(f"the preorder table holds 0 to {SMALL_MAX_BOXES} boxes, got {n!r}")
    n = int(n)
    table = _TABLES.get(n)
    if table is not None:
        return table
    with _LOCK:
        if 0 not in _TABLES:
            empty = np.zeros((1, 0, 0), dtype=bool)
            empty.setflags(write=False)
            _TABLES[0] = empty
        for size in range(1, n + 1):
            if size not in _TABLES:
                worlds = _extend(_TABLES[size - 1])
                worlds.setflags(write=False)
                _TABLES[size] = worlds
    return _TABLES[n]


def small_marginals(probabilities: np.ndarray) -> tuple[np.ndarray, int, float]:
    """Exact conditional marginals of a small group by summing the preorder table.

    Parameters
    ----------
    probabilities : numpy.ndarray, shape (n, n)
        Checked support probabilities (exact 0 and 1 are hard evidence), ``n <=``
        :data:`SMALL_MAX_BOXES`.

    Returns
    -------
    marginals : numpy.ndarray, shape (n, n)
        ``P(S_xy = 1 | consistent)``.
    consistent_worlds : int
        Worlds of non-zero probability.
    log_partition : float
        ``log`` of the sum of the weights, each pair's factors divided by ``max(p, 1 - p)``
        (as in :func:`~unstack.reasoner.marginals.exact_marginals`).

    Raises
    ------
    TooLarge
        More than :data:`SMALL_MAX_BOXES` boxes.
    NoConsistentWorld
        Hard evidence that no preorder satisfies.

    Examples
    --------
    >>> marginals, worlds, _ = small_marginals(np.array([[0, 0.9], [0.0, 0]]))
    >>> marginals.round(6).tolist(), worlds
    ([[0.0, 0.9], [0.0, 0.0]], 2)
    """
    n = probabilities.shape[0]
    if n > SMALL_MAX_BOXES:
        raise TooLarge(f"{n} boxes: the preorder table holds at most {SMALL_MAX_BOXES}")
    worlds = _FLAT[n] if n in _FLAT else _flat(n)
    off_diagonal = _OFF_DIAGONAL[n]
    p = probabilities[off_diagonal]
    one = p >= 1.0
    zero = p <= 0.0
    hard = bool(one.any() or zero.any())
    soft_p = np.where(one | zero, 0.5, p) if hard else p
    scale = np.maximum(soft_p, 1.0 - soft_p)
    absent = np.log((1.0 - soft_p) / scale)
    odds = np.log(soft_p / scale) - absent
    if hard:
        odds[one | zero] = 0.0
        absent[one | zero] = 0.0
    log_weights = worlds @ odds
    if hard:  # a world breaks the evidence when it holds a 0 or lacks a 1
        broken = worlds @ (zero.astype(np.float64) - one) + float(one.sum())
        log_weights[broken > 0.5] = -np.inf
    top = float(log_weights.max())
    if top == -np.inf:
        from unstack.errors import NoConsistentWorld

        raise NoConsistentWorld(
            "no consistent world: the hard evidence (probabilities 0 and 1) contradicts transitivity", []
        )
    weights = np.exp(log_weights - top)
    partition = float(weights.sum())
    marginals = np.zeros((n, n))
    marginals[off_diagonal] = np.minimum(weights @ worlds / partition, 1.0)
    count = int(np.count_nonzero(weights)) if hard else len(worlds)
    return marginals, count, top + float(np.log(partition)) + float(absent.sum())


def _flat(n: int) -> np.ndarray:
    """The table of ``n`` boxes as a float64 matrix ``(worlds, n * (n - 1))`` of the off-diagonal pairs."""
    table = preorders(n)
    with _LOCK:
        if n not in _FLAT:
            flat = np.asfortranarray(table[:, _OFF_DIAGONAL[n]].astype(np.float64))
            flat.setflags(write=False)
            _FLAT[n] = flat
    return _FLAT[n]
