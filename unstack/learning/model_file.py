"""Model files that never run code when loaded (``unstack.model/1``).

A model file is a skops file holding a dict of three entries: ``"format"``
(``"unstack.model/1"``), ``"metadata"`` (a JSON string: learner, feature settings, hyper-
parameters, validation metrics, the fingerprint of the training data) and ``"estimator"``
(the fitted scikit-learn pipeline). Loading checks, before anything is built, that every
type in the file is one skops trusts by default (scikit-learn and numpy types; no custom
class, no pickle), then reads the metadata: a JSON object whose ``features`` entry must
rebuild the :class:`FeatureSettings` (there is no JSON Schema for the metadata; a file
without it, or with settings that do not fit, is refused with one line).

Examples
--------
>>> import tempfile, pathlib
>>> rng = np.random.default_rng(0)
>>> X = rng.normal(size=(80, 19)); y = (X[:, 0] > 0).astype(int)
>>> grid = {"svc__estimator__C": [1.0], "svc__estimator__gamma": [0.1]}
>>> model = SupportClassifier(cv=3, param_grid=grid, random_state=0).fit(X, y)
>>> path = pathlib.Path(tempfile.mkdtemp()) / "model.skops"
>>> save_model(SupportModel.from_classifier(model, FeatureSettings(), training={"seed": 0}), path)
>>> load_model(path).features.sigma
0.5
"""

from __future__ import annotations

import io
import json
import os
import sys
import zipfile
from contextlib import AbstractContextManager
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np
from threadpoolctl import ThreadpoolController

from unstack.atomic import atomic_write_bytes
from unstack.checks import finite_number
from unstack.errors import InvalidFile, UnstackError
from unstack.jsonio import refuse_special_file
from unstack.learning.classifier import SupportClassifier
from unstack.learning.features import FeatureSettings

__all__ = [
    "BUNDLED_MODELS",
    "DATA_SET_OUT_OF_RANGE",
    "DEFAULT_MODEL",
    "DEFAULT_MODEL_NAME",
    "MODEL_FORMAT",
    "PREDICT_OPENMP_THREADS",
    "RANGE_MARGIN",
    "InvalidModel",
    "SupportModel",
    "bundled_model_path",
    "data_set_out_of_distribution",
    "default_model_path",
    "feature_ranges",
    "load_model",
    "openmp_limit",
    "read_payload",
    "save_model",
]

MODEL_FORMAT = "unstack.model/1"
#: OpenMP threads a prediction may use. scikit-learn's gradient boosting predicts tree by tree,
#: each tree a parallel loop over all cores: where a core is busy (a planner's other threads,
#: another process), every loop waits for a descheduled thread. Measured on the default model,
#: 930 pairs (a 31-box scene), 2 cores with one of them busy: 0.93-1.01 s with 2 threads, 0.004 s
#: with 1. OpenMP limits are per thread (libgomp, libomp), so the limit covers the calling
#: thread's prediction only and is restored after it.
PREDICT_OPENMP_THREADS = 1


_controller: tuple[int, ThreadpoolController] | None = None


def _openmp_controller() -> ThreadpoolController:
    """The process's thread pools, found again only when a module was imported since: finding
    them walks every loaded library (about 1 ms a call, a fiftieth of a 5-box decision), and a
    library that brings its own OpenMP runtime comes with an import."""
    global _controller
    cached = _controller
    if cached is None or cached[0] != len(sys.modules):
        cached = (len(sys.modules), ThreadpoolController())
        _controller = cached  # one assignment: a thread reads the old pair or the new
    return cached[1]


def openmp_limit() -> AbstractContextManager[Any]:
    """A context in which OpenMP runs :data:`PREDICT_OPENMP_THREADS` thread(s) on the calling thread.

    Examples
    --------
    >>> with openmp_limit():
    ...     pass
    """
    limiter: AbstractContextManager[Any] = _openmp_controller().limit(limits=PREDICT_OPENMP_THREADS, user_api="openmp")
    return limiter


#: File name of the model shipped with the package (``unstack/learning/models``).
#: Models shipped with the package, by the name ``--model`` accepts: ``general`` (the
#: default: gradient boosting on the pose-only general features, trained on five pile
#: families with detector pose errors; see the generalisation page of the docs), ``paper``
#: (the paper's SVM and 19 features, for the reproduction) and ``extended`` (gradient
#: boosting on the extended features of the paper's piles; see the results page).
BUNDLED_MODELS = {"general": "general-mix.skops", "paper": "default-paper2.skops", "extended": "extended-paper2.skops"}
#: The name of the model used when none is given.
DEFAULT_MODEL_NAME = "general"
#: File name of the default model shipped with the package (``unstack/learning/models``).
DEFAULT_MODEL = BUNDLED_MODELS[DEFAULT_MODEL_NAME]


#: What a model file may unpack to at most (bytes, the zip members' sizes summed): the shipped
#: models unpack to under 1 MB; a small file that unpacks to gigabytes is refused before it is.
MAX_MODEL_BYTES = 256 * 2**20
#: The keys of a model file's payload.
PAYLOAD_KEYS = ("format", "metadata", "estimator")
#: scikit-learn types a model may hold beyond those skops trusts by default: the internals
#: of ``CalibratedClassifierCV`` and of the histogram gradient boosting's trees (plain data
#: holders, reviewed; no callables). Anything else that skops does not trust is refused.
EXTRA_TRUSTED_TYPES = (
    "sklearn.calibration._CalibratedClassifier",
    "sklearn.calibration._SigmoidCalibration",
    "sklearn.ensemble._hist_gradient_boosting.predictor.TreePredictor",
)


class InvalidModel(InvalidFile):
    """A file that is not an unstack model, or a model this version cannot read."""


@dataclass(frozen=True)
class SupportModel:
    """A fitted support classifier with what made it.

    Attributes
    ----------
    estimator : sklearn.pipeline.Pipeline
        ``predict_proba(F)[:, 1]`` is P(SUPP).
    features : FeatureSettings
    metadata : dict
        ``learner``, ``best_params``, ``cv_score``, ``validation`` metrics, ``training``
        (data set fingerprint, seed, r, ISets) and versions.
    source : str
        Where it was read from, for the messages of :class:`InvalidModel`.
    """

    estimator: Any
    features: FeatureSettings
    metadata: dict[str, Any]
    source: str = "the model"

    @classmethod
    def from_classifier(
        cls,
        classifier: SupportClassifier,
        features: FeatureSettings,
        *,
        training: dict[str, Any],
        training_features: np.ndarray | None = None,
        validation: dict[str, Any] | None = None,
    ) -> SupportModel:
        """Wrap a fitted :class:`SupportClassifier`.

        With ``training_features`` (the rows it was trained on) the model keeps the range
        of each feature (:func:`feature_ranges`) to tell when an input lies outside it.
        ``validation``: hold-out figures to keep with it (:func:`unstack.learning.holdout.evaluate_holdout`
        of the same settings; the model itself is fitted on all the rows).
        """
        from unstack.provenance import package_versions

        versions = package_versions("unstack", "scikit-learn", "numpy", "skops")
        metadata = {
            "learner": classifier.learner,
            "best_params": {key: _plain(value) for key, value in classifier.best_params_.items()},
            "cv_score": classifier.cv_score_,
            "cv_folds": classifier.cv_folds_,
            "validation": validation or {},
            "training": training,
            "versions": versions,
        }
        if training_features is not None:
            from unstack.learning.features import feature_names

            metadata["feature_ranges"] = feature_ranges(training_features, feature_names(features))
        return cls(classifier.estimator_, features, metadata)

    def out_of_range(self, features: np.ndarray) -> list[tuple[int, str, float, float, float]]:
        """Rows of ``features`` outside the training range: ``(row, feature, value, low, high)``.

        A value counts as outside when it lies beyond the training range's 0.5 and 99.5
        percentiles by more than :data:`RANGE_MARGIN` of the range's width. Empty for a
        model that does not keep its ranges.
        """
        ranges = self.metadata.get("feature_ranges")
        if not ranges or len(features) == 0:
            return []
        from unstack.learning.features import feature_names

        names = feature_names(self.features)
        low = np.array([ranges[name][0] for name in names])
        high = np.array([ranges[name][1] for name in names])
        margin = RANGE_MARGIN * np.maximum(high - low, 1e-9)
        outside = (features < low - margin) | (features > high + margin)
        return [
            (int(row), names[int(column)], float(features[row, column]), float(low[column]), float(high[column]))
            for row, column in np.argwhere(outside)
        ]

    def out_of_range_summary(self, features: np.ndarray) -> dict[str, Any]:
        """How much of a data set's features lie outside the training range (see
        :meth:`out_of_range`): the share of rows with any feature outside, and the rows outside
        per feature, most first.

        Examples
        --------
        >>> import numpy as np
        >>> model = load_model(bundled_model_path("paper"))
        >>> far = np.full((4, len(model.metadata["feature_ranges"])), 1e3)
        >>> summary = model.out_of_range_summary(far)
        >>> summary["rows"], summary["share"]
        (4, 1.0)
        """
        outside = self.out_of_range(features)
        by_feature: dict[str, int] = {}
        for _, name, *_ in outside:
            by_feature[name] = by_feature.get(name, 0) + 1
        rows = len({row for row, *_ in outside})
        return {
            "rows": rows,
            "share": rows / len(features) if len(features) else 0.0,
            "by_feature": dict(sorted(by_feature.items(), key=lambda item: -item[1])),
        }

    def support_probability(self, features: np.ndarray) -> np.ndarray:
        """P(SUPP) for each row of ``F_XY``, on the calling thread alone (see
        :data:`PREDICT_OPENMP_THREADS`)."""
        if len(features) == 0:
            return np.zeros(0)
        classes = list(self.estimator.classes_)
        try:
            with openmp_limit():
                probability: np.ndarray = self.estimator.predict_proba(features)[:, classes.index(1)]
        except (ValueError, TypeError, AttributeError, IndexError) as error:  # not a model of these features
            raise InvalidModel(self.source, "$.estimator", f"cannot predict P(SUPP): {error}") from error
        valid = (probability >= 0.0) & (probability <= 1.0)  # NaN fails too
        if not valid.all():
            bad = probability[~valid][0]
            raise InvalidModel(self.source, "$.estimator", f"expected probabilities in [0, 1], the model gave {bad}")
        return probability


#: How far beyond its training range (a share of the range's width) a feature may go
#: before the input counts as out of distribution.
RANGE_MARGIN = 0.1
#: A data set with more than this share of its relations outside the training range is out
#: of the model's distribution (by the range's definition, about 1-5 % of a model's own kind of
#: data lies outside: a few tails of ~20 features).
DATA_SET_OUT_OF_RANGE = 0.10


def data_set_out_of_distribution(summary: dict[str, Any], relations: int, source: str) -> str | None:
    """A warning when more than :data:`DATA_SET_OUT_OF_RANGE` of a data set's relations lie
    outside the model's training range (``summary`` from :meth:`SupportModel.out_of_range_summary`).

    Examples
    --------
    >>> data_set_out_of_distribution({"rows": 1, "share": 0.01, "by_feature": {"separation": 1}}, 100, "d") is None
    True
    >>> data_set_out_of_distribution({"rows": 50, "share": 0.5, "by_feature": {"separation": 50}}, 100, "d")[:40]
    'd: out of distribution: 50 of 100 relati'
    """
    if summary["share"] <= DATA_SET_OUT_OF_RANGE:
        return None
    features = ", ".join(f"{name} in {count:,}" for name, count in list(summary["by_feature"].items())[:3])
    return (
        f"{source}: out of distribution: {summary['rows']:,} of {relations:,} relations "
        f"({100 * summary['share']:.0f} %) have features outside the model's training range ({features}); "
        "the scores measure extrapolation"
    )


def feature_ranges(features: np.ndarray, names: tuple[str, ...]) -> dict[str, list[float]]:
    """The 0.5 and 99.5 percentiles of each feature column, by name.

    Examples
    --------
    >>> feature_ranges(np.arange(201.0).reshape(-1, 1), ("x",))
    {'x': [1.0, 199.0]}
    """
    low, high = np.percentile(features, [0.5, 99.5], axis=0)
    return {name: [float(a), float(b)] for name, a, b in zip(names, low, high, strict=True)}


def _plain(value: Any) -> Any:
    return value.item() if isinstance(value, np.generic) else value


def save_model(model: SupportModel, path: str | os.PathLike[str]) -> None:
    """Write a model file atomically."""
    import skops.io

    metadata = {"features": model.features.to_dict(), **model.metadata}
    payload = {"format": MODEL_FORMAT, "metadata": json.dumps(metadata, allow_nan=True), "estimator": model.estimator}
    atomic_write_bytes(path, skops.io.dumps(payload))


def load_model(path: str | os.PathLike[str]) -> SupportModel:
    """Read a model file; a one-line :class:`InvalidModel` for anything else.

    Raises
    ------
    InvalidModel
        Not a readable file, not a skops file, types skops does not trust, not an
        ``unstack.model/1`` payload, or a model of another version.
    """
    source = str(path)
    payload = read_payload(path, MODEL_FORMAT)
    metadata = read_metadata(payload, source)
    given = metadata.pop("features", None)
    if not isinstance(given, dict):
        raise InvalidModel(source, "$.metadata.features", "expected the feature settings (a JSON object)")
    for key, value in given.items():
        if key != "feature_set" and key != "dbaf_method" and finite_number(value) is None:
            raise InvalidModel(source, f"$.metadata.features.{key}", f"expected a finite number, got {value!r:.40}")
    try:
        features = FeatureSettings(**given)
    except TypeError as error:
        raise InvalidModel(source, "$.metadata.features", f"expected the feature settings: {error}") from None
    except UnstackError as error:
        raise InvalidModel(source, "$.metadata.features", str(error)) from None
    estimator = payload["estimator"]
    if not hasattr(estimator, "predict_proba"):
        raise InvalidModel(source, "$.estimator", "expected a fitted classifier with predict_proba")
    model = SupportModel(estimator, features, metadata, source=source)
    _check_usable(model)
    return model


def read_metadata(payload: dict[str, Any], source: str) -> dict[str, Any]:
    """The JSON object a model file's ``metadata`` text holds (NaN allowed: a score not measured).

    Raises
    ------
    InvalidModel
        Not JSON text, nested deeper than files may be, or not an object.
    """
    from unstack.jsonio import MAX_DEPTH, json_kind, too_deep

    text = payload["metadata"]
    if not isinstance(text, str):
        raise InvalidModel(source, "$.metadata", f"expected JSON text, got {type(text).__name__}")
    try:
        metadata = json.loads(text)
    except RecursionError:
        raise InvalidModel(source, "$.metadata", f"expected JSON nested at most {MAX_DEPTH} levels deep") from None
    except ValueError as error:
        raise InvalidModel(source, "$.metadata", f"expected JSON text: {error}") from None
    if not isinstance(metadata, dict):
        raise InvalidModel(source, "$.metadata", f"expected a JSON object, got {json_kind(metadata)}")
    if too_deep(metadata, MAX_DEPTH) is not None:
        raise InvalidModel(source, "$.metadata", f"expected JSON nested at most {MAX_DEPTH} levels deep")
    return metadata


def read_payload(path: str | os.PathLike[str], expected_format: str) -> dict[str, Any]:
    """The dict a skops model file holds, after refusing anything that could run code.

    Every type in the file must be one skops trusts by default or one of
    :data:`EXTRA_TRUSTED_TYPES`; the dict's ``"format"`` must be ``expected_format``.

    Raises
    ------
    InvalidModel
        Not a readable file, not a skops file, untrusted types, another format.
    """
    import skops.io

    source = str(path)
    target = Path(path)
    refuse_special_file(target, InvalidModel)
    if target.is_dir():
        raise InvalidModel(source, "$", "expected a model file, got a directory")
    try:
        data = target.read_bytes()
    except OSError as error:
        raise InvalidModel(source, "$", f"cannot read the model file ({error.strerror or error})") from error
    if not zipfile.is_zipfile(io.BytesIO(data)):
        raise InvalidModel(source, "$", "expected an unstack model file (a skops file), got something else")
    try:
        with zipfile.ZipFile(io.BytesIO(data)) as archive:
            unpacked = sum(member.file_size for member in archive.infolist())
    except (zipfile.BadZipFile, OSError) as error:
        raise InvalidModel(source, "$", f"expected an unstack model file (a skops file): {error}") from None
    if len(data) > MAX_MODEL_BYTES or unpacked > MAX_MODEL_BYTES:
        raise InvalidModel(
            source, "$", f"expected a model of at most {MAX_MODEL_BYTES / 2**20:.0f} MiB, this one unpacks to "
            f"{max(unpacked, len(data)) / 2**20:,.0f} MiB"
        )  # fmt: skip
    try:
        untrusted = skops.io.get_untrusted_types(data=data)
    except Exception as error:  # any failure to parse means "not a model"
        raise InvalidModel(source, "$", f"expected an unstack model file (a skops file): {error}") from error
    refused = sorted(set(untrusted) - set(EXTRA_TRUSTED_TYPES))
    if refused:
        raise InvalidModel(source, "$", f"refusing to load types that are not trusted: {', '.join(refused)}")
    try:
        payload = skops.io.loads(data, trusted=[name for name in untrusted if name in EXTRA_TRUSTED_TYPES])
    except Exception as error:  # a broken skops file
        raise InvalidModel(source, "$", f"the skops file does not load: {error}") from error
    if not isinstance(payload, dict) or "format" not in payload:
        raise InvalidModel(source, "$", "expected an unstack model (a dict with 'format'), got another skops object")
    if not isinstance(payload["format"], str) or payload["format"] != expected_format:
        raise InvalidModel(
            source, "$.format", f"unsupported model format {payload['format']!r:.80}; expected {expected_format}"
        )
    unknown = sorted(str(key) for key in payload if key not in PAYLOAD_KEYS)
    missing = [key for key in PAYLOAD_KEYS if key not in payload]
    if unknown or missing:
        odd = f"unknown: {', '.join(unknown)[:80]}" if unknown else f"missing: {', '.join(missing)}"
        raise InvalidModel(source, "$", f"expected the keys {', '.join(PAYLOAD_KEYS)}; {odd}")
    return payload


def _check_usable(model: SupportModel) -> None:
    """Refuse, in one line, a model that loads but cannot give P(SUPP) for this feature set: never
    fitted, without the class 1, made for another number of features, with feature ranges of
    other features, or predicting something other than probabilities (one row at the middle
    of the feature ranges, or zeros)."""
    from unstack.learning.features import feature_names

    source, estimator = model.source, model.estimator
    names = feature_names(model.features)
    classes = getattr(estimator, "classes_", None)
    if classes is None:
        raise InvalidModel(source, "$.estimator", "expected a fitted classifier, got one that was never fitted")
    if sorted(np.asarray(classes).tolist()) != [0, 1]:  # support_probability reads the class 1
        labels = ", ".join(str(label) for label in classes)
        raise InvalidModel(source, "$.estimator", f"expected the classes 0 and 1 (1: supports), got {labels:.80}")
    width = getattr(estimator, "n_features_in_", None)
    if width is not None and int(width) != len(names):
        raise InvalidModel(
            source,
            "$.estimator",
            f"expected a classifier of the {len(names)} {model.features.feature_set} features, got one of {width}",
        )
    ranges = model.metadata.get("feature_ranges")
    if ranges is not None:
        if not isinstance(ranges, dict) or sorted(ranges) != sorted(names):
            raise InvalidModel(
                source, "$.metadata.feature_ranges", f"expected a [low, high] range for each of: {', '.join(names)}"
            )
        for name in names:
            bounds = ranges[name]
            pair = [finite_number(bound) for bound in bounds] if isinstance(bounds, list) and len(bounds) == 2 else []
            if len(pair) != 2 or pair[0] is None or pair[1] is None or pair[0] > pair[1]:
                raise InvalidModel(
                    source,
                    f"$.metadata.feature_ranges.{name}",
                    f"expected [low, high]: two finite numbers, low <= high, got {bounds!r:.60}",
                )
        middle = np.array([[(float(ranges[name][0]) + float(ranges[name][1])) / 2 for name in names]])
    else:
        middle = np.zeros((1, len(names)))
    model.support_probability(middle)


def default_model_path() -> Path:
    """Where the default model shipped with the package lies."""
    return bundled_model_path(DEFAULT_MODEL_NAME)


def bundled_model_path(name: str) -> Path:
    """Where the shipped model called ``name`` (a key of :data:`BUNDLED_MODELS`) lies.

    Examples
    --------
    >>> bundled_model_path("extended").name
    'extended-paper2.skops'
    """
    return Path(str(resources.files("unstack.learning") / "models" / BUNDLED_MODELS[name]))
