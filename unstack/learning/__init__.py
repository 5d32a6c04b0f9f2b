"""Learning support relations (§III-A): features, SVM with probabilities, evaluation.

Not built yet (issue "Learning"); nothing is exported. It will never import pybullet.
"""

__all__: list[str] = []
