"""What a pick will move: a learned estimate of the boxes that move when a candidate is taken.

Eq. 11 charges a pick with the boxes it supports; what a robot pays is every box that moves
when the pick is taken out -- boxes held up, but also boxes dragged by friction, knocked by a
falling one, tipped. :class:`DisturbanceRegressor` learns the expected number of boxes that
move more than 2 cm from the robot's view of each candidate (:mod:`unstack.learning.pick_features`:
the detected boxes, the cloud and the reasoner's marginals and expected costs), trained on
removal responses measured in the physics engine before every pick of closed-loop unloading
(:mod:`unstack.experiments.pick_responses`). It follows scikit-learn's estimator contract
(keyword-only ``__init__``, fitted attributes ending in ``_``, ``random_state``; ``fit`` only
fits) and is a Poisson-loss gradient-boosting regressor inside.

:class:`DisturbanceModel` is the fitted regressor with what made it, saved as a skops file
(``unstack.disturbance-model/1``) that loads without running code.

Examples
--------
>>> rng = np.random.default_rng(0)
>>> X = rng.uniform(size=(400, 3)); y = rng.poisson(3.0 * X[:, 0])
>>> regressor = DisturbanceRegressor(max_iter=50, random_state=0).fit(X, y)
>>> moves = regressor.predict(np.array([[0.05, 0.5, 0.5], [0.95, 0.5, 0.5]]))
>>> bool(moves[0] < moves[1]), bool((moves >= 0).all())
(True, True)
"""

from __future__ import annotations

import itertools
import json
import os
from dataclasses import dataclass
from typing import Any

import numpy as np
from sklearn.base import BaseEstimator, RegressorMixin
from sklearn.utils.validation import check_is_fitted, validate_data

from unstack.atomic import atomic_write_bytes
from unstack.learning.model_file import InvalidModel, openmp_limit, read_metadata, read_payload
from unstack.learning.pick_features import PICK_FEATURES

__all__ = [
    "DISTURBANCE_FORMAT",
    "DisturbanceModel",
    "DisturbanceRegressor",
    "default_disturbance_path",
    "load_disturbance_model",
    "save_disturbance_model",
]

#: Format tag of a pick-disturbance model file.
DISTURBANCE_FORMAT = "unstack.disturbance-model/1"
#: The shipped model, in ``unstack/learning/models``.
DEFAULT_DISTURBANCE_MODEL = "disturbance.skops"


class DisturbanceRegressor(RegressorMixin, BaseEstimator):  # type: ignore[misc]
    """Expected number of boxes a pick moves, from the pick's features.

    Parameters
    ----------
    max_iter : int
        Boosting rounds.
    learning_rate : float
    max_leaf_nodes : int
    min_samples_leaf : int
    l2_regularization : float
    random_state : int, optional

    Attributes
    ----------
    estimator_ : sklearn.ensemble.HistGradientBoostingRegressor
        The fitted regressor (Poisson loss: predictions are positive expected counts).
    n_features_in_ : int
    """

    def __init__(
        self,
        *,
        max_iter: int = 300,
        learning_rate: float = 0.05,
        max_leaf_nodes: int = 15,
        min_samples_leaf: int = 20,
        l2_regularization: float = 1.0,
        random_state: int | None = None,
    ) -> None:
        self.max_iter = max_iter
        self.learning_rate = learning_rate
        self.max_leaf_nodes = max_leaf_nodes
        self.min_samples_leaf = min_samples_leaf
        self.l2_regularization = l2_regularization
        self.random_state = random_state

    def fit(self, X: Any, y: Any, sample_weight: Any = None) -> DisturbanceRegressor:  # noqa: N803
        """Fit on pick features ``X`` and the boxes each pick moved ``y`` (counts >= 0)."""
        from sklearn.ensemble import HistGradientBoostingRegressor

        X, y = validate_data(self, X, y, dtype=np.float64, y_numeric=True)  # noqa: N806
        if np.any(y < 0):
            raise ValueError("expected counts of boxes moved (>= 0), got negative targets")
        self.estimator_ = HistGradientBoostingRegressor(
            loss="poisson",
            max_iter=self.max_iter,
            learning_rate=self.learning_rate,
            max_leaf_nodes=self.max_leaf_nodes,
            min_samples_leaf=self.min_samples_leaf,
            l2_regularization=self.l2_regularization,
            random_state=self.random_state,
        ).fit(X, y, sample_weight=sample_weight)
        return self

    def predict(self, X: Any) -> np.ndarray:  # noqa: N803
        """Expected boxes moved for each row of ``X``."""
        check_is_fitted(self)
        X = validate_data(self, X, dtype=np.float64, reset=False)  # noqa: N806
        prediction: np.ndarray = self.estimator_.predict(X)
        return prediction


@dataclass(frozen=True)
class DisturbanceModel:
    """A fitted pick-disturbance regressor with what made it.

    Attributes
    ----------
    estimator : sklearn.ensemble.HistGradientBoostingRegressor
        ``predict(features)`` is the expected number of boxes moved.
    features : tuple of str
        The columns it takes (:data:`~unstack.learning.pick_features.PICK_FEATURES`).
    metadata : dict
        Training data, hyper-parameters, held-out figures, versions.
    source : str
    """

    estimator: Any
    features: tuple[str, ...]
    metadata: dict[str, Any]
    source: str = "the disturbance model"

    def expected_moves(self, features: np.ndarray) -> np.ndarray:
        """Expected boxes moved per row of pick features (the calling thread only)."""
        rows = np.asarray(features, dtype=np.float64)
        if rows.ndim != 2 or rows.shape[1] != len(self.features):
            raise InvalidModel(
                self.source, "$.features", f"expected rows of {len(self.features)} pick features, got {rows.shape}"
            )
        if len(rows) == 0:
            return np.zeros(0)
        with openmp_limit():
            prediction = np.asarray(self.estimator.predict(rows), dtype=np.float64)
        return np.maximum(prediction, 0.0)


def save_disturbance_model(model: DisturbanceModel, path: str | os.PathLike[str]) -> None:
    """Write a disturbance model file atomically (skops; no pickle)."""
    import skops.io

    metadata = {"features": list(model.features), **model.metadata}
    payload = {"format": DISTURBANCE_FORMAT, "metadata": json.dumps(metadata), "estimator": model.estimator}
    atomic_write_bytes(path, skops.io.dumps(payload))


def load_disturbance_model(path: str | os.PathLike[str] | None = None) -> DisturbanceModel:
    """Read a disturbance model file (default: the shipped one); one-line errors otherwise.

    Raises
    ------
    InvalidModel
        Not a skops file of this format, untrusted types, features other than this version's,
        or an estimator that does not predict.

    Examples
    --------
    >>> load_disturbance_model().features == PICK_FEATURES
    True
    """
    path = default_disturbance_path() if path is None else path
    source = str(path)
    payload = read_payload(path, DISTURBANCE_FORMAT)
    metadata = read_metadata(payload, source)
    given = metadata.pop("features", None)
    features = tuple(given) if isinstance(given, list) else ()
    estimator = payload["estimator"]
    if features != PICK_FEATURES:
        raise InvalidModel(
            source, "$.metadata.features", f"expected the {len(PICK_FEATURES)} pick features of this version"
        )
    if not hasattr(estimator, "predict") or getattr(estimator, "n_features_in_", None) != len(PICK_FEATURES):
        raise InvalidModel(source, "$.estimator", f"expected a fitted regressor of {len(PICK_FEATURES)} features")
    model = DisturbanceModel(estimator, features, metadata, source=source)
    model.expected_moves(np.zeros((1, len(features))))
    return model


def default_disturbance_path() -> Any:
    """Where the shipped disturbance model lies."""
    from importlib import resources
    from pathlib import Path

    return Path(str(resources.files("unstack.learning") / "models" / DEFAULT_DISTURBANCE_MODEL))


#: Bins of predicted boxes moved in which calibration compares predicted and actual means.
CALIBRATION_BINS = (0.0, 0.05, 0.2, 0.5, 1.0, 2.0, np.inf)


def calibration(predicted: np.ndarray, actual: np.ndarray) -> dict[str, Any]:
    """How well predicted boxes moved match the actual ones: Spearman's rank correlation and,
    per bin of :data:`CALIBRATION_BINS`, the count and the mean predicted and actual.

    Examples
    --------
    >>> table = calibration(np.array([0.0, 0.1, 1.5, 3.0]), np.array([0, 0, 1, 4]))
    >>> table["spearman"] > 0.9, table["bins"][0]["picks"]
    (True, 1)
    """
    from scipy.stats import spearmanr

    predicted = np.asarray(predicted, dtype=np.float64)
    actual = np.asarray(actual, dtype=np.float64)
    rows = []
    for low, high in itertools.pairwise(CALIBRATION_BINS):
        inside = (predicted >= low) & (predicted < high)
        if inside.any():
            rows.append(
                {
                    "predicted_from": low,
                    "predicted_to": None if np.isinf(high) else high,
                    "picks": int(inside.sum()),
                    "mean_predicted": float(predicted[inside].mean()),
                    "mean_actual": float(actual[inside].mean()),
                }
            )
    correlation = spearmanr(predicted, actual).statistic if len(predicted) > 2 and np.ptp(actual) > 0 else float("nan")
    return {"spearman": float(correlation), "picks": len(predicted), "bins": rows}


def held_out_predictions(
    regressor: DisturbanceRegressor, features: np.ndarray, moved: np.ndarray, groups: np.ndarray, *, folds: int = 5
) -> np.ndarray:
    """Predictions for every row from a model fitted without its group (piles held out together)."""
    from sklearn.base import clone
    from sklearn.model_selection import GroupKFold

    piles = len(np.unique(groups))
    if piles < 2:
        from unstack.errors import InvalidArgument

        raise InvalidArgument(
            f"held-out figures need states from at least 2 piles, held out one at a time; these come from {piles}"
        )
    predicted = np.zeros(len(moved))
    for train, test in GroupKFold(n_splits=min(folds, piles)).split(features, moved, groups):
        predicted[test] = clone(regressor).fit(features[train], moved[train]).predict(features[test])
    return predicted
