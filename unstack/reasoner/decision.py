"""Decision making (§IV): unload the box of minimum expected cost (Eqs. 11-13).

``EC(A_j) = sum_i P(w_i^c) c_ij`` (Eq. 13) with the additive cost of Eq. 11 equals
``sum_Y w_Y P(S_jY = 1 | consistent)``, so the decision needs only the conditional
marginals, which the exact engine computes without listing worlds; the SAT method lists
the worlds (Table II) and sums them.

Ties. Boxes whose EC is within ``1e-12 * max(1, min EC)`` of the minimum are tied; the
choice among them is the smallest id in Unicode code-point order. The rule depends on the
ids only, so reordering the boxes in the input never changes the choice.

Near ties. When the supports carry the heights the boxes rest at (their lowest points; a
scene's supports do), boxes whose EC lies within :data:`NEAR_TIE_MARGIN` expected boxes
moved of the minimum count as tied, and the tied box resting highest is taken: a box on
top of others before the boxes under it. Tied boxes resting on one layer (within
:data:`LAYER_TOLERANCE` of the highest) are decided by their EC as in Eq. 12 (then the
smallest id), so a box standing on the floor is never preferred to another on the floor
for being taller -- a box leaning on it may be what the model missed. Which of several
boxes that hold up almost nothing comes first is otherwise left to small differences of
the model; the one resting highest is the one its neighbours press on least. Emptying
whole containers in the physics engine, near ties moved fewer boxes than the minimum EC (Eq. 12)
(docs/results.md). ``near_tie_margin=0`` keeps Eq. 12 exactly.

Examples
--------
>>> from unstack.supports import Supports
>>> supports = Supports(["top", "bottom"], [[0.0, 0.1], [0.9, 0.0]])
>>> decision = decide(supports)
>>> decision.choice
'top'
>>> decision.expected_costs.round(3).tolist()
[0.1, 0.9]
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from unstack.errors import InvalidArgument, TooLarge
from unstack.reasoner.arguments import check_budget, check_choice, check_count, check_margin, check_samples, check_seed
from unstack.reasoner.components import support_components
from unstack.reasoner.confidence import choice_probability
from unstack.reasoner.costs import (
    COSTS,
    DEFAULT_COST,
    cost_weights,
    expected_costs,
    margin_beyond_every_cost,
    own_costs,
    weight_doubts,
)
from unstack.reasoner.marginals import EXACT_MAX_BOXES
from unstack.reasoner.pruning import Evidence, hard_evidence
from unstack.reasoner.reasons import REASON_COSTS, pick_reasons
from unstack.reasoner.reuse import WARM_BURN_IN, WorkCache
from unstack.reasoner.sampling import SampledMarginals
from unstack.supports import Supports

__all__ = [
    "DECISION_FORMAT",
    "DEFAULT_COST",
    "LAYER_TOLERANCE",
    "METHODS",
    "NEAR_TIE_MARGIN",
    "TIE_TOLERANCE",
    "Decision",
    "choose",
    "decide",
]

DECISION_FORMAT = "unstack.decision/1"
#: Reasoning methods: ``exact`` (weighted preorder counting), ``sat`` (list worlds).
METHODS = ("auto", "exact", "sat", "approx")
#: The methods that count every world (a sample budget means nothing to them).
UNSAMPLED_METHODS = ("exact", "sat")
#: With a time limit below this (seconds), ``auto`` samples groups of 8 boxes instead of
#: counting them (exact n = 8 dense: 2.6 s on a quiet 2-core machine, 4.1 s loaded).
AUTO_EXACT8_SECONDS = 10.0
#: Seconds of a time limit kept for the work after sampling (costs, choice probability).
DECISION_MARGIN = 0.03
#: Seconds every sampled group gets even when the time limit is spent.
MINIMUM_SAMPLING = 0.05
#: Below this share of accepted re-insertions the decision warns that the errors may be too small.
LOW_ACCEPTANCE = 0.05
#: Above this Gelman-Rubin R-hat of any sampled EC the decision warns that the chains disagree.
HIGH_RHAT = 1.1
#: A probability this close to 1 but not 1, in a sampled group, pins the chains: a relation
#: the sampler must break to move a box is almost never broken, and the standard errors do not
#: show it (``benchmarks/near_certain.py``); the decision warns.
NEAR_CERTAIN = 1e-3
#: Near-certain relations named one by one in that warning, before "and N more".
NAMED_PAIRS = 3
#: A decision taking this many times its time limit (and a second more) says so: the least a
#: sampled group needs (scattering, burn-in, two batches of sweeps) can exceed any budget.
OVERRUN = 1.5
#: Relative tolerance under which two expected costs count as tied.
TIE_TOLERANCE = 1e-12
#: Expected costs within this many boxes of the lowest count as tied when heights are known;
#: the tied box resting highest is taken.
NEAR_TIE_MARGIN = 0.05
#: Tied boxes resting within this height (metres) of the highest rest on one layer and are
#: decided by their expected cost: ten times a box detector's height error (5 mm), under the
#: height of any carton.
LAYER_TOLERANCE = 0.05


@dataclass(frozen=True, eq=False)
class Decision:
    """Which box to unload first, and why.

    Returned by :func:`decide` (and :func:`unstack.decide` on a scene); :meth:`to_dict` is the
    ``unstack.decision/1`` document that ``unstack decide --json`` prints.

    Attributes
    ----------
    objects : tuple of str
        Box ids (the order of every array).
    choice : str
        The box to unload first.
    expected_costs : numpy.ndarray, shape (n,)
        ``EC(A_j)`` for each box.
    marginals : numpy.ndarray, shape (n, n)
        ``P(SUPP(objects[i], objects[j]) | consistent)``.
    method : str
        ``"exact"``, ``"sat"`` or ``"approx"`` (the method of the largest group).
    cost : str
        ``"load"``, ``"count"`` or ``"mass"``.
    consistent_worlds : int or None
        Number of consistent worlds of non-zero probability, when the method counted them.
    ties : tuple of str
        Every box the choice was made among, by id: those whose EC equals the minimum (the
        choice is the smallest id), or with a near-tie margin, those within it of the
        minimum (the choice is the highest).
    components : tuple of tuple of str
        Groups of boxes linked by non-zero support probabilities; the reasoning runs on each
        group alone (see :mod:`unstack.reasoner.components`).
    evidence : Evidence
        Hard evidence after propagation.
    seconds : float
        Wall time of the reasoning (not in the canonical JSON; see :meth:`to_dict`).
    component_methods : tuple of str
        The method of each group in ``components``.
    expected_cost_errors : numpy.ndarray, shape (n,)
        Standard error of each EC (0 where exact).
    marginal_errors : numpy.ndarray, shape (n, n)
        Standard error of each marginal (0 where exact).
    choice_probability : float
        Probability that ``choice`` has the smallest true EC (1.0 when every EC is exact).
    sampling : dict or None
        How the sampled groups were run (chains, samples, burn-in, acceptance, seed).
    warnings : tuple of str
        Doubts about the input the decision rests on (for a scene: plausibility and
        out-of-distribution warnings from the support model), one sentence each.
    sampling_seconds : float
        Wall time of the sampled groups (0 when none was sampled).
    near_tie_margin : float
        The near-tie margin the choice was made with (0: the minimum EC (Eq. 12)).
    free_cost : float
        When the choice is the highest box holding nothing up
        (:func:`unstack.height_veto.free_highest`): the expected cost those boxes lie below
        (0: the reasoner's own choice).
    reasons : tuple of dict
        With a cost that counts boxes (:data:`~unstack.reasoner.reasons.REASON_COSTS`): per
        box, the boxes it is expected to move as the cost counts them and what drives that
        (the boxes it holds up with their conditional P, its hidden load, the box most likely
        holding it up; :func:`~unstack.reasoner.reasons.pick_reasons`).
    disturbance_model : str
        With the ``moves`` cost: the disturbance model file the expected moves came from.
    model : str
        The support model that gave the probabilities (:func:`unstack.api.model_label`;
        empty when the probabilities were given).
    pick : dict or None
        Where the chosen box is (:func:`unstack.describe.pick_place`): its centre and top
        for a scene, its resting height for supports with heights.
    physics_veto : dict or None
        When physics on the belief tried the pick (:func:`unstack.physics_veto.physics_veto`):
        the boxes tried with the boxes each is expected to move, and whether the reasoner's
        pick was vetoed.

    Examples
    --------
    >>> from unstack.supports import Supports
    >>> decision = decide(Supports(["top", "bottom"], [[0.0, 0.1], [0.9, 0.0]]))
    >>> [(box, round(cost, 3), error) for box, cost, error in decision.ranking()]
    [('top', 0.1, 0.0), ('bottom', 0.9, 0.0)]
    """

    objects: tuple[str, ...]
    choice: str
    expected_costs: np.ndarray
    marginals: np.ndarray
    method: str
    cost: str
    consistent_worlds: int | None
    ties: tuple[str, ...]
    evidence: Evidence
    components: tuple[tuple[str, ...], ...] = ()
    seconds: float = field(default=0.0)
    component_methods: tuple[str, ...] = ()
    expected_cost_errors: np.ndarray | None = None
    marginal_errors: np.ndarray | None = None
    choice_probability: float = 1.0
    sampling: dict[str, Any] | None = None
    warnings: tuple[str, ...] = ()
    sampling_seconds: float = 0.0
    near_tie_margin: float = 0.0
    free_cost: float = 0.0
    reasons: tuple[dict[str, Any], ...] = ()
    disturbance_model: str = ""
    model: str = ""
    pick: dict[str, Any] | None = None
    physics_veto: dict[str, Any] | None = None

    def ranking(self) -> list[tuple[str, float, float]]:
        """Every box with its expected cost and that cost's standard error, best first.

        The choice comes first, then the rest by expected cost (ties by id).

        Returns
        -------
        list of (str, float, float)
            ``(box, EC, standard error)``; the error is 0 where the EC is exact.

        Examples
        --------
        >>> from unstack.supports import Supports
        >>> decide(Supports(["a", "b"], [[0, 0.2], [0.7, 0]])).ranking()[0][0]
        'a'
        """
        errors = self.expected_cost_errors if self.expected_cost_errors is not None else np.zeros(len(self.objects))

        def key(i: int) -> tuple[bool, float, str]:
            box = self.objects[i]
            return (box != self.choice, float(self.expected_costs[i]), box)

        order = sorted(range(len(self.objects)), key=key)
        return [(self.objects[i], float(self.expected_costs[i]), float(errors[i])) for i in order]

    def to_dict(self, *, timing: bool = False) -> dict[str, Any]:
        """The ``unstack.decision/1`` JSON object.

        Parameters
        ----------
        timing : bool
            Add ``"timing"`` (wall-clock seconds of the reasoning and of the sampling).
            Without it the object is canonical: the same input, method and seed give the
            same object on any machine, at any load.

        Returns
        -------
        dict
            JSON-ready (lists, floats, strings), valid against ``decision-1.schema.json``.

        Examples
        --------
        >>> from unstack.supports import Supports
        >>> document = decide(Supports(["a", "b"], [[0, 0.2], [0.7, 0]])).to_dict()
        >>> document["format"], document["choice"], "timing" in document
        ('unstack.decision/1', 'a', False)
        """
        data: dict[str, Any] = {
            "format": DECISION_FORMAT,
            "objects": list(self.objects),
            "choice": self.choice,
            "expected_costs": self.expected_costs.tolist(),
            "marginals": self.marginals.tolist(),
            "method": self.method,
            "cost": self.cost,
        }
        if self.model:
            data["model"] = self.model
        if self.pick is not None:
            data["pick"] = dict(self.pick)
        if self.consistent_worlds is not None:
            data["consistent_worlds"] = self.consistent_worlds
        data["ties"] = list(self.ties)
        if self.near_tie_margin:
            data["near_tie_margin"] = self.near_tie_margin
        if self.free_cost:
            data["free_cost"] = self.free_cost
        if self.physics_veto is not None:
            data["physics_veto"] = self.physics_veto
        data["components"] = [list(group) for group in self.components]
        data["component_methods"] = list(self.component_methods)
        if self.expected_cost_errors is not None and self.marginal_errors is not None:
            data["expected_cost_errors"] = self.expected_cost_errors.tolist()
            data["marginal_errors"] = self.marginal_errors.tolist()
            data["choice_probability"] = self.choice_probability
        if self.reasons:
            data["reasons"] = [dict(reason) for reason in self.reasons]
        if self.disturbance_model:
            data["disturbance_model"] = self.disturbance_model
        if self.sampling is not None:
            data["sampling"] = self.sampling
        data["evidence"] = {
            "forced": [list(pair) for pair in self.evidence.forced],
            "forbidden": [list(pair) for pair in self.evidence.forbidden],
        }
        data["warnings"] = list(self.warnings)
        if timing:
            data["timing"] = {"seconds": round(self.seconds, 6), "sampling_seconds": round(self.sampling_seconds, 6)}
        return data


def choose(
    objects: tuple[str, ...], costs: np.ndarray, *, heights: np.ndarray | None = None, margin: float = 0.0
) -> tuple[str, tuple[str, ...]]:
    """Pick the minimum-EC box; ties (within :data:`TIE_TOLERANCE`) go to the smallest id.

    With ``heights`` and a ``margin``, every box within ``margin`` of the minimum is tied;
    of the tied boxes resting within :data:`LAYER_TOLERANCE` of the highest, the one of
    lowest EC is taken (equal ECs: the smallest id).

    Parameters
    ----------
    objects : tuple of str
        Box ids.
    costs : numpy.ndarray, shape (n,)
        Expected cost of each box.
    heights : numpy.ndarray, shape (n,), optional
        The height each box rests at: its lowest point above the floor (needed for a margin).
    margin : float
        Near-tie margin in expected boxes moved.

    Returns
    -------
    choice : str
    ties : tuple of str
        Every box within the tolerance (or the margin) of the minimum, by id.

    Examples
    --------
    >>> choose(("b", "a", "c"), np.array([0.5, 0.5, 0.7]))
    ('a', ('a', 'b'))

    ``c`` rests on top of another box; ``a`` and ``b`` stand on the floor:

    >>> choose(("b", "a", "c"), np.array([0.5, 0.5, 0.53]), heights=np.array([0.0, 0.0, 0.3]), margin=0.05)
    ('c', ('a', 'b', 'c'))

    On one layer the lower EC wins, however tall the box:

    >>> choose(("tall", "short"), np.array([0.056, 0.019]), heights=np.array([0.0, 0.01]), margin=0.05)
    ('short', ('short', 'tall'))
    """
    costs = np.asarray(costs, dtype=np.float64)
    if costs.shape != (len(objects),) or len(objects) == 0 or not np.all(np.isfinite(costs)):
        raise InvalidArgument(f"expected one finite cost per object ({len(objects)}), got shape {costs.shape}")
    lowest = float(np.min(costs))
    tolerance = TIE_TOLERANCE * max(1.0, abs(lowest))
    if heights is None and margin:
        raise InvalidArgument("a near-tie margin is broken by height: expected the boxes' heights")
    within = np.flatnonzero(costs <= lowest + max(tolerance, margin))
    tied = tuple(sorted(objects[i] for i in within))
    if heights is None or not margin:
        return tied[0], tied
    rests = np.asarray(heights, dtype=np.float64)
    top = float(np.max(rests[within]))
    layer = [i for i in within if rests[i] >= top - LAYER_TOLERANCE]
    least = min(float(costs[i]) for i in layer)
    return min(objects[i] for i in layer if costs[i] <= least + tolerance), tied


def _group_methods(method: str, sizes: list[int], time_limit: float | None, max_boxes: int | None = None) -> list[str]:
    """The method of each group of linked boxes (``sizes``: boxes per group)."""
    if method != "auto":
        return [method] * len(sizes)
    exact_limit = EXACT_MAX_BOXES if max_boxes is None else max_boxes
    if time_limit is not None and time_limit < AUTO_EXACT8_SECONDS:
        exact_limit = min(exact_limit, 7)
    return ["exact" if size <= exact_limit else "approx" for size in sizes]


@dataclass
class _GroupResult:
    """Marginals of one group, with their errors and (when sampled) the batch means."""

    marginals: np.ndarray
    worlds: int | None
    errors: np.ndarray
    sampled: SampledMarginals | None = None


def _group_marginals(
    supports: Supports,
    evidence: Evidence,
    group: np.ndarray,
    method: str,
    max_boxes: int | None,
    sampling: dict[str, Any],
    cache: WorkCache | None = None,
) -> _GroupResult:
    """Conditional marginals (and world count or sampling errors) of one group of linked boxes."""
    probabilities = evidence.probabilities[np.ix_(group, group)]
    if cache is None:
        return _compute_group(supports, probabilities, group, method, max_boxes, sampling, None)
    ids = tuple(supports.objects[i] for i in group)
    key = (ids, method, max_boxes, probabilities.tobytes(), sampling.get("samples"), sampling.get("time_limit"))
    found = cache.results.get(key)
    if found is not None:
        cache.reused += 1
        return found  # type: ignore[no-any-return]
    result = _compute_group(supports, probabilities, group, method, max_boxes, sampling, cache)
    cache.results[key] = result
    if result.sampled is not None and result.sampled.final_worlds is not None:
        cache.chains[ids] = result.sampled.final_worlds
    return result


def _compute_group(
    supports: Supports,
    probabilities: np.ndarray,
    group: np.ndarray,
    method: str,
    max_boxes: int | None,
    sampling: dict[str, Any],
    cache: WorkCache | None,
) -> _GroupResult:
    """:func:`_group_marginals` without the cache (a sampled group may start warm from it)."""
    exact_errors = np.zeros_like(probabilities)
    if method == "sat":
        from unstack.reasoner.worlds import SAT_MAX_BOXES, enumerate_worlds

        objects = [supports.objects[i] for i in group]
        world_set = enumerate_worlds(Supports(objects, probabilities), max_boxes=max_boxes or SAT_MAX_BOXES)
        return _GroupResult(world_set.marginals(), len(world_set), exact_errors)
    if method == "approx":
        from unstack.reasoner.sampling import _sampled_marginals

        warm = None if cache is None else cache.warm_start(tuple(supports.objects[i] for i in group))
        if warm is not None:
            sampling = sampling | {"warm": warm, "burn_in": WARM_BURN_IN}
        result = _sampled_marginals(np.ascontiguousarray(probabilities), **sampling)
        return _GroupResult(result.marginals, None, result.standard_errors, result)
    from unstack.reasoner.marginals import _exact_marginals

    exact = _exact_marginals(probabilities, max_boxes=max_boxes or EXACT_MAX_BOXES)
    return _GroupResult(exact.marginals, exact.consistent_worlds, exact_errors)


def _group_seeds(count: int, seed: int | None) -> list[int | None]:
    """An independent sampler seed per group (``SeedSequence(seed, spawn_key=(group,))``)."""
    if seed is None:
        return [None] * count
    return [int(np.random.SeedSequence(seed, spawn_key=(k,)).generate_state(1)[0]) for k in range(count)]


def _time_share(deadline: float | None, group: np.ndarray, waiting: int) -> float | None:
    """Seconds for a sampled group: the time left, in proportion to its share of the boxes
    still waiting to be sampled (``waiting`` includes this group)."""
    if deadline is None:
        return None
    left = deadline - time.perf_counter() - DECISION_MARGIN
    return max(left, MINIMUM_SAMPLING) * len(group) / waiting


def _sampling_summary(results: list[_GroupResult], seed: int | None) -> dict[str, Any] | None:
    """What the sampled groups ran: chains, samples, burn-in, acceptance (no wall-clock time)."""
    sampled = [result.sampled for result in results if result.sampled is not None]
    if not sampled:
        return None
    summary: dict[str, Any] = {
        "chains": sampled[0].chains,
        "samples": [result.samples for result in sampled],
        "burn_in": sampled[0].burn_in,
        "acceptance": [round(result.acceptance, 4) for result in sampled],
        "seed": seed,
    }
    slowest = min(result.acceptance for result in sampled)
    worst_rhat = max(float(np.max(result.convergence_of(np.ones(result.marginals.shape[0])))) for result in sampled)
    summary["rhat_max"] = round(worst_rhat, 4) if np.isfinite(worst_rhat) else None
    longer = 4 * max(result.samples for result in sampled)  # four times the sweeps halve the errors
    if slowest < LOW_ACCEPTANCE:
        summary["warning"] = (
            f"re-insertion moves were accepted in only {100 * slowest:.1f} % of the tries: the chains mix slowly "
            f"and the standard errors may be too small; sample longer (samples={longer}) and compare two seeds"
        )
    elif not worst_rhat <= HIGH_RHAT:
        summary["warning"] = (
            f"the chains disagree (R-hat of an EC {worst_rhat:.2f} > {HIGH_RHAT}): they have not mixed and the "
            f"standard errors are too small; sample longer (samples={longer})"
        )
    return summary


def decide(
    supports: Supports,
    *,
    method: str = "auto",
    cost: str = DEFAULT_COST,
    max_boxes: int | None = None,
    time_limit: float | None = None,
    samples: int | None = None,
    seed: int | None = None,
    cache: WorkCache | None = None,
    near_tie_margin: float | None = None,
) -> Decision:
    """Choose the box to unload first (Eq. 12) from pairwise support probabilities.

    Parameters
    ----------
    supports : Supports
        Detected boxes and ``P(SUPP(X, Y))`` for every ordered pair.
    method : {"auto", "exact", "sat", "approx"}
        ``exact``: weighted counting of preorders (no world list; a table of every preorder
        up to 5 boxes, a compiled walk up to 8 by default); ``sat``: list the consistent
        worlds with CaDiCaL (up to 6 boxes); ``approx``: Markov chain Monte Carlo over
        consistent worlds, with standard errors (any number of boxes); ``auto``: per
        group of linked boxes, exact up to 8 boxes (7 when ``time_limit`` is under 10 s),
        sampling above.
    cost : {"load", "count", "mass"}
        ``load`` (the default): Eq. 11's count with every box counted together with the
        undetected load the cloud shows on it (``supports.hidden_load``; equal to ``count``
        without it); ``count``: Eq. 11 exactly (number of supported boxes); ``mass``: their
        total mass (needs masses). See :mod:`unstack.reasoner.costs`.
    max_boxes : int, optional
        Override the exact methods' size limit (with ``auto``: the largest group counted
        exactly; larger ones are sampled).
    time_limit : float, optional
        Seconds for the whole decision: the sampled groups share what the exact ones leave.
        Not reproducible (the sweeps that fit depend on the machine's load).
    samples : int, optional
        Recorded sweeps per sampled group (default
        :func:`~unstack.reasoner.sampling.default_samples` of its size, when ``time_limit`` is
        not given either); reproducible for a ``seed``.
    seed : int, optional
        Seed of the sampler and of the choice probability.
    cache : WorkCache, optional
        Work kept from earlier decisions on related scenes (an unloading plan's steps):
        unchanged groups are reused, sampled groups start from earlier chains
        (:mod:`unstack.reasoner.reuse`).
    near_tie_margin : float, optional
        Expected costs within this many boxes of the lowest count as tied and the box
        resting highest of them is taken (one layer: the lowest EC; needs
        ``supports.heights``). Default: :data:`NEAR_TIE_MARGIN`
        when the supports carry heights, else 0; 0 keeps the minimum EC (Eq. 12) exactly.

    Returns
    -------
    Decision

    Raises
    ------
    InvalidArgument
        Not a :class:`~unstack.supports.Supports`, an unknown method or cost, or a budget,
        seed or size limit out of its domain (NaN, negative, zero).
    NoConsistentWorld
        Hard evidence contradicts transitivity (the message names the file and the relations).
    TooLarge
        The scene is beyond the method's limit, or with ``time_limit`` a sampled group's least
        sampling cannot come near the time left for it (:func:`~unstack.reasoner.sampling.sampled_marginals`).

    Examples
    --------
    >>> from unstack.supports import Supports
    >>> decide(Supports(["top", "bottom"], [[0.0, 0.1], [0.9, 0.0]]), method="sat").choice
    'top'
    """
    start = time.perf_counter()
    if not isinstance(supports, Supports):
        raise InvalidArgument(
            f"expected Supports, got {type(supports).__name__}; a Scene gets its probabilities from "
            "a model with unstack.decide or unstack.support_probabilities"
        )
    check_choice(method, "method", METHODS)
    check_choice(cost, "cost", COSTS)
    if max_boxes is not None:
        check_count(max_boxes, "max_boxes")
    if time_limit is not None:
        time_limit = check_budget(time_limit, "time_limit")
        if method in UNSAMPLED_METHODS:
            raise InvalidArgument(
                f"time_limit: method {method!r} counts every world and cannot stop early (use method 'auto', which "
                "samples what the limit does not allow to count)"
            )
    if samples is not None:
        samples = check_samples(samples)
        if method in UNSAMPLED_METHODS:
            raise InvalidArgument(f"samples: method {method!r} samples nothing (use method 'approx' or 'auto')")
    seed = check_seed(seed)
    margin = _near_tie_margin(supports, near_tie_margin)
    n = supports.n_objects
    weights = cost_weights(supports, cost)
    evidence = hard_evidence(supports)
    groups = support_components(evidence.probabilities)
    methods = _group_methods(method, [len(group) for group in groups], time_limit, max_boxes)
    seeds = _group_seeds(len(groups), seed)
    deadline = None if time_limit is None else start + time_limit
    waiting = sum(len(group) for group, method in zip(groups, methods, strict=True) if method == "approx")
    marginals = np.zeros((n, n))
    marginal_errors = np.zeros((n, n))
    covariance = np.zeros((n, n))
    worlds: int | None = 1
    results = []
    for group, group_method, group_seed in zip(groups, methods, seeds, strict=True):
        if len(group) == 1:
            continue
        budget: dict[str, Any] = {"samples": samples, "seed": group_seed, "time_limit": None}
        if group_method == "approx":
            budget["time_limit"] = _time_share(deadline, group, waiting)
            waiting -= len(group)
        try:
            result = _group_marginals(supports, evidence, group, group_method, max_boxes, budget, cache)
        except TooLarge as error:  # a method asked for a group past its engine's limit
            raise TooLarge(supports.named(str(error))) from None
        results.append(result)
        block = np.ix_(group, group)
        marginals[block] = result.marginals
        marginal_errors[block] = result.errors
        if result.sampled is not None:
            covariance[block] = result.sampled.errors_of(weights[group])[1]
        worlds = None if worlds is None or result.worlds is None else worlds * result.worlds
    costs = expected_costs(marginals, weights, own_costs(supports, cost))
    choice, ties = choose(supports.objects, costs, heights=supports.heights, margin=margin)
    largest = int(np.argmax([len(group) for group in groups]))
    sampling = _sampling_summary(results, seed)
    sampling_warning: tuple[str, ...] = (sampling["warning"],) if sampling and "warning" in sampling else ()
    sampled_groups = [group for group, used in zip(groups, methods, strict=True) if used == "approx" and len(group) > 1]
    sampling_warning += _near_certain_doubt(supports, evidence.probabilities, sampled_groups)
    sampling_warning += _overrun(time_limit, time.perf_counter() - start, groups, methods)
    return Decision(
        objects=supports.objects,
        choice=choice,
        components=tuple(tuple(supports.objects[i] for i in group) for group in groups),
        component_methods=tuple(methods),
        expected_costs=costs,
        expected_cost_errors=np.sqrt(np.diag(covariance)),
        marginals=marginals,
        marginal_errors=marginal_errors,
        choice_probability=choice_probability(
            costs, covariance, supports.objects.index(choice), seed=seed, margin=margin
        ),
        sampling=sampling,
        method=methods[largest],
        cost=cost,
        consistent_worlds=worlds,
        ties=ties,
        evidence=evidence,
        seconds=time.perf_counter() - start,
        warnings=supports.warnings + _input_doubts(supports, cost, near_tie_margin) + sampling_warning,
        sampling_seconds=sum(result.sampled.seconds for result in results if result.sampled is not None),
        near_tie_margin=margin,
        reasons=tuple(pick_reasons(supports, marginals, costs)) if cost in REASON_COSTS else (),
    )


def _overrun(time_limit: float | None, seconds: float, groups: list[Any], methods: list[str]) -> tuple[str, ...]:
    """A warning when the decision took well past its time limit, naming the largest sampled group."""
    if time_limit is None or seconds <= OVERRUN * time_limit + 1.0:
        return ()
    sampled = max((len(group) for group, used in zip(groups, methods, strict=True) if used == "approx"), default=0)
    cause = (
        f"the least sampling of a group of {sampled} linked boxes (scattering, burn-in and two batches of sweeps) "
        "takes longer"
        if sampled
        else "reading the evidence and counting took longer"
    )
    return (f"the decision took {seconds:.1f} s against a time limit of {time_limit:g} s: {cause}",)


def _near_certain_doubt(
    supports: Supports, probabilities: np.ndarray, sampled_groups: list[np.ndarray]
) -> tuple[str, ...]:
    """A warning when a sampled group holds relations within :data:`NEAR_CERTAIN` of 1 but not 1.

    Examples
    --------
    >>> p = np.array([[0.0, 1 - 1e-9], [0.2, 0.0]])
    >>> [text[:50] for text in _near_certain_doubt(Supports(["a", "b"], p), p, [np.array([0, 1])])]
    ['1 relation has a probability within 0.001 of 1 but']
    """
    pairs = []
    for group in sampled_groups:
        inside = probabilities[np.ix_(group, group)]
        near = (inside > 1.0 - NEAR_CERTAIN) & (inside < 1.0)
        pairs += [(int(group[x]), int(group[y])) for x, y in zip(*np.nonzero(near), strict=True)]
    if not pairs:
        return ()
    named = ", ".join(
        f"{supports.objects[x]} -> {supports.objects[y]}: {probabilities[x, y]:.9g}" for x, y in pairs[:NAMED_PAIRS]
    )
    more = f" and {len(pairs) - NAMED_PAIRS} more" if len(pairs) > NAMED_PAIRS else ""
    relations = "1 relation has" if len(pairs) == 1 else f"{len(pairs)} relations have"
    return (
        f"{relations} a probability within {NEAR_CERTAIN:g} of 1 but not 1 ({named}{more}): the sampler "
        "almost never breaks them to move a box, and its standard errors may be too small; give 1 where it is "
        "meant (hard evidence is counted exactly) or compare two seeds",
    )


def _input_doubts(supports: Supports, cost: str, near_tie_margin: float | None) -> tuple[str, ...]:
    """What is doubtful in the arguments given with ``supports``: boxes lighter than a carton
    for the mass cost, more undetected boxes on a box than a stack holds for the load cost, a
    near-tie margin above every expected cost."""
    beyond = margin_beyond_every_cost(supports, cost, "near_tie_margin", near_tie_margin)
    return weight_doubts(supports, cost) + ((supports.named(beyond),) if beyond is not None else ())


def _near_tie_margin(supports: Supports, margin: float | None) -> float:
    if margin is None:
        return NEAR_TIE_MARGIN if supports.heights is not None else 0.0
    margin = check_margin(margin, "near_tie_margin")
    if margin and supports.heights is None:
        raise InvalidArgument(
            f"{supports.source}: near_tie_margin breaks near ties by height, but these supports carry no "
            'heights (a Scene\'s do; or add "heights" to the supports file)'
        )
    return margin
