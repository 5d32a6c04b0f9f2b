"""SupportClassifier follows scikit-learn's estimator contract and decides from probabilities."""

from __future__ import annotations

import re

import numpy as np
import pytest
from sklearn.utils.estimator_checks import parametrize_with_checks

from unstack.errors import InvalidArgument
from unstack.learning.classifier import LEARNERS, SupportClassifier

pytestmark = pytest.mark.slow  # scikit-learn's estimator checks and grid searches

SMALL_GRID = {"svc__estimator__C": [1.0, 10.0], "svc__estimator__gamma": [0.1]}


def separable(generator: np.random.Generator, n: int = 160) -> tuple[np.ndarray, np.ndarray]:
    features = generator.normal(size=(n, 19))
    labels = (features[:, 0] + 0.5 * features[:, 1] + 0.3 * generator.normal(size=n) > 0.6).astype(int)
    return features, labels


@parametrize_with_checks(
    [SupportClassifier(cv=3, param_grid=SMALL_GRID, random_state=0)],
)
def test_scikit_learn_estimator_checks(estimator: SupportClassifier, check: object) -> None:
    check(estimator)  # type: ignore[operator]


FAST_GRIDS = {
    "svm": SMALL_GRID,
    "calibrated_svm": SMALL_GRID,
    "gradient_boosting": {"gb__learning_rate": [0.1], "gb__max_leaf_nodes": [7, 15]},
}


@pytest.mark.parametrize("learner", LEARNERS)
def test_every_learner_fits_all_rows_and_ranks_new_ones(learner: str, fixed_rng: np.random.Generator) -> None:
    from sklearn.metrics import roc_auc_score

    features, labels = separable(fixed_rng)
    model = SupportClassifier(learner=learner, cv=3, param_grid=FAST_GRIDS[learner], random_state=0)
    model.fit(features, labels)
    new_features, new_labels = separable(fixed_rng)
    assert roc_auc_score(new_labels, model.predict_proba(new_features)[:, 1]) > 0.85
    assert set(model.best_params_) <= set(model.estimator_.get_params())


def test_fit_uses_every_row(fixed_rng: np.random.Generator) -> None:
    """A row seen by ``fit`` moves the model: nothing is held out inside ``fit``."""
    features, labels = separable(fixed_rng)
    grid = {"gb__learning_rate": [0.3], "gb__max_leaf_nodes": [31], "gb__max_iter": [200]}
    model = SupportClassifier(learner="gradient_boosting", cv=3, param_grid=grid, random_state=0)
    model.fit(features, labels)
    assert np.mean(model.predict(features) == labels) > 0.98  # every row was trained on (trees memorise)
    assert model.cv_folds_ == 3


def test_predict_follows_predict_proba(fixed_rng: np.random.Generator) -> None:
    features, labels = separable(fixed_rng)
    model = SupportClassifier(cv=3, param_grid=SMALL_GRID, random_state=0).fit(features, labels)
    probability = model.predict_proba(features)
    assert np.allclose(probability.sum(axis=1), 1.0)
    assert np.array_equal(model.predict(features), (probability[:, 1] >= 0.5).astype(int))


def test_same_random_state_same_model(fixed_rng: np.random.Generator) -> None:
    features, labels = separable(fixed_rng)
    first = SupportClassifier(cv=3, param_grid=SMALL_GRID, random_state=3).fit(features, labels)
    again = SupportClassifier(cv=3, param_grid=SMALL_GRID, random_state=3).fit(features, labels)
    assert np.array_equal(first.predict_proba(features), again.predict_proba(features))
    assert first.best_params_ == again.best_params_


def test_init_only_stores_and_fitted_attributes_end_with_underscore(fixed_rng: np.random.Generator) -> None:
    model = SupportClassifier(learner="svm", cv=4, param_grid=SMALL_GRID)
    assert model.get_params()["cv"] == 4 and not hasattr(model, "estimator_")
    features, labels = separable(fixed_rng)
    model.fit(features, labels)
    fitted = [name for name in vars(model) if name.endswith("_") and not name.startswith("_")]
    assert set(fitted) == {"classes_", "estimator_", "best_params_", "cv_score_", "cv_folds_", "n_features_in_"}


@pytest.mark.parametrize(
    ("labels", "message"),
    [
        (np.zeros(20, dtype=int), r"needs both classes in y, got only 1 class: \[0\]"),
        (np.arange(20) % 3, "Only binary classification is supported"),
    ],
)
def test_bad_labels(labels: np.ndarray, message: str, fixed_rng: np.random.Generator) -> None:
    with pytest.raises(ValueError, match=message):
        SupportClassifier(cv=3, param_grid=SMALL_GRID).fit(fixed_rng.normal(size=(20, 19)), labels)


def test_unknown_learner(fixed_rng: np.random.Generator) -> None:
    features, labels = separable(fixed_rng)
    with pytest.raises(ValueError, match="unknown learner 'forest'; expected one of svm, gradient_boosting"):
        SupportClassifier(learner="forest").fit(features, labels)


def test_grouped_folds_keep_every_group_on_one_side(fixed_rng: np.random.Generator) -> None:
    from unstack.learning.classifier import fold_splitter

    features, labels = separable(fixed_rng)
    groups = np.arange(len(labels)) // 8  # 20 piles of 8 relations
    splitter, folds, _ = fold_splitter(3, labels, groups, 0)
    for train, test in splitter.split(features, labels, groups):
        assert not set(groups[train]) & set(groups[test])
    assert folds == 3


def test_groups_must_match_the_rows(fixed_rng: np.random.Generator) -> None:
    features, labels = separable(fixed_rng)
    with pytest.raises(ValueError, match="groups has 3 labels for 160 rows"):
        SupportClassifier(cv=3, param_grid=SMALL_GRID).fit(features, labels, groups=[0, 1, 2])


@pytest.mark.parametrize("cv, advice", [(3, r"more ISets, or fewer folds$"), (2, r"more ISets$")])
def test_too_few_of_a_class_for_the_folds_is_one_clear_error(
    fixed_rng: np.random.Generator, cv: int, advice: str
) -> None:
    labels = np.array([1, 1, 1] + [0] * 27)  # three SUPP: some fold's training part holds one or none
    groups = np.arange(30) // 3  # ten piles of three relations, the SUPP all in the first
    with pytest.raises(InvalidArgument, match="too few examples to cross-validate: the training part of fold") as error:
        SupportClassifier(cv=cv, param_grid=SMALL_GRID).fit(fixed_rng.normal(size=(30, 19)), labels, groups=groups)
    assert re.search(advice, str(error.value))  # no fewer than two folds is offered
