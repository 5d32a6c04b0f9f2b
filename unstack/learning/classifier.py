"""``SupportClassifier``: P(SUPP(X, Y)) from the 19 support features (§III-A).

A scikit-learn estimator whose ``fit`` only fits: it chooses the hyper-parameters by
``cv``-fold cross-validation (10-fold, as the paper) and refits the best model on all the
rows it is given. Hold-out figures (the paper's 70/30 split, Fig. 5) and out-of-fold
probabilities are evaluation, not fitting: :mod:`unstack.learning.holdout`.

With ``groups`` (for example the configuration each relation comes from), the folds keep
every group on one side: relations of one pile never appear in both a fold's training and
its test part. Without them the folds split the relations, as the paper describes it.

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
>>> model.cv_folds_
3
"""

from __future__ import annotations

from typing import Any

import numpy as np
from sklearn.base import BaseEstimator, ClassifierMixin
from sklearn.model_selection import GridSearchCV, StratifiedGroupKFold, StratifiedKFold
from sklearn.pipeline import Pipeline
from sklearn.utils.multiclass import type_of_target, unique_labels
from sklearn.utils.validation import check_is_fitted, validate_data

from unstack.errors import InvalidArgument
from unstack.learning.choices import LEARNERS

__all__ = ["LEARNERS", "SupportClassifier", "default_grid", "fold_splitter", "make_learner"]


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


def fold_splitter(cv: int, y: np.ndarray, groups: np.ndarray | None, random_state: int | None) -> tuple[Any, int, int]:
    """The cross-validation folds for ``y``: ``(splitter, folds, calibration_folds)``.

    At most ``cv`` folds, fewer when the rarer class (or the number of groups) is small;
    stratified, and grouped when ``groups`` is given. ``calibration_folds`` is what the SVMs'
    probability calibration can use inside one fold's training part.

    Examples
    --------
    >>> splitter, folds, calibration = fold_splitter(10, np.array([0, 1] * 4), None, 0)
    >>> folds, calibration
    (4, 3)
    """
    smallest_class = int(np.min(np.unique(y, return_counts=True)[1]))
    folds = max(2, min(cv, smallest_class))
    if groups is not None:
        folds = max(2, min(folds, len(np.unique(groups))))
    calibration_folds = max(2, min(5, smallest_class * (folds - 1) // folds))
    splitter = (
        StratifiedKFold(folds, shuffle=True, random_state=random_state)
        if groups is None
        else StratifiedGroupKFold(folds, shuffle=True, random_state=random_state)
    )
    return splitter, folds, calibration_folds


def _require_both_classes_in_every_fold(
    splitter: Any, X: Any, y: np.ndarray, groups: np.ndarray | None, calibration_folds: int
) -> None:
    """Raise where a fold's training part holds fewer than ``calibration_folds`` examples of a
    class: a fit there fails (the calibration inside it needs that many of each)."""
    folds = splitter.get_n_splits()
    for fold, (train, _) in enumerate(splitter.split(X, y, groups)):
        classes, counts = np.unique(y[train], return_counts=True)
        if len(classes) < 2 or counts.min() < calibration_folds:
            rarest = 0 if len(classes) < 2 else int(counts.min())
            fewer = ", or fewer folds" if folds > 2 else ""  # two is the fewest there can be
            raise InvalidArgument(
                f"too few examples to cross-validate: the training part of fold {fold + 1} holds {rarest} of a class "
                f"(at least {calibration_folds} needed; {int(np.unique(y, return_counts=True)[1].min())} of the rarer "
                f"class among {len(y)} relations in all); give more piles or more ISets{fewer}"
            )


class SupportClassifier(ClassifierMixin, BaseEstimator):
    """Probability that box X supports box Y, from ``F_XY``.

    Parameters
    ----------
    learner : {"svm", "gradient_boosting", "calibrated_svm"}
    param_grid : dict, optional
        Grid for the cross-validation (default: :func:`default_grid` of the learner).
    cv : int
        Folds of the cross-validation that chooses the hyper-parameters.
    scoring : str
        Model-selection score (balanced accuracy by default: SUPP is the rarer class).
    n_jobs : int, optional
        Parallel cross-validation fits.
    random_state : int, optional

    Attributes
    ----------
    classes_ : numpy.ndarray
    estimator_ : sklearn.pipeline.Pipeline
        The best pipeline, refit on all the rows given to ``fit``.
    best_params_ : dict
    cv_score_ : float
        Mean cross-validated score of the best parameters.
    cv_folds_ : int
        Folds the cross-validation used.
    n_features_in_ : int

    See Also
    --------
    unstack.learning.holdout.evaluate_holdout : the paper's 70/30 validation, out-of-fold probabilities.
    """

    def __init__(
        self,
        *,
        learner: str = "svm",
        param_grid: dict[str, list[Any]] | None = None,
        cv: int = 10,
        scoring: str = "balanced_accuracy",
        n_jobs: int | None = None,
        random_state: int | None = None,
    ) -> None:
        self.learner = learner
        self.param_grid = param_grid
        self.cv = cv
        self.scoring = scoring
        self.n_jobs = n_jobs
        self.random_state = random_state

    def __sklearn_tags__(self) -> Any:
        tags = super().__sklearn_tags__()
        tags.classifier_tags.multi_class = False  # SUPP or not
        return tags

    def fit(self, X: Any, y: Any, groups: Any = None) -> SupportClassifier:
        """Cross-validate the grid on all rows and refit the best parameters on all rows.

        ``groups``: one label per row; the folds keep each group whole.
        """
        X, y = validate_data(self, X, y)
        target = type_of_target(y, input_name="y", raise_unknown=True)
        if target not in ("binary", "unknown") and len(unique_labels(y)) > 2:
            raise ValueError(
                f"Only binary classification is supported (SUPP or not). The type of the target is {target}."
            )
        self.classes_ = unique_labels(y)
        if len(self.classes_) < 2:
            raise InvalidArgument(  # a ValueError too, as scikit-learn's estimators raise
                f"SupportClassifier needs both classes in y, got only 1 class: {self.classes_.tolist()}"
            )
        group_labels = None if groups is None else np.asarray(groups)
        if group_labels is not None and len(group_labels) != len(y):
            raise ValueError(f"groups has {len(group_labels)} labels for {len(y)} rows")
        splitter, folds, calibration_folds = fold_splitter(self.cv, y, group_labels, self.random_state)
        _require_both_classes_in_every_fold(splitter, X, y, group_labels, calibration_folds)
        search = GridSearchCV(
            make_learner(self.learner, self.random_state, calibration_folds=calibration_folds),
            self.param_grid or default_grid(self.learner),
            scoring=self.scoring,
            cv=splitter,
            n_jobs=self.n_jobs,
            refit=True,
        )
        search.fit(X, y, groups=group_labels)
        self.estimator_ = search.best_estimator_
        self.best_params_ = dict(search.best_params_)
        self.cv_score_ = float(search.best_score_)
        self.cv_folds_ = folds
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
