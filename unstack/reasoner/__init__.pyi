"""Type stub of :mod:`unstack.reasoner`: the public names and their modules, read by lazy_loader and by static tools."""

from .components import support_components
from .consistency import (
    PREORDER_COUNTS,
    is_transitive,
    transitivity_clauses,
)
from .costs import COSTS, cost_weights, expected_costs
from .decision import METHODS, Decision, choose, decide
from .marginals import (
    EXACT_MAX_BOXES,
    ExactMarginals,
    exact_marginals,
)
from .payoff import PayoffMatrix, payoff_matrix
from .pruning import Evidence, propagate_evidence
from .variables import SupportVariables
from .worlds import SAT_MAX_BOXES, WorldSet, enumerate_worlds

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
