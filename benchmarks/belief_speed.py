"""How long physics on the belief takes per decision, beside the load cost, for 5 and 40 detected boxes.

A robot's pick takes about 4-5 s; the decision must take under 1 s median for 40 detected
boxes and under 50 ms for 5 (issue 34, part 3). Each scene is a simulated pile with its own
cloud; the first ``N`` boxes (by the pile's order) are taken as detected, every one a
candidate. ``belief_removals`` (4 belief worlds, every candidate tried) and ``unstack.decide``
with the load cost are timed alternately on the same scenes after one warm-up call each; the
script prints medians and the ratio belief / load.

Usage::

    python benchmarks/belief_speed.py t30-dropped --piles 3 --repeat 2 --sizes 5,30 \\
        --json benchmarks/results/belief-speed.json

``t30-dropped`` is made by::

    unstack simulate --configs 30 --seed 8808 --out t30-dropped
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
from unstack.sim.belief import belief_removals


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("data", type=Path)
    parser.add_argument("--piles", type=int, default=3)
    parser.add_argument("--repeat", type=int, default=2)
    parser.add_argument("--sizes", default="5,40")
    parser.add_argument("--json", type=Path, default=None)
    arguments = parser.parse_args()
    piles = [load_scene(path) for path in sorted(arguments.data.glob("config-*.json"))[: arguments.piles]]
    result: dict[str, dict[str, float]] = {}
    for size in (int(text) for text in arguments.sizes.split(",")):
        scenes = scenes_with_detected(piles, size)
        if not scenes:
            print(f"{size} detected boxes: no pile of the data set has that many")
            continue
        calls = {"belief": lambda scene: belief_removals(scene), "load": lambda scene: unstack.decide(scene, seed=0)}
        timed = median_seconds(scenes, calls, arguments.repeat)
        medians = {name: timed[f"{name}_median_s"] for name in calls}
        result[str(size)] = {**timed, "ratio_belief_to_load": medians["belief"] / medians["load"]}
        print(
            f"{size} detected boxes, {len(scenes)} scenes x {arguments.repeat}: belief {medians['belief']:.2f} s, "
            f"load {1000 * medians['load']:.0f} ms median (belief / load {medians['belief'] / medians['load']:.1f})"
        )
    if arguments.json is not None:
        arguments.json.parent.mkdir(parents=True, exist_ok=True)
        arguments.json.write_text(json.dumps(result, indent=2) + "\n")


if __name__ == "__main__":
    main()
