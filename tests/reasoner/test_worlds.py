"""SAT enumeration: probabilities by Eqs. 8-10 in log space, the payoff matrix of Table II."""

from __future__ import annotations

import jsonschema
import numpy as np
import pytest

from tests.conftest import random_probabilities, supports_of
from tests.reasoner.oracle import brute_force
from unstack.jsonio import load_schema
from unstack.reasoner import enumerate_worlds, payoff_matrix
from unstack.supports import Supports


@pytest.mark.parametrize("n", [2, 3, 4])
def test_world_probabilities_are_normalised_products(n: int, rng: np.random.Generator) -> None:
    probabilities = random_probabilities(n, rng)
    worlds = enumerate_worlds(supports_of(probabilities))
    off = ~np.eye(n, dtype=bool)
    products = np.array([np.prod(np.where(w, probabilities, 1 - probabilities)[off]) for w in worlds.worlds])
    np.testing.assert_allclose(worlds.probabilities, products / products.sum(), rtol=1e-12)
    np.testing.assert_allclose(worlds.log_weights, np.log(products), rtol=1e-12)
    np.testing.assert_allclose(worlds.marginals(), brute_force(probabilities)[0], atol=1e-12)


def test_no_underflow_with_tiny_probabilities() -> None:
    # Every world's plain product underflows to 0 in float64; log space keeps them apart.
    probabilities = np.full((5, 5), 1e-300)  # 4,231 worlds
    probabilities[0, 1] = 1e-250
    np.fill_diagonal(probabilities, 0.0)
    worlds = enumerate_worlds(supports_of(probabilities))
    assert np.isclose(worlds.probabilities.sum(), 1.0)
    assert np.all(np.isfinite(worlds.log_weights))
    best = worlds.worlds[np.argmax(worlds.probabilities)]
    assert not best.any()  # the empty world dominates
    marginals = worlds.marginals()
    assert 0 < marginals[0, 1] < 1e-240 and marginals[0, 1] > marginals[1, 0]


def test_payoff_matrix_matches_the_paper_example() -> None:
    # Fig. 2b: removing A, B, C, D costs 3, 2, 0 and 1 (A>B, A>C, A>D, B>C, B>D, D>C).
    objects = ["A", "B", "C", "D"]
    certain = np.zeros((4, 4))
    for a, b in [("A", "B"), ("A", "C"), ("A", "D"), ("B", "C"), ("B", "D"), ("D", "C")]:
        certain[objects.index(a), objects.index(b)] = 1.0
    table = payoff_matrix(Supports(objects, certain))
    assert len(table.worlds) == 1
    assert table.costs[0].tolist() == [3.0, 2.0, 0.0, 1.0]
    assert table.expected_costs().tolist() == [3.0, 2.0, 0.0, 1.0]


def test_mass_weighted_payoff(rng: np.random.Generator) -> None:
    probabilities = random_probabilities(3, rng)
    masses = np.array([5.0, 10.0, 20.0])
    table = payoff_matrix(Supports(["a", "b", "c"], probabilities, masses), cost="mass")
    expected = table.worlds.marginals() @ masses
    np.testing.assert_allclose(table.expected_costs(), expected, rtol=1e-12)


@pytest.mark.parametrize("cost", ["count", "load"])
def test_the_payoff_matrix_gives_decides_expected_costs(rng: np.random.Generator, cost: str) -> None:
    """The load cost counts the picked box's own hidden load in every world, as decide does."""
    from unstack.reasoner.decision import decide

    probabilities = rng.uniform(0.0, 1.0, (4, 4))
    np.fill_diagonal(probabilities, 0.0)
    supports = Supports(["a", "b", "c", "d"], probabilities, hidden_load=rng.uniform(0.0, 3.0, 4))
    table = payoff_matrix(supports, cost=cost)
    np.testing.assert_allclose(table.expected_costs(), decide(supports, method="exact", cost=cost).expected_costs)


def test_the_payoff_matrix_doubts_masses_lighter_than_a_carton_as_decide_does() -> None:
    supports = Supports(["a", "b"], [[0, 0.5], [0.2, 0]], masses=[1e-300, 12.0])
    light = "box 'a' (1e-300 kg) weighs less than 0.01 kg, lighter than a carton"
    assert any(light in warning for warning in payoff_matrix(supports, cost="mass").warnings)
    assert not payoff_matrix(supports, cost="count").warnings


def test_the_payoff_matrix_carries_the_inputs_warnings_into_its_document() -> None:
    doubtful = Supports(["a", "b"], [[0, 0.9], [0.0, 0]], metadata={"warnings": ["box 'a' floats"]})
    table = payoff_matrix(doubtful)
    assert table.warnings == ("box 'a' floats",) and table.to_dict()["warnings"] == ["box 'a' floats"]
    jsonschema.validate(table.to_dict(), load_schema("unstack.payoff/1"))
    assert "warnings" not in payoff_matrix(Supports(["a", "b"], [[0, 0.9], [0.0, 0]])).to_dict()
