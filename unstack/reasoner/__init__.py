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

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from unstack.reasoner.components import support_components
    from unstack.reasoner.consistency import PREORDER_COUNTS, is_transitive, transitivity_clauses
    from unstack.reasoner.costs import COSTS, cost_weights, expected_costs
    from unstack.reasoner.decision import METHODS, Decision, choose, decide
    from unstack.reasoner.marginals import EXACT_MAX_BOXES, ExactMarginals, exact_marginals
    from unstack.reasoner.payoff import PayoffMatrix, payoff_matrix
    from unstack.reasoner.pruning import Evidence, propagate_evidence
    from unstack.reasoner.variables import SupportVariables
    from unstack.reasoner.worlds import SAT_MAX_BOXES, WorldSet, enumerate_worlds

#: Where each public name lives; modules load on first use (the SAT solver only when worlds
#: are listed), so ``import unstack`` stays light.
_WHERE = {
    "COSTS": "unstack.reasoner.costs",
    "Decision": "unstack.reasoner.decision",
    "EXACT_MAX_BOXES": "unstack.reasoner.marginals",
    "Evidence": "unstack.reasoner.pruning",
    "ExactMarginals": "unstack.reasoner.marginals",
    "METHODS": "unstack.reasoner.decision",
    "PREORDER_COUNTS": "unstack.reasoner.consistency",
    "PayoffMatrix": "unstack.reasoner.payoff",
    "SAT_MAX_BOXES": "unstack.reasoner.worlds",
    "SupportVariables": "unstack.reasoner.variables",
    "WorldSet": "unstack.reasoner.worlds",
    "choose": "unstack.reasoner.decision",
    "cost_weights": "unstack.reasoner.costs",
    "decide": "unstack.reasoner.decision",
    "enumerate_worlds": "unstack.reasoner.worlds",
    "exact_marginals": "unstack.reasoner.marginals",
    "expected_costs": "unstack.reasoner.costs",
    "is_transitive": "unstack.reasoner.consistency",
    "payoff_matrix": "unstack.reasoner.payoff",
    "propagate_evidence": "unstack.reasoner.pruning",
    "support_components": "unstack.reasoner.components",
    "transitivity_clauses": "unstack.reasoner.consistency",
}


def __getattr__(name: str) -> Any:
    if name in _WHERE:
        value = getattr(importlib.import_module(_WHERE[name]), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


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
