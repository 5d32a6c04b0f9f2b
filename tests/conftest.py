"""Shared fixtures: seeded random probability matrices and example files."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from unstack.supports import Supports

REPO = Path(__file__).resolve().parents[1]
EXAMPLES = REPO / "examples"


def random_probabilities(n: int, rng: np.random.Generator, *, hard: float = 0.0) -> np.ndarray:
    """Off-diagonal p ~ U(0.05, 0.95); a share ``hard`` of pairs set to exactly 0."""
    probabilities = rng.uniform(0.05, 0.95, size=(n, n))
    if hard:
        probabilities[rng.random((n, n)) < hard] = 0.0
    np.fill_diagonal(probabilities, 0.0)
    return probabilities


def supports_of(probabilities: np.ndarray) -> Supports:
    return Supports([f"b{i}" for i in range(len(probabilities))], probabilities)


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(20261122)


@pytest.fixture
def repo() -> Path:
    return REPO


@pytest.fixture
def examples() -> Path:
    return EXAMPLES
