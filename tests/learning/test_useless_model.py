"""Training warns when its data cannot make a useful model."""

from __future__ import annotations

import numpy as np
from sklearn.dummy import DummyClassifier
from sklearn.linear_model import LogisticRegression

from unstack.learning.training import useless_model_warnings
from unstack.learning.training_data import SupportExamples


def examples(n_positive: int, n_negative: int) -> SupportExamples:
    rng = np.random.default_rng(0)
    labels = np.r_[np.ones(n_positive), np.zeros(n_negative)].astype(np.int64)
    features = rng.normal(size=(len(labels), 2)) + 3.0 * labels[:, None]
    return SupportExamples(features, labels, np.arange(len(labels)) // 20, np.zeros(len(labels)), [])


def test_a_model_that_never_predicts_support_is_named() -> None:
    rows = examples(30, 170)
    never = DummyClassifier(strategy="most_frequent").fit(rows.features, rows.labels)
    (warning,) = useless_model_warnings(never, rows)
    assert "P(SUPP) < 0.5 for every one of its 200 training relations" in warning
    assert "unstack simulate --configs 50" in warning


def test_too_few_relations_of_a_class_are_named() -> None:
    rows = examples(5, 100)
    fitted = LogisticRegression().fit(rows.features, rows.labels)
    warnings = useless_model_warnings(fitted, rows)
    assert any("only 5 support and 100 non-support relations from 6 configurations" in w for w in warnings)


def test_a_model_that_separates_the_classes_gets_no_warning() -> None:
    rows = examples(100, 100)
    assert useless_model_warnings(LogisticRegression().fit(rows.features, rows.labels), rows) == ()
