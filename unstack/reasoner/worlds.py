"""Consistent worlds listed with a SAT solver, and their probabilities (Eqs. 8-10).

Every ordered pair of boxes is a variable ``("supports", X, Y)``; transitivity is CNF
(:func:`~unstack.reasoner.consistency.transitivity_clauses`); hard evidence after
:func:`~unstack.reasoner.pruning.propagate_evidence` becomes unit clauses. python-sat's
CaDiCaL 1.9.5 lists the models (it was the fastest solver measured here). A world's
probability is the product of its pairwise probabilities (Eq. 8), renormalised over the
consistent worlds (Eqs. 9-10); both steps run in log space, so nothing underflows.

Examples
--------
>>> import numpy as np
>>> from unstack.supports import Supports
>>> worlds = enumerate_worlds(Supports(["a", "b"], [[0, 0.5], [0.5, 0]]))
>>> len(worlds)
4
>>> worlds.probabilities.round(2).tolist()
[0.25, 0.25, 0.25, 0.25]
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from unstack.errors import TooLarge
from unstack.reasoner.consistency import PREORDER_COUNTS, transitivity_clauses
from unstack.reasoner.pruning import Evidence, hard_evidence
from unstack.reasoner.variables import SupportVariables
from unstack.supports import Supports

__all__ = ["SAT_MAX_BOXES", "SAT_SOLVER", "WorldSet", "enumerate_worlds", "log_world_weights"]

#: The python-sat solver used for enumeration.
SAT_SOLVER = "cadical195"
#: Largest scene the SAT enumeration accepts: n = 7 has 9,535,241 worlds (minutes, GBs).
SAT_MAX_BOXES = 6


@dataclass(frozen=True, eq=False)
class WorldSet:
    """The consistent worlds of a scene with their probabilities.

    Attributes
    ----------
    objects : tuple of str
        Box ids.
    worlds : numpy.ndarray of bool, shape (q', n, n)
        ``worlds[i, x, y]`` is ``S_xy`` in the i-th consistent world.
    log_weights : numpy.ndarray, shape (q',)
        ``log P(W = w_i)`` before normalisation (Eq. 8).
    probabilities : numpy.ndarray, shape (q',)
        ``P(w_i^c)`` after normalisation over the consistent worlds (Eqs. 9-10).
    evidence : Evidence
        The propagated hard evidence that pruned the search.
    """

    objects: tuple[str, ...]
    worlds: np.ndarray
    log_weights: np.ndarray
    probabilities: np.ndarray
    evidence: Evidence

    def __len__(self) -> int:
        return int(self.worlds.shape[0])

    def marginals(self) -> np.ndarray:
        """``P(S_xy = 1 | consistent)`` as an ``n x n`` matrix."""
        marginals: np.ndarray = np.einsum("i,ixy->xy", self.probabilities, self.worlds.astype(np.float64))
        return marginals


def log_world_weights(worlds: np.ndarray, probabilities: np.ndarray) -> np.ndarray:
    """``log prod_k P(S_k = s_k)`` of each world (Eq. 8) without forming the product.

    Pairs with probability exactly 0 or 1 contribute ``log 1 = 0`` in the worlds that
    respect them (the only ones the enumeration yields).
    """
    n = probabilities.shape[0]
    off_diagonal = ~np.eye(n, dtype=bool)
    with np.errstate(divide="ignore"):
        log_present = np.where(probabilities > 0, np.log(np.where(probabilities > 0, probabilities, 1)), -np.inf)
        log_absent = np.where(probabilities < 1, np.log1p(-np.where(probabilities < 1, probabilities, 0)), -np.inf)
    terms = np.where(worlds, log_present, log_absent)
    result: np.ndarray = np.sum(terms, axis=(1, 2), where=off_diagonal)
    return result


def enumerate_worlds(supports: Supports, *, solver: str = SAT_SOLVER, max_boxes: int = SAT_MAX_BOXES) -> WorldSet:
    """List every consistent world with its probability (the rows of Table II).

    Parameters
    ----------
    supports : Supports
        The detected boxes and their pairwise support probabilities.
    solver : str, optional
        A python-sat solver name (default CaDiCaL 1.9.5).
    max_boxes : int, optional
        Refuse larger scenes (the number of worlds grows like 2^(n^2/4)).

    Returns
    -------
    WorldSet

    Raises
    ------
    TooLarge
        More than ``max_boxes`` boxes.
    NoConsistentWorld
        The hard evidence contradicts transitivity.
    """
    from pysat.solvers import Solver

    objects = supports.objects
    n = len(objects)
    if n > max_boxes:
        raise TooLarge(
            supports.named(
                f"{n} boxes: listing consistent worlds is limited to {max_boxes} boxes "
                f"(n = {max_boxes + 1} has {PREORDER_COUNTS[max_boxes + 1]:,} worlds); "
                "decide without listing them (unstack decide FILE, or method 'auto': exact up to 8 linked boxes, "
                "sampled above)"
            )
        )
    evidence = hard_evidence(supports)
    variables = SupportVariables(objects)
    index = {name: i for i, name in enumerate(objects)}
    rows = np.array([index[x] for x, _ in variables.pairs], dtype=np.int64)
    cols = np.array([index[y] for _, y in variables.pairs], dtype=np.int64)
    var_ids = np.array([variables.id(x, y) for x, y in variables.pairs], dtype=np.int64)
    clauses = transitivity_clauses(variables)
    clauses += [[variables.id(x, y)] for x, y in evidence.forced]
    clauses += [[-variables.id(x, y)] for x, y in evidence.forbidden]
    # Every variable must reach the solver so that each model assigns it (with two boxes
    # there is no transitivity clause): an auxiliary variable, forced true, appears with
    # each support variable in a clause that it alone satisfies.
    anchor = variables.pool.id(("anchor",))
    clauses += [[anchor]] + [[anchor, int(v)] for v in var_ids]
    models: list[list[int]] = []
    if n == 1:
        models = [[]]
    else:
        with Solver(name=solver, bootstrap_with=clauses) as sat:
            models = list(sat.enum_models())
    worlds = np.zeros((len(models), n, n), dtype=bool)
    if n > 1:
        values = np.array(models, dtype=np.int64).reshape(len(models), -1)
        # models list every variable 1..m in order; pick ours by id
        present = values[:, var_ids - 1] > 0
        worlds[:, rows, cols] = present
    log_weights = log_world_weights(worlds, evidence.probabilities)
    shift = np.max(log_weights)
    probabilities = np.exp(log_weights - shift)
    probabilities /= probabilities.sum()
    return WorldSet(objects, worlds, log_weights, probabilities, evidence)
