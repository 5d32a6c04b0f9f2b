"""Training and measuring the pick-disturbance model on collected states.

The records of :func:`unstack.experiments.pick_responses.pick_table` (one per state and
detector view) become one row per candidate: its pick features and how many boxes its
removal moved in the engine. :func:`train_disturbance` fits
:class:`~unstack.learning.disturbance.DisturbanceRegressor` on all of them and, with piles
held out together (grouped folds), reports calibration (predicted against actual boxes
moved, :func:`~unstack.learning.disturbance.calibration`) and what the held-out picks would
have moved next to highest first, the reasoner's load cost and the look-ahead, per family and
view (:func:`pick_scores`).

Examples
--------
>>> records = [{"features": np.zeros((2, 3)), "moved": np.array([0, 2]), "candidates": ["a", "b"],
...             "default_choice": "a", "resting": np.array([0.0, 0.3]), "view": "full",
...             "pile": "train-wall/config-0000", "state": "s0"}]
>>> features, moved, groups = table_arrays(records)
>>> features.shape, moved.tolist(), groups.tolist()
((2, 3), [0.0, 2.0], [0, 0])
>>> pick_scores(records, [np.array([0.1, 1.0])])["all"]["highest"]
2.0
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from unstack.parameters import FOLDS, SEED, validate_params

__all__ = ["family_of", "pick_scores", "table_arrays", "train_disturbance"]


def family_of(pile: str) -> str:
    """The pile family of a record's pile (``train-wall/config-0003`` -> ``wall``)."""
    return pile.split("/")[0].rsplit("-", 1)[-1]


def table_arrays(records: Sequence[dict[str, Any]]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Rows of features, boxes moved, and the pile (an integer) each row comes from."""
    piles = {pile: k for k, pile in enumerate(sorted({record["pile"] for record in records}))}
    features = np.vstack([record["features"] for record in records])
    moved = np.concatenate([record["moved"] for record in records]).astype(np.float64)
    groups = np.concatenate([[piles[record["pile"]]] * len(record["moved"]) for record in records])
    return features, moved, groups


def _choices(record: dict[str, Any], predicted: np.ndarray | None) -> dict[str, int]:
    from unstack.moves import MOVES_NEAR_TIE_MARGIN
    from unstack.reasoner.decision import choose

    candidates = tuple(record["candidates"])
    resting = np.asarray(record["resting"])
    moved = np.asarray(record["moved"])
    index = {box_id: k for k, box_id in enumerate(candidates)}
    choices = {
        "highest": max(range(len(candidates)), key=lambda k: (resting[k], candidates[k])),
        "load": index[record["default_choice"]],
        "lookahead": min(range(len(candidates)), key=lambda k: (moved[k], -resting[k], candidates[k])),
    }
    if predicted is not None:
        choice, _ = choose(candidates, predicted, heights=resting, margin=MOVES_NEAR_TIE_MARGIN)
        choices["moves"] = index[choice]
    return choices


def pick_scores(records: Sequence[dict[str, Any]], predicted: Sequence[np.ndarray] | None = None) -> dict[str, Any]:
    """Boxes the next pick moves, per policy, averaged over states: in all, and per family and view.

    ``predicted``: the disturbance model's expected moves per record (held out), giving the
    ``moves`` policy; without it only highest first, the load cost and the look-ahead.
    """
    groups: dict[str, dict[str, list[float]]] = {}
    for k, record in enumerate(records):
        moved = np.asarray(record["moved"])
        choices = _choices(record, None if predicted is None else predicted[k])
        for key in ("all", f"{family_of(record['pile'])}/{record['view']}"):
            table = groups.setdefault(key, {})
            for policy, choice in choices.items():
                table.setdefault(policy, []).append(float(moved[choice]))
    return {
        key: {**{policy: float(np.mean(values)) for policy, values in table.items()}, "states": len(table["highest"])}
        for key, table in sorted(groups.items())
    }


@validate_params({"random_state": SEED, "folds": FOLDS})
def train_disturbance(
    records: Sequence[dict[str, Any]], *, random_state: int = 0, folds: int = 5, **parameters: Any
) -> tuple[Any, dict[str, Any]]:
    """Fit the disturbance model on every record; measure it with piles held out.

    Returns
    -------
    model : DisturbanceModel
        Fitted on all rows; its metadata holds the report.
    report : dict
        ``calibration`` of the held-out predictions, ``pick_scores`` of the held-out
        picks beside highest first, the load cost and the look-ahead, the rows and piles.
    """
    from unstack.learning.disturbance import (
        DisturbanceModel,
        DisturbanceRegressor,
        calibration,
        held_out_predictions,
    )
    from unstack.learning.pick_features import PICK_FEATURES
    from unstack.provenance import package_versions

    features, moved, groups = table_arrays(records)
    regressor = DisturbanceRegressor(random_state=random_state, **parameters)
    held_out = held_out_predictions(regressor, features, moved, groups, folds=folds)
    offsets = np.cumsum([0] + [len(record["moved"]) for record in records])
    per_record = [held_out[offsets[k] : offsets[k + 1]] for k in range(len(records))]
    report = {
        "rows": len(moved),
        "piles": len(np.unique(groups)),
        "records": len(records),
        "folds": min(folds, len(np.unique(groups))),  # a fold per pile at most (GroupKFold): the folds used
        "calibration": calibration(held_out, moved),
        "pick_scores": pick_scores(records, per_record),
    }
    fitted = regressor.fit(features, moved)
    metadata = {
        "learner": "HistGradientBoostingRegressor(loss='poisson')",
        "parameters": fitted.get_params(),
        "held_out": report,
        "versions": package_versions("unstack", "scikit-learn", "numpy", "skops"),
    }
    return DisturbanceModel(fitted.estimator_, PICK_FEATURES, metadata), report
