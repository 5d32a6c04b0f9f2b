"""Hold-out evaluation of a support classifier: the paper's 70/30 validation (Fig. 5).

Evaluation is kept out of :meth:`SupportClassifier.fit <unstack.learning.classifier.SupportClassifier.fit>`:
:func:`evaluate_holdout` splits the rows (stratified, or by group so that one pile's
relations stay on one side), fits a clone of the classifier on the training part, scores it
on the held-out part and, on request, computes out-of-fold probabilities of the training
part. A model to ship is then fitted on all the rows.

Out-of-fold probabilities (:func:`out_of_fold_probabilities`) come from the chosen
hyper-parameters cross-validated on the same folds the search used: a threshold chosen on
them is not flattered by the model having seen the rows (in-sample probabilities of a
boosted model are far more confident than on new piles).

Examples
--------
>>> import numpy as np
>>> from unstack.learning.classifier import SupportClassifier
>>> rng = np.random.default_rng(0)
>>> X = rng.normal(size=(120, 3)); y = (X[:, 0] + 0.3 * rng.normal(size=120) > 0).astype(int)
>>> grid = {"svc__estimator__C": [1.0], "svc__estimator__gamma": [0.1]}
>>> result = evaluate_holdout(SupportClassifier(cv=3, param_grid=grid, random_state=0), X, y)
>>> len(result.train_indices), len(result.validation_indices)
(84, 36)
>>> result.validation_metrics["relations"]
36
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from sklearn.base import clone
from sklearn.model_selection import GroupShuffleSplit, cross_val_predict, train_test_split

from unstack.errors import InvalidArgument
from unstack.learning.classifier import SupportClassifier, fold_splitter

__all__ = ["HoldoutResult", "evaluate_holdout", "holdout_split", "out_of_fold_probabilities"]


@dataclass(frozen=True)
class HoldoutResult:
    """A classifier fitted on the training part and scored on the held-out part.

    Attributes
    ----------
    classifier : SupportClassifier
        Fitted on ``train_indices`` only.
    train_indices, validation_indices : numpy.ndarray
        Sorted rows of each part.
    grouped : bool
        Whether the split kept groups whole.
    validation_probabilities : numpy.ndarray
        P(SUPP) of the held-out rows (``validation_indices`` order).
    validation_metrics : dict
        :func:`unstack.learning.metrics.classification_report` on the held-out part.
    out_of_fold : numpy.ndarray or None
        Out-of-fold P(SUPP) of the training rows (``train_indices`` order), when asked for.
    """

    classifier: SupportClassifier
    train_indices: np.ndarray
    validation_indices: np.ndarray
    grouped: bool
    validation_probabilities: np.ndarray
    validation_metrics: dict[str, Any]
    out_of_fold: np.ndarray | None


def holdout_split(
    y: Any, *, groups: Any = None, validation_size: float = 0.3, random_state: int | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Rows of the training and the held-out part, each sorted.

    Stratified by ``y``; with ``groups``, every group lies wholly on one side.

    Examples
    --------
    >>> train, held_out = holdout_split([0, 1] * 10, groups=np.arange(20) // 4, random_state=0)
    >>> sorted(set(np.arange(20)[train] // 4) & set(np.arange(20)[held_out] // 4))
    []
    """
    labels = np.asarray(y)
    if not 0.0 < validation_size < 1.0:
        raise ValueError(f"validation_size must lie strictly between 0 and 1, got {validation_size}")
    rows = np.arange(len(labels))
    if groups is not None:
        group_labels = np.asarray(groups)
        if len(group_labels) != len(labels):
            raise ValueError(f"groups has {len(group_labels)} labels for {len(labels)} rows")
        splitter = GroupShuffleSplit(n_splits=1, test_size=validation_size, random_state=random_state)
        train_rows, valid_rows = next(splitter.split(rows, labels, group_labels))
    else:
        _require_each_class_on_each_side(labels, validation_size)
        train_rows, valid_rows = train_test_split(
            rows, test_size=validation_size, stratify=labels, random_state=random_state
        )
    return np.sort(train_rows), np.sort(valid_rows)


def _require_each_class_on_each_side(labels: np.ndarray, validation_size: float) -> None:
    """Raise where a stratified split of ``labels`` cannot put every class on both sides (the
    held-out part takes ``ceil(validation_size * n)`` rows, as scikit-learn's split does)."""
    total, classes = len(labels), len(np.unique(labels))
    values, counts = np.unique(labels, return_counts=True)
    if counts.min() < 2:  # a stratified split puts a member of each class on each side
        rare = values[int(np.argmin(counts))]
        name = "supported" if rare == 1 else "unsupported" if rare == 0 else repr(rare)
        raise InvalidArgument(
            f"the {total} relations drawn hold {counts.min()} {name} one only: a split that keeps each class on "
            "both sides needs two; draw more ISets (isets) or use more piles"
        )
    held_out = math.ceil(validation_size * total)
    if min(held_out, total - held_out) < classes:
        smallest = math.ceil(classes / total * 1000) / 1000
        largest = math.floor((total - classes) / total * 1000) / 1000
        raise InvalidArgument(
            f"validation_size {validation_size:g} holds out {held_out} of the {total} relations: the held-out and "
            f"the training part need one of each of the {classes} classes; give from {smallest:g} to {largest:g} "
            "(0: no hold-out)"
        )


def out_of_fold_probabilities(classifier: SupportClassifier, X: Any, y: Any, groups: Any = None) -> np.ndarray:
    """Out-of-fold P(SUPP) of every row of ``X`` from a fitted classifier's chosen parameters.

    The folds are those :meth:`SupportClassifier.fit` used on the same rows.

    Examples
    --------
    >>> rng = np.random.default_rng(1)
    >>> X = rng.normal(size=(60, 2)); y = (X[:, 0] > 0).astype(int)
    >>> grid = {"svc__estimator__C": [1.0], "svc__estimator__gamma": [0.1]}
    >>> model = SupportClassifier(cv=3, param_grid=grid, random_state=0).fit(X, y)
    >>> out_of_fold_probabilities(model, X, y).shape
    (60,)
    """
    features, labels = np.asarray(X, dtype=float), np.asarray(y)
    group_labels = None if groups is None else np.asarray(groups)
    splitter, _, _ = fold_splitter(classifier.cv, labels, group_labels, classifier.random_state)
    positive = list(classifier.estimator_.classes_).index(classifier.classes_[1])
    probabilities: np.ndarray = cross_val_predict(
        clone(classifier.estimator_), features, labels, groups=group_labels, cv=splitter,
        n_jobs=classifier.n_jobs, method="predict_proba",
    )[:, positive]  # fmt: skip
    return probabilities


def evaluate_holdout(
    classifier: SupportClassifier,
    X: Any,
    y: Any,
    *,
    groups: Any = None,
    validation_size: float = 0.3,
    out_of_fold: bool = False,
) -> HoldoutResult:
    """Fit a clone of ``classifier`` on a training part and score it on the held-out rest.

    Parameters
    ----------
    classifier : SupportClassifier
        Unfitted (it is cloned; its ``random_state`` seeds the split too).
    X, y : array-like
    groups : array-like, optional
        One label per row (the pile): the split and the folds keep each group whole.
    validation_size : float
        Share held out (the paper: 0.3).
    out_of_fold : bool
        Also compute out-of-fold probabilities of the training part.

    Returns
    -------
    HoldoutResult
    """
    from unstack.learning.metrics import classification_report

    features, labels = np.asarray(X, dtype=float), np.asarray(y)
    group_labels = None if groups is None else np.asarray(groups)
    train, held_out = holdout_split(
        labels, groups=group_labels, validation_size=validation_size, random_state=classifier.random_state
    )
    if len(np.unique(labels[train])) < 2:
        raise InvalidArgument(
            "the training part holds one class only; use more groups (piles) or a smaller validation_size"
        )
    train_groups = None if group_labels is None else group_labels[train]
    fitted = clone(classifier).fit(features[train], labels[train], groups=train_groups)
    probabilities = fitted.predict_proba(features[held_out])[:, 1]
    metrics = classification_report(labels[held_out] == fitted.classes_[1], probabilities) if len(held_out) else {}
    oof = out_of_fold_probabilities(fitted, features[train], labels[train], train_groups) if out_of_fold else None
    return HoldoutResult(fitted, train, held_out, group_labels is not None, probabilities, metrics, oof)
