"""pytest-benchmark suite of the reasoner: ``unstack.decide`` by both methods.

Not part of the normal test run (``--benchmark-disable`` in the project's addopts and
``benchmarks/`` outside ``testpaths``). Run it with::

    pytest benchmarks --benchmark-enable

Sizes: n = 3..8 for ``method="exact"``, n = 3..6 for ``method="sat"`` (it refuses n > 6);
families ``dense`` and ``sparse`` of :mod:`instances`, seed 0. Numba's JIT (its cached
machine code) is loaded once per session by a call at n = 3 before anything is timed, so
these are compute times, not end-to-end times. Each benchmark's group is ``family n=..``,
so pytest-benchmark's table shows exact and sat of the same instance side by side.
"""

from __future__ import annotations

import numpy as np
import pytest
from instances import FAMILIES, supports
from pytest_benchmark.fixture import BenchmarkFixture

import unstack

EXACT_SIZES = range(3, 9)
SAT_SIZES = range(3, 7)
SEED = 0
CASES = [("exact", family, n) for family in FAMILIES for n in EXACT_SIZES]
CASES += [("sat", family, n) for family in FAMILIES for n in SAT_SIZES]


@pytest.fixture(scope="session", autouse=True)
def warm_jit() -> None:
    """Load the compiled exact engine (and python-sat) before the first timing."""
    for method in ("exact", "sat"):
        unstack.decide(supports("dense", 3, seed=SEED), method=method)


@pytest.mark.parametrize(("method", "family", "n"), CASES, ids=lambda value: str(value))
def test_decide(benchmark: BenchmarkFixture, method: str, family: str, n: int) -> None:
    scene = supports(family, n, seed=SEED)
    benchmark.group = f"{family} n={n}"
    benchmark.extra_info.update({"method": method, "family": family, "n": n, "seed": SEED})
    rounds = 3 if (method == "exact" and n >= 8) or (method == "sat" and n >= 6) else None
    if rounds is None:
        decision = benchmark(unstack.decide, scene, method=method)
    else:
        decision = benchmark.pedantic(unstack.decide, args=(scene,), kwargs={"method": method}, rounds=rounds)
    marginals = decision.marginals
    assert marginals.shape == (n, n)
    assert np.all((marginals >= 0) & (marginals <= 1))
    assert decision.choice in scene.objects
    benchmark.extra_info["consistent_worlds"] = decision.consistent_worlds


@pytest.mark.parametrize("family", FAMILIES)
@pytest.mark.parametrize("n", [3, 4, 5])
def test_methods_agree(family: str, n: int) -> None:
    """The two timed methods compute the same marginals (a check, not a timing)."""
    scene = supports(family, n, seed=SEED)
    exact = unstack.decide(scene, method="exact").marginals
    sat = unstack.decide(scene, method="sat").marginals
    np.testing.assert_allclose(exact, sat, atol=1e-9)
