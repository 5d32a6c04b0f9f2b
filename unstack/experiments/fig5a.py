"""Fig. 5a: the classifier's validation confusion matrix on the simulated data set, beside the paper's.

Trains a :class:`~unstack.learning.SupportClassifier` on ISets of a simulated data set
(70/30 split, 10-fold cross-validation, as the paper) and reports the held-out confusion
matrix, plus the recalls at the probability threshold that balances the two classes' errors
on the *training* part (a threshold chosen without the validation data), since the paper's
data set had 33 % SUPP relations and ours far fewer.

Examples
--------
>>> PAPER_FIG_5A["supp_recall"], PAPER_FIG_5A["not_supp_recall"]
(0.784, 0.875)
"""

from __future__ import annotations

import os
from typing import Any

import numpy as np

__all__ = ["PAPER_FIG_5A", "SPLITS", "fig5a"]

#: How the relations are split for validation and cross-validation.
SPLITS = ("pairs", "configuration")

#: The paper's Fig. 5a: 145 of 185 SUPP and 351 of 401 not-SUPP validation relations right.
PAPER_FIG_5A = {"confusion_matrix": [[145, 40], [50, 351]], "supp_recall": 0.784, "not_supp_recall": 0.875}


def _balanced_threshold(truth: np.ndarray, probability: np.ndarray) -> float:
    """The threshold whose SUPP and not-SUPP recalls on these relations are closest."""
    candidates = np.unique(np.round(probability, 4))
    best, gap = 0.5, np.inf
    for threshold in candidates:
        supp = np.mean(probability[truth == 1] >= threshold) if (truth == 1).any() else 0.0
        not_supp = np.mean(probability[truth == 0] < threshold) if (truth == 0).any() else 0.0
        if abs(supp - not_supp) < gap:
            best, gap = float(threshold), abs(supp - not_supp)
    return best


def fig5a(
    data_dir: str | os.PathLike[str],
    *,
    r: int = 5,
    isets: int = 1,
    seed: int = 0,
    cv: int = 10,
    n_jobs: int = 1,
    draw: str = "random",
    learner: str = "svm",
    split_by: str = "pairs",
) -> dict[str, Any]:
    """Train on the data set and report the validation confusion matrix against the paper.

    ``split_by``: ``pairs`` (the paper's 70/30 split of the relations) or ``configuration``
    (every pile's relations on one side of the split and of each fold).
    """
    from unstack.learning.classifier import SupportClassifier
    from unstack.learning.metrics import classification_report
    from unstack.learning.training_data import dataset_examples

    if split_by not in SPLITS:
        raise ValueError(f"unknown split {split_by!r}; expected one of {', '.join(SPLITS)}")
    examples = dataset_examples(data_dir, r=r, isets=isets, seed=seed, n_jobs=n_jobs, draw=draw)
    classifier = SupportClassifier(learner=learner, cv=cv, random_state=seed, n_jobs=n_jobs).fit(
        examples.features, examples.labels, groups=examples.configuration if split_by == "configuration" else None
    )
    train_x, train_y = examples.features[classifier.train_indices_], examples.labels[classifier.train_indices_]
    valid_x = examples.features[classifier.validation_indices_]
    valid_y = examples.labels[classifier.validation_indices_]
    threshold = _balanced_threshold(train_y, classifier.predict_proba(train_x)[:, 1])
    valid_p = classifier.predict_proba(valid_x)[:, 1]
    at_threshold = classification_report(valid_y, (valid_p >= threshold).astype(float))
    return {
        "data": str(data_dir),
        "isets_from": draw,
        "learner": learner,
        "split_by": split_by,
        "relations": len(examples.labels),
        "supp": int(examples.labels.sum()),
        "best_params": {key: float(value) for key, value in classifier.best_params_.items()},
        "validation": classifier.validation_metrics_,
        "balanced_threshold": threshold,
        "validation_at_balanced_threshold": {
            key: at_threshold[key] for key in ("confusion_matrix", "supp_recall", "not_supp_recall", "success_rate")
        },
        "paper": PAPER_FIG_5A,
    }
