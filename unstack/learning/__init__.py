"""Learning support relations (§III-A): features, the classifier, evaluation, model files.

Imports neither pybullet nor the simulator at import time; reading training data from a
simulated data set folder uses only its JSON and ``.npy`` files.

Examples
--------
>>> from unstack.learning import FEATURE_NAMES
>>> len(FEATURE_NAMES)
19
"""

from unstack.learning.classifier import LEARNERS, SupportClassifier
from unstack.learning.features import FEATURE_NAMES, FeatureSettings, dbaf, pair_features
from unstack.learning.metrics import average_entropy, balanced_error_rate, classification_report
from unstack.learning.model_file import InvalidModel, SupportModel, default_model_path, load_model, save_model
from unstack.learning.probabilities import scene_support_probabilities
from unstack.learning.training_data import SupportExamples, dataset_examples, scene_examples

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
    "scene_support_probabilities",
]
