"""Every public reasoner function refuses bad arguments with an InvalidArgument (a ValueError)."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import unstack
from tests.conftest import EXAMPLES
from unstack.api import payoff
from unstack.errors import InvalidArgument, UnstackError
from unstack.reasoner.decision import choose, decide
from unstack.reasoner.marginals import exact_marginals
from unstack.reasoner.plan import unloading_plan
from unstack.reasoner.sampling import sample_worlds, sampled_marginals
from unstack.supports import Supports

PAIR = Supports(["a", "b"], [[0, 0.3], [0.6, 0]])


def test_invalid_argument_is_both_an_unstack_error_and_a_value_error() -> None:
    assert issubclass(InvalidArgument, UnstackError) and issubclass(InvalidArgument, ValueError)


@pytest.mark.parametrize("budget", [float("nan"), -1.0, 0.0, float("inf"), "1", True])
@pytest.mark.parametrize("call", [decide, unloading_plan])
def test_bad_time_limits_are_refused(call: Callable[..., Any], budget: Any) -> None:
    with pytest.raises(InvalidArgument, match="time_limit must be a"):
        call(PAIR, time_limit=budget)


@pytest.mark.parametrize("call", [decide, unloading_plan])
def test_a_time_limit_beyond_a_day_is_refused(call: Callable[..., Any]) -> None:
    with pytest.raises(InvalidArgument, match=r"time_limit must be at most 86,400 seconds \(a day\), got 100,000"):
        call(PAIR, time_limit=1e5)


@pytest.mark.parametrize("samples", [10**8 + 1, 10**20])
def test_more_samples_than_the_largest_budget_are_refused_at_once(samples: int) -> None:
    with pytest.raises(InvalidArgument, match=r"samples must be at most 100,000,000 .* give a time limit"):
        decide(PAIR, samples=samples)


@pytest.mark.parametrize("samples", [0, -5, 2.5, float("nan"), True])
def test_bad_sample_counts_are_refused(samples: Any) -> None:
    with pytest.raises(InvalidArgument, match="samples must be"):
        decide(PAIR, samples=samples)


@pytest.mark.parametrize(
    ("keyword", "value", "message"),
    [
        ("method", "fast", "unknown method 'fast'; expected one of auto, exact, sat, approx"),
        ("cost", "weight", "unknown cost 'weight'"),
        ("seed", -1, "seed must be at least 0, got -1"),
        ("seed", 1.5, "seed must be an integer, got 1.5"),
        ("max_boxes", 0, "max_boxes must be at least 1, got 0"),
    ],
)
def test_bad_options_are_refused(keyword: str, value: Any, message: str) -> None:
    with pytest.raises(InvalidArgument, match=message):
        decide(PAIR, **{keyword: value})


def test_decide_refuses_what_is_not_supports() -> None:
    with pytest.raises(InvalidArgument, match="expected Supports, got ndarray"):
        decide(np.zeros((2, 2)))  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("matrix", "message"),
    [
        (np.zeros((2, 3)), r"probabilities must be a non-empty square matrix, got shape \(2, 3\)"),
        (np.zeros((0, 0)), r"non-empty square matrix, got shape \(0, 0\)"),
        ("abc", "square matrix, got str"),
        (np.array([[0.0, math.nan], [0.0, 0.0]]), r"probabilities\[0\]\[1\]: expected a finite number, got nan"),
        (np.array([[0.5, 0.2], [0.0, 0.0]]), r"probabilities\[0\]\[0\]: expected 0 on the diagonal"),
        (np.array([[0.0, -0.2], [0.0, 0.0]]), r"expected a probability in \[0, 1\], got -0.2"),
    ],
)
@pytest.mark.parametrize("engine", [exact_marginals, lambda p: sampled_marginals(p, samples=8)])
def test_engines_refuse_bad_matrices(engine: Callable[[Any], Any], matrix: Any, message: str) -> None:
    with pytest.raises(InvalidArgument, match=message):
        engine(matrix)


def test_sample_worlds_and_choose_check_their_arguments() -> None:
    with pytest.raises(InvalidArgument, match="worlds must be at least 0, got -1"):
        sample_worlds(np.zeros((2, 2)), -1)
    with pytest.raises(InvalidArgument, match="thin must be at least 1, got 0"):
        sample_worlds(np.zeros((2, 2)), 2, thin=0)
    with pytest.raises(InvalidArgument, match="expected one finite cost per object"):
        choose(("a", "b"), np.array([0.1, math.nan]))


@settings(deadline=None, max_examples=60)
@given(st.floats(allow_nan=True, allow_infinity=True) | st.integers(-(2**70), 2**70))
def test_a_budget_is_used_exactly_when_positive_finite_and_at_most_a_day(budget: float) -> None:
    if math.isfinite(budget) and 0 < budget <= 86_400:
        assert decide(PAIR, method="approx", time_limit=budget, samples=64, seed=0).choice == "a"
    elif math.isfinite(budget) and budget > 0:
        with pytest.raises(InvalidArgument, match="time_limit must be at most 86,400 seconds"):
            decide(PAIR, time_limit=budget)
    else:
        with pytest.raises(InvalidArgument, match="time_limit must be a positive, finite number"):
            decide(PAIR, time_limit=budget)


@pytest.mark.parametrize(
    ("keyword", "value", "said"),
    [("time_limit", 1e300, r"got 1e\+300"), ("samples", 10**400, "got an integer of about 401 digits")],
    ids=["time_limit", "samples"],
)
def test_a_huge_budget_is_refused_in_a_short_line(keyword: str, value: Any, said: str) -> None:
    """1e300 seconds and 10**400 samples were printed whole: lines of 456 and 664 characters."""
    with pytest.raises(InvalidArgument, match=said) as refused:
        unstack.decide(unstack.load_supports(EXAMPLES / "stack5.supports.json"), **{keyword: value})
    assert len(str(refused.value)) < 200


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda supports: payoff(supports, cost="bad"), r"unknown cost 'bad'"),
        (lambda supports: unstack.decide(supports, cost="mass", method="exact"), "masses"),
    ],
    ids=["unknown-cost", "mass-without-masses"],
)
def test_cost_errors_are_argument_errors(call: Callable[[Any], Any], message: str) -> None:
    """They were bare UnstackErrors, not InvalidArgument (a ValueError) as every other argument error."""
    supports = unstack.Supports(["a", "b"], [[0.0, 0.2], [0.7, 0.0]])
    with pytest.raises(InvalidArgument, match=message):
        call(supports)


def _generator_progress(done: int, total: int) -> Any:
    yield done, total


@pytest.mark.parametrize(("progress", "kind"), [(int, "the class int"), (_generator_progress, "a generator function")])
def test_progress_callables_that_would_never_report_are_refused_before_any_work(progress: Any, kind: str) -> None:
    """A class passed the check and failed after the first step; a generator function never ran."""
    supports = unstack.Supports(["a", "b"], [[0.0, 0.2], [0.7, 0.0]])
    with pytest.raises(InvalidArgument, match=f"progress must be a callable progress\\(done, total\\), got {kind}"):
        unstack.plan(supports, progress=progress)
