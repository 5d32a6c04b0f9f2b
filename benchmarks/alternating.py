"""Timing two ways of deciding side by side on the same scenes: alternately, after a warm-up each.

The speed scripts (``moves_speed.py``, ``belief_speed.py``) take a simulated data set, keep the
first ``N`` boxes of each pile as the detected ones, and time each call alternately on every
scene, so that a shared, noisy machine slows both alike; they report medians and ratios.
"""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable, Sequence
from typing import Any

from unstack.scene import Scene


def scenes_with_detected(piles: Sequence[Scene], size: int) -> list[Scene]:
    """Each pile with its first ``size`` boxes detected (piles with fewer boxes are left out)."""
    scenes = [Scene(p.boxes, p.points, p.box_ids[:size], metadata=p.metadata, source=p.source) for p in piles]
    return [scene for scene in scenes if len(scene.detected) == size]


def median_seconds(scenes: Sequence[Scene], calls: dict[str, Callable[[Scene], Any]], repeat: int) -> dict[str, Any]:
    """Median seconds per call, each call warmed up once per scene and then timed alternately."""
    seconds: dict[str, list[float]] = {name: [] for name in calls}
    for scene in scenes:
        for call in calls.values():
            call(scene)  # warm-up: kernels compiled, models loaded, pybullet imported
        for _ in range(repeat):
            for name, call in calls.items():
                start = time.perf_counter()
                call(scene)
                seconds[name].append(time.perf_counter() - start)
    medians = {f"{name}_median_s": statistics.median(times) for name, times in seconds.items()}
    first = next(iter(calls))
    return {**medians, "scenes": len(scenes), "calls": len(seconds[first])}
