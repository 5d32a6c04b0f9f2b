"""The arrays the sampler's kernels take, in two structures instead of twenty arguments.

The sampler's kernels (:mod:`unstack.reasoner._sampler_kernels`, one family compiled for both
layouts of a set: one 64-bit word in groups of up to 63 boxes, an array of words above) take
the state of every chain as one :class:`ChainArrays` and the blocks redrawn exactly after
every sweep as one :class:`BlockArrays` (numba passes a named tuple of arrays as one argument
and reads its fields by name).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

__all__ = ["BlockArrays", "ChainArrays"]


class ChainArrays(NamedTuple):
    """Every chain's state, updated in place by the kernels.

    Attributes
    ----------
    successors, predecessors : numpy.ndarray, int64
        ``(chains, n)`` bit masks (one word) or ``(chains, n, words)`` word arrays: the boxes
        each box supports, and is supported by.
    rng : numpy.ndarray, uint64, shape (chains,)
        Each chain's random stream.
    cursors : numpy.ndarray, int64, shape (chains,)
        Each chain's position in the re-insertion schedule.
    accepted : numpy.ndarray, int64, shape (chains,)
        Moves that changed the state, per chain.
    sums : numpy.ndarray, shape (chains, rounds, n, n)
        The recorded conditionals of each round.
    """

    successors: np.ndarray
    predecessors: np.ndarray
    rng: np.ndarray
    cursors: np.ndarray
    accepted: np.ndarray
    sums: np.ndarray


class BlockArrays(NamedTuple):
    """The blocks of strongly linked boxes (:class:`~unstack.reasoner.block_gibbs.BlockTables`),
    one row per block (no blocks: zero rows); ``block_of``: each box's block or -1."""

    members: np.ndarray
    sizes: np.ndarray
    counts: np.ndarray
    masks: np.ndarray
    log_weights: np.ndarray
    linear_weights: np.ndarray
    cumulative: np.ndarray
    marginals: np.ndarray
    pairs: np.ndarray
    block_of: np.ndarray
