"""A decision in plain words: what its cost means, which model gave the probabilities, where the pick is.

The terminal output of ``unstack decide`` reads these; a planner's log can too.

Examples
--------
>>> import unstack
>>> scene = unstack.load("examples/pile5.scene.json")
>>> place = pick_place(scene, "b13")
>>> place["height_rank"], place["boxes"]
(1, 5)
>>> place_in_words(place)
'x 1.11 m, y -0.06 m (centre), top at 0.78 m: the highest top of 5 detected'
>>> model_in_words("default:general-mix.skops")
'general (the default model)'
"""

from __future__ import annotations

from typing import Any

import numpy as np

from unstack.scene import Scene
from unstack.supports import Supports

__all__ = [
    "COST_WORDS",
    "LOAD_FROM_FILE_WORDS",
    "cost_in_words",
    "model_in_words",
    "ordinal",
    "pick_place",
    "place_in_words",
]

#: What each cost counts, in one sentence.
COST_WORDS = {
    "load": "the boxes that would come down with it (the detected boxes it holds up, directly or through "
    "others, with the undetected load the point cloud shows on them)",
    "count": "the detected boxes it is expected to hold up, directly or through others (the paper's Eq. 11)",
    "mass": "the kilograms of detected boxes it is expected to hold up, directly or through others",
    "moves": "the boxes that taking it out is expected to move by more than 2 cm (the learned disturbance model)",
}
#: What the ``load`` cost counts when the undetected load came from a supports file, not a cloud.
LOAD_FROM_FILE_WORDS = (
    "the boxes that would come down with it (the detected boxes it holds up, directly or through others, with "
    "the undetected load the supports file gives on them, hidden_load)"
)
#: The unit of each cost's expected value, for a column header.
COST_UNITS = {"load": "boxes brought down", "count": "boxes held up", "mass": "kg held up", "moves": "boxes moved"}


def cost_in_words(cost: str, *, cloud: bool = True) -> str:
    """One sentence saying what ``cost`` counts, ending with which way is safer; ``cloud``:
    whether the undetected load came from a point cloud (a scene) or from a supports file.

    Examples
    --------
    >>> cost_in_words("mass")
    "cost 'mass': the kilograms of detected boxes it is expected to hold up, directly or through others; lower is safer"
    >>> cost_in_words("load", cloud=False).endswith("the supports file gives on them, hidden_load); lower is safer")
    True
    """
    words = (
        LOAD_FROM_FILE_WORDS if cost == "load" and not cloud else COST_WORDS.get(cost, "the expected cost of Eq. 13")
    )
    return f"cost {cost!r}: {words}; lower is safer"


def model_in_words(label: str) -> str:
    """A support model's provenance label (:func:`unstack.api.model_label`) in words.

    Examples
    --------
    >>> model_in_words("shipped:default-paper2.skops")
    'paper (a shipped model)'
    >>> model_in_words("")
    'none (the probabilities were given)'
    """
    if not label:  # before the model table's import: a supports file's decision loads no learning
        return "none (the probabilities were given)"
    from unstack.learning.model_file import BUNDLED_MODELS

    names = {file: name for name, file in BUNDLED_MODELS.items()}
    kind, _, file = label.partition(":")
    if kind == "default" and file in names:
        return f"{names[file]} (the default model)"
    if kind == "shipped" and file in names:
        return f"{names[file]} (a shipped model)"
    return f"the model file {label}"


def ordinal(rank: int) -> str:
    """``1`` -> ``"1st"``, ``12`` -> ``"12th"``, ``23`` -> ``"23rd"``.

    Examples
    --------
    >>> [ordinal(k) for k in (1, 2, 3, 4, 11, 12, 13, 21, 22)]
    ['1st', '2nd', '3rd', '4th', '11th', '12th', '13th', '21st', '22nd']
    """
    suffix = "th" if 10 <= rank % 100 <= 20 else {1: "st", 2: "nd", 3: "rd"}.get(rank % 10, "th")
    return f"{rank}{suffix}"


def pick_place(where: Scene | Supports, box: str) -> dict[str, Any] | None:
    """Where ``box`` is: its centre and top (a scene) or its resting height (supports with heights).

    Parameters
    ----------
    where : Scene or Supports
        The scene decided on (the box's pose), or the support probabilities (their
        ``heights``, the height each box rests at, if they carry them).
    box : str
        A detected box (a scene) or one of the objects (supports).

    Returns
    -------
    dict or None
        ``centre`` (x, y, z in metres, a scene only), ``top`` (its highest point, a scene
        only), ``rests_at`` (its lowest point), ``height_rank`` (1: its top, or for supports
        its resting height, is the highest of the boxes decided on) and ``boxes`` (how many
        were decided on); ``None`` for supports without heights.
    """
    if isinstance(where, Scene):
        from unstack.geometry import bounding_boxes

        ids = list(where.detected)
        bounds = bounding_boxes([where.box(box_id) for box_id in ids])
        tops = bounds[:, 5]
        k = ids.index(box)
        return {
            "centre": [round(float(value), 4) for value in where.box(box).position],
            "top": round(float(tops[k]), 4),
            "rests_at": round(float(bounds[k, 2]), 4),
            "height_rank": int(np.sum(tops > tops[k]) + 1),
            "boxes": len(ids),
        }
    if where.heights is None:
        return None
    heights = np.asarray(where.heights, dtype=np.float64)
    k = where.objects.index(box)
    return {"rests_at": round(float(heights[k]), 4), "height_rank": int(np.sum(heights > heights[k]) + 1),
            "boxes": len(where.objects)}  # fmt: skip


def place_in_words(place: dict[str, Any]) -> str:
    """:func:`pick_place` as one phrase (heights above the floor, z = 0).

    Examples
    --------
    >>> place_in_words({"rests_at": 0.3, "height_rank": 2, "boxes": 5})
    'resting at 0.30 m: the 2nd highest of 5'
    >>> place_in_words({"centre": [1.0, 0.0, 0.5], "top": 0.7, "rests_at": 0.3, "height_rank": 1, "boxes": 5})
    'x 1.00 m, y 0.00 m (centre), top at 0.70 m: the highest top of 5 detected'
    """
    rank = "the highest" if place["height_rank"] == 1 else f"the {ordinal(place['height_rank'])} highest"
    if "centre" not in place:
        return f"resting at {place['rests_at']:.2f} m: {rank} of {place['boxes']}"
    x, y, _ = place["centre"]
    return f"x {x:.2f} m, y {y:.2f} m (centre), top at {place['top']:.2f} m: {rank} top of {place['boxes']} detected"
