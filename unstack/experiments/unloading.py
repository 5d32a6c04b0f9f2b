"""Whole unloading orders executed in the simulator (beyond the paper).

For each test pile, every detected box is ordered by each decision maker and the order is
executed box by box in the physics engine (:mod:`unstack.sim.unloading`); the disturbance of
each removal is measured on every box still in place. Decision makers:

``reasoner``
    ``unstack plan``: repeated decisions on the detected boxes still in place (sampling with
    error bars where a group is too large to count).
``priors``
    the same repeated choice from the raw probabilities (row sums, no consistency step).
``highest``
    highest centroid first.
``free``
    repeatedly the highest box that no remaining detected box covers from above.
``random``
    a seeded random order.
With ``closed_loop=True`` (``--closed-loop``) two more:

``reasoner_closed_loop``
    unstack as a robot would run it: before each pick the pile is sensed again (poses and
    a new point cloud), the model gives the probabilities of the boxes left, and the decision
    picks one (:func:`unstack.sim.unloading.execute_policy`).
``highest_closed_loop``
    highest centroid first, measured again before each pick.

Undetected boxes are never picked (the robot does not know them) but they are watched: a
detected box taken from under a hidden one disturbs it too.

Examples
--------
>>> UNLOADING_MAKERS + CLOSED_LOOP_MAKERS
('reasoner', 'priors', 'highest', 'free', 'random', 'reasoner_closed_loop', 'highest_closed_loop')
"""

from __future__ import annotations

import dataclasses
import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from unstack.experiments.dispatch import run_unordered
from unstack.parameters import COUNT, JOBS, SEED, OneOf, validate_params
from unstack.reasoner.costs import COSTS, DEFAULT_COST

__all__ = [
    "CLOSED_LOOP_MAKERS",
    "UNLOADING_MAKERS",
    "UNLOAD_SAMPLES",
    "DecisionSettings",
    "closed_loop_policies",
    "plot_unloading",
    "unloading_experiment",
    "unloading_orders",
]

UNLOADING_MAKERS = ("reasoner", "priors", "highest", "free", "random")
#: Recorded sweeps per sampled group in each decision of the experiment (a 40-box group:
#: about 0.35 s on 2 busy cores, the experiment's former 0.3 s time limit, with 1024 sweeps of
#: every box; 3 times the sweeps since a sweep re-inserts
#: :data:`~unstack.reasoner.sampling.MOVES` boxes, as the default budget).
UNLOAD_SAMPLES = 3072
#: The makers that sense the pile again before each pick (``closed_loop=True``; the others
#: plan on the untouched pile).
CLOSED_LOOP_MAKERS = ("reasoner_closed_loop", "highest_closed_loop")


@dataclass(frozen=True)
class DecisionSettings:
    """How unstack decides at every pick of an unloading run: the sampler's seed and budget, the
    cost and whether statics raise the probabilities.

    Attributes
    ----------
    seed : int
        Seed of the sampler (and of the ``random`` order).
    samples : int, optional
        Recorded sweeps per sampled group of each decision.
    time_limit : float, optional
        Seconds per decision instead of ``samples`` (not reproducible).
    cost : str
        The cost of unstack's decisions (:data:`unstack.reasoner.costs.COSTS`).
    statics : bool
        As in :func:`~unstack.pipeline.scene_support_probabilities`.

    Examples
    --------
    >>> DecisionSettings(seed=3, samples=64).cost
    'load'
    """

    seed: int
    samples: int | None = None
    time_limit: float | None = None
    cost: str = DEFAULT_COST
    statics: bool = True


def _repeated(pick: Callable[[list[str]], str], boxes: list[str]) -> list[str]:
    """An order made by picking from the boxes still in place until none is left."""
    remaining = list(boxes)
    order = []
    while remaining:
        order.append(pick(remaining))
        remaining.remove(order[-1])
    return order


def closed_loop_policies(model: Any, settings: DecisionSettings) -> dict[str, Callable[[Any], str]]:
    """The closed-loop decision makers: each maps the freshly sensed scene to the box to take."""
    from unstack.pipeline import scene_support_probabilities
    from unstack.reasoner.decision import decide

    def reasoner(scene: Any) -> str:
        supports = scene_support_probabilities(scene, model, statics=settings.statics)
        decision = decide(
            supports, cost=settings.cost, samples=settings.samples, time_limit=settings.time_limit,
            seed=settings.seed, near_tie_margin=0.0,
        )  # fmt: skip
        return str(decision.choice)

    def highest(scene: Any) -> str:
        return str(min(scene.detected, key=lambda box_id: (-scene.box(box_id).position[2], box_id)))

    return {"reasoner_closed_loop": reasoner, "highest_closed_loop": highest}


def unloading_orders(scene: Any, model: Any, settings: DecisionSettings) -> dict[str, list[str]]:
    """The order of the scene's detected boxes for every decision maker (the baselines do not
    use the probabilities except ``priors``)."""
    from unstack.experiments.decisions import free_pick
    from unstack.pipeline import scene_support_probabilities
    from unstack.reasoner.decision import choose
    from unstack.reasoner.plan import unloading_plan

    supports = scene_support_probabilities(scene, model, statics=settings.statics)
    detected = list(scene.detected)
    # the minimum EC (Eq. 12) at every step (no near ties by height): the open-loop figures of the results page
    plan = unloading_plan(
        supports, cost=settings.cost, samples=settings.samples, time_limit=settings.time_limit, seed=settings.seed,
        near_tie_margin=0.0,
    )  # fmt: skip

    def raw_priors(remaining: list[str]) -> str:
        subset = supports.subset(remaining)
        return choose(subset.objects, subset.probabilities.sum(axis=1))[0]

    def footprint_rule(remaining: list[str]) -> str:
        return remaining[free_pick([scene.box(box_id) for box_id in remaining])]

    heights = {box_id: scene.box(box_id).position[2] for box_id in detected}
    return {
        "reasoner": plan.order,
        "priors": _repeated(raw_priors, detected),
        "highest": sorted(detected, key=lambda box_id: (-heights[box_id], box_id)),
        "free": _repeated(footprint_rule, detected),
        "random": [str(box_id) for box_id in np.random.default_rng(settings.seed).permutation(detected)],
    }


def _pile_key(path: Path, model: Any, settings: DecisionSettings, closed_loop: bool) -> dict[str, Any]:
    """What a pile's result depends on: the scene file, the model, the decisions' settings and
    the makers."""
    from unstack.dataset_folders import scene_digest
    from unstack.experiments.outputs import model_digest

    return {
        "scene": path.name,
        "scene_sha256": scene_digest(path),
        "model_sha256": model_digest(model),
        "samples": settings.samples,
        "time_limit": settings.time_limit,
        "seed": settings.seed,
        "closed_loop": closed_loop,
        "cost": settings.cost,
        "statics": settings.statics,
    }


def _finished_pile(checkpoints: Path | None, key: dict[str, Any]) -> dict[str, Any] | None:
    """The stored result of a pile run with the same key, if any (a damaged file is redone)."""
    if checkpoints is None:
        return None
    from unstack.experiments.outputs import stored_result

    result = stored_result(checkpoints / f"{Path(key['scene']).stem}.json", key)
    return result if result is not None and isinstance(result.get("runs"), dict) else None


def _run_pile(
    path: Path, number: int, model: Any, settings: DecisionSettings, closed_loop: bool
) -> tuple[int, dict[str, Any]]:
    """Every decision maker's run on one pile (``number`` is passed back for the caller's order)."""
    from unstack.scene import load_scene
    from unstack.sim.unloading import execute_policy, execute_unloading

    scene = load_scene(path)
    orders = unloading_orders(scene, model, settings)
    executed = {maker: execute_unloading(scene, orders[maker]).to_dict() for maker in orders}
    policies = closed_loop_policies(model, settings) if closed_loop else {}
    for maker, policy in policies.items():
        executed[maker] = execute_policy(scene, policy, scene.detected).to_dict()
    return number, {"scene": path.name, "boxes": len(scene.boxes), "detected": len(scene.detected), "runs": executed}


@validate_params({
    "configs": COUNT, "seed": SEED, "cost": OneOf(COSTS), "n_jobs": JOBS,
})  # fmt: skip
def unloading_experiment(
    data_dir: str | os.PathLike[str],
    model: Any,
    *,
    configs: int = 4,
    samples: int | None = None,
    time_limit: float | None = None,
    seed: int = 0,
    progress: Callable[[int, int], None] | None = None,
    checkpoints: str | os.PathLike[str] | None = None,
    closed_loop: bool = False,
    cost: str = DEFAULT_COST,
    statics: bool = True,
    n_jobs: int = 1,
    client: Any = None,
) -> dict[str, Any]:
    """Order and execute the detected boxes of the first ``configs`` piles of a data set.

    ``samples``: recorded sweeps per sampled group of every decision (default
    :data:`UNLOAD_SAMPLES`; with the seed, results are identical whatever the machine's load);
    ``time_limit``: seconds per decision instead (not reproducible).
    ``checkpoints``: a folder where each pile's result is stored as soon as it is done; a run
    that is stopped and started again with the same scenes, model, budget and seed reuses
    them (resumable). Results do not depend on resuming: each pile has its own seed.
    ``closed_loop``: also run the :data:`CLOSED_LOOP_MAKERS` (about three times slower).
    ``cost``: the cost of unstack's decisions (:data:`unstack.reasoner.costs.COSTS`).
    ``statics``: let a box that cannot stand without another make it its supporter
    (:mod:`unstack.understanding.statics`, the default pipeline); ``False``: the model's probabilities alone.
    ``n_jobs``: piles run in parallel processes; ``client``: on the workers of a
    ``distributed.Client`` instead (the results do not depend on either).
    """
    import json

    from unstack.atomic import atomic_write_text
    from unstack.dataset_folders import first_configurations
    from unstack.experiments.outputs import checkpoint_folder

    if samples is None and time_limit is None:
        samples = UNLOAD_SAMPLES
    settings = DecisionSettings(seed=seed, samples=samples, time_limit=time_limit, cost=cost, statics=statics)
    files = first_configurations(data_dir, configs, "configurations")
    per_pile_settings = [dataclasses.replace(settings, seed=seed + number) for number in range(len(files))]
    keys = [_pile_key(path, model, per_pile_settings[number], closed_loop) for number, path in enumerate(files)]
    with checkpoint_folder(checkpoints) as folder:
        piles: list[dict[str, Any] | None] = [_finished_pile(folder, key) for key in keys]
        todo = [number for number, pile in enumerate(piles) if pile is None]
        if progress is not None:
            progress(len(files) - len(todo), len(files))
        arguments = [(files[number], number, model, per_pile_settings[number], closed_loop) for number in todo]
        results = run_unordered(_run_pile, arguments, n_jobs=n_jobs, client=client)
        for number, pile in results:
            piles[number] = pile
            if folder is not None:
                stored = {"key": keys[number], "result": pile}
                atomic_write_text(folder / f"{files[number].stem}.json", json.dumps(stored) + "\n")
            if progress is not None:
                progress(sum(pile is not None for pile in piles), len(files))
    done: list[dict[str, Any]] = [pile for pile in piles if pile is not None]
    makers = UNLOADING_MAKERS + (CLOSED_LOOP_MAKERS if closed_loop else ())
    summary = {}
    for maker in makers:
        runs: list[dict[str, Any]] = [pile["runs"][maker] for pile in done]
        steps = sum(len(run["steps"]) for run in runs)
        summary[maker] = {
            "boxes_moved_per_pile": float(np.mean([run["boxes_moved"] for run in runs])),
            "boxes_moved_per_pick": float(sum(run["boxes_moved"] for run in runs) / max(steps, 1)),
            "displacement_m_per_pile": float(np.mean([run["displacement_m"] for run in runs])),
            "calm_picks": float(sum(step["boxes_moved"] == 0 for run in runs for step in run["steps"]) / max(steps, 1)),
        }
    from unstack.experiments.decisions import paired_difference

    def per_pile(maker: str, key: str) -> np.ndarray:
        return np.array([pile["runs"][maker][key] for pile in done], dtype=np.float64)

    against_reasoner = {  # the same piles for every maker: is a gap more than noise?
        maker: {key: paired_difference(per_pile(maker, key), per_pile("reasoner", key))
                for key in ("boxes_moved", "displacement_m")}
        for maker in makers
        if maker != "reasoner"
    }  # fmt: skip
    return {
        "data": str(data_dir),
        "configs": len(done),
        "samples": samples,
        "time_limit": time_limit,
        "seed": seed,
        "cost": cost,
        "statics": statics,
        "makers": list(makers),
        "summary": summary,
        "against_reasoner": against_reasoner,
        "piles": done,
    }


def plot_unloading(result: dict[str, Any], output: str | os.PathLike[str]) -> None:
    """Boxes moved so far against the share of the detected boxes unloaded, per decision maker."""
    from unstack.plotting import CURVE_STYLES, curve_labels, pyplot, save_figure

    plt = pyplot()
    figure, axis = plt.subplots(figsize=(7, 4.5))
    grid = np.linspace(0.0, 1.0, 21)
    makers = list(result.get("makers", UNLOADING_MAKERS))
    means = []
    for maker in makers:
        curves = []
        for pile in result["piles"]:
            moved = np.cumsum([step["boxes_moved"] for step in pile["runs"][maker]["steps"]])
            share = np.arange(1, len(moved) + 1) / max(len(moved), 1)
            curves.append(np.interp(grid, np.concatenate([[0.0], share]), np.concatenate([[0.0], moved])))
        means.append(np.mean(curves, axis=0))
    # each maker its own marker and line style; a curve equal to an earlier one says so in the legend
    # and is drawn with larger hollow markers, so that neither hides the other
    labels = curve_labels(makers, means)
    for index, (mean, label) in enumerate(zip(means, labels, strict=True)):
        marker, line = CURVE_STYLES[index % len(CURVE_STYLES)]
        hidden = label != makers[index]
        axis.plot(
            100 * grid, mean, marker=marker, linestyle=line, markersize=8 if hidden else 4,
            markerfacecolor="none" if hidden else None, label=label,
        )  # fmt: skip
    axis.set_xlabel("% of the detected boxes unloaded")
    from unstack.sim.settings import DISPLACEMENT_THRESHOLD, ROTATION_THRESHOLD_DEG

    axis.set_ylabel(
        f"boxes moved > {100 * DISPLACEMENT_THRESHOLD:g} cm or {ROTATION_THRESHOLD_DEG:g}° so far (mean over piles)"
    )
    axis.set_title(f"Unloading {result['configs']} piles of {Path(result['data']).name} in the simulator")
    axis.legend()
    figure.tight_layout()
    save_figure(figure, output)
