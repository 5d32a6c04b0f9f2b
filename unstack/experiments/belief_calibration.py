"""How well physics on the belief predicts what a pick moves (issue 34, part 2, route b).

Each pile is emptied as a robot does (:func:`unstack.sim.unloading.unload_container`) by a
fixed behaviour -- highest first, so that the states do not depend on the predictor being
measured. Before every pick, every reachable candidate's removal is tried twice: in the
true pile (:func:`~unstack.sim.unloading.probe_removals`, what it would move) and in the
belief built from what the robot sees (:func:`unstack.sim.belief.belief_removals`, what the
robot expects it to move). Reported: the calibration of the expected against the actual
boxes moved per candidate (:func:`unstack.learning.disturbance.calibration`: Spearman's rank
correlation and means per predicted bin), and what the pick of each rule would have moved
in the same states (highest first, the belief's choice, the look-ahead's).

Examples
--------
>>> pick_summary([{"highest": 2, "belief": 0, "belief_veto": 0, "lookahead": 0},
...               {"highest": 0, "belief": 1, "belief_veto": 0, "lookahead": 0}])
{'states': 2, 'highest': 2, 'belief': 1, 'belief_veto': 0, 'lookahead': 0}
"""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from unstack.experiments.dispatch import run_unordered
from unstack.parameters import COUNT, JOBS, MISSED_SHARE, OPTIONAL_COUNT, SEED, OneOf, validate_params
from unstack.scene import Scene
from unstack.sim.belief import FILLS

__all__ = ["belief_calibration", "pick_summary"]

RULES = ("highest", "belief", "belief_veto", "lookahead")
#: The boxes a belief is built from (:func:`belief_calibration`).
VIEWS = ("candidates", "in_view")


def pick_summary(states: Sequence[dict[str, int]]) -> dict[str, int]:
    """Boxes the pick of each rule would have moved, summed over states."""
    return {"states": len(states), **{rule: int(sum(state[rule] for state in states)) for rule in RULES}}


def _calibrate_pile(path: Path, number: int, options: dict[str, Any]) -> tuple[int, dict[str, Any]]:
    from unstack.geometry import bounding_boxes
    from unstack.scene import load_scene
    from unstack.sim.belief import belief_removals, choose_by_expected_moves
    from unstack.sim.unloading import in_view_scene, unload_container

    scene = load_scene(path)
    pairs: list[tuple[float, int]] = []
    states: list[dict[str, int]] = []

    def policy(current: Scene, outcomes: dict[str, Any]) -> str:
        believed = in_view_scene(current) if options["view"] == "in_view" else current
        expected = belief_removals(
            believed, current.detected, worlds=options["worlds"], seed=options["seed"], fill=options["fill"]
        )
        resting = {box_id: float(bounding_boxes([current.box(box_id)])[0, 2]) for box_id in current.detected}

        highest = max(current.detected, key=lambda box_id: (resting[box_id], box_id))
        means = {box_id: expected[box_id].expected_moved for box_id in current.detected}
        picks = {
            "highest": highest,
            "belief": choose_by_expected_moves(means, resting, "fewest"),
            "belief_veto": choose_by_expected_moves(means, resting, "veto"),
            "lookahead": choose_by_expected_moves(
                {box_id: float(outcomes[box_id].boxes_moved) for box_id in current.detected}, resting, "fewest"
            ),
        }
        pairs.extend((expected[box_id].expected_moved, outcomes[box_id].boxes_moved) for box_id in current.detected)
        states.append({rule: outcomes[box_id].boxes_moved for rule, box_id in picks.items()})
        return highest

    unload_container(
        scene, policy, detector_misses=options["detector_misses"], seed=options["seed"] + number, probe=True,
        max_picks=options["max_picks"],
    )  # fmt: skip
    return number, {"scene": path.name, "pairs": pairs, "states": states}


@validate_params({
    "piles": COUNT, "detector_misses": MISSED_SHARE, "worlds": OPTIONAL_COUNT, "max_picks": OPTIONAL_COUNT,
    "seed": SEED, "n_jobs": JOBS, "fill": OneOf(FILLS), "view": OneOf(VIEWS),
})  # fmt: skip
def belief_calibration(
    data_dir: str | os.PathLike[str],
    *,
    piles: int = 2,
    detector_misses: float = 0.0,
    worlds: int | None = None,
    max_picks: int | None = None,
    seed: int = 0,
    fill: str = "cloud",
    view: str = "candidates",
    n_jobs: int = 1,
    client: Any = None,
    progress: Callable[[int, int], None] | None = None,
) -> dict[str, Any]:
    """Expected against actual boxes moved per candidate, on the first ``piles`` piles.

    Parameters
    ----------
    data_dir : path-like
        A simulated data set (``unstack simulate``).
    piles : int
    detector_misses : float
        Share of the reachable boxes the detector misses at each scan.
    worlds : int, optional
        Belief worlds per decision (default :data:`~unstack.sim.belief.BELIEF_WORLDS`).
    max_picks : int, optional
        Stop each pile after this many picks.
    seed : int
    fill : {"cloud", "occlusion"}
        What the belief puts where no box is seen (:data:`~unstack.sim.belief.FILLS`).
    view : {"candidates", "in_view"}
        The boxes put in the belief: the reachable candidates, or every box the detector
        reports (:data:`~unstack.sim.unloading.IN_VIEW`); the candidates are tried either way.
    n_jobs, client
        Piles in parallel processes, or on a dask.distributed cluster.

    Returns
    -------
    dict
        ``calibration`` (Spearman, bins), ``picks`` (boxes the pick of each rule would have
        moved, summed over the states) and per pile the same.
    """
    from unstack.dataset_folders import first_configurations
    from unstack.learning.disturbance import calibration
    from unstack.sim.belief import BELIEF_WORLDS

    files = first_configurations(data_dir, piles)
    options = {"detector_misses": detector_misses, "worlds": BELIEF_WORLDS if worlds is None else worlds,
               "max_picks": max_picks, "seed": seed, "fill": fill, "view": view}  # fmt: skip
    results: list[dict[str, Any] | None] = [None] * len(files)
    if progress is not None:
        progress(0, len(files))
    tasks = [(path, number, options) for number, path in enumerate(files)]
    for number, result in run_unordered(_calibrate_pile, tasks, n_jobs=n_jobs, client=client):
        results[number] = result
        if progress is not None:
            progress(sum(item is not None for item in results), len(files))
    done = [result for result in results if result is not None]
    pairs = np.array([pair for result in done for pair in result["pairs"]], dtype=np.float64).reshape(-1, 2)
    return {
        "data": str(data_dir),
        "piles": len(done),
        **options,
        "calibration": calibration(pairs[:, 0], pairs[:, 1]),
        "picks": pick_summary([state for result in done for state in result["states"]]),
        "per_pile": [{"scene": result["scene"], **pick_summary(result["states"])} for result in done],
    }
