"""Relations of a world as bit masks, the layout the compiled sampler works on.

Row ``i`` of a relation (``i`` supports ``j``) becomes the set of its ``j``. Up to
:data:`ONE_WORD_BOXES` boxes a set is one ``int64`` (bit ``j``), so a relation on ``n`` boxes
is an ``(..., n)`` array; above, a set is ``words = ceil(n / 64)`` words (bit ``j % 64`` of
word ``j // 64``) and a relation is ``(..., n, words)``. Both layouts hold the same bits:
the one-word layout is the first word of the other.

Examples
--------
>>> import numpy as np
>>> relation = np.array([[0, 1, 1], [0, 0, 1], [0, 0, 0]], dtype=bool)   # 0 -> 1 -> 2
>>> pack(relation).tolist()
[6, 4, 0]
>>> bool((unpack(pack(relation), 3) == relation).all())
True
>>> wide = np.zeros((70, 70), dtype=bool); wide[0, 69] = True
>>> pack(wide).shape, bool(unpack(pack(wide), 70)[0, 69])
((70, 2), True)
"""

from __future__ import annotations

import numpy as np

__all__ = ["ONE_WORD_BOXES", "mask_words", "pack", "unpack"]

#: Largest group whose sets fit one ``int64`` (bit 63, the sign bit, stays unused).
ONE_WORD_BOXES = 63


def mask_words(n: int) -> int:
    """Words per set for ``n`` boxes: 0 for the one-integer layout (``n <= 63``).

    Examples
    --------
    >>> mask_words(63), mask_words(64), mask_words(256)
    (0, 1, 4)
    """
    return 0 if n <= ONE_WORD_BOXES else -(-n // 64)


def pack(relation: np.ndarray, *, wide: bool | None = None) -> np.ndarray:
    """Bit masks of the rows of ``relation`` (``(..., n, n)`` bool).

    ``wide`` forces the word-array layout (``True``) even for ``n <= 63``; by default it is
    used above :data:`ONE_WORD_BOXES` boxes.
    """
    relation = np.asarray(relation, dtype=bool)
    n = relation.shape[-1]
    words = mask_words(n) if wide is None else (max(1, -(-n // 64)) if wide else 0)
    if words == 0:
        bits = np.left_shift(np.int64(1), np.arange(n, dtype=np.int64))
        result: np.ndarray = (relation * bits).sum(axis=-1, dtype=np.int64)
        return result
    padded = np.zeros((*relation.shape[:-1], words * 64), dtype=np.uint64)
    padded[..., :n] = relation
    shifts = np.arange(64, dtype=np.uint64)
    grouped = padded.reshape((*relation.shape[:-1], words, 64)) << shifts
    return np.ascontiguousarray(np.bitwise_or.reduce(grouped, axis=-1).view(np.int64))


def unpack(masks: np.ndarray, n: int, *, wide: bool | None = None) -> np.ndarray:
    """The ``(..., n, n)`` bool relation of bit masks on ``n`` boxes.

    ``wide``: the masks are in the word-array layout (by default when ``n > 63``).
    """
    masks = np.asarray(masks, dtype=np.int64)
    if wide is None:
        wide = mask_words(n) > 0
    if not wide:
        return ((masks[..., None] >> np.arange(n, dtype=np.int64)) & 1).astype(bool)
    words = masks.shape[-1]
    shifts = np.arange(64, dtype=np.uint64)
    bits = (masks.view(np.uint64)[..., None] >> shifts) & np.uint64(1)
    result: np.ndarray = bits.reshape((*masks.shape[:-1], words * 64))[..., :n].astype(bool)
    return result
