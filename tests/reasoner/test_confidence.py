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
