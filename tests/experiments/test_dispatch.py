"""The joblib-or-dask dispatch shared by the container and unloading experiments."""

from __future__ import annotations

import operator

import pytest

from unstack.experiments.dispatch import run_unordered


@pytest.mark.parametrize("n_jobs", [1, 2])
def test_every_task_is_run_once_in_local_processes(n_jobs: int) -> None:
    arguments = [(number, 10) for number in range(7)]
    results = list(run_unordered(operator.mul, arguments, n_jobs=n_jobs))
    assert sorted(results) == [number * 10 for number in range(7)]


def test_an_error_in_a_task_reaches_the_caller() -> None:
    with pytest.raises(ZeroDivisionError):
        list(run_unordered(operator.truediv, [(1, 0)]))
