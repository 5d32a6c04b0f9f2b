"""The probability that the chosen box has the smallest true expected cost."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.stats import norm

from unstack.reasoner.confidence import choice_probability


def test_exact_costs_make_the_choice_certain() -> None:
    assert choice_probability(np.array([0.2, 0.5]), np.zeros((2, 2)), 0) == 1.0


def test_two_noisy_costs_give_the_normal_probability() -> None:
    costs, sd = np.array([1.0, 1.1]), 0.05
    expected = norm.cdf(0.1 / (sd * np.sqrt(2)))
    assert choice_probability(costs, np.eye(2) * sd**2, 0, seed=1) == pytest.approx(expected, abs=0.02)


@pytest.mark.parametrize("seed", range(3))
def test_boxes_far_above_the_choice_change_nothing(seed: int) -> None:
    rng = np.random.default_rng(seed)
    costs = rng.uniform(0.0, 0.2, 5)
    covariance = np.diag(rng.uniform(0.01, 0.05, 5) ** 2)
    choice = int(np.argmin(costs))
    alone = choice_probability(costs, covariance, choice, seed=seed)
    far = np.concatenate([costs, [5.0, 7.0]])
    wider = np.zeros((7, 7))
    wider[:5, :5] = covariance
    wider[5:, 5:] = np.diag([0.05, 0.05]) ** 2
    assert choice_probability(far, wider, choice, seed=seed) == alone


@pytest.mark.parametrize("choice", [0, 2, 3])
def test_a_choice_tied_at_an_exact_minimum_is_as_sure_as_any_of_the_ties(choice: int) -> None:
    # boxes 0, 2 and 3 certainly hold half a box up; box 1 probably holds a little more
    costs = np.array([0.5, 0.52, 0.5, 0.5])
    covariance = np.diag([0.0, 0.01, 0.0, 0.0]) ** 2
    assert choice_probability(costs, covariance, choice, seed=0) == pytest.approx(norm.cdf(2.0), abs=0.02)


@pytest.mark.parametrize("choice", [0, 2])
def test_a_choice_that_certainly_holds_nothing_up_is_certain(choice: int) -> None:
    # a noisy estimate near zero cannot be below zero: no box holds up fewer than none
    costs = np.array([0.0, 0.004, 0.0])
    covariance = np.diag([0.0, 0.01, 0.0]) ** 2
    assert choice_probability(costs, covariance, choice, seed=0) == 1.0


def test_a_choice_above_an_exact_tie_is_never_the_minimum() -> None:
    costs = np.array([0.0, 0.0, 0.3])
    covariance = np.diag([0.0, 0.0, 0.01]) ** 2
    assert choice_probability(costs, covariance, 2, seed=0) == 0.0
