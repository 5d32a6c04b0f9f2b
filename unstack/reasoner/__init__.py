"""The possible-worlds reasoner (§III-B, §III-C, §IV).

Turns pairwise support probabilities into the distribution over consistent (transitive)
worlds and picks the box of minimum expected cost. Imports neither scikit-learn nor
pybullet.

Examples
--------
>>> from unstack.supports import Supports
>>> from unstack.reasoner import decide
>>> decide(Supports(["a", "b"], [[0, 0.2], [0.7, 0]])).choice
'a'
"""

from unstack.reasoner.components import support_components
from unstack.reasoner.consistency import PREORDER_COUNTS, is_transitive, transitivity_clauses
from unstack.reasoner.costs import COSTS, cost_weights, expected_costs
from unstack.reasoner.decision import METHODS, Decision, choose, decide
from unstack.reasoner.marginals import EXACT_MAX_BOXES, ExactMarginals, exact_marginals
from unstack.reasoner.payoff import PayoffMatrix, payoff_matrix
from unstack.reasoner.pruning import Evidence, propagate_evidence
from unstack.reasoner.variables import SupportVariables
from unstack.reasoner.worlds import SAT_MAX_BOXES, WorldSet, enumerate_worlds

__all__ = [
    "COSTS",
    "EXACT_MAX_BOXES",
    "METHODS",
    "PREORDER_COUNTS",
    "SAT_MAX_BOXES",
    "Decision",
    "Evidence",
    "ExactMarginals",
    "PayoffMatrix",
    "SupportVariables",
    "WorldSet",
    "choose",
    "cost_weights",
    "decide",
    "enumerate_worlds",
    "exact_marginals",
    "expected_costs",
    "is_transitive",
    "payoff_matrix",
    "propagate_evidence",
    "support_components",
    "transitivity_clauses",
]
