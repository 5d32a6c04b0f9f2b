"""Training a support model to ship: pooled examples, hold-out figures, a fit on all rows, provenance.

:func:`pooled_examples` draws ISets from one or more data-set folders (pile families, say)
and keeps each folder's configurations apart. :func:`train_support_model` reports the
hold-out figures of the settings (:func:`unstack.learning.holdout.evaluate_holdout`: fitted
on the training part, scored on the rest) and then fits the model it returns on *all* the
rows, so no shipped model leaves part of its data unseen. The model keeps where its data
came from (:func:`training_provenance`).

Examples
--------
>>> CONFIGURATION_OFFSET
100000
"""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from unstack.errors import UnstackError
from unstack.learning.choices import SPLITS
from unstack.learning.features import FeatureSettings
from unstack.learning.holdout import HoldoutResult
from unstack.learning.model_file import SupportModel
from unstack.learning.training_data import SupportExamples
from unstack.parameters import LEARNING_SEED, validate_params

__all__ = [
    "CONFIGURATION_OFFSET",
    "SPLITS",
    "TrainingRun",
    "holdout_by_data_set",
    "pooled_examples",
    "train_support_model",
    "training_provenance",
]

#: Configuration numbers of the n-th data set of a training run start at n times this.
CONFIGURATION_OFFSET = 100_000


def pooled_examples(
    data_dirs: Sequence[str | os.PathLike[str]],
    *,
    r: int,
    isets: int,
    seed: int,
    settings: FeatureSettings,
    n_jobs: int = 1,
    draw: str = "random",
    vary_clouds: bool = False,
    pose_noise: float = 0.0,
    progress: Callable[[int, int], None] | None = None,
) -> SupportExamples:
    """Examples of several data sets, pooled; the n-th folder is seeded ``seed + n``.

    The configuration numbers of the n-th folder are offset by ``n * CONFIGURATION_OFFSET``,
    so a split by configuration keeps every pile of every folder whole. ``progress(done,
    total)`` counts configurations over all folders. Every folder is checked before any work.

    Raises
    ------
    UnstackError
        A folder holds no configuration, or no ISet of two detected boxes was drawn.
    """
    from unstack.dataset_folders import require_configurations
    from unstack.learning.training_data import dataset_examples

    sizes = [len(require_configurations(folder)) for folder in data_dirs]
    total = sum(sizes)
    parts = []
    for number, folder in enumerate(data_dirs):
        before = sum(sizes[:number])

        def report(done: int, _size: int, before: int = before) -> None:
            if progress is not None:
                progress(before + done, total)

        part = dataset_examples(
            folder, r=r, isets=isets, seed=seed + number, settings=settings, n_jobs=n_jobs, progress=report,
            draw=draw, vary_clouds=vary_clouds, pose_noise=pose_noise,
        )  # fmt: skip
        parts.append(replace(part, configuration=part.configuration + number * CONFIGURATION_OFFSET))
    examples = SupportExamples.concatenate(parts)
    if len(examples.labels) == 0:
        names = ", ".join(str(folder) for folder in data_dirs)
        raise UnstackError(f"{names}: no ISet of at least 2 detected boxes; nothing to learn from")
    return examples


def training_provenance(
    data_dirs: Sequence[str | os.PathLike[str]], examples: SupportExamples, **options: Any
) -> dict[str, Any]:
    """Where a model's data came from: folders, their fingerprints, simulation seeds and settings.

    ``options`` (the ISet draw, seeds, split...) are recorded as given. One folder is
    recorded as plain values, several as lists.
    """
    from unstack.dataset_folders import read_manifest
    from unstack.learning.training_data import dataset_fingerprint

    manifests = [read_manifest(folder) or {} for folder in data_dirs]
    fields: dict[str, list[Any]] = {
        "data": [str(folder) for folder in data_dirs],
        "fingerprint": [dataset_fingerprint(folder) for folder in data_dirs],
        "simulation_seed": [manifest.get("seed") for manifest in manifests],
        "simulation_settings": [manifest.get("settings") for manifest in manifests],
    }
    single: dict[str, Any] = {key: values[0] for key, values in fields.items()} if len(data_dirs) == 1 else fields
    return {
        **single,
        **options,
        "relations": len(examples.labels),
        "supp": int(examples.labels.sum()),
    }


@dataclass(frozen=True)
class TrainingRun:
    """A model fitted on all its rows, and the hold-out figures of its settings (if asked for)."""

    model: SupportModel
    holdout: HoldoutResult | None
    warnings: tuple[str, ...] = ()


@validate_params({"seed": LEARNING_SEED})
def train_support_model(
    examples: SupportExamples,
    settings: FeatureSettings,
    *,
    learner: str = "svm",
    cv: int = 10,
    validation_size: float = 0.3,
    split_by: str = "pairs",
    seed: int = 0,
    n_jobs: int = 1,
    provenance: dict[str, Any] | None = None,
) -> TrainingRun:
    """Hold-out figures on ``validation_size`` of the rows, then a model fitted on all of them.

    Parameters
    ----------
    examples : SupportExamples
    settings : FeatureSettings
        The features the examples were computed with.
    learner, cv, seed, n_jobs
        Passed to :class:`SupportClassifier <unstack.learning.classifier.SupportClassifier>`.
    validation_size : float
        Share held out for the figures (0: no hold-out figures).
    split_by : {"pairs", "configuration"}
        ``configuration`` keeps each pile's relations on one side of the split and the folds.
    provenance : dict, optional
        :func:`training_provenance`; ``validation_size`` and ``split_by`` are added.

    Returns
    -------
    TrainingRun
    """
    from sklearn.base import clone

    from unstack.learning.classifier import SupportClassifier
    from unstack.learning.holdout import evaluate_holdout

    if split_by not in SPLITS:
        raise ValueError(f"unknown split {split_by!r}; expected one of {', '.join(SPLITS)}")
    if not 0.0 <= validation_size < 1.0:
        raise ValueError(f"validation_size must lie in [0, 1), got {validation_size}")
    groups = examples.configuration if split_by == "configuration" else None
    if groups is not None:
        _require_configurations_to_split(groups, validation_size)
    supporting = int(np.sum(examples.labels == 1))
    others = len(examples.labels) - supporting
    if min(supporting, others) < MIN_TO_TRAIN:
        from unstack.errors import InvalidArgument

        raise InvalidArgument(
            f"{supporting} SUPP and {others} other relations among the {len(examples.labels)} drawn: too few of a "
            f"class to learn from (at least {MIN_TO_TRAIN} of each); give more piles, more ISets or larger ones (--r)"
        )
    template = SupportClassifier(learner=learner, cv=cv, n_jobs=n_jobs, random_state=seed)
    holdout = (
        evaluate_holdout(template, examples.features, examples.labels, groups=groups, validation_size=validation_size)
        if validation_size > 0
        else None
    )
    classifier = clone(template).fit(examples.features, examples.labels, groups=groups)
    training = {**(provenance or {}), "split_by": split_by, "validation_size": validation_size, "fitted_on": "all"}
    validation = None
    if holdout is not None:
        data = (provenance or {}).get("data")
        names = data if isinstance(data, list) else None
        validation = {**holdout.validation_metrics, **holdout_by_data_set(examples, holdout, names)}
    model = SupportModel.from_classifier(
        classifier,
        settings,
        training=training,
        training_features=examples.features,
        validation=validation,
    )
    return TrainingRun(
        model,
        holdout,
        (*fewer_folds_warnings(classifier, examples, groups), *useless_model_warnings(classifier, examples)),
    )


def fewer_folds_warnings(classifier: Any, examples: SupportExamples, groups: Any = None) -> tuple[str, ...]:
    """A warning when the fitted ``classifier`` cross-validated on fewer folds than its ``cv``
    asked for: a fold needs a relation of the rarer class (and, split by configuration, a pile).

    Examples
    --------
    >>> from types import SimpleNamespace
    >>> rows = SimpleNamespace(labels=np.array([0] * 30 + [1] * 6))
    >>> fewer_folds_warnings(SimpleNamespace(cv=10, cv_folds_=6), rows)[0]
    '6 cross-validation folds were used, not the 10 asked for: a fold needs one relation of each class (6 SUPP)'
    """
    if classifier.cv_folds_ >= classifier.cv:
        return ()
    supporting = int(np.sum(examples.labels == 1))
    others = len(examples.labels) - supporting
    rarer = f"{supporting} SUPP" if supporting <= others else f"{others} other"
    piles = f" and one pile ({len(np.unique(groups))} in all)" if groups is not None else ""
    return (
        f"{classifier.cv_folds_} cross-validation folds were used, not the {classifier.cv} asked for: a fold "
        f"needs one relation of each class ({rarer}){piles}",
    )


#: Fewer relations of a class than this cannot be split and cross-validated at all.
MIN_TO_TRAIN = 4


def _require_configurations_to_split(groups: Any, validation_size: float) -> None:
    """Raise before any work where splitting by configuration leaves fewer than two
    configurations to cross-validate on (the validation share takes ``ceil(share * n)``)."""
    import math

    from unstack.errors import InvalidArgument

    total = len(np.unique(groups))
    training = total - (math.ceil(validation_size * total) if validation_size > 0 else 0)
    if training < 2:
        held = f" after the validation share {validation_size:g} takes {total - training}" if validation_size else ""
        raise InvalidArgument(
            f"split by configuration: {total} {'configuration leaves' if total == 1 else 'configurations leave'} "
            f"{training} to cross-validate on{held}; at least 2 "
            "are needed (give more piles, a smaller validation share, or split by pairs)"
        )


#: Fewer relations of either class than this make a model too thin to trust.
MIN_CLASS_EXAMPLES = 20


def useless_model_warnings(classifier: Any, examples: SupportExamples) -> tuple[str, ...]:
    """Why a fitted model cannot be useful: one class too rare, or one answer for every relation.

    Examples
    --------
    >>> import numpy as np
    >>> class Never:
    ...     def predict_proba(self, features):
    ...         return np.column_stack([np.ones(len(features)), np.zeros(len(features))])
    >>> labels = np.r_[np.ones(20), np.zeros(20)]
    >>> rows = SupportExamples(np.zeros((40, 2)), labels, np.arange(40) // 10, np.zeros(40), [])
    >>> useless_model_warnings(Never(), rows)[0][:56]
    'the model says P(SUPP) < 0.5 for every one of its 40 tra'
    """
    labels = np.asarray(examples.labels)
    configurations = len(set(np.asarray(examples.configuration).tolist()))
    more = f"simulate more piles (unstack simulate --configs {max(50, 4 * configurations)}) and train again"
    warnings = []
    positives, negatives = int(labels.sum()), int(len(labels) - labels.sum())
    if min(positives, negatives) < MIN_CLASS_EXAMPLES:
        warnings.append(
            f"only {positives} support and {negatives} non-support relations from {configurations} configurations: "
            f"too few to learn from; {more}"
        )
    predicted = classifier.predict_proba(examples.features)[:, 1] >= 0.5
    if not predicted.any() or predicted.all():
        side = "< 0.5" if not predicted.any() else ">= 0.5"
        warnings.append(
            f"the model says P(SUPP) {side} for every one of its {len(labels)} training relations: it cannot tell "
            f"support from none (BER 0.5); {more}"
        )
    return tuple(warnings)


def holdout_by_data_set(
    examples: SupportExamples, holdout: HoldoutResult, names: Sequence[str] | None = None
) -> dict[str, Any]:
    """The hold-out figures of each pooled data set apart (``{"by_data_set": {name: report}}``).

    Rows belong to the data set their configuration number says (:data:`CONFIGURATION_OFFSET`);
    ``names`` are the folders in pooling order (default ``"0"``, ``"1"``...). A run on one
    data set gives ``{}``. Each report is
    :func:`~unstack.learning.metrics.classification_report` without its reliability bins.

    Examples
    --------
    >>> import numpy as np
    >>> from unstack.learning.training_data import SupportExamples
    >>> from unstack.learning.holdout import HoldoutResult
    >>> examples = SupportExamples(
    ...     np.zeros((4, 1)), np.array([1, 0, 1, 0]), np.array([0, 0, 100000, 100000]), np.zeros(4, int), []
    ... )
    >>> holdout = HoldoutResult(None, np.array([], int), np.arange(4), True, np.array([0.9, 0.2, 0.3, 0.1]), {}, None)
    >>> figures = holdout_by_data_set(examples, holdout, ["wall", "stacked"])["by_data_set"]
    >>> figures["wall"]["supp_recall"], figures["stacked"]["supp_recall"]
    (1.0, 0.0)
    """
    from unstack.learning.metrics import classification_report

    folder = examples.configuration[holdout.validation_indices] // CONFIGURATION_OFFSET
    numbers = sorted(set(folder.tolist()))
    if len(numbers) < 2:
        return {}
    labels = examples.labels[holdout.validation_indices]
    reports = {}
    for number in numbers:
        rows = folder == number
        report = classification_report(labels[rows], holdout.validation_probabilities[rows])
        report.pop("reliability")
        reports[names[number] if names is not None else str(number)] = report
    return {"by_data_set": reports}
