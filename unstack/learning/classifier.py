"""``SupportClassifier``: P(SUPP(X, Y)) from the 19 support features (§III-A).

A scikit-learn estimator. ``fit`` holds out ``validation_size`` of the data (stratified,
70/30 by default, as the paper), chooses the hyper-parameters by ``cv``-fold
cross-validation on the training part (10-fold, as the paper), refits the best model on
the training part and scores it on the held-out part (``validation_metrics_``).

With ``groups`` (for example the configuration each relation comes from), the hold-out
and the folds keep every group on one side: relations of one pile never appear in both
training and validation. Without them the split is by relation, as the paper describes it,
and pairs of one pile land on both sides -- which flatters the validation figures.

Learners (``learner=``):

``"svm"`` (the paper)
    Standardised features, RBF ``SVC`` with LIBSVM's probability estimates (Wu, Lin and
    Weng, as the paper: a sigmoid fitted to 5-fold cross-validated decision values);
    C and gamma from a log grid.
``"gradient_boosting"``
    ``HistGradientBoostingClassifier``; learning rate and tree size from a grid.
``"calibrated_svm"``
    The RBF SVM with isotonic calibration of its cross-validated decision values instead
    of the sigmoid.

Decisions come from ``predict_proba`` only: ``predict`` thresholds it at 0.5 (``SVC.predict``
can disagree with ``SVC.predict_proba``).

Examples
--------
>>> rng = np.random.default_rng(0)
>>> X = rng.normal(size=(120, 3)); y = (X[:, 0] + 0.3 * rng.normal(size=120) > 0).astype(int)
>>> grid = {"svc__estimator__C": [1.0], "svc__estimator__gamma": [0.1]}
>>> model = SupportClassifier(cv=3, param_grid=grid, random_state=0).fit(X, y)
>>> model.predict_proba(X[:2]).shape
(2, 2)
>>> sorted(model.validation_metrics_)[:3]
['average_entropy', 'balanced_error_rate', 'brier_score']
"""

from __future__ import annotations

from typing import Any

import numpy as np
from sklearn.base import BaseEstimator, ClassifierMixin, clone
from sklearn.model_selection import (
    GridSearchCV,
    GroupShuffleSplit,
    StratifiedGroupKFold,
    StratifiedKFold,
    cross_val_predict,
    train_test_split,
)
from sklearn.pipeline import Pipeline
from sklearn.utils.multiclass import type_of_target, unique_labels
from sklearn.utils.validation import check_is_fitted, validate_data

__all__ = ["LEARNERS", "SupportClassifier", "default_grid", "make_learner"]

#: Learner names accepted by ``SupportClassifier(learner=...)``.
LEARNERS = ("svm", "gradient_boosting", "calibrated_svm")


def make_learner(name: str, random_state: int | None, *, calibration_folds: int = 5) -> Pipeline:
    """The unfitted pipeline of a learner (``calibration_folds`` for the SVMs' probabilities)."""
    from sklearn.preprocessing import StandardScaler

    if name in ("svm", "calibrated_svm"):
        from sklearn.calibration import CalibratedClassifierCV
        from sklearn.svm import SVC

        # "svm": LIBSVM's probability method (Platt's sigmoid fitted on 5-fold cross-validated
        # decision values, then one SVM on all data), which scikit-learn >= 1.9 spells this way
        # instead of SVC(probability=True). "calibrated_svm": isotonic instead of the sigmoid.
        method = "sigmoid" if name == "svm" else "isotonic"
        svm = CalibratedClassifierCV(SVC(kernel="rbf"), method=method, cv=calibration_folds, ensemble=False)
        return Pipeline([("scale", StandardScaler()), ("svc", svm)])
    if name == "gradient_boosting":
        from sklearn.ensemble import HistGradientBoostingClassifier

        return Pipeline([("gb", HistGradientBoostingClassifier(random_state=random_state))])
    raise ValueError(f"unknown learner {name!r}; expected one of {', '.join(LEARNERS)}")


def default_grid(name: str) -> dict[str, list[Any]]:
    """The hyper-parameter grid searched for a learner."""
    if name in ("svm", "calibrated_svm"):
        return {
            "svc__estimator__C": [1.0, 10.0, 100.0, 1000.0],
            "svc__estimator__gamma": [0.001, 0.003, 0.01, 0.03, 0.1],
        }
    if name == "gradient_boosting":
        return {"gb__learning_rate": [0.05, 0.1], "gb__max_leaf_nodes": [7, 15], "gb__max_iter": [100, 300]}
    raise ValueError(f"unknown learner {name!r}; expected one of {', '.join(LEARNERS)}")


class SupportClassifier(ClassifierMixin, BaseEstimator):
    """Probability that box X supports box Y, from ``F_XY``.

    Parameters
    ----------
    learner : {"svm", "gradient_boosting", "calibrated_svm"}
    param_grid : dict, optional
        Grid for the cross-validation (default: :func:`default_grid` of the learner).
    cv : int
        Folds of the cross-validation on the training part.
    validation_size : float
        Share held out for validation (0 keeps everything for training; no metrics then).
    scoring : str
        Model-selection score (balanced accuracy by default: SUPP is the rarer class).
    n_jobs : int, optional
        Parallel cross-validation fits.
    random_state : int, optional

    Attributes
    ----------
    classes_ : numpy.ndarray
    estimator_ : sklearn.pipeline.Pipeline
        The best pipeline, refit on the training part.
    best_params_ : dict
    cv_score_ : float
        Mean cross-validated score of the best parameters.
    validation_metrics_ : dict
        :func:`unstack.learning.metrics.classification_report` on the held-out part.
    train_indices_, validation_indices_ : numpy.ndarray
        Rows of ``X`` in the training and the held-out part.
    grouped_ : bool
        Whether the split kept groups together.
    cv_probabilities_ : numpy.ndarray
        Out-of-fold P(SUPP) of each training row (``train_indices_`` order): the chosen
        hyper-parameters cross-validated on the same folds. A threshold chosen on these
        is not flattered by the model having seen the rows (in-sample probabilities of a
        boosted model are far more confident than on new piles).
    n_features_in_ : int
    """

    def __init__(
        self,
        *,
        learner: str = "svm",
        param_grid: dict[str, list[Any]] | None = None,
        cv: int = 10,
        validation_size: float = 0.3,
        scoring: str = "balanced_accuracy",
        n_jobs: int | None = None,
        random_state: int | None = None,
    ) -> None:
        self.learner = learner
        self.param_grid = param_grid
        self.cv = cv
        self.validation_size = validation_size
        self.scoring = scoring
        self.n_jobs = n_jobs
        self.random_state = random_state

    def __sklearn_tags__(self) -> Any:
        tags = super().__sklearn_tags__()
        tags.classifier_tags.multi_class = False  # SUPP or not
        return tags

    def fit(self, X: Any, y: Any, groups: Any = None) -> SupportClassifier:
        """Split, cross-validate the grid on the training part, refit, validate.

        ``groups``: one label per row; the hold-out and the folds keep each group whole.
        """
        from unstack.learning.metrics import classification_report

        X, y = validate_data(self, X, y)
        target = type_of_target(y, input_name="y", raise_unknown=True)
        if target not in ("binary", "unknown") and len(unique_labels(y)) > 2:
            raise ValueError(
                f"Only binary classification is supported (SUPP or not). The type of the target is {target}."
            )
        self.classes_ = unique_labels(y)
        if len(self.classes_) < 2:
            raise ValueError(f"SupportClassifier needs both classes in y, got only 1 class: {self.classes_.tolist()}")
        rows = np.arange(len(y))
        group_labels = None if groups is None else np.asarray(groups)
        if group_labels is not None and len(group_labels) != len(y):
            raise ValueError(f"groups has {len(group_labels)} labels for {len(y)} rows")
        if self.validation_size > 0 and group_labels is not None:
            splitter = GroupShuffleSplit(n_splits=1, test_size=self.validation_size, random_state=self.random_state)
            train_rows, valid_rows = next(splitter.split(X, y, group_labels))
        elif self.validation_size > 0:
            train_rows, valid_rows = train_test_split(
                rows, test_size=self.validation_size, stratify=y, random_state=self.random_state
            )
        else:
            train_rows, valid_rows = rows, rows[:0]
        self.train_indices_, self.validation_indices_ = np.sort(train_rows), np.sort(valid_rows)
        self.grouped_ = group_labels is not None
        X_train, y_train = X[self.train_indices_], y[self.train_indices_]
        X_valid, y_valid = X[self.validation_indices_], y[self.validation_indices_]
        if len(np.unique(y_train)) < 2:
            raise ValueError("the training part holds one class only; use more groups or a smaller validation_size")
        smallest_class = int(np.min(np.unique(y_train, return_counts=True)[1]))
        folds = max(2, min(self.cv, smallest_class))
        if group_labels is not None:
            folds = max(2, min(folds, len(np.unique(group_labels[self.train_indices_]))))
        # the probability calibration runs inside each fold's training part: fewer folds for tiny data
        calibration_folds = max(2, min(5, smallest_class * (folds - 1) // folds))
        splitter = (
            StratifiedKFold(folds, shuffle=True, random_state=self.random_state)
            if group_labels is None
            else StratifiedGroupKFold(folds, shuffle=True, random_state=self.random_state)
        )
        train_groups = None if group_labels is None else group_labels[self.train_indices_]
        search = GridSearchCV(
            make_learner(self.learner, self.random_state, calibration_folds=calibration_folds),
            self.param_grid or default_grid(self.learner),
            scoring=self.scoring,
            cv=splitter,
            n_jobs=self.n_jobs,
            refit=True,
        )
        search.fit(X_train, y_train, groups=train_groups)
        positive = list(search.best_estimator_.classes_).index(self.classes_[1])
        self.cv_probabilities_ = cross_val_predict(
            clone(search.best_estimator_), X_train, y_train, groups=train_groups, cv=splitter,
            n_jobs=self.n_jobs, method="predict_proba",
        )[:, positive]  # fmt: skip
        self.estimator_ = search.best_estimator_
        self.best_params_ = dict(search.best_params_)
        self.cv_score_ = float(search.best_score_)
        self.cv_folds_ = folds
        self.validation_metrics_ = (
            classification_report(y_valid == self.classes_[1], self._positive_probability(X_valid))
            if len(y_valid)
            else {}
        )
        return self

    def _positive_probability(self, X: np.ndarray) -> np.ndarray:
        column = list(self.estimator_.classes_).index(self.classes_[1])
        probability: np.ndarray = self.estimator_.predict_proba(X)[:, column]
        return probability

    def predict_proba(self, X: Any) -> np.ndarray:
        """``[P(not SUPP), P(SUPP)]`` for each row (columns follow ``classes_``)."""
        check_is_fitted(self)
        X = validate_data(self, X, reset=False)
        positive = self._positive_probability(X)
        return np.column_stack([1.0 - positive, positive])

    def predict(self, X: Any) -> np.ndarray:
        """The class whose probability is at least 0.5 (from ``predict_proba``, never ``SVC.predict``)."""
        probabilities = self.predict_proba(X)
        labels: np.ndarray = self.classes_[(probabilities[:, 1] >= 0.5).astype(int)]
        return labels
