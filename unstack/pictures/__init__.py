"""Pictures of a decision: matplotlib renders of a pile or a support graph, and an interactive 3D page.

Only the data model is imported here (scene, supports, geometry, plotting, atomic, errors):
the caller decides and hands the numbers in as :class:`DecisionValues`.

Examples
--------
>>> from unstack.pictures import DecisionValues
>>> DecisionValues(["a"], [0.0], choice="a").choice
'a'
"""

from unstack.pictures.camera import Camera, point_box_labels
from unstack.pictures.values import DecisionValues, check_threshold, read_decision_values

__all__ = ["Camera", "DecisionValues", "check_threshold", "point_box_labels", "read_decision_values"]
