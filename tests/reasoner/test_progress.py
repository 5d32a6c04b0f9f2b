"""Sampling progress is written for the thread that watches, and only for it."""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

from unstack.reasoner.progress import SamplingProgress, sampling_progress, watching_sampling
from unstack.reasoner.sampling import sampled_marginals


def _half(n: int) -> np.ndarray:
    matrix = np.full((n, n), 0.5)
    np.fill_diagonal(matrix, 0.0)
    return matrix


def _watched(n: int) -> tuple[int, int, int | None]:
    seen: list[int] = []
    with watching_sampling() as watch:
        original = watch.start
        watch.start = lambda boxes, total: (seen.append(boxes), original(boxes, total))  # type: ignore[method-assign]
        sampled_marginals(_half(n), samples=2048, seed=n)
    return seen[0], watch.done, watch.total


def test_threads_each_see_their_own_group_only() -> None:
    with ThreadPoolExecutor(4) as pool:
        seen = list(pool.map(_watched, [3, 4, 5, 6]))
    assert seen == [(n, 2048, 2048) for n in (3, 4, 5, 6)]
    assert sampling_progress() is None  # nobody watches here


@pytest.mark.parametrize("samples, time_limit", [(1000, None), (None, 0.2)])
def test_the_total_is_what_is_recorded_or_unknown_under_a_time_limit(
    samples: int | None, time_limit: float | None
) -> None:
    with watching_sampling() as watch:
        result = sampled_marginals(_half(4), samples=samples, time_limit=time_limit, seed=0)
    assert watch.done == result.samples
    assert watch.total == (result.samples if samples else None)
    assert (watch.seconds_left() is None) == (time_limit is not None)


def test_nothing_is_said_before_a_group_is_sampled_or_after_its_sampling() -> None:
    progress = SamplingProgress()
    assert progress.line() is None
    progress.start(12, 4096)
    assert progress.line() == "sampling a group of 12 boxes: 0 of 4,096 sweeps"
    progress.finish()  # the rest of the decision (a physics veto, say) is not sampling
    assert progress.line() is None
