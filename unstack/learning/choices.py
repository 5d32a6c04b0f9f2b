"""The names a user chooses among when training: learners and hold-out splits.

Kept apart from the modules that use them, which import scikit-learn: the command line
lists these choices (``unstack --help``, ``unstack train --help``) without paying for it.

Examples
--------
>>> LEARNERS[0], SPLITS
('svm', ('pairs', 'configuration'))
"""

from __future__ import annotations

__all__ = ["LEARNERS", "SPLITS"]

#: Learner names accepted by ``SupportClassifier(learner=...)``.
LEARNERS = ("svm", "gradient_boosting", "calibrated_svm")
#: How the rows are split for hold-out figures and folds: ``pairs`` (the paper: by relation)
#: or ``configuration`` (each pile's relations on one side).
SPLITS = ("pairs", "configuration")
