"""The compiled insertion sum over a free set and the sampler's summed rows
(unstack.reasoner._insertion_sum_kernels, unstack.reasoner.summed_insertions)."""

from __future__ import annotations

import numpy as np
import pytest

from tests.reasoner.chain_check import assert_costs_match_exact, seven_boxes
from tests.reasoner.test_insertion import enumerated_row, random_probabilities
from unstack.reasoner._insertion_sum_kernels import insertion_row, workspace
from unstack.reasoner.insertion import insertion_row_marginals
from unstack.reasoner.marginals import exact_marginals
from unstack.reasoner.sampling import _Chains, sample_worlds, sampled_marginals
from unstack.reasoner.summed_insertions import MAX_EXTRA_COST, choose, free_sets


def masks_of(world: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The sampler's state of a world: successor and predecessor bit masks."""
    n = len(world)
    relation = np.array(world, dtype=bool)
    np.fill_diagonal(relation, False)
    bits = np.left_shift(np.int64(1), np.arange(n, dtype=np.int64))
    return (
        np.array([int(bits[relation[y]].sum()) for y in range(n)], dtype=np.int64),
        np.array([int(bits[relation[:, y]].sum()) for y in range(n)], dtype=np.int64),
    )


def compiled_row(world: np.ndarray, p: np.ndarray, box: int, free: int, slots: int = 2048) -> np.ndarray | None:
    successors, predecessors = masks_of(world)
    row = np.full(len(p), np.nan)
    inside = insertion_row(box, np.int64(free), p, successors, predecessors, *workspace(len(p), slots), row)
    return row if inside else None


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(20261202)


@pytest.mark.parametrize("n", [2, 4, 6, 9, 12])
def test_compiled_sum_over_every_box_equals_the_python_reference(n: int, rng: np.random.Generator) -> None:
    p = random_probabilities(n, rng)
    everyone = (1 << n) - 1
    for world in sample_worlds(p, 4, seed=int(rng.integers(1000))):
        for box in range(n):
            row = compiled_row(world, p, box, everyone)
            assert row is not None
            np.testing.assert_allclose(row, insertion_row_marginals(world, p, box), atol=1e-12)


@pytest.mark.parametrize("n", [3, 4, 5])
def test_compiled_sum_over_a_free_set_equals_enumerating_the_cell(n: int, rng: np.random.Generator) -> None:
    p = random_probabilities(n, rng)
    checked = 0
    for world in sample_worlds(p, 6, seed=int(rng.integers(1000))):
        for box in range(n):
            free = [y for y in range(n) if y != box and rng.random() < 0.7]
            row = compiled_row(world, p, box, sum(1 << y for y in free))
            linked = set(np.flatnonzero(world[box]).tolist()) | set(np.flatnonzero(world[:, box]).tolist())
            if not linked - {box} <= set(free):
                assert row is None  # the world's insertion leaves the free set: a cell of its own
                continue
            assert row is not None
            np.testing.assert_allclose(row, enumerated_row(world, p, box, free), atol=1e-12)
            checked += 1
    assert checked > 0


def test_full_free_set_equals_enumerating_every_insertion(rng: np.random.Generator) -> None:
    p = random_probabilities(4, rng)
    world = sample_worlds(p, 1, seed=3)[0]
    np.testing.assert_allclose(compiled_row(world, p, 1, 0b1101), enumerated_row(world, p, 1), atol=1e-12)


def test_a_sum_that_outgrows_the_workspace_is_abandoned(rng: np.random.Generator) -> None:
    p = np.full((10, 10), 0.5)
    np.fill_diagonal(p, 0.0)
    empty = np.zeros((10, 10), dtype=bool)
    assert compiled_row(empty, p, 0, (1 << 10) - 2, slots=4) is None
    assert compiled_row(empty, p, 0, (1 << 10) - 2, slots=2048) is not None


def test_cell_averages_over_every_consistent_world_are_the_exact_marginals(rng: np.random.Generator) -> None:
    """The tower rule the sampler relies on: a cell's average, weighed by the worlds' probability, is
    the marginal. The free set leaves box 3 out, so worlds linking box 0 to it are their own cell."""
    from unstack.reasoner.worlds import enumerate_worlds
    from unstack.supports import Supports

    n = 4
    p = random_probabilities(n, rng)
    worlds = enumerate_worlds(Supports([f"b{i}" for i in range(n)], p)).worlds
    weights = np.array([np.prod(np.where(w, p, 1 - p)[~np.eye(n, dtype=bool)]) for w in worlds])
    weights /= weights.sum()
    exact = np.tensordot(weights, worlds.astype(float), axes=1)
    for box in range(n):
        free = 0b0110 if box == 0 else ((1 << n) - 1) & ~(1 << box)
        rows = []
        for world in worlds:
            row = compiled_row(world, p, box, free)
            rows.append(world[box].astype(float) if row is None else row)
        estimate = np.tensordot(weights, np.array(rows), axes=1)
        estimate[box] = 0.0
        np.testing.assert_allclose(estimate, np.where(np.eye(n, dtype=bool)[box], 0.0, exact[box]), atol=1e-12)


@pytest.mark.slow
@pytest.mark.parametrize("seed", [0, 1])
def test_chains_with_summed_rows_agree_with_the_exact_engine(seed: int) -> None:
    p = seven_boxes(seed)
    exact = exact_marginals(p).marginals
    chains = _Chains(p, chains=8, seed=seed, burn_in=64, tries=1, blocks=False)
    chains.sum_insertions(np.arange(7), free_sets(exact, np.arange(7), threshold=0.2), slots=2048)
    assert_costs_match_exact(chains, exact)
    sums, fallbacks, _ = chains.sum_stats.sum(axis=0)
    assert sums > 0 and fallbacks > 0  # both kinds of cells were met


def test_sampled_marginals_with_insertion_sums_is_reproducible_and_says_what_it_summed() -> None:
    rng = np.random.default_rng(5)
    n = 12
    p = rng.uniform(0.0, 1.0, (n, n)) ** 3
    np.fill_diagonal(p, 0.0)
    first = sampled_marginals(p, samples=4096, seed=2, insertion_sums=True)
    second = sampled_marginals(p, samples=4096, seed=2, insertion_sums=True)
    np.testing.assert_array_equal(first.marginals, second.marginals)
    assert first.summed_boxes is not None
    np.testing.assert_array_equal(first.summed_boxes, second.summed_boxes)
    plain = sampled_marginals(p, samples=4096, seed=2)
    assert plain.summed_boxes is not None and len(plain.summed_boxes) == 0


def test_free_sets_hold_the_boxes_linked_either_way_above_the_threshold() -> None:
    marginals = np.array([[0.0, 0.5, 0.001], [0.0, 0.0, 0.0], [0.2, 0.0, 0.0]])
    assert free_sets(marginals, np.array([0, 1, 2]), threshold=0.01).tolist() == [0b110, 0b001, 0b001]


@pytest.mark.parametrize(
    ("variances", "costs", "eligible", "expected"),
    [
        ([9.0, 1.0, 1.0], [0.1, 0.1, 0.1], [True, True, True], [0]),
        ([9.0, 8.0, 1.0], [0.1, 0.1, 0.1], [True, True, True], [0, 1]),
        ([9.0, 8.0, 1.0], [MAX_EXTRA_COST + 0.1, 0.1, 0.1], [True, True, True], []),
        ([9.0, 1.0, 1.0], [0.1, 0.1, 0.1], [False, True, True], []),
        ([9.0, 9.0, 9.0], [0.6, 0.6, 0.6], [True, True, True], []),
    ],
)
def test_choose_sums_the_noisiest_boxes_only_when_the_predicted_largest_variance_falls(
    variances: list[float], costs: list[float], eligible: list[bool], expected: list[int]
) -> None:
    assert choose(np.array(variances), np.array(costs), np.array(eligible)).tolist() == expected
