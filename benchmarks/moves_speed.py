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
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from alternating import median_seconds, scenes_with_detected

import unstack
from unstack.scene import load_scene


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
        scenes = scenes_with_detected(piles, size)
        calls = {
            cost: (lambda scene, cost=cost: unstack.decide(scene, cost=cost, seed=0)) for cost in ("moves", "load")
        }
        timed = median_seconds(scenes, calls, arguments.repeat)
        medians = {cost: timed[f"{cost}_median_s"] for cost in calls}
        result[str(size)] = {**timed, "ratio_moves_to_load": medians["moves"] / medians["load"]}
        moves_ms, load_ms = medians["moves"] * 1000, medians["load"] * 1000
        print(
            f"{size} detected boxes, {len(scenes)} scenes x {arguments.repeat}: "
            f"moves {moves_ms:.1f} ms, load {load_ms:.1f} ms median (moves / load {moves_ms / load_ms:.2f})"
        )
    if arguments.json is not None:
        arguments.json.write_text(json.dumps(result, indent=1) + "\n")


if __name__ == "__main__":
    main()
