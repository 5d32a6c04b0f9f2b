"""Ground truth by removal on piles whose answer is known, and the transitivity statistic."""

from __future__ import annotations

import networkx as nx
import numpy as np
import pytest
from hypothesis import given
from hypothesis import settings as hypothesis_settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from unstack.sim.ground_truth import removal_responses, support_labels, transitivity_violations
from unstack.sim.settings import SimulationSettings
from unstack.sim.world import PhysicsWorld


@pytest.mark.slow  # runs removals in the physics engine
def test_a_column_of_three(settings: SimulationSettings) -> None:
    with PhysicsWorld(settings, door=False) as world:
        for level in range(3):
            world.add_box([0.4, 0.3, 0.3], [0.5, 0.0, 0.15 + 0.3 * level], [0, 0, 0, 1], mass=8.0)
        world.settle()
        before, _ = world.poses()
        response = removal_responses(world, settings.ground_truth)
        after, _ = world.poses()
    labels = support_labels(response.displacement, response.rotation_deg)
    assert labels.tolist() == [[0, 1, 1], [0, 0, 1], [0, 0, 0]]
    assert response.baseline_displacement < settings.ground_truth.creep_displacement
    assert np.array_equal(before, after)  # the world is left in the settled state


@pytest.mark.slow  # runs removals in the physics engine
def test_side_by_side_boxes_do_not_support_each_other(settings: SimulationSettings) -> None:
    with PhysicsWorld(settings, door=False) as world:
        world.add_box([0.4, 0.3, 0.3], [0.5, -0.3, 0.15], [0, 0, 0, 1], mass=8.0)
        world.add_box([0.4, 0.3, 0.3], [0.5, 0.3, 0.15], [0, 0, 0, 1], mass=8.0)
        world.settle()
        response = removal_responses(world, settings.ground_truth)
    assert support_labels(response.displacement, response.rotation_deg).sum() == 0
    assert response.displacement.max() < 1e-3


def test_thresholds_are_applied_to_the_raw_responses() -> None:
    moved = np.array([[0.0, 0.015, 0.3], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]])
    turned = np.array([[0.0, 0.0, 0.0], [6.0, 0.0, 0.0], [0.0, 0.0, 0.0]])
    assert support_labels(moved, turned).tolist() == [[0, 0, 1], [1, 0, 0], [0, 0, 0]]
    loose = support_labels(moved, turned, displacement_threshold=0.01, rotation_threshold_deg=10.0)
    assert loose.tolist() == [[0, 1, 1], [0, 0, 0], [0, 0, 0]]


def _violations_by_networkx(support: np.ndarray) -> tuple[int, int]:
    graph = nx.DiGraph(support)
    violated = premises = 0
    for x, y in graph.edges:
        for z in graph.successors(y):
            if len({x, y, z}) == 3:
                premises += 1
                violated += not graph.has_edge(x, z)
    return violated, premises


@hypothesis_settings(max_examples=60, deadline=None)
@given(arrays(np.int64, st.tuples(st.integers(1, 7)).map(lambda n: (n[0], n[0])), elements=st.integers(0, 1)))
def test_transitivity_statistic_matches_networkx(support: np.ndarray) -> None:
    np.fill_diagonal(support, 0)
    assert transitivity_violations(support) == _violations_by_networkx(support)


@pytest.mark.parametrize("n", [2, 5])
def test_a_transitive_relation_has_no_violations(n: int) -> None:
    order = np.triu(np.ones((n, n), dtype=np.int64), 1)
    assert transitivity_violations(order)[0] == 0
