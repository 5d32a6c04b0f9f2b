"""Decisions from several Python threads at once equal the serial ones and never abort.

numba's parallel kernels (the exact walk, the sampler, the DBAF and contact-feature counts)
run under one lock (:mod:`unstack.threads`); the table path and everything in Python run
concurrently.
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import unstack
from unstack.threads import PARALLEL_KERNELS

pytestmark = pytest.mark.slow  # runs decisions in four threads


def _dense(n: int, seed: int) -> unstack.Supports:
    rng = np.random.default_rng(seed)
    p = rng.uniform(0.05, 0.95, (n, n))
    np.fill_diagonal(p, 0.0)
    return unstack.Supports([f"b{i}" for i in range(n)], p)


def _jobs(examples: Path) -> list[tuple[Any, dict[str, Any]]]:
    scene = unstack.load_scene(examples / "pile5.scene.json")
    return [
        (_dense(20, 1), {"seed": 3, "samples": 2048}),  # sampled: the parallel sampler kernel
        (_dense(7, 2), {"method": "exact"}),  # the compiled exact walk (parallel)
        (_dense(5, 3), {}),  # the table path
        (scene, {"model": "extended"}),  # features: the contact and DBAF kernels
        (_dense(12, 4), {"seed": 5, "samples": 1024, "method": "approx"}),
        (scene, {}),
    ]


def _summary(decision: unstack.Decision) -> tuple[str, list[float], list[float]]:
    errors = decision.expected_cost_errors
    return decision.choice, decision.expected_costs.tolist(), [] if errors is None else errors.tolist()


def test_four_threads_give_the_serial_answers(examples: Path) -> None:
    jobs = _jobs(examples)
    serial = [_summary(unstack.decide(subject, **options)) for subject, options in jobs]
    work = jobs * 3
    with ThreadPoolExecutor(max_workers=4) as pool:
        concurrent = list(pool.map(lambda job: _summary(unstack.decide(job[0], **job[1])), work))
    assert concurrent == serial * 3


def test_the_kernel_lock_is_reentrant_and_released() -> None:
    with PARALLEL_KERNELS, PARALLEL_KERNELS:
        unstack.decide(_dense(7, 0), method="exact")
    assert PARALLEL_KERNELS.acquire(blocking=False)
    PARALLEL_KERNELS.release()
