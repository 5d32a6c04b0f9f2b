"""Rules that stay with height but choose within the top layer: what they move one pick ahead.

Highest first takes the box whose centre is highest; in a layer of boxes of one size the
millimetres between their centres decide. These rules keep to the top layer (candidates whose
centre is within ``DELTA`` of the highest) and choose in it by what the robot sees: the box
touching the fewest detected boxes on its sides, the box nearest the door or farthest from it;
and two rules by other heights (the highest top face, the highest lowest point). For every
state of a pick-responses collection (``unstack experiment pick-responses``: every candidate's
removal probed in the engine) it sums the boxes each rule's pick would have moved, beside
highest first and the look-ahead (the candidate the probe says moves fewest).

Usage::

    python benchmarks/height_layer_rules.py states/train-four states/train-stacked states/train-mixed
"""

from __future__ import annotations

import argparse
import collections
from collections.abc import Callable
from pathlib import Path

import numpy as np

from unstack.experiments.pick_responses import load_states
from unstack.geometry import bounding_boxes
from unstack.scene import Scene

#: How far below the highest centre a candidate is still in the top layer (m).
DELTAS = (0.03, 0.08)
#: Side faces closer than this touch (m); they must also overlap by ``OVERLAP`` along the face.
GAP = 0.015
OVERLAP = 0.02


def side_contacts(bounds: np.ndarray, row: int) -> int:
    """How many other boxes (rows of ``bounds``, ``[min xyz, max xyz]``) touch box ``row`` on a side face."""
    overlap = np.minimum(bounds[row, 3:], bounds[:, 3:]) - np.maximum(bounds[row, :3], bounds[:, :3])
    beside = overlap[:, 2] > 0.01  # at the same height, not stacked
    across_x = (overlap[:, 0] > -GAP) & (overlap[:, 1] > OVERLAP)
    across_y = (overlap[:, 1] > -GAP) & (overlap[:, 0] > OVERLAP)
    touching = beside & (across_x | across_y)
    touching[row] = False
    return int(touching.sum())


def rule_picks(scene: Scene, candidates: list[str], moved: dict[str, int]) -> dict[str, str]:
    """Each rule's pick among ``candidates`` (``moved``: the probe's outcome, for the look-ahead only)."""
    detected = list(scene.detected)
    bounds = bounding_boxes([scene.box(box_id) for box_id in detected])
    row = {box_id: detected.index(box_id) for box_id in candidates}
    centre = {box_id: scene.box(box_id).position[2] for box_id in candidates}
    door = {box_id: scene.box(box_id).position[0] for box_id in candidates}  # the door is at -x

    def best(pool: list[str], key: Callable[[str], float]) -> str:
        return min(pool, key=lambda box_id: (key(box_id), -centre[box_id], box_id))

    picks = {
        "highest first": best(candidates, lambda box_id: 0.0),
        "look-ahead": best(candidates, lambda box_id: moved[box_id]),
        "highest top face": best(candidates, lambda box_id: -bounds[row[box_id], 5]),
        "highest lowest point": best(candidates, lambda box_id: -bounds[row[box_id], 2]),
    }
    for delta in DELTAS:
        layer = [box_id for box_id in candidates if centre[box_id] >= max(centre.values()) - delta]
        picks[f"layer {delta:.2f}: fewest side contacts"] = best(layer, lambda b: side_contacts(bounds, row[b]))
        picks[f"layer {delta:.2f}: nearest the door"] = best(layer, lambda box_id: door[box_id])
        picks[f"layer {delta:.2f}: farthest from the door"] = best(layer, lambda box_id: -door[box_id])
    return picks


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("collections", nargs="+", type=Path, help="folders DATA-SET of a pick-responses collection")
    args = parser.parse_args()
    for folder in args.collections:
        totals: collections.Counter[str] = collections.Counter()
        states = 0
        for pile in sorted(path for path in folder.iterdir() if path.is_dir()):
            for header, scene in load_states(pile):
                moved = {box_id: len(header["moved"][box_id]) for box_id in header["candidates"]}
                for rule, pick in rule_picks(scene, list(header["candidates"]), moved).items():
                    totals[rule] += moved[pick]
                states += 1
        print(f"{folder} ({states} states): " + ", ".join(f"{rule} {total}" for rule, total in totals.items()))


if __name__ == "__main__":
    main()
