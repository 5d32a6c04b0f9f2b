"""Consistent worlds: Table I by both methods, the OEIS counts, networkx as the oracle."""

from __future__ import annotations

import networkx as nx
import numpy as np
import pytest

from tests.conftest import random_probabilities, supports_of
from unstack.reasoner import (
    PREORDER_COUNTS,
    SupportVariables,
    enumerate_worlds,
    exact_marginals,
    is_transitive,
    transitivity_clauses,
)

TABLE_I = {3: 29, 4: 355, 5: 6942, 6: 209527}


def uniform(n: int) -> np.ndarray:
    half = np.full((n, n), 0.5)
    np.fill_diagonal(half, 0.0)
    return half


def networkx_transitive(world: np.ndarray) -> bool:
    graph = nx.DiGraph()
    graph.add_nodes_from(range(world.shape[0]))
    graph.add_edges_from(map(tuple, np.argwhere(world)))
    closure = nx.transitive_closure(graph, reflexive=None)
    return {(a, b) for a, b in closure.edges if a != b} == set(graph.edges)


@pytest.mark.parametrize(("n", "count"), sorted(TABLE_I.items()))
def test_table_i_by_exact_engine(n: int, count: int) -> None:
    assert exact_marginals(uniform(n)).consistent_worlds == count


@pytest.mark.parametrize(
    ("n", "count"), [pytest.param(n, count, marks=[pytest.mark.slow] if n == 6 else []) for n, count in TABLE_I.items()]
)
def test_table_i_by_sat_enumeration(n: int, count: int) -> None:
    assert len(enumerate_worlds(supports_of(uniform(n)))) == count


def test_seven_boxes_have_9535241_worlds() -> None:
    assert exact_marginals(uniform(7)).consistent_worlds == 9_535_241 == PREORDER_COUNTS[7]


@pytest.mark.parametrize("n", [2, 3, 4, 5])
def test_every_enumerated_world_passes_networkx(n: int, rng: np.random.Generator) -> None:
    worlds = enumerate_worlds(supports_of(random_probabilities(n, rng, hard=0.2)))
    assert all(networkx_transitive(world) for world in worlds.worlds)
    assert all(is_transitive(world) for world in worlds.worlds)
    assert len({world.tobytes() for world in worlds.worlds}) == len(worlds)


def test_transitivity_clauses_name_domain_tuples() -> None:
    variables = SupportVariables(["a", "b", "c"])
    clauses = transitivity_clauses(variables)
    named = {tuple((lit > 0, variables.relation(lit)) for lit in clause) for clause in clauses}
    assert ((False, ("a", "b")), (False, ("b", "c")), (True, ("a", "c"))) in named
    assert len(clauses) == 3 * 2 * 1
    assert variables.pool.obj(variables.id("c", "a")) == ("supports", "c", "a")


def test_is_transitive_rejects_the_papers_figure_2c() -> None:
    # A supports B, B supports D, but A does not support D (Fig. 2c).
    world = np.zeros((4, 4), dtype=bool)
    world[0, 1] = world[1, 3] = True
    assert not is_transitive(world)
    assert not networkx_transitive(world)
    world[0, 3] = True
    assert is_transitive(world)
