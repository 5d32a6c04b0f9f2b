"""Hold-out evaluation lives outside ``fit``: the split, the scores, out-of-fold probabilities."""

from __future__ import annotations

import numpy as np
import pytest
from sklearn.metrics import roc_auc_score

from unstack.errors import InvalidArgument
from unstack.learning.classifier import SupportClassifier
from unstack.learning.holdout import evaluate_holdout, holdout_split, out_of_fold_probabilities

pytestmark = pytest.mark.slow  # fits classifiers with cross-validation

SMALL_GRID = {"svc__estimator__C": [1.0, 10.0], "svc__estimator__gamma": [0.1]}
MEMORISING_GRID = {"gb__learning_rate": [0.3], "gb__max_leaf_nodes": [31], "gb__max_iter": [200]}


def separable(generator: np.random.Generator, n: int = 160) -> tuple[np.ndarray, np.ndarray]:
    features = generator.normal(size=(n, 19))
    labels = (features[:, 0] + 0.5 * features[:, 1] + 0.3 * generator.normal(size=n) > 0.6).astype(int)
    return features, labels


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_the_split_covers_every_row_once_and_keeps_groups_whole(seed: int) -> None:
    rng = np.random.default_rng(seed)
    labels = rng.integers(0, 2, 160)
    groups = np.arange(160) // 8
    train, held_out = holdout_split(labels, groups=groups, validation_size=0.3, random_state=seed)
    assert sorted(train.tolist() + held_out.tolist()) == list(range(160))
    assert not set(groups[train]) & set(groups[held_out])
    train, held_out = holdout_split(labels, validation_size=0.3, random_state=seed)
    assert len(held_out) == 48


def test_the_holdout_scores_a_model_that_never_saw_the_held_out_rows(fixed_rng: np.random.Generator) -> None:
    features, labels = separable(fixed_rng)
    result = evaluate_holdout(SupportClassifier(cv=3, param_grid=SMALL_GRID, random_state=0), features, labels)
    assert result.validation_metrics["relations"] == len(result.validation_indices) == 48
    assert result.validation_metrics["success_rate"] > 0.7
    refit = SupportClassifier(cv=3, param_grid=SMALL_GRID, random_state=0).fit(
        features[result.train_indices], labels[result.train_indices]
    )
    held_out = features[result.validation_indices]
    np.testing.assert_allclose(refit.predict_proba(held_out)[:, 1], result.validation_probabilities)


def test_out_of_fold_probabilities_are_not_memorised(fixed_rng: np.random.Generator) -> None:
    features, labels = fixed_rng.normal(size=(200, 5)), fixed_rng.integers(0, 2, 200)  # nothing to learn
    model = SupportClassifier(learner="gradient_boosting", cv=4, param_grid=MEMORISING_GRID, random_state=0)
    model.fit(features, labels)
    assert roc_auc_score(labels, model.predict_proba(features)[:, 1]) > 0.95  # the trees memorise their rows
    out_of_fold = out_of_fold_probabilities(model, features, labels)
    assert out_of_fold.shape == labels.shape
    assert abs(roc_auc_score(labels, out_of_fold) - 0.5) < 0.15  # but not the held-out folds


def test_evaluate_holdout_returns_out_of_fold_probabilities_of_the_training_part(
    fixed_rng: np.random.Generator,
) -> None:
    features, labels = separable(fixed_rng)
    template = SupportClassifier(cv=3, param_grid=SMALL_GRID, random_state=0)
    result = evaluate_holdout(template, features, labels, out_of_fold=True)
    assert result.out_of_fold is not None and result.out_of_fold.shape == result.train_indices.shape
    assert not hasattr(template, "estimator_")  # the template is cloned, never fitted


@pytest.mark.parametrize(("size", "message"), [(0.0, "strictly between 0 and 1, got 0.0"), (1.0, "got 1.0")])
def test_a_validation_share_outside_zero_one_is_refused(size: float, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        holdout_split([0, 1] * 10, validation_size=size)


@pytest.mark.parametrize(("size", "held_out"), [(0.001, 1), (0.99, 143)])
def test_a_validation_share_that_leaves_a_side_without_a_class_is_refused_with_the_shares_that_work(
    size: float, held_out: int
) -> None:
    with pytest.raises(InvalidArgument, match=rf"^validation_size {size:g} holds out {held_out} of the 144 relations: "
                       r".* give from 0.014 to 0.986 \(0: no hold-out\)$"):  # fmt: skip
        holdout_split([0, 1] * 72, validation_size=size)
    train, held = holdout_split([0, 1] * 72, validation_size=0.014, random_state=0)
    assert len(held) == 3 and len(train) == 141


@pytest.mark.parametrize(("labels", "rare"), [([0] * 7 + [1], "supported"), ([1] * 7 + [0], "unsupported")])
def test_a_class_of_one_relation_cannot_be_split_and_says_so(labels: list[int], rare: str) -> None:
    """scikit-learn's stratified split raised its own ValueError (a traceback from fig5a)."""
    from unstack.learning.holdout import holdout_split

    with pytest.raises(InvalidArgument, match=rf"the 8 relations drawn hold 1 {rare} one only"):
        holdout_split(np.array(labels), validation_size=0.3, random_state=0)
