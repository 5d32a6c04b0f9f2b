"""Learning support relations (§III-A): features, the classifier, evaluation, model files.

Imports neither pybullet nor the simulator at import time; reading training data from a
simulated data set folder uses only its JSON and ``.npy`` files.

Examples
--------
>>> from unstack.learning import FEATURE_NAMES
>>> len(FEATURE_NAMES)
19
"""

from importlib import import_module
from typing import Any

#: Where each public name lives: imported on first use, so that importing a light module of
#: the package (the feature names, say) does not import scikit-learn.
_HOMES = {
    "LEARNERS": "classifier",
    "SupportClassifier": "classifier",
    "HoldoutResult": "holdout",
    "evaluate_holdout": "holdout",
    "FEATURE_NAMES": "features",
    "FeatureSettings": "features",
    "dbaf": "features",
    "pair_features": "features",
    "average_entropy": "metrics",
    "balanced_error_rate": "metrics",
    "classification_report": "metrics",
    "InvalidModel": "model_file",
    "SupportModel": "model_file",
    "default_model_path": "model_file",
    "load_model": "model_file",
    "save_model": "model_file",
    "SupportExamples": "training_data",
    "dataset_examples": "training_data",
    "scene_examples": "training_data",
}


def __getattr__(name: str) -> Any:
    if name in _HOMES:
        return getattr(import_module(f"unstack.learning.{_HOMES[name]}"), name)
    raise AttributeError(f"module 'unstack.learning' has no attribute {name!r}")


__all__ = [
    "FEATURE_NAMES",
    "LEARNERS",
    "FeatureSettings",
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
    "load_model",
    "pair_features",
    "save_model",
    "scene_examples",
]
