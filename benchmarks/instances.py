"""Seeded benchmark instances: support-probability matrices of three families.

Both the pytest-benchmark suite (``test_reasoner.py``) and the side-by-side peer script
(``peers.py``) build their inputs here, so the same ``(family, n, seed)`` is the same
matrix everywhere. ``dense`` and ``sparse`` are random (:data:`FAMILIES`, the suite's
families); ``classifier`` is read from a file (:data:`ALL_FAMILIES` holds all three).

``dense``
    every off-diagonal ``P[i, j] ~ U(0.05, 0.95)``: no pair is nearly decided, the worst
    case for reasoning (every consistent world keeps a noticeable weight).
``sparse``
    70 % of the off-diagonal pairs (``round(0.7 * n * (n - 1))`` of them, chosen at
    random) get ``P[i, j] ~ U(0.001, 0.02)`` -- "almost surely not supporting", as a
    classifier says for most pairs of a real pile -- the rest ``U(0.05, 0.95)``.
``classifier``
    what the shipped support classifier says about simulated piles: the matrices of
    ``data/classifier-matrices.npz`` (8 piles of 31-40 boxes, keys ``config-0000`` ..
    ``config-0007``, written by ``make_classifier_matrices.py`` from
    ``unstack simulate --configs 8 --seed 7``). ``(n, seed)`` is the top-left ``n x n``
    block -- the first ``n`` boxes in the scene's order, i.e. the order they were dropped
    in -- of pile number ``seed % 8`` (keys sorted). Not random: most pairs are nearly
    impossible and the likely ones follow the pile's real geometry (probabilities are
    clipped to ``[1e-6, 1 - 1e-6]``). ``n`` larger than that pile is an error.

Each ``dense``/``sparse`` matrix comes from its own ``numpy.random.default_rng(seed)``;
row supports column, diagonal 0 (the project's convention).

Examples
--------
>>> probabilities = instance("sparse", 4, seed=0)
>>> probabilities.shape
(4, 4)
>>> bool((probabilities == instance("sparse", 4, seed=0)).all())
True
>>> int((probabilities[~np.eye(4, dtype=bool)] < 0.05).sum())  # round(0.7 * 12)
8
>>> bool((instance("classifier", 5, seed=9) == instance("classifier", 31, seed=1)[:5, :5]).all())
True
"""

from __future__ import annotations

from functools import cache
from pathlib import Path

import numpy as np

from unstack.supports import Supports

__all__ = [
    "ALL_FAMILIES",
    "CLASSIFIER_MATRICES",
    "FAMILIES",
    "SPARSE_SHARE",
    "box_ids",
    "classifier_matrices",
    "instance",
    "supports",
]

#: The random instance families (the pytest-benchmark suite runs these).
FAMILIES: tuple[str, ...] = ("dense", "sparse")
#: Every family, the file-backed ``classifier`` included.
ALL_FAMILIES: tuple[str, ...] = (*FAMILIES, "classifier")
#: The classifier's matrices of simulated piles (see ``make_classifier_matrices.py``).
CLASSIFIER_MATRICES = Path(__file__).resolve().parent / "data" / "classifier-matrices.npz"
#: Share of off-diagonal pairs that the sparse family makes nearly impossible.
SPARSE_SHARE = 0.7
#: Ranges of ``U(low, high)`` for ordinary and nearly impossible pairs.
ORDINARY = (0.05, 0.95)
UNLIKELY = (0.001, 0.02)


@cache
def classifier_matrices() -> tuple[tuple[str, np.ndarray], ...]:
    """``(key, matrix)`` of every pile in :data:`CLASSIFIER_MATRICES`, keys sorted."""
    with np.load(CLASSIFIER_MATRICES) as data:
        return tuple((key, data[key]) for key in sorted(data.files))


def instance(family: str, n: int, seed: int = 0) -> np.ndarray:
    """The ``n x n`` support-probability matrix of ``family`` for ``seed``.

    Parameters
    ----------
    family : {"dense", "sparse", "classifier"}
        Which instance family.
    n : int
        Number of boxes (at least 2; for ``classifier`` at most the pile's box count).
    seed : int
        Seed of ``numpy.random.default_rng``; for ``classifier`` the pile is number
        ``seed % 8`` (of the file's piles, keys sorted).

    Returns
    -------
    numpy.ndarray, shape (n, n)
        ``P[i, j] = P(SUPP(box_i, box_j))``, diagonal 0.
    """
    if family not in ALL_FAMILIES:
        raise ValueError(f"unknown family {family!r}; expected one of {', '.join(ALL_FAMILIES)}")
    if n < 2:
        raise ValueError(f"need at least 2 boxes, got {n}")
    if family == "classifier":
        piles = classifier_matrices()
        key, matrix = piles[seed % len(piles)]
        if n > len(matrix):
            raise ValueError(
                f"classifier seed {seed}: pile {key} (number {seed % len(piles)} of {len(piles)}) has "
                f"{len(matrix)} boxes, asked for n = {n}"
            )
        return matrix[:n, :n].copy()
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
