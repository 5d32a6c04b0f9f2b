"""The exact conditional of a box's relations given the rest (unstack.reasoner.insertion)."""

from __future__ import annotations

from itertools import product

import networkx as nx
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from unstack.errors import InvalidArgument
from unstack.reasoner.insertion import insertion_row_marginals
from unstack.reasoner.sampling import sample_worlds
from unstack.reasoner.worlds import enumerate_worlds
from unstack.supports import Supports


def is_transitive(relation: np.ndarray) -> bool:
    """networkx as the oracle: the relation equals its own transitive closure (self-loops aside)."""
    graph = nx.DiGraph()
    graph.add_nodes_from(range(len(relation)))
    graph.add_edges_from(zip(*np.nonzero(relation), strict=True))
    closure = nx.transitive_closure(graph, reflexive=False)
    return {(a, b) for a, b in closure.edges if a != b} == {(a, b) for a, b in graph.edges if a != b}


def enumerated_row(world: np.ndarray, probabilities: np.ndarray, box: int, free: list[int] | None = None) -> np.ndarray:
    """Every way of putting ``box`` back into ``world`` (among the boxes of ``free`` only, when
    given; the others then stay unlinked to it), weighed and checked one by one."""
    n = len(probabilities)
    others = [y for y in range(n) if y != box] if free is None else list(free)
    base = np.array(world, dtype=bool)
    np.fill_diagonal(base, False)
    base[box, :] = False
    base[:, box] = False
    total, held = 0.0, np.zeros(n)
    for row in product([False, True], repeat=len(others)):
        for column in product([False, True], repeat=len(others)):
            candidate = base.copy()
            candidate[box, others] = row
            candidate[others, box] = column
            if not is_transitive(candidate):
                continue
            weight = np.prod(np.where(row, probabilities[box, others], 1 - probabilities[box, others]))
            weight *= np.prod(np.where(column, probabilities[others, box], 1 - probabilities[others, box]))
            total += weight
            held += weight * candidate[box]
    return held / total


def half(n: int) -> np.ndarray:
    p = np.full((n, n), 0.5)
    np.fill_diagonal(p, 0.0)
    return p


def random_probabilities(n: int, rng: np.random.Generator) -> np.ndarray:
    p = rng.uniform(0.0, 1.0, (n, n)) ** 2
    np.fill_diagonal(p, 0.0)
    return p


@pytest.mark.parametrize("n", [2, 3, 4])
@pytest.mark.parametrize("seed", range(4))
def test_insertion_row_marginals_equal_every_insertion_enumerated(n: int, seed: int) -> None:
    rng = np.random.default_rng(seed)
    p = random_probabilities(n, rng)
    for world in sample_worlds(p, 3, seed=seed, thin=5):
        for box in range(n):
            assert insertion_row_marginals(world, p, box) == pytest.approx(enumerated_row(world, p, box), abs=1e-12)


@pytest.mark.parametrize("seed", range(3))
def test_averaged_over_the_consistent_worlds_the_rows_are_the_exact_marginals(seed: int) -> None:
    rng = np.random.default_rng(100 + seed)
    p = random_probabilities(4, rng)
    worlds = enumerate_worlds(Supports(list("abcd"), p))
    for box in range(4):
        rows = np.array([insertion_row_marginals(world, p, box) for world in worlds.worlds])
        assert worlds.probabilities @ rows == pytest.approx(worlds.marginals()[box], abs=1e-12)


def test_a_box_put_onto_a_stack_brings_the_boxes_above_along() -> None:
    p = np.array([[0.0, 0.5, 0.5], [0.0, 0.0, 0.9], [0.0, 0.0, 0.0]])
    world = np.zeros((3, 3), dtype=bool)
    world[1, 2] = True
    row = insertion_row_marginals(world, p, 0)
    # {}: 0.5 * 0.5, {2}: 0.5 * 0.5, {1, 2}: 0.5 * 0.5 ({1} alone breaks transitivity)
    assert row.tolist() == pytest.approx([0.0, 1 / 3, 2 / 3])


def test_the_box_own_relations_in_the_world_do_not_matter() -> None:
    rng = np.random.default_rng(7)
    p = random_probabilities(5, rng)
    world = sample_worlds(p, 1, seed=7)[0]
    changed = world.copy()
    changed[2, :] = False
    changed[:, 2] = False
    assert insertion_row_marginals(world, p, 2) == pytest.approx(insertion_row_marginals(changed, p, 2), abs=1e-15)


def test_hard_evidence_is_kept() -> None:
    p = np.array([[0.0, 1.0, 0.3], [0.0, 0.0, 0.8], [0.0, 0.0, 0.0]])
    world = np.zeros((3, 3), dtype=bool)
    world[1, 2] = True
    assert insertion_row_marginals(world, p, 0).tolist() == pytest.approx([0.0, 1.0, 1.0])


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**16), n=st.integers(2, 6))
def test_relabelling_the_boxes_relabels_the_row(seed: int, n: int) -> None:
    rng = np.random.default_rng(seed)
    p = random_probabilities(n, rng)
    world = sample_worlds(p, 1, seed=seed)[0]
    order = rng.permutation(n)
    box = int(rng.integers(n))
    row = insertion_row_marginals(world, p, box)
    relabelled = insertion_row_marginals(
        world[np.ix_(order, order)], p[np.ix_(order, order)], int(np.flatnonzero(order == box)[0])
    )
    assert relabelled == pytest.approx(row[order], abs=1e-12)
    assert np.all((row >= 0.0) & (row <= 1.0 + 1e-12))


def test_a_world_that_is_not_transitive_without_the_box_is_refused() -> None:
    world = np.zeros((4, 4), dtype=bool)
    world[1, 2] = world[2, 3] = True
    with pytest.raises(InvalidArgument, match="not transitive once the box is removed"):
        insertion_row_marginals(world, half(4), 0)


@pytest.mark.parametrize(
    ("world", "box", "message"),
    [
        (np.zeros((2, 2), dtype=bool), 0, r"world: expected shape \(3, 3\)"),
        (np.zeros((3, 3), dtype=bool), 3, r"box: expected an index in \[0, 3\)"),
        (np.zeros((3, 3), dtype=bool), -1, r"box: expected an index in \[0, 3\)"),
    ],
)
def test_bad_arguments_are_refused(world: np.ndarray, box: int, message: str) -> None:
    with pytest.raises(InvalidArgument, match=message):
        insertion_row_marginals(world, half(3), box)
