"""Blocks of strongly linked boxes, drawn exactly inside the sampler (block Gibbs).

A classifier's probabilities are never exactly 0, so a real pile is one linked group even
where it is really several nearly independent parts. The sampler exploits this: boxes
joined by links stronger than :data:`BLOCK_THRESHOLD` (``max(p_xy, p_yx)``) form a block when
they are at most :data:`~unstack.reasoner.small.SMALL_MAX_BOXES` and no strong link leaves
them, and every sweep redraws the relations *inside* each block exactly from their
distribution given every other relation.

That conditional is simple. Write ``In(u)`` / ``Out(u)`` for the boxes outside the block that
support / are supported by ``u``. With the relations across fixed, transitivity allows the
relation ``u -> v`` inside the block only if ``In(u)`` lies in ``In(v)`` and ``Out(v)`` in
``Out(u)``, and forces it if some outside box ``w`` has ``u -> w -> v``. Every other triple
either lies inside the block (a preorder of the block) or does not involve a relation inside
it. So the conditional is the block's own distribution with these relations forbidden or
forced -- hard evidence on a group of at most five boxes, summed over its table of preorders
(:func:`~unstack.reasoner.small.preorders`). The same sum gives the conditional marginal of
every pair inside the block, which the sampler records instead of the pair's own
conditional (a coarser Rao-Blackwellisation): a block with no relation across contributes
its exact marginals, without noise. The partition into blocks only changes how fast the
chain mixes, never its target; the re-insertion moves still reach every consistent world.

Examples
--------
>>> import numpy as np
>>> p = np.full((4, 4), 1e-3); p[0, 1] = p[1, 0] = 0.6; p[2, 3] = 0.9; np.fill_diagonal(p, 0)
>>> [block.tolist() for block in strong_blocks(p)]
[[0, 1], [2, 3]]
>>> tables = block_tables(p, strong_blocks(p))
>>> tables.masks.shape, int(tables.counts[0])
((2, 4), 4)
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from unstack.reasoner.components import support_components
from unstack.reasoner.small import SMALL_MAX_BOXES, preorders

__all__ = ["BLOCK_STRIDE", "BLOCK_THRESHOLD", "BlockTables", "block_tables", "strong_blocks"]

#: Links with ``max(p_xy, p_yx)`` above this join two boxes in one block.
BLOCK_THRESHOLD = 0.02
#: Bit of the pair ``(a, b)`` of a block in a table mask: ``a * BLOCK_STRIDE + b``.
BLOCK_STRIDE = SMALL_MAX_BOXES


@dataclass(frozen=True, eq=False)
class BlockTables:
    """Everything the compiled sampler needs about the blocks (arrays padded to the largest).

    Attributes
    ----------
    members : numpy.ndarray, shape (blocks, 5), int64
        Box indices of each block (``-1`` padding).
    sizes : numpy.ndarray, shape (blocks,), int64
    counts : numpy.ndarray, shape (blocks,), int64
        Preorders of each block.
    masks : numpy.ndarray, shape (blocks, most), int64
        Each preorder as bits ``a * BLOCK_STRIDE + b`` (``a`` supports ``b``).
    log_weights : numpy.ndarray, shape (blocks, most)
        ``log`` of each preorder's weight (largest 0; ``-inf`` where it breaks hard evidence).
    block_of : numpy.ndarray, shape (n,), int64
        Block of each box (``-1``: in none).
    cumulative : numpy.ndarray, shape (blocks, most)
        Cumulative weights of the preorders (a block with no relation across draws from these).
    marginals : numpy.ndarray, shape (blocks, BLOCK_STRIDE ** 2)
        Marginal of every pair of each block alone (bit ``a * BLOCK_STRIDE + b``).
    pairs : numpy.ndarray, shape (blocks, most, BLOCK_STRIDE ** 2)
        ``masks`` as 0/1 floats (a branch-free sum of the conditional marginals; 1.4 MB per
        block of five).
    """

    members: np.ndarray
    sizes: np.ndarray
    counts: np.ndarray
    masks: np.ndarray
    log_weights: np.ndarray
    block_of: np.ndarray
    cumulative: np.ndarray
    marginals: np.ndarray
    pairs: np.ndarray


def strong_blocks(
    probabilities: np.ndarray, *, threshold: float = BLOCK_THRESHOLD, max_size: int = SMALL_MAX_BOXES
) -> list[np.ndarray]:
    """Groups of 2 to ``max_size`` boxes joined by links above ``threshold`` and by no such
    link to any other box.

    A larger strongly linked group gets no block: cut into blocks of five it was measured
    (classifier piles of 31 and 39 boxes) to cost 2-4 times the time per sweep for no smaller
    error; single-box moves handle it.

    Examples
    --------
    >>> p = np.array([[0, 0.5, 0.001], [0.2, 0, 0.001], [0.001, 0.001, 0]])
    >>> [block.tolist() for block in strong_blocks(p)]
    [[0, 1]]
    """
    strong = np.where(np.maximum(probabilities, probabilities.T) > threshold, 1.0, 0.0)
    np.fill_diagonal(strong, 0.0)
    return [group for group in support_components(strong) if 2 <= len(group) <= max_size]


@lru_cache(maxsize=SMALL_MAX_BOXES + 1)
def _block_layout(size: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The preorders of a block of ``size`` boxes laid out for :func:`block_tables`
    (computed once per size; read-only, so threads share them).

    Returns the preorders' off-diagonal relations (preorders x pairs, 0/1 floats), their
    masks (bits ``a * BLOCK_STRIDE + b``), the masks as 0/1 floats per bit (preorders x
    ``BLOCK_STRIDE ** 2``), the bit of each off-diagonal pair and the off-diagonal selector.
    """
    table = preorders(size)
    bits = (np.arange(size)[:, None] * BLOCK_STRIDE + np.arange(size)[None, :]).astype(np.int64)
    masks = (table * (np.int64(1) << bits)[None]).sum(axis=(1, 2))
    off = ~np.eye(size, dtype=bool)
    relations = np.ascontiguousarray(table[:, off], dtype=np.float64)
    mask_bits = ((masks[:, None] >> np.arange(BLOCK_STRIDE * BLOCK_STRIDE)) & 1).astype(np.float64)
    layout = (relations, masks, mask_bits, bits[off], off)
    for array in layout:
        array.flags.writeable = False
    return layout


def block_tables(probabilities: np.ndarray, blocks: list[np.ndarray]) -> BlockTables:
    """The preorder tables of ``blocks`` with their log weights under ``probabilities``."""
    n = probabilities.shape[0]
    most = max((len(preorders(len(block))) for block in blocks), default=1)
    members = np.full((len(blocks), SMALL_MAX_BOXES), -1, dtype=np.int64)
    sizes = np.zeros(len(blocks), dtype=np.int64)
    counts = np.zeros(len(blocks), dtype=np.int64)
    masks = np.zeros((len(blocks), most), dtype=np.int64)
    log_weights = np.full((len(blocks), most), -np.inf)
    block_of = np.full(n, -1, dtype=np.int64)
    cumulative = np.zeros((len(blocks), most))
    marginals = np.zeros((len(blocks), BLOCK_STRIDE * BLOCK_STRIDE))
    pairs = np.empty((len(blocks), most, BLOCK_STRIDE * BLOCK_STRIDE))
    for k, block in enumerate(blocks):
        size = len(block)
        relations, table_masks, mask_bits, off_bits, off = _block_layout(size)
        count = len(relations)
        members[k, :size] = block
        sizes[k] = size
        counts[k] = count
        block_of[block] = k
        masks[k, :count] = table_masks
        p = probabilities[np.ix_(block, block)][off]
        with np.errstate(divide="ignore"):
            present, absent = np.log(p), np.log1p(-p)
        if np.all(np.isfinite(present)) and np.all(np.isfinite(absent)):
            weights = relations @ (present - absent) + absent.sum()
        else:  # a probability of 0 or 1: a product would meet 0 * inf
            weights = np.where(relations > 0, present[None], absent[None]).sum(axis=1)
        top = weights.max()
        log_weights[k, :count] = weights - (top if np.isfinite(top) else 0.0)
        linear = np.exp(log_weights[k, :count])
        cumulative[k, :count] = np.cumsum(linear)
        cumulative[k, count:] = np.inf
        marginals[k, off_bits] = linear @ relations / linear.sum()
        pairs[k, :count] = mask_bits
        pairs[k, count:] = 0.0
    return BlockTables(members, sizes, counts, masks, log_weights, block_of, cumulative, marginals, pairs)
