"""What every pick would move: closed-loop unloading with a physics probe of every candidate.

The training data of the pick-disturbance model (:mod:`unstack.learning.disturbance`). Each
pile of a simulated data set is emptied as a robot does (:func:`unstack.sim.unloading.
unload_container`: scan, detect, reach), and before every pick *every* reachable candidate's
removal is tried in the engine and undone (:func:`unstack.sim.unloading.probe_removals`), so
each visited state yields one labelled example per candidate: which boxes its removal moves
more than 2 cm. A state is saved whole -- the boxes with their poses, the point cloud, the
candidates and every candidate's outcome -- so that the robot's-view features
(:mod:`unstack.learning.pick_features`) can be computed again without the engine.

Which candidate is then taken (the behaviour) is, by default (``"mixed"``), drawn per step,
seeded: the one the probe says moves least (ties to the box resting highest) with probability
:data:`BEHAVIOUR_SHARES` ``["lookahead"]``, the highest box, or a random one -- so the states
cover both calm piles and piles a poorer policy leaves behind. A closed-loop decision maker
named as the behaviour (:data:`~unstack.experiments.container.CONTAINER_MAKERS`) takes every
pick instead: the states are those that policy itself reaches, as DAgger collects them for a
policy learned from states another behaviour reached.

Examples
--------
>>> behaviour_pick({"a": 0, "b": 2}, {"a": 0.1, "b": 0.9}, 0.1)
'a'
>>> behaviour_pick({"a": 0, "b": 2}, {"a": 0.1, "b": 0.9}, 0.6)
'b'
"""

from __future__ import annotations

import json
import os
from collections.abc import Callable, Iterator, Mapping
from pathlib import Path
from typing import Any

import numpy as np

from unstack.experiments.dispatch import run_unordered
from unstack.parameters import COUNT, JOBS, OPTIONAL_COUNT, SEED, OneOf, validate_params
from unstack.scene import Scene

__all__ = [
    "BEHAVIOURS",
    "BEHAVIOUR_SHARES",
    "STATE_FORMAT",
    "VIEWS",
    "behaviour_pick",
    "collect_pick_responses",
    "collected_piles",
    "load_states",
    "pick_table",
    "state_rows",
]

#: Format tag of a saved state (an ``.npz`` file with a JSON header).
STATE_FORMAT = "unstack.pick-state/1"
#: Shares of the behaviours that choose the pick taken after the probe (they sum to 1).
BEHAVIOUR_SHARES = {"lookahead": 0.5, "highest": 0.3, "random": 0.2}


def _behaviours() -> tuple[str, ...]:
    from unstack.experiments.container import CONTAINER_MAKERS, ORACLE_MAKERS

    return ("mixed", *(maker for maker in CONTAINER_MAKERS if maker not in ORACLE_MAKERS))


#: What may take the picks of a collection: ``"mixed"`` (:func:`behaviour_pick`'s draw) or a
#: closed-loop decision maker that reads only what the robot sees (no oracle).
BEHAVIOURS = _behaviours()


def behaviour_pick(moved: Mapping[str, int], resting: Mapping[str, float], draw: float, order: int = 0) -> str:
    """The pick of the behaviour that ``draw`` (uniform in [0, 1)) selects.

    ``moved``: boxes each candidate's removal moves (the probe); ``resting``: each candidate's
    lowest point. ``order`` picks the random candidate (an integer drawn beside ``draw``).
    """
    candidates = sorted(moved)
    if draw < BEHAVIOUR_SHARES["lookahead"]:
        return min(candidates, key=lambda box_id: (moved[box_id], -resting[box_id], box_id))
    if draw < BEHAVIOUR_SHARES["lookahead"] + BEHAVIOUR_SHARES["highest"]:
        return max(candidates, key=lambda box_id: (resting[box_id], box_id))
    return candidates[order % len(candidates)]


def _state_payload(current: Scene, outcomes: Mapping[str, Any], pile: str, step: int) -> dict[str, Any]:
    boxes = current.boxes
    header = {
        "format": STATE_FORMAT,
        "pile": pile,
        "step": step,
        "ids": [box.id for box in boxes],
        "candidates": list(current.detected),
        "moved": {box_id: list(outcome.moved) for box_id, outcome in outcomes.items()},
        "fallen": {box_id: list(outcome.fallen) for box_id, outcome in outcomes.items()},
    }
    return {
        "header": np.array(json.dumps(header)),
        "sizes": np.array([box.size for box in boxes]),
        "positions": np.array([box.position for box in boxes]),
        "orientations": np.array([box.orientation_xyzw for box in boxes]),
        "masses": np.array([np.nan if box.mass is None else box.mass for box in boxes]),
        "points": current.points.astype(np.float32),
    }


def _load_state(path: Path) -> tuple[dict[str, Any], Scene]:
    """One saved state: its header and the scene (every box in place, the cloud, the
    reachable candidates as ``detected``)."""
    from unstack.scene import Box

    with np.load(path) as data:
        header = json.loads(str(data["header"]))
        boxes = [
            Box(box_id, size, position, orientation, mass=None if np.isnan(mass) else float(mass))
            for box_id, size, position, orientation, mass in zip(
                header["ids"], data["sizes"], data["positions"], data["orientations"], data["masses"], strict=True
            )
        ]
        points = data["points"].astype(np.float64)
    source = f"{path.parent.parent.name}/{path.parent.name}/{path.name}"
    return header, Scene(boxes, points, header["candidates"], source=source)


def load_states(folder: str | os.PathLike[str]) -> Iterator[tuple[dict[str, Any], Scene]]:
    """Every saved state of a collection (``DATA-SET/PILE/step-NNN.npz``), or of one pile's
    folder in it, in order, as ``(header, scene)``."""
    paths = sorted(Path(folder).glob("step-*.npz")) or sorted(Path(folder).glob("*/*/step-*.npz"))
    for path in paths:
        yield _load_state(path)


def _maker(behaviour: str, model: Any, disturbance: Any, seed: int) -> Callable[..., str] | None:
    """The decision maker that takes every pick, or None for the ``"mixed"`` draw."""
    if behaviour == "mixed":
        return None
    from unstack.experiments.container import PROBING_MAKERS, container_policies
    from unstack.learning.model_file import default_model_path, load_model

    if model is None:
        model = load_model(default_model_path())
    maker = container_policies(model, seed=seed, makers=[behaviour], disturbance=disturbance)[behaviour]
    if behaviour in PROBING_MAKERS:
        return maker
    return lambda current, _outcomes: maker(current)


#: The ``behaviour`` of :func:`_collect_pile` when the picks are drawn.
_MIXED = ("mixed", None, None)


def _pile_key(
    path: Path, seed: int, max_picks: int | None, behaviour: str, model: Any, disturbance: Any
) -> dict[str, Any]:
    """What a pile's states depend on: the scene with its cloud, the seed, the picks allowed, the
    behaviour and (for a decision maker) its models."""
    from unstack.dataset_folders import scene_digest
    from unstack.experiments.outputs import file_digest, model_digest

    key: dict[str, Any] = {"scene_sha256": scene_digest(path), "seed": seed, "max_picks": max_picks,
                           "behaviour": behaviour}  # fmt: skip
    if behaviour != "mixed":
        for name, given in (("model", model), ("disturbance", disturbance)):
            if hasattr(given, "metadata") and hasattr(given, "features"):
                key[name] = model_digest(given)
            elif given is not None:
                source = Path(str(getattr(given, "source", given)))
                key[name] = file_digest(source) if source.is_file() else str(source)
    return key


def _finished(done: Path, key: dict[str, Any]) -> dict[str, Any] | None:
    """A pile's summary when its states were collected with the same key, else None."""
    try:
        summary = json.loads(done.read_text())
    except (OSError, ValueError):
        return None
    return summary if isinstance(summary, dict) and summary.get("key") == json.loads(json.dumps(key)) else None


def _collect_pile(
    path: Path,
    number: int,
    out: Path,
    seed: int,
    max_picks: int | None,
    behaviour: tuple[str, Any, Any] = _MIXED,
    key: dict[str, Any] | None = None,
) -> tuple[int, dict[str, Any]]:
    """Empty one pile with the probe, saving every state; the run's summary (with ``key``, what
    the states depend on) comes back. ``behaviour``: its name, the support model and the
    disturbance model of a decision maker. States an earlier run left in the pile's folder are
    removed first."""
    from unstack.atomic import atomic_write_bytes, atomic_write_text
    from unstack.geometry import bounding_boxes
    from unstack.scene import load_scene
    from unstack.sim.unloading import unload_container

    scene = load_scene(path)
    folder = out / path.stem
    folder.mkdir(parents=True, exist_ok=True)
    for left in [*folder.glob("step-*.npz"), folder / "done.json"]:  # another run's, or an interrupted one's
        left.unlink(missing_ok=True)
    rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(number,)))
    steps = [0]
    maker = _maker(*behaviour, seed)

    def policy(current: Scene, outcomes: Mapping[str, Any]) -> str:
        import io

        buffer = io.BytesIO()
        np.savez_compressed(buffer, **_state_payload(current, outcomes, path.stem, steps[0]))
        atomic_write_bytes(folder / f"step-{steps[0]:03d}.npz", buffer.getvalue())
        steps[0] += 1
        if maker is not None:
            return maker(current, outcomes)
        bounds = bounding_boxes([current.box(box_id) for box_id in current.detected])
        resting = {box_id: float(bounds[k, 2]) for k, box_id in enumerate(current.detected)}
        moved = {box_id: outcome.boxes_moved for box_id, outcome in outcomes.items()}
        return behaviour_pick(moved, resting, float(rng.random()), int(rng.integers(1 << 30)))

    run = unload_container(scene, policy, seed=seed + number, max_picks=max_picks, probe=True)
    summary = {"scene": path.name, "boxes": len(scene.boxes), "states": steps[0], "boxes_moved": run.boxes_moved,
               "stopped": run.stopped}  # fmt: skip
    if maker is not None:
        summary["behaviour"] = behaviour[0]
    if key is not None:
        summary["key"] = key
    atomic_write_text(folder / "done.json", json.dumps(summary) + "\n")
    return number, summary


@validate_params(
    {
        "piles": OPTIONAL_COUNT,
        "seed": SEED,
        "max_picks": OPTIONAL_COUNT,
        "n_jobs": JOBS,
        "behaviour": OneOf(BEHAVIOURS),
    }
)
def collect_pick_responses(
    data_dirs: list[str | os.PathLike[str]],
    out: str | os.PathLike[str],
    *,
    piles: int | None = None,
    seed: int = 0,
    max_picks: int | None = None,
    behaviour: str = "mixed",
    model: Any = None,
    disturbance: Any = None,
    n_jobs: int = 1,
    client: Any = None,
    progress: Callable[[int, int], None] | None = None,
) -> list[dict[str, Any]]:
    """Empty the piles of ``data_dirs`` with the probe and save every state under ``out``.

    Parameters
    ----------
    data_dirs : list of path-like
        Simulated data sets (``unstack simulate``); the first ``piles`` of each are used.
    out : path-like
        Folder of the collection: ``DATA-SET/PILE/step-NNN.npz``, one file per state
        (:func:`load_states` reads them). Piles already finished are skipped (resumable).
    seed : int
        Seeds the scans and the behaviour, pile by pile.
    max_picks : int, optional
        Stop each pile after this many picks.
    behaviour : str
        What takes the picks (:data:`BEHAVIOURS`): ``"mixed"``, the seeded draw of
        :func:`behaviour_pick`, or a closed-loop decision maker (the states it reaches itself).
    model, disturbance
        The support model and the disturbance model (a file or a fitted model; None: the
        shipped one) of a decision maker taking the picks; ``"mixed"`` reads neither.
    n_jobs, client
        Piles in parallel processes, or on a dask.distributed cluster.

    Returns
    -------
    list of dict
        Per pile: scene, boxes, states saved, boxes moved by the behaviour, why it stopped
        (and the behaviour, when a decision maker took the picks).
    """
    from unstack.dataset_folders import first_configurations
    from unstack.errors import InvalidArgument
    from unstack.experiments.outputs import checkpoint_folder

    names = [Path(data_dir).resolve().name for data_dir in data_dirs]
    named_twice = sorted({name for name in names if names.count(name) > 1})
    if named_twice:  # each data set's states go to a sub-folder of its name
        raise InvalidArgument(
            f"two data sets are both named {named_twice[0]!r}: their states would share one folder under {out}; "
            "give one of them another folder name (or run them into two collections)"
        )
    if behaviour == "mixed":
        import warnings

        for given, what in ((model, "the support model"), (disturbance, "the disturbance model")):
            if given is not None:
                warnings.warn(f"{what} is not used: the picks are drawn (behaviour 'mixed')", stacklevel=2)
        model = disturbance = None
    files: list[Path] = []
    for data_dir in data_dirs:
        files += first_configurations(data_dir, piles)
    with checkpoint_folder(out) as held:
        assert held is not None
        return _collect_into(held, files, seed, max_picks, behaviour, model, disturbance, n_jobs, client, progress)


def _collect_into(
    folder: Path,
    files: list[Path],
    seed: int,
    max_picks: int | None,
    behaviour: str,
    model: Any,
    disturbance: Any,
    n_jobs: int,
    client: Any,
    progress: Callable[[int, int], None] | None,
) -> list[dict[str, Any]]:
    """:func:`collect_pick_responses`'s work in a collection folder it holds."""
    tasks = []
    summaries: list[dict[str, Any] | None] = [None] * len(files)
    for number, path in enumerate(files):
        pile_folder = folder / Path(path).parent.name  # one sub-folder per data set, one below it per pile
        key = _pile_key(path, seed, max_picks, behaviour, model, disturbance)
        finished = _finished(pile_folder / path.stem / "done.json", key)
        if finished is not None:
            summaries[number] = finished
        else:
            tasks.append((path, number, pile_folder, seed, max_picks, (behaviour, model, disturbance), key))
    if progress is not None:
        progress(len(files) - len(tasks), len(files))
    for number, summary in run_unordered(_collect_pile, tasks, n_jobs=n_jobs, client=client):
        summaries[number] = summary
        if progress is not None:
            progress(sum(item is not None for item in summaries), len(files))
    return [summary for summary in summaries if summary is not None]


#: The detector views a state is seen through: every reachable box detected, or a detector
#: that misses each with this probability (at least one found), as ``--detector-misses``.
VIEWS = {"full": 0.0, "missed": 0.5}


def _view_candidates(candidates: list[str], share: float, seed: np.random.SeedSequence) -> list[str]:
    if not share:
        return candidates
    from unstack.sim.unloading import detector_misses_draw

    return detector_misses_draw(candidates, share, seed)


def state_rows(
    header: dict[str, Any], scene: Scene, model: Any, *, view: str, seed: int, samples: int
) -> dict[str, Any]:
    """The pick features of one state seen through ``view`` (:data:`VIEWS`), with every
    candidate's outcome and the reasoner's expected costs."""
    from unstack.learning.pick_features import pick_features
    from unstack.moves import MOVES_EXACT_MAX_BOXES
    from unstack.pipeline import scene_support_probabilities
    from unstack.reasoner.decision import decide

    draw = np.random.SeedSequence(seed, spawn_key=(int(header["step"]), len(header["ids"])))
    detected = _view_candidates(list(header["candidates"]), VIEWS[view], draw)
    seen = Scene(scene.boxes, scene.points, detected, source=scene.source)
    supports = scene_support_probabilities(seen, model)
    decision = decide(supports, cost="load", samples=samples, seed=seed, max_boxes=MOVES_EXACT_MAX_BOXES)
    return {
        "features": pick_features(seen, supports, decision.marginals, decision.expected_costs),
        "moved": np.array([len(header["moved"][box_id]) for box_id in supports.objects]),
        "candidates": list(supports.objects),
        "default_choice": decision.choice,
        "resting": np.asarray(supports.heights),
    }


def collected_piles(states: str | os.PathLike[str]) -> list[Path]:
    """The piles of a collection whose states are all written (``DATA-SET/PILE/done.json``), in order."""
    return sorted(path.parent for path in Path(states).glob("*/*/done.json"))


@validate_params({"seed": SEED, "samples": COUNT, "n_jobs": JOBS})
def pick_table(
    states: str | os.PathLike[str],
    model: Any,
    *,
    views: tuple[str, ...] = tuple(VIEWS),
    seed: int = 0,
    samples: int = 1536,
    n_jobs: int = 1,
    progress: Callable[[int, int], None] | None = None,
) -> list[dict[str, Any]]:
    """Every saved state of a collection through every view: one record per (state, view)
    with the features, outcomes and candidates (:func:`state_rows`), pile by pile."""
    folders = collected_piles(states)
    records: list[dict[str, Any]] = []
    tasks = [(folder, model, views, seed, samples) for folder in folders]
    for done, rows in enumerate(run_unordered(_pile_table_task, tasks, n_jobs=n_jobs), start=1):
        records += rows
        if progress is not None:
            progress(done, len(tasks))
    return sorted(records, key=lambda record: (record["state"], record["view"]))


def _pile_table_task(folder: Path, model: Any, views: tuple[str, ...], seed: int, samples: int) -> list[dict[str, Any]]:
    rows = []
    for path in sorted(folder.glob("step-*.npz")):
        header, scene = _load_state(path)
        for view in views:
            record = state_rows(header, scene, model, view=view, seed=seed, samples=samples)
            record.update(view=view, state=scene.source, pile=f"{folder.parent.name}/{folder.name}")
            rows.append(record)
    return rows
