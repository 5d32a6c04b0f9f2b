"""Decision quality on simulated test piles (§V-B, Fig. 4), with baselines and a physical check.

For every test ISet (``r`` detected boxes drawn from a test scene's complete set), each
decision maker picks the box to unload first:

``reasoner``
    unstack: the classifier's probabilities, the consistent worlds and the minimum EC
    (Eq. 12, as the paper decides) with the default cost (``load``: every box counted with
    the undetected load the cloud shows on it).
``near_ties``
    the reasoner's choice: the same expected costs, near ties (within
    :data:`~unstack.reasoner.decision.NEAR_TIE_MARGIN`) to the box resting highest.
``default``
    unstack's default choice on a scene (:func:`unstack.height_veto.free_highest`): the
    highest box of the ISet whose expected cost is below 0.5, else ``near_ties``' choice.
``count``
    the same with Eq. 11's count exactly (``cost="count"``): the load nobody detected is
    not counted.
``priors``
    the same probabilities without the consistency step: EC = row sums of the raw
    probabilities (what the possible-worlds reasoning adds is the difference).
``highest``
    the box with the highest centroid (the rule of Papazov et al. cited by the paper).
``free``
    a geometric rule: a box is free when no other box of the ISet overlaps its footprint
    from above; the highest free box (the highest box if none is free).
``hybrid``
    height vetoed by unstack (:func:`unstack.height_veto.highest_free_box`): the highest box
    of the ISet whose expected cost (``reasoner``'s) is below 0.5.
``random``
    uniform over the ISet; its figures are exact expectations over the choice, not samples.

Scores, against the ground truth of the ISet (Eq. 11 cost = boxes of the ISet the chosen box
supports):

* MSE(cost) of Eq. 14 against the minimum possible cost, overall and binned by the
  classifier's success rate, balanced error rate (Eq. 16) and average entropy (Eq. 15) on the
  ISet's relations (the paper's Fig. 4), with the histogram of ISets per bin;
* the share of ISets whose first pick has the minimum possible cost;
* the physical disturbance of the pick, from the simulator's removal responses stored in the
  scene: boxes of the whole pile (not only the ISet) that moved more than 2 cm when the chosen
  box was taken away, and the sum of their displacements;
* for every other decision maker, the paired difference (other minus unstack) of each score
  over the same ISets, with its standard error (``against_reasoner``);
* every ISet's own record (``per_iset``: its boxes, their true costs, each maker's pick and
  the boxes it moved), so that two runs on the same ISets -- two models, say -- can be paired
  afterwards (:func:`paired_between_runs`).

Examples
--------
>>> costs = np.array([2.0, 0.0, 1.0])
>>> squared_regret(costs, 0)
4.0
"""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from unstack.errors import UnstackError
from unstack.learning.training_data import ISET_DRAWS
from unstack.parameters import COUNT, ISET_SIZE, SEED, OneOf, validate_params
from unstack.sim.settings import DISPLACEMENT_THRESHOLD

__all__ = [
    "DECISION_MAKERS",
    "PAPER_TEST_ISETS",
    "IsetOutcome",
    "decision_scores",
    "evaluate_decisions",
    "iset_outcome",
    "paired_between_runs",
    "paired_difference",
    "squared_regret",
    "uncovered_boxes",
]

DECISION_MAKERS = ("reasoner", "near_ties", "default", "count", "priors", "highest", "free", "hybrid", "random")


def squared_regret(costs: np.ndarray, choice: int) -> float:
    """``(DMC - MPC)^2`` of one pick (Eq. 14's term)."""
    return float((costs[choice] - costs.min()) ** 2)


def paired_difference(other: np.ndarray, ours: np.ndarray) -> dict[str, float | None]:
    """Mean of ``other - ours`` over the same cases, with its standard error (None from one case).

    Examples
    --------
    >>> paired_difference(np.array([1.0, 2.0, 3.0]), np.array([0.0, 2.0, 1.0]))
    {'mean': 1.0, 'standard_error': 0.5773502691896258}
    """
    difference = np.asarray(other, dtype=np.float64) - np.asarray(ours, dtype=np.float64)
    spread = float(difference.std(ddof=1) / np.sqrt(len(difference))) if len(difference) > 1 else None
    return {"mean": float(difference.mean()), "standard_error": spread}


@dataclass(frozen=True)
class IsetOutcome:
    """One ISet of Fig. 4: its true costs, each decision maker's pick, and what each pick disturbs."""

    scene_file: str
    ids: list[str]
    costs: np.ndarray  # ground-truth cost of unloading each box first (Eq. 11)
    picks: dict[str, int]
    disturbance: np.ndarray  # (r, 2): boxes moved > 2 cm, sum of displacements, per pick candidate
    success_rate: float
    balanced_error_rate: float
    average_entropy: float


def uncovered_boxes(boxes: Sequence[Any], among: Sequence[int] | None = None) -> list[int]:
    """Indices (of ``among``, default all) of the boxes no other box of ``boxes`` covers from above.

    A box covers another when their footprints' bounding boxes overlap by more than 2 cm both
    ways and it starts at most 5 cm below the other's top and ends above it.

    Examples
    --------
    >>> from unstack.scene import Box
    >>> low, high = Box("low", [0.4, 0.4, 0.4], [0, 0, 0.2]), Box("high", [0.4, 0.4, 0.4], [0, 0, 0.6])
    >>> uncovered_boxes([low, high])
    [1]
    """
    from unstack.geometry import bounding_box_overlap_xy, bounding_boxes

    bounds = bounding_boxes(list(boxes))
    free = []
    for i in range(len(boxes)) if among is None else among:
        covered = False
        for j in range(len(boxes)):
            if i == j:
                continue
            overlap_x, overlap_y = bounding_box_overlap_xy(bounds[i], bounds[j])[0]
            above = bounds[j, 2] >= bounds[i, 5] - 0.05 and bounds[j, 5] > bounds[i, 5]
            if overlap_x > 0.02 and overlap_y > 0.02 and above:
                covered = True
                break
        if not covered:
            free.append(i)
    return free


def free_pick(boxes: list[Any]) -> int:
    """The footprint rule: the highest box that no other covers from above (the highest if all are covered)."""
    heights = [boxes[i].position[2] for i in range(len(boxes))]
    candidates = uncovered_boxes(boxes) or list(range(len(boxes)))
    return max(candidates, key=lambda i: heights[i])


def iset_outcome(scene: Any, ids: list[str], model: Any, *, statics: bool = True) -> IsetOutcome:
    """Decide one ISet of a simulated scene with ``model`` and every decision maker; score the picks.

    ``statics``: as in :func:`~unstack.pipeline.scene_support_probabilities` (the
    default pipeline); the scores compare the picks with the simulator's ground truth either way.
    """
    import dataclasses

    from unstack.height_veto import free_highest, hybrid_choice
    from unstack.learning.metrics import classification_report
    from unstack.pipeline import scene_support_probabilities
    from unstack.reasoner.decision import NEAR_TIE_MARGIN, choose, decide

    supports = scene_support_probabilities(scene, model, boxes=ids, statics=statics)
    index = [scene.box_ids.index(box_id) for box_id in ids]
    truth = scene.ground_truth[np.ix_(index, index)]
    costs = truth.sum(axis=1).astype(np.float64)
    probabilities = supports.probabilities
    off = ~np.eye(len(ids), dtype=bool)
    report = classification_report(truth[off], probabilities[off])
    boxes = [scene.box(box_id) for box_id in ids]
    priors_costs = probabilities.sum(axis=1)
    decision = decide(supports, near_tie_margin=0.0)
    near_tie, _ = choose(tuple(ids), decision.expected_costs, heights=supports.heights, margin=NEAR_TIE_MARGIN)
    picks = {
        "reasoner": ids.index(decision.choice),
        "near_ties": ids.index(near_tie),
        "default": ids.index(free_highest(dataclasses.replace(decision, choice=near_tie), scene).choice),
        "count": ids.index(decide(supports, cost="count", near_tie_margin=0.0).choice),
        "priors": ids.index(choose(tuple(ids), priors_costs)[0]),
        "highest": int(np.argmax([box.position[2] for box in boxes])),
        "free": free_pick(boxes),
        "hybrid": ids.index(hybrid_choice(scene, decision, candidates=ids)),
    }
    removal = scene.metadata.get("simulation", {}).get("removal", {})
    displacement = np.asarray(removal.get("displacement_m", np.zeros((len(scene.boxes),) * 2)))
    rows = displacement[index]
    disturbed = rows > DISPLACEMENT_THRESHOLD
    disturbance = np.column_stack([disturbed.sum(axis=1), np.where(disturbed, rows, 0).sum(axis=1)])
    return IsetOutcome(
        str(scene.source),
        ids,
        costs,
        picks,
        disturbance,
        report["success_rate"],
        report["balanced_error_rate"],
        report["average_entropy"],
    )


def decision_scores(isets: list[IsetOutcome], maker: str) -> dict[str, np.ndarray]:
    """Per-ISet squared regret, first-pick-right indicator and disturbance for a decision maker.

    ``random`` is scored by its exact expectation over the ISet's boxes.

    Examples
    --------
    >>> outcome = IsetOutcome("s", ["a", "b"], np.array([0.0, 1.0]), {"count": 0}, np.zeros((2, 2)), 1.0, 0.0, 0.0)
    >>> decision_scores([outcome], "random")["first_pick_right"].tolist()
    [0.5]
    """
    if maker == "random":
        regret = np.array([np.mean([squared_regret(s.costs, k) for k in range(len(s.ids))]) for s in isets])
        right = np.array([np.mean(s.costs == s.costs.min()) for s in isets])
        moved = np.array([s.disturbance[:, 0].mean() for s in isets])
        shift = np.array([s.disturbance[:, 1].mean() for s in isets])
    else:
        regret = np.array([squared_regret(s.costs, s.picks[maker]) for s in isets])
        right = np.array([float(s.costs[s.picks[maker]] == s.costs.min()) for s in isets])
        moved = np.array([s.disturbance[s.picks[maker], 0] for s in isets])
        shift = np.array([s.disturbance[s.picks[maker], 1] for s in isets])
    return {"squared_regret": regret, "first_pick_right": right, "moved": moved, "displacement": shift}


BINS = {
    "success_rate": np.linspace(0.5, 1.0, 6),
    "balanced_error_rate": np.linspace(0.0, 0.5, 6),
    "average_entropy": np.linspace(0.0, 0.7, 8),
}


def _binned(isets: list[IsetOutcome], scores: dict[str, dict[str, np.ndarray]]) -> dict[str, Any]:
    result: dict[str, Any] = {}
    for criterion, edges in BINS.items():
        values = np.array([getattr(s, criterion) for s in isets])
        which = np.clip(np.digitize(values, edges[1:-1]), 0, len(edges) - 2)
        rows = []
        for k in range(len(edges) - 1):
            members = which == k
            low, high = (round(float(edge), 12) for edge in edges[k : k + 2])  # linspace's 0.30000000000000004
            row: dict[str, Any] = {"low": low, "high": high, "isets": int(members.sum())}
            for maker in ("reasoner", "random"):
                regret = scores[maker]["squared_regret"][members]
                row[f"mse_{maker}"] = float(regret.mean()) if members.any() else None
            rows.append(row)
        result[criterion] = rows
    return result


#: The paper's decision test (§V, Fig. 4): 493 test ISets.
PAPER_TEST_ISETS = 493


@validate_params({"r": ISET_SIZE, "isets": COUNT, "seed": SEED, "draw": OneOf(ISET_DRAWS)})
def evaluate_decisions(
    data_dir: str | os.PathLike[str],
    model: Any,
    *,
    r: int = 5,
    isets: int = PAPER_TEST_ISETS,
    seed: int = 0,
    progress: Callable[[int, int], None] | None = None,
    draw: str = "random",
    statics: bool = True,
) -> dict[str, Any]:
    """Draw ``isets`` test ISets of ``r`` boxes from the data set's scenes and score every decision maker.

    ``draw``: how the ISets are drawn (see :data:`unstack.learning.training_data.ISET_DRAWS`).
    ``statics``: let a box that cannot stand without another make it its supporter
    (:mod:`unstack.understanding.statics`, the default); ``False``: the model's probabilities alone. It does
    not change which ISets are drawn, so runs with and without it pair ISet by ISet.
    """
    from unstack.dataset_folders import require_configurations
    from unstack.learning.training_data import detected_positions, sample_isets
    from unstack.scene import load_scene

    files = require_configurations(data_dir)
    rng = np.random.default_rng(seed)
    per_scene = int(np.ceil(isets / len(files)))
    results: list[IsetOutcome] = []
    for path in files:
        if len(results) >= isets:
            break
        scene = load_scene(path)
        drawn = sample_isets(
            scene.detected,
            r=r,
            isets=min(per_scene, isets - len(results)),
            rng=rng,
            draw=draw,
            positions=detected_positions(scene),
        )
        for ids in drawn:
            results.append(iset_outcome(scene, list(ids), model, statics=statics))
            if progress is not None:
                progress(len(results), isets)
    if not results:
        raise UnstackError(f"{data_dir}: no ISet of at least 2 detected boxes (r = {r}); nothing to decide on")
    smaller = sorted({len(outcome.ids) for outcome in results if len(outcome.ids) < r})
    if smaller:  # the paper's draw takes one box fewer than a small pile's detected boxes
        import warnings

        held = f"{smaller[0]}" if len(smaller) == 1 else f"{smaller[0]}-{smaller[-1]}"
        warnings.warn(
            f"{data_dir}: r = {r} is more than some piles can give: "
            f"{sum(len(outcome.ids) < r for outcome in results)} of the {len(results)} ISets hold {held} boxes",
            stacklevel=2,
        )
    scores = {maker: decision_scores(results, maker) for maker in DECISION_MAKERS}
    summary = {
        maker: {
            "mse_cost": float(values["squared_regret"].mean()),
            "first_pick_right": float(values["first_pick_right"].mean()),
            "boxes_moved": float(values["moved"].mean()),
            "displacement_m": float(values["displacement"].mean()),
        }
        for maker, values in scores.items()
    }
    # the same ISets for every maker: paired differences say whether a gap is more than noise
    measures = {"squared_regret": "mse_cost", "first_pick_right": "first_pick_right", "moved": "boxes_moved",
                "displacement": "displacement_m"}  # fmt: skip
    against_reasoner = {
        maker: {name: paired_difference(scores[maker][key], scores["reasoner"][key]) for key, name in measures.items()}
        for maker in DECISION_MAKERS
        if maker != "reasoner"
    }
    from unstack.dataset_folders import dataset_digest

    return {
        "data": str(data_dir),
        "data_sha256": dataset_digest(files),
        "r": r,
        "isets": len(results),
        "seed": seed,
        "draw": draw,
        "statics": statics,
        "summary": summary,
        "against_reasoner": against_reasoner,
        "bins": _binned(results, scores),
        "classifier": {
            "success_rate": float(np.mean([s.success_rate for s in results])),
            "balanced_error_rate": float(np.mean([s.balanced_error_rate for s in results])),
            "average_entropy": float(np.mean([s.average_entropy for s in results])),
        },
        "per_iset": [_iset_record(outcome, scores, k) for k, outcome in enumerate(results)],
    }


def _iset_record(outcome: IsetOutcome, scores: dict[str, dict[str, np.ndarray]], k: int) -> dict[str, Any]:
    """One ISet's boxes, true costs, picks (box ids) and boxes moved per maker."""
    return {
        "scene": Path(outcome.scene_file).name,
        "boxes": list(outcome.ids),
        "costs": outcome.costs.tolist(),
        "picks": {maker: outcome.ids[pick] for maker, pick in outcome.picks.items()},
        "moved": {maker: float(values["moved"][k]) for maker, values in scores.items()},
    }


def require_same_draw(first: dict[str, Any], second: dict[str, Any]) -> None:
    """Raise ``ValueError`` unless two decisions runs drew their ISets alike: the same data (by
    the digest of its configurations where both runs carry one, else by the folder's name as
    given), ``r``, seed and draw.

    Examples
    --------
    >>> require_same_draw({"data": "d", "r": 2, "seed": 0, "draw": "random"}, {"data": "./d", "r": 3, "seed": 0})
    Traceback (most recent call last):
    ...
    ValueError: the runs drew their ISets differently (r, draw): nothing to pair
    """
    both = all("data_sha256" in run for run in (first, second))
    settings = ("data_sha256" if both else "data", "r", "seed", "draw")

    def setting(run: dict[str, Any], key: str) -> Any:
        value = run.get(key)
        # The same folder written as "piles", "./piles" or "piles/" draws the same ISets.
        return os.path.normpath(value) if key == "data" and isinstance(value, str) else value

    differing = [key.removesuffix("_sha256") for key in settings if setting(first, key) != setting(second, key)]
    if differing:
        raise ValueError(f"the runs drew their ISets differently ({', '.join(differing)}): nothing to pair")


def check_decisions_run(run: dict[str, Any]) -> None:
    """Raise ``ValueError`` unless ``run`` is a result of :func:`evaluate_decisions` with its
    per-ISet records (what :func:`paired_between_runs` pairs).

    Examples
    --------
    >>> try:
    ...     check_decisions_run({"runs": [], "makers": []})
    ... except ValueError as error:
    ...     print(str(error).split(", got ")[1])
    another document (keys makers, runs)
    """
    if "per_iset" in run:
        return
    if "against_reasoner" in run and "bins" in run:
        raise ValueError("a decisions run with no per-ISet records (made before they were kept): run it again")
    keys = ", ".join(sorted(run)[:6]) + (", ..." if len(run) > 6 else "")
    raise ValueError(
        f"expected the decisions.json of an `unstack experiment decisions` run, got another document (keys {keys})"
    )


def paired_between_runs(
    first: dict[str, Any], second: dict[str, Any], *, maker: str = "reasoner"
) -> dict[str, float | None]:
    """Boxes moved by ``maker``, ``second`` run minus ``first``, paired over their common ISets.

    Both runs must come from :func:`evaluate_decisions` on the same data, ``r``, seed and draw
    (then they drew the same ISets, whatever model each used); an ISet is matched by its scene
    and boxes.

    Raises
    ------
    ValueError
        The runs drew different ISets, or a run has no per-ISet records.

    Examples
    --------
    >>> run = {"data": "d", "r": 2, "seed": 0, "draw": "random", "per_iset": [
    ...     {"scene": "s", "boxes": ["a", "b"], "moved": {"reasoner": 1.0}}]}
    >>> other = {**run, "per_iset": [{"scene": "s", "boxes": ["a", "b"], "moved": {"reasoner": 0.0}}]}
    >>> paired_between_runs(run, other)["mean"]
    -1.0
    """
    for run in (first, second):
        check_decisions_run(run)
    require_same_draw(first, second)

    def by_iset(run: dict[str, Any]) -> dict[tuple[str, tuple[str, ...]], float]:
        return {(row["scene"], tuple(row["boxes"])): float(row["moved"][maker]) for row in run["per_iset"]}

    try:
        ours, theirs = by_iset(first), by_iset(second)
    except (KeyError, TypeError, ValueError) as error:
        raise ValueError(
            f"a run's per-ISet records are not those of a decisions.json ({error!r} missing or wrong)"
        ) from None
    common = [key for key in ours if key in theirs]
    if not common:
        raise ValueError("the runs share no ISet: nothing to pair")
    return paired_difference(np.array([theirs[key] for key in common]), np.array([ours[key] for key in common]))


def plot_fig4(result: dict[str, Any], output: str | os.PathLike[str]) -> None:
    """The paper's Fig. 4: MSE(cost) per bin for unstack and the random decision maker, with histograms."""
    from unstack.plotting import curve_labels, pyplot

    plt = pyplot()

    labels = {
        "success_rate": "classifier success rate",
        "balanced_error_rate": "balanced error rate (Eq. 16)",
        "average_entropy": "average entropy (Eq. 15)",
    }
    figure, axes = plt.subplots(2, 3, figsize=(13, 6), height_ratios=[3, 1], sharex="col")
    for column, (criterion, label) in enumerate(labels.items()):
        rows = result["bins"][criterion]
        centres = [(row["low"] + row["high"]) / 2 for row in rows]
        width = rows[0]["high"] - rows[0]["low"]
        curves = {
            maker: [row[f"mse_{maker}"] if row[f"mse_{maker}"] is not None else np.nan for row in rows]
            for maker in ("reasoner", "random")
        }
        names = curve_labels(["unstack", "random"], list(curves.values()))
        # random: larger hollow squares on a dashed line, so that unstack's dots show through where they meet
        axes[0, column].plot(centres, curves["reasoner"], "o-", markersize=5, label=names[0])
        axes[0, column].plot(centres, curves["random"], "s--", markersize=8, mfc="none", label=names[1])
        axes[0, column].set_ylabel("MSE(cost) (Eq. 14)")
        axes[0, column].legend()
        total = max(result["isets"], 1)
        axes[1, column].bar(centres, [100 * row["isets"] / total for row in rows], width=width * 0.9, color="grey")
        axes[1, column].set_xlabel(label)
        axes[1, column].set_ylabel("% of ISets")
    figure.suptitle(f"{result['isets']} test ISets of {result['r']} boxes from {Path(result['data']).name}")
    figure.tight_layout()
    from unstack.plotting import save_figure

    save_figure(figure, output)
