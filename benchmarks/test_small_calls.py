"""pytest-benchmark suite of the small in-process calls a planner makes many times per container.

Run with ``pytest benchmarks/test_small_calls.py --benchmark-enable``. Each call is the
whole public function (argument checks, evidence, groups, the decision object), not only
the engine: ``unstack.decide`` on 2-7 dense boxes (the preorder table up to 5 boxes, the
compiled walk at 6 and 7), a 20-box sampled decision with a fixed budget, a plan on 5
boxes, and ``Decision.to_dict``. No timing is asserted (tests never time anything); the
measured figures are in README.md and docs/benchmarks.md.
"""

from __future__ import annotations

import numpy as np
import pytest
from pytest_benchmark.fixture import BenchmarkFixture

import unstack


def dense(n: int, seed: int = 0) -> unstack.Supports:
    rng = np.random.default_rng(seed)
    probabilities = rng.uniform(0.05, 0.95, (n, n))
    np.fill_diagonal(probabilities, 0.0)
    return unstack.Supports([f"b{i}" for i in range(n)], probabilities)


@pytest.fixture(scope="module", autouse=True)
def warm() -> None:
    """Build the preorder tables and load the compiled kernels before any timing."""
    for n in (5, 7, 12):
        unstack.decide(dense(n), samples=64, seed=0)


@pytest.mark.parametrize("n", [2, 3, 4, 5, 6, 7])
def test_decide_dense(benchmark: BenchmarkFixture, n: int) -> None:
    supports = dense(n)
    benchmark.group = "decide, dense"
    decision = benchmark(unstack.decide, supports)
    assert decision.method == "exact"


def test_decide_sampled_20_boxes(benchmark: BenchmarkFixture) -> None:
    supports = dense(20)
    benchmark.group = "decide, sampled"
    decision = benchmark(unstack.decide, supports, samples=1024, seed=0)
    assert decision.method == "approx"


def test_plan_5_boxes(benchmark: BenchmarkFixture) -> None:
    supports = dense(5)
    benchmark.group = "plan"
    plan = benchmark(unstack.plan, supports)
    assert len(plan.order) == 5


def test_decision_to_dict(benchmark: BenchmarkFixture) -> None:
    decision = unstack.decide(dense(5))
    benchmark.group = "json"
    document = benchmark(decision.to_dict)
    assert document["format"] == "unstack.decision/1"
