"""Decisions from several Python threads at once equal the serial ones and never abort.

numba's parallel kernels (the sampler, the DBAF and contact-feature counts) run under one
lock (:mod:`unstack.threads`); the exact walk runs GIL-free kernels on threads of its own;
the table path and everything in Python run concurrently.
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import unstack
from unstack.threads import PARALLEL_KERNELS, map_on_threads

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
        (_dense(7, 2), {"method": "exact"}),  # the compiled exact walk (its own threads)
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


def test_map_on_threads_keeps_the_order_and_uses_numbas_threads() -> None:
    import threading

    import numba

    seen_threads = set()

    def square_slowly(item: int) -> int:
        seen_threads.add(threading.get_ident())
        threading.Event().wait(0.01 * (8 - item))  # late items finish first
        return item * item

    assert map_on_threads(square_slowly, range(8)) == [item * item for item in range(8)]
    assert len(seen_threads) == min(numba.get_num_threads(), 8)


def test_map_on_threads_runs_in_the_calling_thread_when_numba_may_use_one() -> None:
    import threading

    import numba

    def worker() -> set[int]:
        numba.set_num_threads(1)  # local to this thread
        seen = set()
        map_on_threads(lambda item: seen.add(threading.get_ident()), range(4))
        return seen | {threading.get_ident()}

    with ThreadPoolExecutor(max_workers=1) as pool:
        assert len(pool.submit(worker).result()) == 1


def test_map_on_threads_raises_the_first_error_and_drops_the_items_not_started() -> None:
    import threading

    import numba

    if numba.get_num_threads() < 2:
        pytest.skip("one kernel thread: items run in the calling thread")
    started = []

    def fail_first(item: int) -> int:
        started.append(item)
        if item == 0:
            raise ValueError("item 0 failed")
        threading.Event().wait(0.05)
        return item

    with pytest.raises(ValueError, match="item 0 failed"):
        map_on_threads(fail_first, range(200))
    assert len(started) < 200
