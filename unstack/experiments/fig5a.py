"""Fig. 5a: the classifier's validation confusion matrix on the simulated data set, beside the paper's.

Trains a :class:`~unstack.learning.SupportClassifier` on ISets of a simulated data set
(70/30 split, 10-fold cross-validation, as the paper) and reports the held-out confusion
matrix, plus the recalls at two thresholds chosen on the *training* part's out-of-fold
probabilities (so without the validation data): the one that balances the two classes'
errors (the paper's data set had 33 % SUPP relations and ours far fewer), and the one whose
SUPP recall reaches the paper's 78.4 % (the paper's operating point). The validation ROC
curve says which not-SUPP recall any threshold reaches at the paper's SUPP recall: the
paper's point beats us only if it lies above our curve (``fig5a.png`` draws both).

Examples
--------
>>> PAPER_FIG_5A["supp_recall"], PAPER_FIG_5A["not_supp_recall"]
(0.784, 0.875)
"""

from __future__ import annotations

import os
from typing import Any, cast

import numpy as np

from unstack.learning.choices import LEARNERS, SPLITS
from unstack.learning.features import FEATURE_SETS
from unstack.learning.training_data import ISET_DRAWS
from unstack.parameters import COUNT, FOLDS, ISET_SIZE, JOBS, LEARNING_SEED, OneOf, validate_params

#: The paper's size of Fig. 5a (§V): 200 simulated configurations (its 493 test ISets for Fig. 4
#: are :data:`unstack.experiments.decisions.PAPER_TEST_ISETS`).
PAPER_CONFIGURATIONS = 200

__all__ = [
    "PAPER_CONFIGURATIONS",
    "PAPER_FIG_5A",
    "balanced_threshold",
    "fig5a",
    "paper_point",
    "plot_fig5a",
    "recall_threshold",
    "require_paper_size",
    "validation_roc",
]

#: The paper's Fig. 5a: 145 of 185 SUPP and 351 of 401 not-SUPP validation relations right.
PAPER_FIG_5A: dict[str, Any] = {
    "confusion_matrix": [[145, 40], [50, 351]],
    "supp_recall": 0.784,
    "not_supp_recall": 0.875,
}


def balanced_threshold(truth: np.ndarray, probability: np.ndarray) -> float:
    """The threshold whose SUPP and not-SUPP recalls on these relations are closest.

    Examples
    --------
    >>> balanced_threshold(np.array([0, 0, 1, 1]), np.array([0.1, 0.3, 0.7, 0.9]))
    0.7
    """
    candidates = np.unique(np.round(probability, 4))
    best, gap = 0.5, np.inf
    for threshold in candidates:
        supp = np.mean(probability[truth == 1] >= threshold) if (truth == 1).any() else 0.0
        not_supp = np.mean(probability[truth == 0] < threshold) if (truth == 0).any() else 0.0
        if abs(supp - not_supp) < gap:
            best, gap = float(threshold), abs(supp - not_supp)
    return best


def recall_threshold(truth: np.ndarray, probability: np.ndarray, supp_recall: float) -> float:
    """The largest threshold whose SUPP recall on these relations reaches ``supp_recall``.

    Examples
    --------
    >>> recall_threshold(np.array([0, 1, 1, 1, 1]), np.array([0.1, 0.2, 0.5, 0.8, 0.9]), 0.75)
    0.5
    """
    supp = np.sort(probability[truth == 1])[::-1]
    if len(supp) == 0:
        return 0.5
    return float(supp[max(int(np.ceil(supp_recall * len(supp))) - 1, 0)])


def validation_roc(truth: np.ndarray, probability: np.ndarray, *, points: int = 101) -> dict[str, Any]:
    """ROC of the validation relations: AUC, the curve (thinned) and the not-SUPP recall at the paper's SUPP recall.

    Examples
    --------
    >>> roc = validation_roc(np.array([0, 0, 1, 1]), np.array([0.1, 0.6, 0.4, 0.9]))
    >>> roc["auc"], roc["not_supp_recall_at_paper_supp_recall"]
    (0.75, 0.5)
    """
    from sklearn.metrics import roc_curve

    false_positive, true_positive, _ = roc_curve(truth, probability)
    grid = np.linspace(0.0, 1.0, points)
    point = paper_point(truth, probability)
    return {
        "auc": point["auc"],
        "not_supp_recall": grid.tolist(),
        "supp_recall": [float(true_positive[false_positive <= 1.0 - level].max()) for level in grid],
        "not_supp_recall_at_paper_supp_recall": point["not_supp_recall"],
    }


def paper_point(truth: np.ndarray, probability: np.ndarray) -> dict[str, float]:
    """Where a model's ROC curve passes the paper's Fig. 5a point: the AUC, and the best
    not-SUPP recall at the paper's SUPP recall beside the paper's own.

    Examples
    --------
    >>> point = paper_point(np.array([0, 0, 1, 1]), np.array([0.1, 0.6, 0.4, 0.9]))
    >>> point["auc"], point["not_supp_recall"], point["paper_not_supp_recall"]
    (0.75, 0.5, 0.875)
    """
    from sklearn.metrics import roc_auc_score

    from unstack.learning.metrics import not_supp_recall_at

    truth = np.asarray(truth).astype(bool)
    both = bool(truth.any() and not truth.all())
    return {
        "auc": float(roc_auc_score(truth, probability)) if both else float("nan"),
        "supp_recall": PAPER_FIG_5A["supp_recall"],
        "not_supp_recall": not_supp_recall_at(truth, probability, PAPER_FIG_5A["supp_recall"]),
        "paper_not_supp_recall": PAPER_FIG_5A["not_supp_recall"],
    }


def plot_fig5a(result: dict[str, Any], output: str | os.PathLike[str]) -> None:
    """The validation ROC curve (SUPP recall against not-SUPP recall) with the paper's Fig. 5a point."""
    from unstack.plotting import pyplot, save_figure

    plt = pyplot()
    roc = result["validation_roc"]
    figure, axes = plt.subplots(figsize=(5.5, 5))
    ours = f"unstack {result['learner']} (AUC {roc['auc']:.3f})"
    axes.plot(roc["not_supp_recall"], roc["supp_recall"], "-", label=ours)
    paper = ([PAPER_FIG_5A["not_supp_recall"]], [PAPER_FIG_5A["supp_recall"]])
    axes.plot(*paper, "r*", markersize=12, label="paper, Fig. 5a")
    balanced = result["validation_at_balanced_threshold"]
    axes.plot([balanced["not_supp_recall"]], [balanced["supp_recall"]], "ko", label="threshold balanced on training")
    operating = result["validation_at_paper_recall_threshold"]
    same = all(operating[key] == balanced[key] for key in ("not_supp_recall", "supp_recall"))
    axes.plot([operating["not_supp_recall"]], [operating["supp_recall"]], "ks", mfc="none", markersize=10,
              label="threshold for the paper's SUPP recall on training"
              + (" (same point as the balanced one)" if same else ""))  # fmt: skip
    axes.set_xlabel("not-SUPP recall (validation)")
    axes.set_ylabel("SUPP recall (validation)")
    axes.set_xlim(0.5, 1.0)
    axes.set_ylim(0.5, 1.0)
    axes.grid(alpha=0.3)
    axes.legend(loc="lower left")
    validation = result["validation"]
    title = f"{validation['relations']} validation relations ({validation['supp']} SUPP), "
    axes.set_title(title + f"features {result['features']['feature_set']}, split by {result['split_by']}", fontsize=9)
    figure.tight_layout()
    save_figure(figure, output)


def require_paper_size(data_dir: str | os.PathLike[str], cv: int) -> None:
    """Refuse a run that claims the paper's size of Fig. 5a and is smaller.

    The paper trains on :data:`PAPER_CONFIGURATIONS` simulated configurations with 10-fold
    cross-validation.
    """
    from unstack.dataset_folders import require_configurations
    from unstack.errors import UnstackError

    found = len(require_configurations(data_dir))
    if found < PAPER_CONFIGURATIONS or cv != 10:
        raise UnstackError(
            f"{data_dir}: the paper's size is {PAPER_CONFIGURATIONS} configurations and 10 folds; "
            f"this data set has {found} and cv is {cv} (make it with unstack simulate --configs 200)"
        )


@validate_params({
    "r": ISET_SIZE, "isets": COUNT, "seed": LEARNING_SEED, "cv": FOLDS, "n_jobs": JOBS, "draw": OneOf(ISET_DRAWS),
    "learner": OneOf(LEARNERS), "split_by": OneOf(SPLITS), "feature_set": OneOf(FEATURE_SETS),
})  # fmt: skip
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
    feature_set: str = "paper",
) -> dict[str, Any]:
    """Train on the data set and report the validation confusion matrix against the paper.

    ``split_by``: ``pairs`` (the paper's 70/30 split of the relations) or ``configuration``
    (every pile's relations on one side of the split and of each fold). ``feature_set``:
    ``paper`` (Eq. 6) or ``extended`` (with the contact features).
    """
    from unstack.learning.classifier import SupportClassifier
    from unstack.learning.features import FeatureSettings
    from unstack.learning.holdout import evaluate_holdout
    from unstack.learning.metrics import classification_report
    from unstack.learning.training_data import dataset_examples

    settings = FeatureSettings(feature_set=feature_set)
    examples = dataset_examples(data_dir, r=r, isets=isets, seed=seed, settings=settings, n_jobs=n_jobs, draw=draw)
    holdout = evaluate_holdout(
        SupportClassifier(learner=learner, cv=cv, random_state=seed, n_jobs=n_jobs),
        examples.features,
        examples.labels,
        groups=examples.configuration if split_by == "configuration" else None,
        out_of_fold=True,
    )
    classifier = holdout.classifier
    out_of_fold = cast(np.ndarray, holdout.out_of_fold)
    train_y = examples.labels[holdout.train_indices]
    valid_y = examples.labels[holdout.validation_indices]
    threshold = balanced_threshold(train_y, out_of_fold)
    paper_threshold = recall_threshold(train_y, out_of_fold, PAPER_FIG_5A["supp_recall"])
    valid_p = holdout.validation_probabilities
    at_threshold = classification_report(valid_y, (valid_p >= threshold).astype(float))
    at_paper_threshold = classification_report(valid_y, (valid_p >= paper_threshold).astype(float))
    reported = ("confusion_matrix", "supp_recall", "not_supp_recall", "success_rate")
    return {
        "data": str(data_dir),
        "r": r,
        "isets": isets,
        "isets_from": draw,
        "seed": seed,
        "learner": learner,
        "cv": cv,
        "cv_folds": int(classifier.cv_folds_),
        "split_by": split_by,
        "features": settings.to_dict(),
        "relations": len(examples.labels),
        "supp": int(examples.labels.sum()),
        "best_params": {key: float(value) for key, value in classifier.best_params_.items()},
        "validation": holdout.validation_metrics,
        "balanced_threshold": threshold,
        "validation_at_balanced_threshold": {key: at_threshold[key] for key in reported},
        "paper_recall_threshold": paper_threshold,
        "validation_at_paper_recall_threshold": {key: at_paper_threshold[key] for key in reported},
        "validation_roc": validation_roc(valid_y, valid_p),
        "paper": PAPER_FIG_5A,
    }
