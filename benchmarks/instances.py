"""Seeded benchmark instances: support-probability matrices of two families.

Both the pytest-benchmark suite (``test_reasoner.py``) and the side-by-side peer script
(``peers.py``) build their inputs here, so the same ``(family, n, seed)`` is the same
matrix everywhere.

``dense``
    every off-diagonal ``P[i, j] ~ U(0.05, 0.95)``: no pair is nearly decided, the worst
    case for reasoning (every consistent world keeps a noticeable weight).
``sparse``
    70 % of the off-diagonal pairs (``round(0.7 * n * (n - 1))`` of them, chosen at
    random) get ``P[i, j] ~ U(0.001, 0.02)`` -- "almost surely not supporting", as a
    classifier says for most pairs of a real pile -- the rest ``U(0.05, 0.95)``.

Each matrix comes from its own ``numpy.random.default_rng(seed)``; row supports column,
diagonal 0 (the project's convention).

Examples
--------
>>> probabilities = instance("sparse", 4, seed=0)
>>> probabilities.shape
(4, 4)
>>> bool((probabilities == instance("sparse", 4, seed=0)).all())
True
>>> int((probabilities[~np.eye(4, dtype=bool)] < 0.05).sum())  # round(0.7 * 12)
8
"""

from __future__ import annotations

import numpy as np

from unstack.supports import Supports

__all__ = ["FAMILIES", "SPARSE_SHARE", "box_ids", "instance", "supports"]

#: The instance families.
FAMILIES: tuple[str, ...] = ("dense", "sparse")
#: Share of off-diagonal pairs that the sparse family makes nearly impossible.
SPARSE_SHARE = 0.7
#: Ranges of ``U(low, high)`` for ordinary and nearly impossible pairs.
ORDINARY = (0.05, 0.95)
UNLIKELY = (0.001, 0.02)


def instance(family: str, n: int, seed: int = 0) -> np.ndarray:
    """The ``n x n`` support-probability matrix of ``family`` for ``seed``.

    Parameters
    ----------
    family : {"dense", "sparse"}
        Which instance family.
    n : int
        Number of boxes (at least 2).
    seed : int
        Seed of ``numpy.random.default_rng``.

    Returns
    -------
    numpy.ndarray, shape (n, n)
        ``P[i, j] = P(SUPP(box_i, box_j))``, diagonal 0.
    """
    if family not in FAMILIES:
        raise ValueError(f"unknown family {family!r}; expected one of {', '.join(FAMILIES)}")
    if n < 2:
        raise ValueError(f"need at least 2 boxes, got {n}")
    rng = np.random.default_rng(seed)
    off_diagonal = ~np.eye(n, dtype=bool)
    values = rng.uniform(*ORDINARY, size=n * (n - 1))
    if family == "sparse":
        unlikely = rng.choice(values.size, size=round(SPARSE_SHARE * values.size), replace=False)
        values[unlikely] = rng.uniform(*UNLIKELY, size=unlikely.size)
    probabilities = np.zeros((n, n))
    probabilities[off_diagonal] = values
    return probabilities


def box_ids(n: int) -> list[str]:
    """Box ids ``b0 .. b{n-1}`` (the matrix order)."""
    return [f"b{i}" for i in range(n)]


def supports(family: str, n: int, seed: int = 0) -> Supports:
    """:func:`instance` wrapped as :class:`unstack.Supports` with ids ``b0 .. b{n-1}``."""
    return Supports(box_ids(n), instance(family, n, seed))
