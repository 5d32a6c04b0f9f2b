"""Path-consistency pruning of hard evidence with networkx."""

from __future__ import annotations

import numpy as np
import pytest

from tests.conftest import random_probabilities
from tests.reasoner.oracle import brute_force
from unstack.errors import NoConsistentWorld
from unstack.reasoner import propagate_evidence

IDS = ["a", "b", "c", "d"]


def matrix(entries: dict[tuple[str, str], float], fill: float = 0.5) -> np.ndarray:
    probabilities = np.full((4, 4), fill)
    np.fill_diagonal(probabilities, 0.0)
    for (x, y), value in entries.items():
        probabilities[IDS.index(x), IDS.index(y)] = value
    return probabilities


def test_forced_chain_forces_its_closure() -> None:
    evidence = propagate_evidence(IDS, matrix({("a", "b"): 1, ("b", "c"): 1, ("c", "d"): 1}))
    assert set(evidence.forced) == {("a", "b"), ("b", "c"), ("c", "d"), ("a", "c"), ("a", "d"), ("b", "d")}
    assert evidence.forbidden == ()


def test_forbidden_relation_propagates_backwards_through_forced_ones() -> None:
    # a -> b forced and a -> c forbidden: b -> c would force a -> c, so it is forbidden too.
    evidence = propagate_evidence(IDS, matrix({("a", "b"): 1, ("a", "c"): 0}))
    assert ("b", "c") in evidence.forbidden
    assert evidence.probabilities[IDS.index("b"), IDS.index("c")] == 0.0


def test_pruning_keeps_the_conditional_distribution(rng: np.random.Generator) -> None:
    probabilities = random_probabilities(4, rng, hard=0.2)
    probabilities[0, 1] = probabilities[1, 2] = 1.0
    probabilities[0, 3] = 0.0
    pruned = propagate_evidence(IDS, probabilities).probabilities
    np.testing.assert_allclose(brute_force(pruned)[0], brute_force(probabilities)[0], atol=1e-12)


def test_contradiction_names_the_relations() -> None:
    probabilities = matrix({("a", "b"): 1, ("b", "c"): 1, ("a", "c"): 0})
    with pytest.raises(
        NoConsistentWorld,
        match=r"P\(SUPP\(a, b\)\) = 1 and P\(SUPP\(b, c\)\) = 1 force SUPP\(a, c\).*P\(SUPP\(a, c\)\) = 0",
    ) as caught:
        propagate_evidence(IDS, probabilities)
    assert caught.value.conflict == [("a", "b", 1), ("b", "c", 1), ("a", "c", 0)]


def test_mutual_support_is_allowed() -> None:
    evidence = propagate_evidence(IDS, matrix({("a", "b"): 1, ("b", "a"): 1}))
    assert {("a", "b"), ("b", "a")} <= set(evidence.forced)
