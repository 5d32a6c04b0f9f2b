"""Re-inserting the noisiest boxes more often (unstack.reasoner.revisits and the sampler's schedule)."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.reasoner.chain_check import assert_costs_match_exact, seven_boxes
from unstack.reasoner.marginals import exact_marginals
from unstack.reasoner.revisits import MAX_VISITS, schedule, visits
from unstack.reasoner.sampling import _Chains, sampled_marginals


@given(st.lists(st.floats(min_value=0.0, max_value=1.0), min_size=1, max_size=63))
@settings(max_examples=200, deadline=None)
def test_schedule_holds_every_box_its_visits_times(errors: list[float]) -> None:
    standard_errors = np.array(errors)
    counts = visits(standard_errors)
    order = schedule(standard_errors)
    assert np.all((counts >= 1) & (counts <= MAX_VISITS))
    np.testing.assert_array_equal(np.bincount(order, minlength=len(errors)), counts)


def test_a_tiny_reference_error_gives_the_most_visits_without_a_warning() -> None:
    errors = np.array([1.0, 1e-300, 1e-300, 1e-300, 1e-300])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert visits(errors).tolist() == [MAX_VISITS, 1, 1, 1, 1]


def test_no_error_anywhere_keeps_every_box_once_in_order() -> None:
    np.testing.assert_array_equal(schedule(np.zeros(5)), np.arange(5))


def test_the_noisiest_box_gets_the_most_visits_spread_through_the_pass() -> None:
    errors = np.full(20, 0.01)
    errors[7] = 0.03
    order = schedule(errors)
    assert visits(errors)[7] == 9
    gaps = np.diff(np.flatnonzero(order == 7))
    assert gaps.max() <= 4  # 28 re-insertions, box 7 never waits long


@pytest.mark.slow
@pytest.mark.parametrize("seed", [0, 1])
def test_chains_with_a_skewed_schedule_agree_with_the_exact_engine(seed: int) -> None:
    p = seven_boxes(seed)
    chains = _Chains(p, chains=8, seed=seed, burn_in=64, tries=1, blocks=False)
    chains.schedule = np.array([0, 3, 3, 1, 3, 2, 3, 4, 3, 5, 6, 3], dtype=np.int64)
    chains.moves = 3  # fewer moves than boxes, so the schedule decides who moves
    assert_costs_match_exact(chains, exact_marginals(p).marginals)


@pytest.fixture
def two_groups() -> np.ndarray:
    """Ten boxes in two groups of five with nothing across: exact per group, sampled whole."""
    rng = np.random.default_rng(3)
    p = np.zeros((10, 10))
    for start in (0, 5):
        block = rng.uniform(0.0, 1.0, (5, 5)) ** 2
        np.fill_diagonal(block, 0.0)
        p[start : start + 5, start : start + 5] = block
    return p


def test_sampled_marginals_revisits_the_noisy_boxes_and_reports_the_schedule(two_groups: np.ndarray) -> None:
    result = sampled_marginals(two_groups, samples=16_384, seed=4)
    assert result.schedule is not None
    assert len(result.schedule) >= 10
    np.testing.assert_array_equal(np.unique(result.schedule), np.arange(10))
    plain = sampled_marginals(two_groups, samples=16_384, seed=4, revisits=False)
    np.testing.assert_array_equal(plain.schedule, np.arange(10))
    again = sampled_marginals(two_groups, samples=16_384, seed=4)
    np.testing.assert_array_equal(result.marginals, again.marginals)


@pytest.mark.slow
def test_sampled_marginals_with_revisits_agree_with_the_exact_engine_per_group(two_groups: np.ndarray) -> None:
    truth = np.zeros((10, 10))
    for start in (0, 5):
        block = slice(start, start + 5)
        truth[block, block] = exact_marginals(two_groups[block, block]).marginals
    result = sampled_marginals(two_groups, samples=65_536, seed=5)
    costs, covariance = result.errors_of(np.ones(10))
    assert np.all(np.abs(costs - truth.sum(axis=1)) < 4 * np.sqrt(np.diag(covariance)) + 2e-3)
