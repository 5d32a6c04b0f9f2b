"""Factorisation over groups of linked boxes agrees with the unfactorised engine."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.conftest import random_probabilities, supports_of
from unstack.reasoner.components import support_components
from unstack.reasoner.decision import decide
from unstack.reasoner.marginals import exact_marginals


def block_matrix(sizes: list[int], rng: np.random.Generator) -> np.ndarray:
    """Dense blocks on the diagonal, exactly 0 across blocks."""
    n = sum(sizes)
    probabilities = np.zeros((n, n))
    start = 0
    for size in sizes:
        probabilities[start : start + size, start : start + size] = random_probabilities(size, rng)
        start += size
    return probabilities


@pytest.mark.parametrize("sizes", [[4, 3], [2, 2, 2, 2], [5, 1, 2], [3, 3, 2]])
@pytest.mark.parametrize("method", ["exact", "sat"])
def test_factorised_equals_unfactorised(sizes: list[int], method: str, rng: np.random.Generator) -> None:
    probabilities = block_matrix(sizes, rng)
    order = rng.permutation(len(probabilities))  # groups interleaved in the input order
    probabilities = probabilities[np.ix_(order, order)]
    whole = exact_marginals(probabilities)
    decision = decide(supports_of(probabilities), method=method)
    assert np.allclose(decision.marginals, whole.marginals, atol=1e-12)
    assert decision.consistent_worlds == whole.consistent_worlds
    assert sorted(len(group) for group in decision.components) == sorted(sizes)


def test_a_scene_of_eighteen_boxes_in_three_groups(rng: np.random.Generator) -> None:
    probabilities = block_matrix([6, 6, 6], rng)
    decision = decide(supports_of(probabilities))
    assert decision.method == "exact" and decision.consistent_worlds == 209_527**3
    for block in range(3):
        part = slice(6 * block, 6 * block + 6)
        assert np.allclose(decision.marginals[part, part], exact_marginals(probabilities[part, part]).marginals)
    assert np.count_nonzero(decision.marginals) == 3 * 30


def test_forbidden_evidence_splits_groups() -> None:
    probabilities = np.array([[0.0, 0.6, 0.0], [0.3, 0.0, 0.0], [0.0, 0.0, 0.0]])
    decision = decide(supports_of(probabilities))
    assert decision.components == (("b0", "b1"), ("b2",))
    assert decision.to_dict()["components"] == [["b0", "b1"], ["b2"]]


@settings(max_examples=40, deadline=None)
@given(st.lists(st.integers(1, 4), min_size=1, max_size=5), st.integers(0, 2**32 - 1))
def test_groups_are_the_blocks(sizes: list[int], seed: int) -> None:
    rng = np.random.default_rng(seed)
    probabilities = block_matrix(sizes, rng)
    groups = support_components(probabilities)
    starts = np.cumsum([0, *sizes[:-1]])
    expected = [list(range(start, start + size)) for start, size in zip(starts, sizes, strict=True)]
    assert [group.tolist() for group in groups] == expected
