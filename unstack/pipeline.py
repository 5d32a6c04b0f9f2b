"""The one recipe from a scene to support probabilities: the model meets scene understanding.

Features of every ordered pair of detected boxes, then the model's P(SUPP); the scene's
plausibility warnings and the model's out-of-distribution warnings; statics' raises for a
box another leans on; the hidden load the cloud shows on each detected box; the heights the
boxes rest at. It sits above learning and scene understanding and below the public API
(``docs/architecture.md``): the only module where a learned model meets a scene.

A learned probability is never hard evidence: values are clipped into
``[PROBABILITY_FLOOR, 1 - PROBABILITY_FLOOR]`` so that only a planner's explicit 0 or 1
constrains the worlds (the clipping is recorded in the output's metadata).

Examples
--------
>>> from unstack.learning.model_file import default_model_path, load_model
>>> from unstack.scene import load_scene
>>> supports = scene_support_probabilities(load_scene("examples/pile5.scene.json"), load_model(default_model_path()))
>>> supports.n_objects
5
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Sequence

import numpy as np

from unstack.errors import InvalidScene
from unstack.geometry import bounding_boxes
from unstack.learning.features import pair_features
from unstack.learning.model_file import SupportModel
from unstack.scene import Scene
from unstack.supports import Supports

__all__ = ["PROBABILITY_FLOOR", "scene_support_probabilities"]

#: Learned probabilities are kept at least this far from 0 and 1.
PROBABILITY_FLOOR = 1e-6


#: Out-of-distribution features named one by one in a warning, before "and N more".
NAMED_OUT_OF_RANGE = 3


def _out_of_distribution(
    source: str, model: SupportModel, features: np.ndarray, pairs: list[tuple[str, str]]
) -> list[str]:
    """One warning naming the pairs and features outside the model's training range."""
    outside = model.out_of_range(features)
    if not outside:
        return []
    named = "; ".join(
        f"({pairs[row][0]!r}, {pairs[row][1]!r}) {name} = {value:.3g} outside [{low:.3g}, {high:.3g}]"
        for row, name, value, low, high in outside[:NAMED_OUT_OF_RANGE]
    )
    more = f" and {len(outside) - NAMED_OUT_OF_RANGE} more" if len(outside) > NAMED_OUT_OF_RANGE else ""
    rows = sorted({row for row, *_ in outside})
    counts = Counter(box for row in rows for box in pairs[row])
    boxes = ", ".join(f"{box!r} ({count})" for box, count in counts.most_common(3))
    return [
        f"{source}: out of distribution: features of {len(rows)} of {len(pairs)} box pairs lie outside the model's "
        f"training range: {named}{more}; the probabilities there are extrapolated. The boxes in most of those pairs: "
        f"{boxes}: check their poses and sizes; if they are right, the piles are unlike the model's (unstack train "
        "makes a model of piles like yours)"
    ]


def scene_support_probabilities(
    scene: Scene,
    model: SupportModel,
    *,
    model_name: str = "",
    boxes: Sequence[str] | None = None,
    statics: bool = True,
) -> Supports:
    """``P(SUPP(X, Y))`` for every ordered pair of the scene's detected boxes.

    Parameters
    ----------
    scene : Scene
        Its ``detected`` boxes become the objects, in that order.
    model : SupportModel
    model_name : str
        Recorded in the metadata (for example the model file's path).
    boxes : sequence of str, optional
        Box ids to use instead of the scene's detected boxes (an ISet drawn from them).
    statics : bool
        Raise ``P(X supports Y)`` where ``Y`` cannot stand without ``X`` (it leans on it, or
        rests across a gap on it and another)
        (:mod:`unstack.understanding.statics`; each raise is a warning and is listed in
        ``metadata["tip_supports"]``); ``False``: the model's probabilities alone.

    Returns
    -------
    Supports
        With masses when every detected box has one, the hidden load of every box
        (:mod:`unstack.understanding.hidden_load`), and in ``metadata["warnings"]`` what is doubtful:
        the scene's plausibility warnings (:func:`unstack.understanding.plausibility.scene_warnings`)
        and features outside the model's training range (out of distribution).
    """
    index = {box_id: k for k, box_id in enumerate(scene.box_ids)}
    objects = list(scene.detected if boxes is None else boxes)
    detected = [index[box_id] for box_id in objects]
    heights = bounding_boxes([scene.boxes[k] for k in detected])[:, 2] if detected else np.zeros(0)
    _refuse_heights(scene, detected, heights)
    n = len(detected)
    pairs = [(detected[i], detected[j]) for i in range(n) for j in range(n) if i != j]
    probabilities = np.zeros((n, n))
    from unstack.understanding.plausibility import scene_warnings

    doubts = scene_warnings(scene)
    if pairs:
        features = pair_features(scene.boxes, scene.points, pairs, model.features)
        values = np.clip(model.support_probability(features), PROBABILITY_FLOOR, 1.0 - PROBABILITY_FLOOR)
        rows, columns = np.nonzero(~np.eye(n, dtype=bool))
        probabilities[rows, columns] = values
        doubts += _out_of_distribution(
            scene.source, model, features, [(objects[i], objects[j]) for i, j in zip(rows, columns, strict=True)]
        )
    held_up: list[dict[str, object]] = []
    from unstack.understanding.cloud_columns import CloudColumns

    binned = CloudColumns(scene.points)  # binned once for the statics and the hidden load
    if statics and n > 1:
        from unstack.understanding.statics import raise_tip_supports, tip_supports

        found = tip_supports(scene, objects, columns=binned)
        probabilities, raised = raise_tip_supports(probabilities, objects, found)
        doubts += [f"{scene.source}: {sentence}" for sentence in raised]
        held_up = [
            {"held": f.held, "supporter": f.supporter, "overhang_m": round(f.overhang, 4), "on_floor": f.on_floor}
            for f in found
        ]
    from unstack.understanding.hidden_load import hidden_load

    masses = [scene.boxes[k].mass for k in detected]
    metadata = {
        "scene": scene.source,
        "model": model_name,
        "learner": model.metadata.get("learner"),
        "features": model.features.to_dict(),
        "clipped_to": [PROBABILITY_FLOOR, 1.0 - PROBABILITY_FLOOR],
        "warnings": doubts,
        "statics": statics,
        "tip_supports": held_up,
    }
    return Supports(
        objects,
        probabilities,
        masses=masses if all(mass is not None for mass in masses) else None,
        metadata=metadata,
        source=scene.source,
        hidden_load=hidden_load(scene, objects, columns=binned),
        heights=heights,  # the heights the boxes rest at
    )


def _refuse_heights(scene: Scene, detected: Sequence[int], heights: np.ndarray) -> None:
    """A detected box resting outside the heights support probabilities hold, named by its
    position (the supports' ``$.heights``, a field the caller never gave, was blamed)."""
    from unstack.checks import HEIGHT_RANGE

    low, high = HEIGHT_RANGE
    for k, height in zip(detected, heights, strict=True):
        if not low <= height <= high:
            box = scene.boxes[k]
            raise InvalidScene(
                scene.source,
                f"$.boxes[{k}].position",
                f"box {box.id!r} rests at {height:.2f} m: expected its bottom from {low:g} to {high:g} m above "
                "the floor (z = 0); is the scene in the floor's frame?",
            )
