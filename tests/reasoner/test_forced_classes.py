"""Boxes that surely support each other: sampled as one class, and agreeing with the exact engine.

The sampler re-inserts one box at a time, so before the classes it never changed the relations of
two boxes tied by P = 1 both ways and gave far-off expected costs with tiny errors (fuzz round 10).
"""

from __future__ import annotations

import networkx as nx
import numpy as np
import pytest

from tests.reasoner.oracle import assert_within_errors
from unstack.reasoner.forced_classes import forced_classes, quotient_probabilities, spread_pairs
from unstack.reasoner.marginals import exact_marginals
from unstack.reasoner.sampling import sample_worlds, sampled_marginals


def with_forced_pairs(rng: np.random.Generator, n: int, pairs: list[tuple[int, int]]) -> np.ndarray:
    """Probabilities from U(0.1, 0.9) with P = 1 both ways between the boxes of each pair."""
    p = rng.uniform(0.1, 0.9, (n, n))
    np.fill_diagonal(p, 0.0)
    for a, b in pairs:
        p[a, b] = p[b, a] = 1.0
    return p


def test_the_classes_are_the_strongly_connected_boxes_of_the_certain_relations(rng: np.random.Generator) -> None:
    p = rng.uniform(0.1, 0.9, (7, 7))
    np.fill_diagonal(p, 0.0)
    p[0, 3] = p[3, 5] = p[5, 0] = 1.0  # a cycle of certain relations
    p[1, 2] = 1.0  # one way only: no class
    p[4, 6] = p[6, 4] = 1.0
    graph = nx.DiGraph((int(i), int(j)) for i, j in zip(*np.nonzero(p >= 1.0), strict=True))
    graph.add_nodes_from(range(7))
    expected = {frozenset(component) for component in nx.strongly_connected_components(graph)}
    classes = forced_classes(p)
    assert classes is not None
    assert {frozenset(np.flatnonzero(classes == c).tolist()) for c in range(classes.max() + 1)} == expected


def test_no_class_of_two_boxes_leaves_the_matrix_to_the_sampler_as_it_is() -> None:
    p = np.array([[0.0, 1.0, 0.3], [0.2, 0.0, 1.0], [0.0, 0.4, 0.0]])
    assert forced_classes(p) is None


def test_a_class_relates_to_another_by_the_sum_of_its_pairs_logits() -> None:
    p = np.array([[0.0, 1.0, 0.8], [1.0, 0.0, 0.6], [0.3, 0.5, 0.0]])
    merged = quotient_probabilities(p, np.array([0, 0, 1]))
    odds = (0.8 / 0.2) * (0.6 / 0.4)
    assert merged[0, 1] == pytest.approx(odds / (1 + odds))
    assert merged[1, 0] == pytest.approx(0.3 * 0.5 / (0.3 * 0.5 + 0.7 * 0.5))


@pytest.mark.parametrize("pairs", [[(0, 1)], [(0, 1), (2, 3)], [(0, 1), (1, 2), (4, 5)]])
def test_sampled_marginals_with_forced_classes_agree_with_the_exact_engine(
    rng: np.random.Generator, pairs: list[tuple[int, int]]
) -> None:
    p = with_forced_pairs(rng, 8, pairs)
    exact = exact_marginals(p).marginals
    result = sampled_marginals(p, samples=16_000, seed=1)
    assert_within_errors(result, exact)
    for a, b in pairs:
        assert result.marginals[a, b] == result.marginals[b, a] == 1.0 and result.standard_errors[a, b] == 0.0


def test_sampled_worlds_keep_a_class_together_and_match_the_exact_marginals(rng: np.random.Generator) -> None:
    p = with_forced_pairs(rng, 6, [(0, 1), (2, 3)])
    draws = sample_worlds(p, 6000, seed=0)
    assert draws.dtype == bool and draws[:, 0, 1].all() and draws[:, 3, 2].all()
    assert np.array_equal(draws[:, 0, 4], draws[:, 1, 4]) and np.array_equal(draws[:, 5, 2], draws[:, 5, 3])
    np.testing.assert_allclose(draws.mean(axis=0), exact_marginals(p).marginals, atol=0.05)


def test_spreading_keeps_batches_and_the_diagonal() -> None:
    batches = np.array([[[0.0, 0.25], [0.5, 0.0]], [[0.0, 0.75], [0.5, 0.0]]])
    spread = spread_pairs(batches, np.array([1, 0, 0]), 1.0)
    assert spread.shape == (2, 3, 3)
    assert spread[1].tolist() == [[0.0, 0.5, 0.5], [0.75, 0.0, 1.0], [0.75, 1.0, 0.0]]
