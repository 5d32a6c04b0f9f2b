"""Training a model to ship: the hold-out figures of each pooled data set apart."""

from __future__ import annotations

import numpy as np
import pytest

from unstack.learning.classifier import SupportClassifier
from unstack.learning.holdout import evaluate_holdout
from unstack.learning.metrics import classification_report
from unstack.learning.training import CONFIGURATION_OFFSET, holdout_by_data_set
from unstack.learning.training_data import SupportExamples

pytestmark = pytest.mark.slow  # fits a classifier with cross-validation

SMALL_GRID = {"svc__estimator__C": [1.0], "svc__estimator__gamma": [0.1]}


def pooled(generator: np.random.Generator, piles: tuple[int, ...]) -> SupportExamples:
    """Rows of several data sets, 8 per pile; data set n has its configurations offset by n * OFFSET."""
    configuration = np.concatenate(
        [number * CONFIGURATION_OFFSET + np.repeat(np.arange(count), 8) for number, count in enumerate(piles)]
    )
    features = generator.normal(size=(len(configuration), 4))
    noise = 0.3 + configuration // CONFIGURATION_OFFSET  # the later data sets are harder
    labels = (features[:, 0] + noise * generator.normal(size=len(configuration)) > 0.5).astype(int)
    return SupportExamples(features, labels, configuration, np.zeros(len(labels), int), [])


def test_each_data_set_is_scored_on_its_own_held_out_rows(fixed_rng: np.random.Generator) -> None:
    examples = pooled(fixed_rng, (12, 10, 8))
    holdout = evaluate_holdout(
        SupportClassifier(cv=3, param_grid=SMALL_GRID, random_state=0), examples.features, examples.labels,
        groups=examples.configuration,
    )  # fmt: skip
    reports = holdout_by_data_set(examples, holdout, ["wall", "stacked", "dropped"])["by_data_set"]
    assert list(reports) == ["wall", "stacked", "dropped"]
    assert sum(report["relations"] for report in reports.values()) == holdout.validation_metrics["relations"]
    folder = examples.configuration[holdout.validation_indices] // CONFIGURATION_OFFSET
    labels = examples.labels[holdout.validation_indices]
    for number, report in enumerate(reports.values()):
        rows = folder == number
        expected = classification_report(labels[rows], holdout.validation_probabilities[rows])
        assert report["confusion_matrix"] == expected["confusion_matrix"]
        assert "reliability" not in report
    assert reports["wall"]["success_rate"] > reports["dropped"]["success_rate"]  # the noisier set scores lower


def test_one_data_set_has_no_split_figures(fixed_rng: np.random.Generator) -> None:
    examples = pooled(fixed_rng, (20,))
    holdout = evaluate_holdout(
        SupportClassifier(cv=3, param_grid=SMALL_GRID, random_state=0), examples.features, examples.labels,
        groups=examples.configuration,
    )  # fmt: skip
    assert holdout_by_data_set(examples, holdout) == {}


@pytest.mark.parametrize(
    ("piles", "validation_size", "message"),
    [
        (2, 0.3, r"2 configurations leave 1 to cross-validate on after the validation share 0.3 takes 1"),
        (1, 0.0, r"1 configuration leaves 1 to cross-validate on; at least 2 are needed"),
    ],
)
def test_splitting_by_configuration_needs_two_configurations_to_cross_validate(
    fixed_rng: np.random.Generator, piles: int, validation_size: float, message: str
) -> None:
    from unstack.errors import InvalidArgument
    from unstack.learning.features import FeatureSettings
    from unstack.learning.training import train_support_model

    with pytest.raises(InvalidArgument, match=message):
        train_support_model(
            pooled(fixed_rng, (piles,)), FeatureSettings(), split_by="configuration", validation_size=validation_size
        )


@pytest.mark.parametrize("supporting", [0, 1, 3])
def test_a_class_too_thin_to_learn_from_is_refused_before_any_fit(
    fixed_rng: np.random.Generator, supporting: int
) -> None:
    from dataclasses import replace

    from unstack.errors import InvalidArgument
    from unstack.learning.features import FeatureSettings
    from unstack.learning.training import train_support_model

    examples = pooled(fixed_rng, (6,))
    labels = np.zeros(len(examples.labels), dtype=int)
    labels[:supporting] = 1
    with pytest.raises(InvalidArgument, match=rf"{supporting} SUPP and {len(labels) - supporting} other relations"):
        train_support_model(replace(examples, labels=labels), FeatureSettings())


def test_fewer_folds_than_asked_for_are_said_with_the_rarer_class(fixed_rng: np.random.Generator) -> None:
    from unstack.learning.training import fewer_folds_warnings

    examples = pooled(fixed_rng, (10,))
    rarer = int(min(examples.labels.sum(), len(examples.labels) - examples.labels.sum()))
    fitted = SupportClassifier(cv=500, param_grid=SMALL_GRID, random_state=0).fit(examples.features, examples.labels)
    assert fitted.cv_folds_ == rarer
    [warning] = fewer_folds_warnings(fitted, examples)
    assert warning.startswith(f"{rarer} cross-validation folds were used, not the 500 asked for: ")
    fitted = SupportClassifier(cv=3, param_grid=SMALL_GRID, random_state=0).fit(examples.features, examples.labels)
    assert fewer_folds_warnings(fitted, examples) == ()
