"""The shipped model's prediction with 1 OpenMP thread (what unstack uses) and with every core,
on a quiet machine and beside other work (a planner's: :mod:`neighbours`).

scikit-learn's gradient boosting predicts tree by tree, each tree one OpenMP parallel loop; when
a core is busy every loop waits for a descheduled thread. One run measures both settings on the
same feature rows (all ordered pairs of the boxes of a scene), alternating, best and median of
``--repeat`` calls each, and prints the ratios.

Usage::

    python benchmarks/prediction_threads.py examples/pile5.scene.json --repeat 7 --busy 0,1,2,4,omp

(every box of the scene, detected or not: 37 boxes, 1,332 pairs).
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
from collections.abc import Callable
from pathlib import Path

import neighbours
import numpy as np
from threadpoolctl import threadpool_limits

from unstack.learning.features import pair_features
from unstack.learning.model_file import default_model_path, load_model
from unstack.scene import load_scene


def timings(
    predict: Callable[[np.ndarray], np.ndarray], rows: np.ndarray, threads: int | None, repeat: int
) -> list[float]:
    seconds = []
    for _ in range(repeat):
        with threadpool_limits(limits=threads, user_api="openmp"):
            start = time.perf_counter()
            predict(rows)
            seconds.append(time.perf_counter() - start)
    return seconds


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("scene", type=Path)
    parser.add_argument("--repeat", type=int, default=7)
    parser.add_argument(
        "--busy",
        type=lambda text: text.split(","),
        default=["0", "1", "2", "4", "omp"],
        help="comma-separated loads beside it (benchmarks/neighbours.py)",
    )
    args = parser.parse_args(argv)
    model = load_model(default_model_path())
    scene = load_scene(args.scene)
    n = len(scene.boxes)
    pairs = [(i, j) for i in range(n) for j in range(n) if i != j]
    rows = pair_features(scene.boxes, scene.points, pairs, model.features)
    predict = model.estimator.predict_proba
    predict(rows)  # warm-up
    cores = os.cpu_count() or 1
    print(f"python benchmarks/prediction_threads.py {args.scene} --repeat {args.repeat} --busy {','.join(args.busy)}")
    print(f"{len(rows)} pairs, {cores} cores, load average {os.getloadavg()[0]:.2f}")
    print("| load beside it | 1 thread: best / median | all cores: best / median | median ratio |")
    print("|---|---:|---:|---:|")
    for busy in args.busy:
        running = neighbours.start(busy)
        try:
            one, every = [], []
            for _ in range(args.repeat):
                one += timings(predict, rows, 1, 1)
                every += timings(predict, rows, None, 1)
        finally:
            neighbours.stop(*running)
        ratio = statistics.median(every) / statistics.median(one)
        print(
            f"| {busy} | {min(one) * 1e3:.1f} / {statistics.median(one) * 1e3:.1f} ms "
            f"| {min(every) * 1e3:.1f} / {statistics.median(every) * 1e3:.1f} ms | {ratio:.1f} |"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
