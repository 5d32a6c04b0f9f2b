"""Learning benchmark: features of a 40-box scene with a 300k-point cloud, and prediction for all pairs.

Targets (issue "Learning"): all 40 x 39 pair features in under 0.5 s, with the ratio to the
direct O(N) numpy sum of Eq. 2; P(SUPP) for all 1560 ordered pairs in under 0.1 s. Also timed:
the 17 contact features of the extended set, and the shipped models: ``paper`` (SVM) on the
paper's 19 features, ``extended`` (gradient boosting) on its 36, and the default model on the
features it was trained with.

The scene is seeded: 40 boxes of the paper's sizes spread over a 2 m container section and a
cloud of 300,000 points (the measured sensor gives 265,912 points at 640 x 480). Times are the
best of ``--repeat`` runs after one warm-up (numba compiles on first use and caches on disk).

Usage::

    python benchmarks/learning.py --repeat 5 --json learning-benchmark.json
"""

from __future__ import annotations

import argparse
import json
import math
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
from rich.console import Console
from rich.table import Table

from unstack.atomic import atomic_write_text
from unstack.learning.contact_features import contact_features
from unstack.learning.features import FeatureSettings, interest_points, pair_features
from unstack.learning.model_file import bundled_model_path, default_model_path, load_model
from unstack.scene import Box


def scene(seed: int, boxes: int = 40, points: int = 300_000) -> tuple[list[Box], np.ndarray]:
    rng = np.random.default_rng(seed)
    sizes = np.array([[0.6, 0.4, 0.4], [0.4, 0.3, 0.3]])
    pile = [
        Box(f"b{k:02d}", sizes[rng.integers(2)], rng.uniform([0.3, -1.0, 0.2], [1.8, 1.0, 1.5])) for k in range(boxes)
    ]
    cloud = rng.uniform([0.0, -1.175, 0.0], [2.0, 1.175, 2.39], size=(points, 3))
    return pile, cloud


def best_time(run: Callable[[], object], repeat: int) -> float:
    run()
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        run()
        times.append(time.perf_counter() - start)
    return min(times)


def numpy_direct(boxes: list[Box], cloud: np.ndarray, sigma: float = 0.5) -> np.ndarray:
    """Eq. 2 as a plain numpy loop over the 240 interest points (the O(N) reference)."""
    queries = interest_points(boxes).reshape(-1, 3)
    constant = 1.0 / (len(cloud) * math.sqrt((2 * math.pi * sigma) ** 3))
    return np.array([constant * np.exp(-((cloud - q) ** 2).sum(axis=1) / (2 * sigma**2)).sum() for q in queries])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--json", type=Path, default=None)
    arguments = parser.parse_args()
    boxes, cloud = scene(arguments.seed)
    pairs = [(i, j) for i in range(len(boxes)) for j in range(len(boxes)) if i != j]
    model = load_model(bundled_model_path("paper"))  # the paper's 19 features
    extended_model = load_model(bundled_model_path("extended"))
    default_model = load_model(default_model_path())  # whatever features it was trained with
    features = pair_features(boxes, cloud, pairs)
    extended = pair_features(boxes, cloud, pairs, FeatureSettings(feature_set="extended"))
    default_features = pair_features(boxes, cloud, pairs, default_model.features)
    timings = {
        "features, direct (numba, all cores)": best_time(
            lambda: pair_features(boxes, cloud, pairs, FeatureSettings(dbaf_method="direct")), arguments.repeat
        ),
        "features, kdtree (tolerance 1e-9)": best_time(
            lambda: pair_features(boxes, cloud, pairs, FeatureSettings(dbaf_method="kdtree")), 1
        ),
        "DBAF, numpy direct sum (reference)": best_time(lambda: numpy_direct(boxes, cloud), 1),
        "contact features alone (17 more, gridded counts)": best_time(
            lambda: contact_features(boxes, cloud, pairs), arguments.repeat
        ),
        "features, extended set (direct DBAF + contact)": best_time(
            lambda: pair_features(boxes, cloud, pairs, FeatureSettings(feature_set="extended")), arguments.repeat
        ),
        f"features, the default model's ({default_model.features.feature_set})": best_time(
            lambda: pair_features(boxes, cloud, pairs, default_model.features), arguments.repeat
        ),
        "P(SUPP) for all 1560 pairs, paper model (SVM)": best_time(
            lambda: model.support_probability(features), arguments.repeat
        ),
        "P(SUPP), extended model (gradient boosting)": best_time(
            lambda: extended_model.support_probability(extended), arguments.repeat
        ),
        f"P(SUPP), the default model ({default_model_path().name})": best_time(
            lambda: default_model.support_probability(default_features), arguments.repeat
        ),
    }
    reference = timings["DBAF, numpy direct sum (reference)"]
    table = Table(title=f"40 boxes, {len(cloud):,} points, {len(pairs)} ordered pairs (best of {arguments.repeat})")
    table.add_column("what")
    table.add_column("seconds", justify="right")
    table.add_column("numpy reference / this", justify="right")
    for name, seconds in timings.items():
        ratio = f"{reference / seconds:.1f}x" if name.startswith(("features", "DBAF")) else "-"
        table.add_row(name, f"{seconds:.4f}", ratio)
    Console().print(table)
    if arguments.json:
        report = {"seconds": timings, "points": len(cloud), "pairs": len(pairs)}
        atomic_write_text(arguments.json, json.dumps(report, indent=2))


if __name__ == "__main__":
    main()
