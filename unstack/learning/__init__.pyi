"""Type stub of :mod:`unstack.learning`: the public names and their modules, read by lazy_loader and by static tools."""

from .classifier import LEARNERS, SupportClassifier
from .features import (
    FEATURE_NAMES,
    FeatureSettings,
    dbaf,
    pair_features,
)
from .holdout import HoldoutResult, evaluate_holdout
from .metrics import (
    average_entropy,
    balanced_error_rate,
    classification_report,
)
from .model_file import (
    InvalidModel,
    SupportModel,
    default_model_path,
    load_model,
    save_model,
)
from .training_data import (
    SupportExamples,
    dataset_examples,
    scene_examples,
)

__all__ = [
    "FEATURE_NAMES",
    "LEARNERS",
    "FeatureSettings",
    "HoldoutResult",
    "InvalidModel",
    "SupportClassifier",
    "SupportExamples",
    "SupportModel",
    "average_entropy",
    "balanced_error_rate",
    "classification_report",
    "dataset_examples",
    "dbaf",
    "default_model_path",
    "evaluate_holdout",
    "load_model",
    "pair_features",
    "save_model",
    "scene_examples",
]
