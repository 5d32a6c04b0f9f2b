"""How long a decision on the moves cost takes, beside the load cost, for 5 and 40 detected boxes.

A robot's pick takes about 4-5 s; the decision must take under 1 s median for 40 detected
boxes and under 50 ms for 5. Each scene is a simulated pile with its own cloud; the first
``N`` boxes (by the pile's order) are taken as detected. Both costs are timed alternately on
the same scenes after one warm-up call each, ``--repeat`` calls per scene and cost; the
script prints medians and the ratio moves / load.

Usage::

    python benchmarks/moves_speed.py test-dropped --piles 5 --repeat 5 --sizes 5,40 \\
        --json benchmarks/results/moves-speed.json

``test-dropped`` is made by::

    unstack simulate --family dropped --configs 30 --seed 9001 --viewpoint-jitter 0.3 --out test-dropped
"""

from __future__ import annotations

import argparse
import json
import statistics
import time
from pathlib import Path

import unstack
from unstack.scene import Scene, load_scene


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("data", type=Path)
    parser.add_argument("--piles", type=int, default=5)
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--sizes", default="5,40")
    parser.add_argument("--json", type=Path, default=None)
    arguments = parser.parse_args()
    piles = [load_scene(path) for path in sorted(arguments.data.glob("config-*.json"))[: arguments.piles]]
    result: dict[str, dict[str, float]] = {}
    for size in (int(text) for text in arguments.sizes.split(",")):
        scenes = [Scene(p.boxes, p.points, p.box_ids[:size], metadata=p.metadata, source=p.source) for p in piles]
        scenes = [scene for scene in scenes if len(scene.detected) == size]
        seconds: dict[str, list[float]] = {"moves": [], "load": []}
        for scene in scenes:
            for cost in seconds:
                unstack.decide(scene, cost=cost, seed=0)  # warm-up: kernels compiled, models loaded
            for _ in range(arguments.repeat):
                for cost, times in seconds.items():
                    start = time.perf_counter()
                    unstack.decide(scene, cost=cost, seed=0)
                    times.append(time.perf_counter() - start)
        medians = {cost: statistics.median(times) for cost, times in seconds.items()}
        result[str(size)] = {**{f"{cost}_median_s": value for cost, value in medians.items()},
                             "ratio_moves_to_load": medians["moves"] / medians["load"], "scenes": len(scenes),
                             "calls": len(seconds["moves"])}  # fmt: skip
        moves_ms, load_ms = medians["moves"] * 1000, medians["load"] * 1000
        print(
            f"{size} detected boxes, {len(scenes)} scenes x {arguments.repeat}: "
            f"moves {moves_ms:.1f} ms, load {load_ms:.1f} ms median (moves / load {moves_ms / load_ms:.2f})"
        )
    if arguments.json is not None:
        arguments.json.write_text(json.dumps(result, indent=1) + "\n")


if __name__ == "__main__":
    main()
