"""Evaluation of support probabilities (§V-B): confusion matrix, success rate, BER (Eq. 16),
average entropy (Eq. 15), calibration (Brier score, reliability diagram).

Class C1 is SUPP (label 1), C2 is not-SUPP (label 0). A relation is predicted SUPP when
its probability is at least 0.5.

Examples
--------
>>> truth = np.array([1, 1, 0, 0]); probability = np.array([0.9, 0.4, 0.2, 0.6])
>>> report = classification_report(truth, probability)
>>> report["supp_recall"], report["not_supp_recall"], report["balanced_error_rate"]
(0.5, 0.5, 0.5)
"""

from __future__ import annotations

import os
from typing import Any

import numpy as np

__all__ = [
    "average_entropy",
    "balanced_error_rate",
    "classification_report",
    "confusion_counts",
    "expected_calibration_error",
    "not_supp_recall_at",
    "reliability_curve",
    "save_reliability_diagram",
]


def confusion_counts(truth: np.ndarray, probability: np.ndarray) -> np.ndarray:
    """2 x 2 counts in the paper's Fig. 5 layout: rows actual (SUPP, not), columns predicted (SUPP, not).

    Examples
    --------
    >>> confusion_counts(np.array([1, 0, 0]), np.array([0.8, 0.7, 0.1])).tolist()
    [[1, 0], [1, 1]]
    """
    from sklearn.metrics import confusion_matrix

    actual = np.asarray(truth).astype(bool)
    predicted = np.asarray(probability) >= 0.5
    counts: np.ndarray = confusion_matrix(actual, predicted, labels=[True, False])
    return counts


def balanced_error_rate(truth: np.ndarray, probability: np.ndarray) -> float:
    """Eq. 16: the mean of the two classes' error rates (a missing class counts 0).

    Examples
    --------
    >>> balanced_error_rate(np.array([1, 1, 0, 0]), np.array([0.9, 0.9, 0.9, 0.1]))
    0.25
    """
    counts = confusion_counts(truth, probability)
    rates = [counts[row, 1 - row] / counts[row].sum() if counts[row].sum() else 0.0 for row in (0, 1)]
    return float(0.5 * sum(rates))


def average_entropy(probability: np.ndarray) -> float:
    """Eq. 15: mean binary entropy (natural log) of the relations' probabilities.

    Examples
    --------
    >>> round(average_entropy(np.array([0.5, 1.0])), 4)
    0.3466
    """
    p = np.clip(np.asarray(probability, dtype=np.float64), 0.0, 1.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        terms = -np.where(p > 0, p * np.log(p), 0.0) - np.where(p < 1, (1 - p) * np.log(1 - p), 0.0)
    return float(terms.mean()) if terms.size else 0.0


def reliability_curve(truth: np.ndarray, probability: np.ndarray, bins: int = 10) -> dict[str, list[float]]:
    """Mean predicted probability, observed SUPP frequency and count per probability bin."""
    edges = np.linspace(0.0, 1.0, bins + 1)
    which = np.clip(np.digitize(probability, edges[1:-1]), 0, bins - 1)
    mean_predicted, observed, counts = [], [], []
    for k in range(bins):
        members = which == k
        counts.append(int(members.sum()))
        mean_predicted.append(float(probability[members].mean()) if members.any() else float("nan"))
        observed.append(float(np.asarray(truth)[members].mean()) if members.any() else float("nan"))
    return {"bin_edges": edges.tolist(), "mean_predicted": mean_predicted, "observed": observed, "counts": counts}


def expected_calibration_error(truth: Any, probability: Any, bins: int = 10) -> float:
    """Expected calibration error: the bin-size weighted mean of |observed - predicted| over
    ``bins`` equal-width probability bins (0 for a perfectly calibrated classifier).

    Examples
    --------
    >>> expected_calibration_error([0, 1, 0, 1], [0.05, 0.95, 0.05, 0.95])
    0.05
    """
    actual = np.asarray(truth, dtype=np.float64)
    p = np.asarray(probability, dtype=np.float64)
    if actual.size == 0:
        return float("nan")
    curve = reliability_curve(actual, p, bins)
    total = 0.0
    for count, predicted, observed in zip(curve["counts"], curve["mean_predicted"], curve["observed"], strict=True):
        if count:
            total += count * abs(observed - predicted)
    return round(total / actual.size, 12)


def not_supp_recall_at(truth: Any, probability: Any, supp_recall: float) -> float:
    """One point of the ROC curve: the best not-SUPP recall of any threshold whose SUPP recall
    reaches ``supp_recall`` (how Fig. 5a's point is compared with a curve).

    Parameters
    ----------
    truth : array_like of {0, 1}
    probability : array_like of float
    supp_recall : float
        The SUPP recall to reach, in [0, 1].

    Returns
    -------
    float
        NaN when one class is missing.

    Examples
    --------
    >>> not_supp_recall_at([0, 0, 1, 1], [0.1, 0.6, 0.4, 0.9], 1.0)
    0.5
    """
    from sklearn.metrics import roc_curve

    actual = np.asarray(truth).astype(bool)
    if actual.all() or not actual.any():
        return float("nan")
    false_positive, true_positive, _ = roc_curve(actual, np.asarray(probability, dtype=np.float64))
    return float(1.0 - false_positive[true_positive >= supp_recall].min())


def classification_report(truth: Any, probability: Any) -> dict[str, Any]:
    """Every metric of a set of relations, JSON-ready.

    Keys: ``relations``, ``supp``, ``not_supp``, ``confusion_matrix`` (Fig. 5 layout),
    ``supp_recall``, ``not_supp_recall``, ``success_rate``, ``balanced_error_rate``,
    ``average_entropy``, ``brier_score``, ``expected_calibration_error``, ``reliability``.
    """
    from sklearn.metrics import brier_score_loss

    actual = np.asarray(truth).astype(bool)
    p = np.asarray(probability, dtype=np.float64)
    counts = confusion_counts(actual, p)
    supp, not_supp = int(counts[0].sum()), int(counts[1].sum())
    return {
        "relations": int(actual.size),
        "supp": supp,
        "not_supp": not_supp,
        "confusion_matrix": counts.tolist(),
        "supp_recall": float(counts[0, 0] / supp) if supp else float("nan"),
        "not_supp_recall": float(counts[1, 1] / not_supp) if not_supp else float("nan"),
        "success_rate": float((counts[0, 0] + counts[1, 1]) / max(actual.size, 1)),
        "balanced_error_rate": balanced_error_rate(actual, p),
        "average_entropy": average_entropy(p),
        "brier_score": float(brier_score_loss(actual, p, pos_label=True)) if actual.size else float("nan"),
        "expected_calibration_error": expected_calibration_error(actual, p),
        "reliability": reliability_curve(actual, p),
    }


def one_class_warning(report: dict[str, Any], source: str) -> str | None:
    """What a :func:`classification_report` of relations of one class only cannot say, or None.

    Examples
    --------
    >>> report = classification_report([0, 0, 0], [0.1, 0.2, 0.9])
    >>> print(one_class_warning(report, "piles")[:60])
    piles: no SUPP relation among the 3 scored: the SUPP recall,
    """
    missing = "SUPP" if report["supp"] == 0 else "not-SUPP" if report["not_supp"] == 0 else None
    if missing is None:
        return None
    return (
        f"{source}: no {missing} relation among the {report['relations']:,} scored: the {missing} recall, the "
        "balanced error rate (Eq. 16) and the ROC curve are undefined"
    )


def save_reliability_diagram(report: dict[str, Any], output: str | os.PathLike[str], *, title: str = "") -> None:
    """Draw the reliability diagram of a :func:`classification_report` into a PNG (atomically)."""

    from unstack.plotting import pyplot

    plt = pyplot()

    curve = report["reliability"]
    edges = np.asarray(curve["bin_edges"])
    centres = (edges[:-1] + edges[1:]) / 2.0
    figure, (top, bottom) = plt.subplots(2, 1, figsize=(5.5, 6.5), height_ratios=[3, 1], sharex=True)
    top.plot([0, 1], [0, 1], linestyle="--", color="grey", label="perfectly calibrated")
    top.plot(curve["mean_predicted"], curve["observed"], marker="o", label="classifier")
    top.set_ylabel("observed share of SUPP")
    top.set_title(title or f"reliability (Brier score {report['brier_score']:.3f})")
    top.legend(loc="upper left")
    bottom.bar(centres, curve["counts"], width=edges[1] - edges[0], color="tab:blue", alpha=0.6)
    bottom.set_xlabel("predicted P(SUPP)")
    bottom.set_ylabel("relations")
    figure.tight_layout()
    from unstack.plotting import save_figure

    save_figure(figure, output)
