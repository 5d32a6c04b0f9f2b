"""Evaluation metrics: Fig. 5 layout, BER (Eq. 16), entropy (Eq. 15), Brier, reliability."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from sklearn.metrics import balanced_accuracy_score, brier_score_loss

from unstack.learning.metrics import (
    average_entropy,
    balanced_error_rate,
    classification_report,
    confusion_counts,
    not_supp_recall_at,
    save_reliability_diagram,
)


def test_the_papers_fig_5a_counts() -> None:
    truth = np.array([1] * 185 + [0] * 401)
    probability = np.array([0.9] * 145 + [0.1] * 40 + [0.9] * 50 + [0.1] * 351)
    report = classification_report(truth, probability)
    assert report["confusion_matrix"] == [[145, 40], [50, 351]]
    assert round(100 * report["supp_recall"], 1) == 78.4
    assert round(100 * report["not_supp_recall"], 1) == 87.5


def test_balanced_error_rate_is_one_minus_balanced_accuracy(rng: np.random.Generator) -> None:
    truth = rng.integers(0, 2, 200)
    probability = rng.random(200)
    expected = 1 - balanced_accuracy_score(truth, probability >= 0.5)
    assert balanced_error_rate(truth, probability) == pytest.approx(expected)


def test_entropy_and_brier(rng: np.random.Generator) -> None:
    assert average_entropy(np.array([0.0, 1.0])) == 0.0
    assert average_entropy(np.array([0.5])) == pytest.approx(np.log(2))
    truth = rng.integers(0, 2, 100)
    probability = rng.random(100)
    assert classification_report(truth, probability)["brier_score"] == pytest.approx(
        brier_score_loss(truth, probability)
    )


def test_confusion_rows_are_actual_classes() -> None:
    assert confusion_counts(np.array([1, 1, 0]), np.array([0.6, 0.2, 0.7])).tolist() == [[1, 1], [1, 0]]


def test_reliability_diagram_png(tmp_path: Path, rng: np.random.Generator) -> None:
    truth = rng.integers(0, 2, 300)
    report = classification_report(truth, np.clip(truth * 0.6 + rng.random(300) * 0.4, 0, 1))
    assert sum(report["reliability"]["counts"]) == 300
    target = tmp_path / "reliability.png"
    save_reliability_diagram(report, target)
    assert target.read_bytes()[:4] == b"\x89PNG" and [p.name for p in tmp_path.iterdir()] == ["reliability.png"]


def test_not_supp_recall_at_matches_a_threshold_sweep(rng: np.random.Generator) -> None:
    truth = rng.random(300) < 0.3
    probability = np.clip(truth * 0.3 + rng.random(300) * 0.7, 0.0, 1.0)
    target = 0.784
    best = max(
        float(np.mean(probability[~truth] < threshold))
        for threshold in np.unique(probability)
        if np.mean(probability[truth] >= threshold) >= target
    )
    assert not_supp_recall_at(truth, probability, target) == pytest.approx(best)


def test_not_supp_recall_at_is_nan_without_both_classes() -> None:
    assert np.isnan(not_supp_recall_at([1, 1], [0.2, 0.9], 0.5))


@pytest.mark.parametrize(("truth", "missing"), [([0, 0, 0], "SUPP"), ([1, 1, 1], "not-SUPP"), ([0, 1, 1], None)])
def test_relations_of_one_class_are_said_to_leave_the_recall_ber_and_roc_undefined(
    truth: list[int], missing: str | None
) -> None:
    from unstack.learning.metrics import one_class_warning

    warning = one_class_warning(classification_report(truth, [0.2, 0.5, 0.9]), "d")
    if missing is None:
        assert warning is None
    else:
        assert warning == (f"d: no {missing} relation among the 3 scored: the {missing} recall, the balanced error "
                           "rate (Eq. 16) and the ROC curve are undefined")  # fmt: skip
