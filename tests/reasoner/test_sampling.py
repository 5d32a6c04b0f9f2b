"""The sampling engine against exact answers, and its invariants."""

from __future__ import annotations

from pathlib import Path

import networkx as nx
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from tests.reasoner.oracle import assert_within_errors
from unstack.errors import UnstackError
from unstack.reasoner import sampling
from unstack.reasoner.marginals import exact_marginals
from unstack.reasoner.pruning import propagate_evidence
from unstack.reasoner.sampling import sample_worlds, sampled_marginals
from unstack.supports import Supports


def random_probabilities(rng: np.random.Generator, n: int, kind: str) -> np.ndarray:
    """Dense (uniform), sparse (mostly small) or pile-like (a few strong relations) matrices."""
    if kind == "dense":
        p = rng.uniform(0.0, 1.0, (n, n))
    elif kind == "sparse":
        p = rng.beta(0.3, 3.0, (n, n))
    else:
        p = rng.uniform(0.01, 0.08, (n, n))
        strong = rng.random((n, n)) < 2.0 / n
        p[strong] = rng.uniform(0.5, 0.95, strong.sum())
    np.fill_diagonal(p, 0.0)
    return p


def is_transitive(world: np.ndarray) -> bool:
    """networkx as the oracle: the closure adds no relation."""
    graph = nx.DiGraph()
    graph.add_nodes_from(range(len(world)))
    graph.add_edges_from(zip(*np.nonzero(world), strict=True))
    closure = nx.transitive_closure(graph, reflexive=False)
    return {(int(i), int(j)) for i, j in closure.edges if i != j} == {
        (int(i), int(j)) for i, j in zip(*np.nonzero(world), strict=True)
    }


@pytest.mark.parametrize("kind", ["dense", "sparse", "pile"])
@pytest.mark.parametrize("n", [2, 4, 6])
def test_marginals_agree_with_the_exact_engine(rng: np.random.Generator, n: int, kind: str) -> None:
    p = random_probabilities(rng, n, kind)
    exact = exact_marginals(p).marginals
    assert_within_errors(sampled_marginals(p, samples=16_000, seed=1), exact)


@pytest.mark.parametrize("moves", [1, 2])
def test_sweeps_of_a_few_re_insertions_in_turn_agree_with_the_exact_engine(
    rng: np.random.Generator, moves: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Groups of more than ``MOVES`` boxes re-insert only the next ``MOVES`` boxes per sweep."""
    monkeypatch.setattr(sampling, "MOVES", moves)
    p = random_probabilities(rng, 6, "dense")
    exact = exact_marginals(p).marginals
    result = sampled_marginals(p, samples=16_000, seed=1, blocks=False)
    assert result.samples == 16_000
    assert_within_errors(result, exact)


def test_independent_components_up_to_forty_boxes(rng: np.random.Generator) -> None:
    """Eight unlinked groups of five: the exact answer is known group by group."""
    n, size = 40, 5
    p = np.zeros((n, n))
    exact = np.zeros((n, n))
    for start in range(0, n, size):
        block = slice(start, start + size)
        p[block, block] = random_probabilities(rng, size, "pile")
        exact[block, block] = exact_marginals(p[block, block]).marginals
    result = sampled_marginals(p, samples=4_000, seed=2)
    costs, covariance = result.errors_of(np.ones(n))
    errors = np.abs(costs - exact.sum(axis=1))
    assert np.all(errors <= 5 * np.sqrt(np.diag(covariance)) + 2e-3)
    assert errors.max() < 0.05
    assert np.all(result.marginals[p == 0] == 0.0)


@pytest.mark.slow
@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(arrays(np.float64, (5, 5), elements=st.sampled_from([0.0, 0.05, 0.3, 0.5, 0.9, 1.0])), st.integers(0, 2**32))
def test_every_sampled_world_is_consistent_and_respects_evidence(matrix: np.ndarray, seed: int) -> None:
    np.fill_diagonal(matrix, 0.0)
    try:
        evidence = propagate_evidence([str(i) for i in range(5)], matrix)
    except UnstackError:
        return  # contradictory hard evidence: nothing to sample
    p = evidence.probabilities
    for world in sample_worlds(p, 20, seed=seed, burn_in=2):
        assert is_transitive(world)
        assert np.all(world[p >= 1.0]) and not np.any(world[p <= 0.0])


def test_same_seed_and_samples_give_the_same_answer(rng: np.random.Generator) -> None:
    p = random_probabilities(rng, 9, "dense")
    first = sampled_marginals(p, samples=800, seed=5)
    second = sampled_marginals(p, samples=800, seed=5)
    np.testing.assert_array_equal(first.marginals, second.marginals)
    np.testing.assert_array_equal(first.standard_errors, second.standard_errors)
    assert not np.array_equal(first.marginals, sampled_marginals(p, samples=800, seed=6).marginals)


def test_more_samples_give_smaller_errors(rng: np.random.Generator) -> None:
    p = random_probabilities(rng, 12, "pile")
    short = sampled_marginals(p, samples=1_000, seed=3)
    long = sampled_marginals(p, samples=16_000, seed=3)
    assert long.standard_errors.max() < short.standard_errors.max()
    assert long.samples >= 16_000 and short.samples >= 1_000


def test_time_limit_bounds_the_run(rng: np.random.Generator) -> None:
    """A 0.2 s limit ends the run within a generous margin (shared CI machines are slow and noisy)."""
    import time

    p = random_probabilities(rng, 20, "pile")
    sampled_marginals(p, samples=10, seed=0)  # compile the kernels outside the timed run
    start = time.perf_counter()
    result = sampled_marginals(p, time_limit=0.2, seed=0)
    elapsed = time.perf_counter() - start
    assert elapsed < 0.2 + 5.0, elapsed
    assert result.samples > 0 and len(result.batch_marginals) >= 2 * result.chains


def test_bad_arguments_are_refused(rng: np.random.Generator) -> None:
    with pytest.raises(UnstackError, match="samples must be at least 1, got 0"):
        sampled_marginals(np.zeros((3, 3)), samples=0)
    with pytest.raises(UnstackError, match="seed must be at least 0, got -2"):
        sampled_marginals(np.zeros((3, 3)), samples=10, seed=-2)
    with pytest.raises(ValueError, match="time_limit must be a positive, finite number of seconds, got nan"):
        sampled_marginals(np.zeros((3, 3)), time_limit=float("nan"))
    with pytest.raises(ValueError, match="chains must be at least 1, got 0"):
        sampled_marginals(np.zeros((3, 3)), samples=10, chains=0)
    with pytest.raises(ValueError, match=r"probabilities\[0\]\[1\]: expected a probability in \[0, 1\], got 2.0"):
        sampled_marginals(np.array([[0, 2.0], [0, 0]]), samples=10)


def test_convergence_is_near_one_when_chains_agree(rng: np.random.Generator) -> None:
    p = random_probabilities(rng, 5, "dense")
    result = sampled_marginals(p, samples=16_000, seed=0)
    rhat = result.convergence_of(np.ones(5))
    assert rhat.shape == (5,) and np.all(rhat < 1.05)


def test_a_short_run_on_a_real_pile_warns_that_chains_disagree(repo: Path) -> None:
    from unstack.reasoner.decision import decide
    from unstack.supports import load_supports

    supports = load_supports(repo / "examples" / "pile31.supports.json")
    short = decide(supports, samples=500, seed=0)
    assert short.sampling is not None and short.sampling["rhat_max"] > 1.1
    assert "the chains disagree" in short.sampling["warning"]
    assert short.sampling["warning"] in short.warnings  # with the decision's warnings, printed by the CLI
    longer = decide(supports, samples=8_000, seed=0)
    assert longer.sampling is not None and "warning" not in longer.sampling
    assert not any("chains disagree" in warning for warning in longer.warnings)


def _sparse_pile(n: int, seed: int = 0) -> Supports:
    """``n`` boxes, 4 n random relations (``P`` uniform), zeros elsewhere: one linked group."""
    rng = np.random.default_rng(seed)
    probabilities = np.zeros((n, n))
    rows, columns = rng.integers(n, size=(2, 4 * n))
    probabilities[rows, columns] = rng.random(4 * n)
    np.fill_diagonal(probabilities, 0.0)
    return Supports([f"b{i:04d}" for i in range(n)], probabilities)


def test_a_time_limit_the_least_sampling_cannot_come_near_is_refused_after_a_few_sweeps(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """1,000 linked boxes with a limit of 0.2 s ran 20 s (3,000 with 2 s: over 400 s) before
    warning. Without the 2 s of slack any group's least sampling is beyond a limit already used
    up, on any machine: 200 boxes then show the refusal in a second."""
    from unstack.errors import TooLarge
    from unstack.reasoner.decision import decide

    monkeypatch.setattr(sampling, "_UNMEETABLE_SLACK", 0.0)
    with pytest.raises(TooLarge, match=r"a group of \d+ linked boxes needs about \d+ s more of sampling at the least"):
        decide(_sparse_pile(200), time_limit=1e-6, seed=1)


@pytest.mark.parametrize("time_limit", [0.01, 0.3])
def test_a_container_sized_group_is_never_refused_for_its_time_limit(time_limit: float) -> None:
    from unstack.reasoner.decision import decide

    decision = decide(_sparse_pile(60), time_limit=time_limit, seed=1)
    assert decision.sampling is not None and decision.choice in decision.objects
