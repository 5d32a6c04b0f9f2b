"""Timing two ways of deciding side by side on the same scenes: alternately, after a warm-up each.

The speed scripts (``moves_speed.py``, ``belief_speed.py``) take a simulated data set, keep the
first ``N`` boxes of each pile as the detected ones, and time each call alternately on every
scene, so that a shared, noisy machine slows both alike; they report medians and ratios.
"""

from __future__ import annotations

import argparse
import json
import statistics
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from unstack.scene import Scene, load_scene


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


def compare_by_size(
    description: str, calls: dict[str, Callable[[Scene], Any]], *, piles: int, repeat: int
) -> dict[str, dict[str, float]]:
    """The speed scripts' whole run: arguments, scenes of each size, alternate timing, report.

    Reads the command line (one data set or several, ``--piles`` of each; ``--repeat``,
    ``--sizes``, ``--json``),
    times ``calls`` alternately on each size's scenes, prints the medians and the ratio of the
    first call to the second, and writes them to ``--json`` when given.
    """
    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("data", type=Path, nargs="+")
    parser.add_argument("--piles", type=int, default=piles)
    parser.add_argument("--repeat", type=int, default=repeat)
    parser.add_argument("--sizes", default="5,40")
    parser.add_argument("--json", type=Path, default=None)
    arguments = parser.parse_args()
    loaded = [
        load_scene(path)
        for folder in arguments.data
        for path in sorted(folder.glob("config-*.json"))[: arguments.piles]
    ]
    measured, reference = list(calls)[:2]
    result: dict[str, dict[str, float]] = {}
    for size in (int(text) for text in arguments.sizes.split(",")):
        scenes = scenes_with_detected(loaded, size)
        if not scenes:
            print(f"{size} detected boxes: no pile of the data set has that many")
            continue
        timed = median_seconds(scenes, calls, arguments.repeat)
        medians = {name: timed[f"{name}_median_s"] for name in calls}
        ratio = medians[measured] / medians[reference]
        result[str(size)] = {**timed, f"ratio_{measured}_to_{reference}": ratio}
        shown = ", ".join(f"{name} {1000 * seconds:.1f} ms" for name, seconds in medians.items())
        print(
            f"{size} detected boxes, {len(scenes)} scenes x {arguments.repeat}: {shown} median "
            f"({measured} / {reference} {ratio:.2f})"
        )
    if arguments.json is not None:
        arguments.json.parent.mkdir(parents=True, exist_ok=True)
        arguments.json.write_text(json.dumps(result, indent=2) + "\n")
    return result
