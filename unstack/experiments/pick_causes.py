"""Why a pick moved what it moved: each moved box put down to one cause, from the true pile.

For a removal measured in the engine (a saved state of :mod:`unstack.experiments.pick_responses`),
every box that moved more than 2 cm is given the first cause that fits, from the true poses
before the pick:

``held up``
    it rested on the pick (its bottom within :data:`CONTACT_GAP` of the pick's top, over a
    fifth of the smaller footprint);
``load above``
    it rested, directly or through others, on a box that is ``held up`` (the stack came down);
``dragged``
    it touched the pick's side (a gap under :data:`CONTACT_GAP`, a shared height band):
    friction or a lean on the pick;
``knocked``
    none of those: hit by a falling box, or a pile that shifted further away.

Each moved box is also marked ``detected`` or not (a candidate the robot had seen as a box).

Examples
--------
>>> from unstack.scene import Box
>>> boxes = [Box("pick", [0.4, 0.4, 0.3], [1.0, 0.0, 0.15]), Box("on", [0.4, 0.4, 0.3], [1.0, 0.0, 0.45]),
...          Box("top", [0.4, 0.4, 0.3], [1.0, 0.0, 0.75]), Box("side", [0.4, 0.4, 0.3], [1.0, 0.41, 0.15])]
>>> moved_causes(boxes, "pick", ["on", "top", "side"])
{'on': 'held up', 'top': 'load above', 'side': 'dragged'}
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from unstack.geometry import bounding_boxes

__all__ = ["CAUSES", "CONTACT_GAP", "cause_table", "moved_causes"]

#: The causes, in the order they are tried.
CAUSES = ("held up", "load above", "dragged", "knocked")
#: Two faces closer than this (metres) touch.
CONTACT_GAP = 0.02


def _rests_on(upper: np.ndarray, lower: np.ndarray) -> bool:
    shared = np.prod([max(0.0, min(upper[3 + a], lower[3 + a]) - max(upper[a], lower[a])) for a in (0, 1)])
    smaller = min(np.prod(upper[3:5] - upper[:2]), np.prod(lower[3:5] - lower[:2]))
    return bool(shared > 0.2 * smaller and abs(upper[2] - lower[5]) < CONTACT_GAP)


def _beside(first: np.ndarray, second: np.ndarray) -> bool:
    band = min(first[5], second[5]) - max(first[2], second[2])
    gaps = np.maximum(second[:2] - first[3:5], first[:2] - second[3:5])
    return bool(band > 0.05 and gaps.max() < CONTACT_GAP)


def moved_causes(boxes: Sequence[Any], pick: str, moved: Sequence[str]) -> dict[str, str]:
    """The cause (:data:`CAUSES`) of each moved box of a removal, from the poses before it."""
    ids = [box.id for box in boxes]
    bounds = dict(zip(ids, bounding_boxes(list(boxes)), strict=True))
    causes: dict[str, str] = {}
    held = {box_id for box_id in moved if _rests_on(bounds[box_id], bounds[pick])}
    causes.update({box_id: "held up" for box_id in held})
    frontier = set(held)
    while frontier:  # boxes resting on a box that came down, and so on up
        above = {
            box_id
            for box_id in moved
            if box_id not in causes and any(_rests_on(bounds[box_id], bounds[lower]) for lower in frontier)
        }
        causes.update({box_id: "load above" for box_id in above})
        frontier = above
    for box_id in moved:
        if box_id not in causes:
            causes[box_id] = "dragged" if _beside(bounds[box_id], bounds[pick]) else "knocked"
    return {box_id: causes[box_id] for box_id in moved}


def cause_table(picks: Sequence[tuple[str, Sequence[Any], str, Sequence[str], Sequence[str]]]) -> dict[str, Any]:
    """Shares of moved boxes by cause and by detection, per group.

    ``picks``: ``(group, boxes, pick, moved, detected)`` for every pick that moved something
    (``group`` names the family and policy, say). Returns per group the picks, the moved
    boxes, the share of each cause and the share of moved boxes nobody detected.
    """
    table: dict[str, dict[str, Any]] = {}
    for group, boxes, pick, moved, detected in picks:
        if not moved:
            continue
        row = table.setdefault(group, {"picks": 0, "moved": 0, **dict.fromkeys(CAUSES, 0), "undetected": 0})
        row["picks"] += 1
        row["moved"] += len(moved)
        for box_id, cause in moved_causes(boxes, pick, moved).items():
            row[cause] += 1
            row["undetected"] += box_id not in detected
    return {
        group: {
            "picks": row["picks"],
            "moved": row["moved"],
            **{f"share_{name.replace(' ', '_')}": row[name] / row["moved"] for name in (*CAUSES, "undetected")},
        }
        for group, row in sorted(table.items())
    }
