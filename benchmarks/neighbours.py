"""Other work on the machine, for the benchmarks that measure unstack beside it.

A load is named by a string: ``"0"`` (a quiet machine), ``"N"`` (N processes spinning in Python,
each keeping one core busy) or ``"omp"`` (one process running scikit-learn's gradient boosting
predictions in a loop: OpenMP parallel loops on every core, whose workers spin while they wait,
as another OpenMP program next to a planner does).
"""

from __future__ import annotations

import multiprocessing
import time
from typing import Any


def _spin(stop: Any) -> None:
    while not stop.is_set():
        sum(range(10_000))


def _openmp_loops(stop: Any) -> None:
    import numpy as np
    from sklearn.ensemble import HistGradientBoostingClassifier

    rng = np.random.default_rng(0)
    features = rng.normal(size=(2_000, 10))
    classifier = HistGradientBoostingClassifier(max_iter=50).fit(features, features[:, 0] > 0)
    while not stop.is_set():
        classifier.predict_proba(features)


def start(load: str) -> tuple[Any, list[Any]]:
    """Start the processes of ``load``; stop them with :func:`stop`. They are spawned, not forked:
    a child forked from a process whose OpenMP runtime is running hangs in its first parallel loop."""
    context = multiprocessing.get_context("spawn")
    event = context.Event()
    if load == "omp":
        processes = [context.Process(target=_openmp_loops, args=(event,))]
    else:
        processes = [context.Process(target=_spin, args=(event,)) for _ in range(int(load))]
    for process in processes:
        process.start()
    time.sleep(4.0 if load == "omp" else 1.0 if processes else 0.0)  # started, and the model fitted
    return event, processes


def stop(event: Any, processes: list[Any]) -> None:
    event.set()
    for process in processes:
        process.join()
