"""Executing an unloading order in the simulator, box by box, and measuring the disturbance.

The simulated scene holds the settled pile (poses, sizes, masses) and the settings it was
made with. The pile is rebuilt in a fresh physics world (door open), left to settle for a
moment (the drift of this re-settling is reported: a rebuilt pile is not bit-identical to the
original), and then the boxes of the order are taken out one at a time. After each removal
the world runs for the ground truth's horizon and every box still in place is measured
against where it was before that removal: how many moved more than 2 cm (or turned more than
5 degrees, the ground truth's thresholds) and by how much in total. The world is not reset
between removals: each step starts from what the previous ones left, as for a robot.

Examples
--------
>>> step = UnloadStep("b03", ("b07",), 0.031, 0.031)
>>> step.boxes_moved
1
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from unstack.errors import UnstackError
from unstack.scene import Scene

__all__ = [
    "IN_VIEW",
    "LOST_BELOW_FLOOR",
    "REACH_RULES",
    "UnloadRun",
    "UnloadStep",
    "detector_misses_draw",
    "execute_policy",
    "execute_unloading",
    "fallen_boxes",
    "in_view_scene",
    "probe_removals",
    "reachable_boxes",
    "rebuilt_removals",
    "unload_container",
]

#: Seconds of simulation to let a rebuilt pile find its contacts before the first removal.
RESETTLE_SECONDS = 0.5
#: Which detected boxes a gripper can take (:func:`reachable_boxes`): ``door`` -- a box whose
#: door-facing side or top is at most half covered by another box; ``any`` -- every detected box.
REACH_RULES = ("door", "any")
#: Key of the policy's scene metadata listing every box the detector reports at this scan,
#: reachable or not (the candidates are the reachable ones of these).
IN_VIEW = "in_view"
#: Share of a face another box may cover before the face is blocked.
BLOCKED_SHARE = 0.5
#: How close (metres) a box must come to a face to cover it.
COVER_GAP = 0.03
#: A box has fallen when a removal drops it more than this (metres) ...
FALL_DROP = 0.2
#: ... or tips it more than this (degrees between its old and new vertical axis).
FALL_TILT_DEG = 45.0
#: A box whose centre is this far below the container floor (z = 0) has left the container --
#: fallen out of the open door side or, rarely, through the floor in the physics engine: it
#: is no longer part of the pile (not scanned into a scene, not a candidate, not watched).
LOST_BELOW_FLOOR = 1.0


@dataclass(frozen=True)
class UnloadStep:
    """One removal: the box taken out and what it did to the boxes still in place."""

    box: str
    moved: tuple[str, ...]
    displacement_m: float
    max_displacement_m: float
    fallen: tuple[str, ...] = ()
    lost: tuple[str, ...] = ()  # boxes that left the container in this step (also in ``fallen``)

    @property
    def boxes_moved(self) -> int:
        """Boxes that moved more than the threshold."""
        return len(self.moved)

    def to_dict(self) -> dict[str, Any]:
        return {
            "box": self.box,
            "moved": list(self.moved),
            "boxes_moved": self.boxes_moved,
            "displacement_m": self.displacement_m,
            "max_displacement_m": self.max_displacement_m,
            "fallen": list(self.fallen),
            "lost": list(self.lost),
        }


@dataclass(frozen=True)
class UnloadRun:
    """An executed order: its steps and the drift of the rebuilt pile before the first step."""

    order: tuple[str, ...]
    steps: tuple[UnloadStep, ...]
    resettle_drift_m: float
    stopped: str = "order done"

    @property
    def boxes_moved(self) -> int:
        """Boxes moved over all steps (a box moved twice counts twice)."""
        return sum(step.boxes_moved for step in self.steps)

    @property
    def displacement_m(self) -> float:
        return float(sum(step.displacement_m for step in self.steps))

    def to_dict(self) -> dict[str, Any]:
        return {
            "order": list(self.order),
            "boxes_moved": self.boxes_moved,
            "displacement_m": self.displacement_m,
            "resettle_drift_m": self.resettle_drift_m,
            "stopped": self.stopped,
            "steps": [step.to_dict() for step in self.steps],
        }


def _scene_settings(scene: Scene) -> Any:
    from unstack.sim.settings import scene_settings

    settings = scene_settings(scene)
    if settings is None:
        raise UnstackError(f"{scene.source}: $.metadata.settings: executing an order needs a simulated scene")
    return settings


def execute_unloading(scene: Scene, order: Sequence[str]) -> UnloadRun:
    """Take the boxes of ``order`` out of the scene's pile in turn and measure each step.

    Parameters
    ----------
    scene : Scene
        A simulated scene (``unstack simulate``): its settings and settled poses are used.
    order : sequence of str
        Box ids, each at most once.

    Returns
    -------
    UnloadRun
    """
    unknown = [box_id for box_id in order if box_id not in scene.box_ids]
    if unknown or len(set(order)) != len(order):
        raise UnstackError(f"{scene.source}: the order names unknown or repeated boxes: {unknown or list(order)}")
    pending = list(order)

    def next_in_order(_number: int, _world: Any, in_place: list[str]) -> str | None:
        while pending and pending[0] not in in_place:  # a box of the order that left the container
            pending.pop(0)
        return pending.pop(0) if pending else None

    return _execute(scene, next_in_order)


def execute_policy(scene: Scene, policy: Callable[[Scene], str], boxes: Sequence[str]) -> UnloadRun:
    """Unload ``boxes`` in a closed loop: before each pick, sense the pile again and ask ``policy``.

    Before every removal the scene is rebuilt from the world as it is then: the poses of the
    boxes still in place, a new point cloud from the scene's sensor, and as ``detected`` the
    boxes of ``boxes`` not yet taken (the robot keeps track of what it detected). ``policy``
    returns one of them. This is how a robot would run (the open-loop
    :func:`execute_unloading` executes an order planned on the untouched pile).

    Parameters
    ----------
    scene : Scene
        A simulated scene.
    policy : callable
        ``policy(current_scene) -> box id`` among ``current_scene.detected``.
    boxes : sequence of str
        The boxes to unload (typically the scene's detected boxes).
    """
    from unstack.sim.sensor import scan_pile

    settings = _scene_settings(scene)
    remaining = list(boxes)

    def sense_and_pick(number: int, world: Any, in_place: list[str]) -> str | None:
        remaining[:] = [box_id for box_id in remaining if box_id in in_place]  # not those that left the container
        if not remaining:
            return None
        current_boxes = _boxes_in_place(scene, world, in_place)
        scan = scan_pile(world, settings.sensor, seed=number)
        current = Scene(current_boxes, scan.points, remaining, metadata=scene.metadata, source=scene.source)
        choice = policy(current)
        if choice not in remaining:
            raise UnstackError(f"{scene.source}: the policy picked {choice!r}, not one of the boxes left to unload")
        remaining.remove(choice)
        return choice

    return _execute(scene, sense_and_pick)


def reachable_boxes(boxes: Sequence[Any], candidates: Sequence[str], rule: str = "door") -> list[str]:
    """The ``candidates`` a gripper at the door can take, by ``rule`` (:data:`REACH_RULES`).

    ``door``: a box is reachable when its door-facing side (the face towards -x) or its top
    is at most :data:`BLOCKED_SHARE` covered by the axis-aligned bounding box of another box
    within :data:`COVER_GAP` of that face. ``any``: every candidate.

    Examples
    --------
    >>> from unstack.scene import Box
    >>> front = Box("front", [0.4, 0.4, 0.4], [0.2, 0.0, 0.2])
    >>> behind = Box("behind", [0.4, 0.4, 0.4], [0.6, 0.0, 0.2])
    >>> on_top = Box("on_top", [0.4, 0.4, 0.4], [0.6, 0.0, 0.6])
    >>> reachable_boxes([front, behind, on_top], ["front", "behind", "on_top"])
    ['front', 'on_top']
    """
    from unstack.geometry import bounding_boxes

    if rule not in REACH_RULES:
        raise UnstackError(f"unknown reach rule {rule!r}; expected one of {', '.join(REACH_RULES)}")
    if rule == "any":
        return list(candidates)
    ids = [box.id for box in boxes]
    bounds = bounding_boxes(list(boxes))

    def covered(i: int, normal: int, across: tuple[int, int], towards: int) -> bool:
        """Whether another box covers face ``normal`` of box i (towards -1: its low side, +1: high)."""
        face = bounds[i]
        area = np.prod([face[3 + a] - face[a] for a in across])
        for j in range(len(boxes)):
            if j == i:
                continue
            other = bounds[j]
            gap = face[normal] - other[3 + normal] if towards < 0 else other[normal] - face[3 + normal]
            if gap > COVER_GAP or gap < -0.5 * (face[3 + normal] - face[normal]):
                continue
            overlap = np.prod([max(0.0, min(face[3 + a], other[3 + a]) - max(face[a], other[a])) for a in across])
            if overlap > BLOCKED_SHARE * area:
                return True
        return False

    result = []
    for box_id in candidates:
        i = ids.index(box_id)
        front_free = not covered(i, 0, (1, 2), -1)
        top_free = not covered(i, 2, (0, 1), +1)
        if front_free or top_free:
            result.append(box_id)
    return result


def detector_misses_draw(candidates: list[str], share: float, seed: np.random.SeedSequence) -> list[str]:
    """The candidates a detector that misses ``share`` of the boxes finds (at least one)."""
    rng = np.random.default_rng(seed)
    while True:
        found = [box_id for box_id in candidates if rng.random() >= share]
        if found:
            return found


def unload_container(
    scene: Scene,
    policy: Callable[..., str],
    *,
    detector_noise: float = 0.0,
    detector_misses: float = 0.0,
    reach: str = "door",
    max_picks: int | None = None,
    seed: int = 0,
    probe: bool = False,
) -> UnloadRun:
    """Unload the container as a robot does: scan, detect, pick, and again, until it is empty.

    Before every pick the sensor of the scene scans the pile as it is then, and the detected
    boxes are found again by the rule of the data sets: a box is detected when the sensor sees
    at least ``sensor.min_pixels`` of it. A box hidden behind others is detected once the boxes
    in front are gone. The detected boxes the gripper can reach (:func:`reachable_boxes`) are
    the candidates; ``policy`` gets a scene whose ``detected`` are those candidates, with the
    poses a detector reports (:func:`unstack.understanding.detector.detector_poses` with ``detector_noise``
    metres; 0 gives the true poses), the point cloud of the scan, and in its metadata under
    :data:`IN_VIEW` every box the detector reports (reachable or not, the missed ones left
    out). The run stops when the
    container is empty, after ``max_picks`` picks, or when no box is both detected and
    reachable (:attr:`UnloadRun.stopped` says which).

    Parameters
    ----------
    scene : Scene
        A simulated scene (``unstack simulate``).
    policy : callable
        ``policy(current_scene) -> box id`` among ``current_scene.detected``.
    detector_noise : float
        Position error of the detector (metres; yaw errors follow, see :mod:`unstack.understanding.detector`).
    detector_misses : float
        Share of the seen boxes the detector misses, drawn box by box at every scan (a real
        detector's misses: only the cloud shows such a box). When every reachable box was
        missed the draw is made again, as a robot would scan again.
    reach : {"door", "any"}
    max_picks : int, optional
    seed : int
        Seeds the scans' depth noise and the detector errors, step by step.
    probe : bool
        Before every pick, try each candidate's removal in the engine (:func:`probe_removals`,
        the true pile) and call ``policy(current_scene, outcomes)`` with what each would move:
        the physics look-ahead, and the source of the pick-disturbance training data.

    Returns
    -------
    UnloadRun
    """
    from unstack.sim.progress import pick_progress
    from unstack.sim.sensor import scan_pile
    from unstack.understanding.detector import detector_poses

    if reach not in REACH_RULES:
        raise UnstackError(f"unknown reach rule {reach!r}; expected one of {', '.join(REACH_RULES)}")
    if not (detector_noise >= 0 and np.isfinite(detector_noise)):
        raise UnstackError(f"detector_noise must be a finite number of metres >= 0, got {detector_noise}")
    if not (0.0 <= detector_misses < 1.0):
        raise UnstackError(f"detector_misses must be a share in [0, 1), got {detector_misses}")
    if max_picks is not None and max_picks < 0:
        raise UnstackError(f"max_picks must be at least 0, got {max_picks}")
    settings = _scene_settings(scene)
    limit = len(scene.boxes) if max_picks is None else min(max_picks, len(scene.boxes))
    stopped = ["container empty" if limit == len(scene.boxes) else "pick limit"]
    watch = pick_progress()

    def sense_and_pick(number: int, world: Any, in_place: list[str]) -> str | None:
        if watch is not None:
            watch.pick(number, len(in_place))
        if number >= limit or not in_place:
            return None
        true_boxes = _boxes_in_place(scene, world, in_place)
        step_seed = np.random.SeedSequence(seed, spawn_key=(number,))
        scan = scan_pile(world, settings.sensor, seed=step_seed)
        seen = {scene.box_ids[k] for k in np.flatnonzero(scan.pixel_counts >= settings.sensor.min_pixels)}
        detected = [box_id for box_id in in_place if box_id in seen]
        candidates = reachable_boxes(true_boxes, detected, reach)
        if not candidates:
            stopped[0] = "nothing detected and reachable"
            return None
        missed: set[str] = set()
        if detector_misses:
            misses_seed = np.random.SeedSequence(seed, spawn_key=(number, 1))
            kept = detector_misses_draw(candidates, detector_misses, misses_seed)
            missed, candidates = set(candidates) - set(kept), kept
        reported = (
            detector_poses(true_boxes, detector_noise, np.random.default_rng(step_seed))
            if detector_noise
            else true_boxes
        )
        in_view = [box_id for box_id in detected if box_id not in missed]  # what the detector reports
        metadata = {**scene.metadata, IN_VIEW: in_view}
        current = Scene(reported, scan.points, candidates, metadata=metadata, source=scene.source)
        if probe:
            choice = policy(current, probe_removals(scene, world, in_place, candidates, number))
        else:
            choice = policy(current)
        if choice not in candidates:
            raise UnstackError(f"{scene.source}: the policy picked {choice!r}, not one of the reachable detected boxes")
        return choice

    run = _execute(scene, sense_and_pick)
    return UnloadRun(run.order, run.steps, run.resettle_drift_m, stopped[0])


def in_view_scene(current: Scene) -> Scene:
    """A policy's scene with every box the detector reports (:data:`IN_VIEW`) as its detected boxes.

    :func:`unload_container` hands its policies the reachable candidates as ``detected`` and
    lists every reported box under :data:`IN_VIEW`; a belief built from everything in view
    takes this scene (in the scene's box order) and tries the original candidates.

    Examples
    --------
    >>> from unstack.scene import Box
    >>> boxes = [Box("low", [0.4, 0.4, 0.3], [1.0, 0.0, 0.15]), Box("top", [0.4, 0.4, 0.3], [1.0, 0.0, 0.45])]
    >>> current = Scene(boxes, np.zeros((0, 3)), ["top"], metadata={IN_VIEW: ["low", "top"]})
    >>> in_view_scene(current).detected
    ('low', 'top')
    """
    import dataclasses

    in_view = set(current.metadata.get(IN_VIEW, ())) | set(current.detected)
    return dataclasses.replace(current, detected=tuple(box_id for box_id in current.box_ids if box_id in in_view))


def _boxes_in_place(scene: Scene, world: Any, in_place: list[str]) -> list[Any]:
    """The scene's boxes still in place, at their poses in ``world`` now."""
    from unstack.scene import Box

    positions, orientations = world.poses([world.boxes[scene.box_ids.index(box_id)] for box_id in in_place])
    unit = orientations / np.linalg.norm(orientations, axis=1, keepdims=True)
    return [
        Box(box_id, scene.box(box_id).size, position, orientation, mass=scene.box(box_id).mass)
        for box_id, position, orientation in zip(in_place, positions, unit, strict=True)
    ]


def _execute(scene: Scene, next_box: Callable[[int, Any, list[str]], str | None]) -> UnloadRun:
    """Rebuild the pile, then take out ``next_box(step, world, in_place)`` and measure, until it says None.

    Boxes that leave the container (:data:`LOST_BELOW_FLOOR`) leave ``in_place`` with the step
    that lost them (``UnloadStep.lost``).
    """
    from unstack.sim.world import PhysicsWorld

    settings = _scene_settings(scene)
    truth = settings.ground_truth
    with PhysicsWorld(settings, door=False) as world:
        bodies = {}
        for box in scene.boxes:
            mass = box.mass if box.mass is not None else float(np.mean(settings.pile.mass_range))
            bodies[box.id] = world.add_box(box.size, box.position, box.orientation_xyzw, mass=mass)
        start, _ = world.poses()
        world.step(RESETTLE_SECONDS)
        settled, _ = world.poses()
        drift = float(np.max(np.linalg.norm(settled - start, axis=1), initial=0.0))
        in_place = [box_id for box_id, z in zip(scene.box_ids, settled[:, 2], strict=True) if z >= -LOST_BELOW_FLOOR]
        steps = []
        order = []
        for number in itertools.count():
            box_id = next_box(number, world, list(in_place))
            if box_id is None:
                break
            order.append(box_id)
            in_place.remove(box_id)
            step = _remove_and_measure(world, bodies, in_place, box_id, number, truth)
            steps.append(step)
            in_place = [other for other in in_place if other not in step.lost]
    return UnloadRun(tuple(order), tuple(steps), drift)


def _remove_and_measure(
    world: Any, bodies: dict[str, int], in_place: list[str], box_id: str, number: int, truth: Any
) -> UnloadStep:
    """Take ``box_id`` out of ``world`` (parked in slot ``number``), run the horizon and measure
    the boxes of ``in_place`` (which must not hold ``box_id``)."""
    from unstack.geometry import rotation_angles_deg
    from unstack.sim.ground_truth import PARKING, run_horizon

    watched = [bodies[other] for other in in_place]
    before, before_turn = world.poses(watched)
    parking = PARKING + np.array([10.0 * number, 0.0, 0.0])
    world.client.resetBasePositionAndOrientation(bodies[box_id], parking.tolist(), [0.0, 0.0, 0.0, 1.0])
    world.client.resetBaseVelocity(bodies[box_id], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0])
    run_horizon(world, truth, watched)
    after, after_turn = world.poses(watched)
    moved = np.linalg.norm(after - before, axis=1)
    disturbed = (moved > truth.displacement_threshold) | (
        rotation_angles_deg(before_turn, after_turn) > truth.rotation_threshold_deg
    )
    fallen = fallen_boxes(before, before_turn, after, after_turn)
    return UnloadStep(
        box_id,
        tuple(in_place[k] for k in np.flatnonzero(disturbed)),
        float(moved[disturbed].sum()),
        float(moved.max(initial=0.0)),
        tuple(in_place[k] for k in np.flatnonzero(fallen)),
        tuple(in_place[k] for k in np.flatnonzero(after[:, 2] < -LOST_BELOW_FLOOR)),
    )


def probe_removals(
    scene: Scene, world: Any, in_place: Sequence[str], candidates: Sequence[str], number: int = 0
) -> dict[str, UnloadStep]:
    """What taking out each candidate would do, tried in ``world`` itself and undone.

    The world's state is saved, each candidate removed and measured as an unloading step
    would be (:data:`RESETTLE_SECONDS` aside: the same horizon, thresholds and parking), and
    the state restored after each try, so the world is left as it was and each outcome is
    what choosing that candidate next would do (the same boxes move; restoring a state keeps
    poses and velocities, not the contact solver's warm start, so distances differ slightly). This
    is the physics look-ahead of the container experiment: it knows the true pile.

    Parameters
    ----------
    scene : Scene
        The simulated scene whose pile ``world`` holds (``world.boxes`` in its box order).
    world : PhysicsWorld
    in_place : sequence of str
        The boxes still in the container.
    candidates : sequence of str
        Boxes of ``in_place`` to try.
    number : int
        Parking slot of the removed box (the step number).

    Returns
    -------
    dict of str to UnloadStep
    """
    truth = _scene_settings(scene).ground_truth
    bodies = dict(zip(scene.box_ids, world.boxes, strict=True))
    state = world.client.saveState()
    outcomes = {}
    try:
        for box_id in candidates:
            others = [other for other in in_place if other != box_id]
            outcomes[box_id] = _remove_and_measure(world, bodies, others, box_id, number, truth)
            world.client.restoreState(stateId=state)
    finally:
        world.client.restoreState(stateId=state)
        world.client.removeState(state)
    return outcomes


def rebuilt_removals(
    scene: Scene,
    candidates: Sequence[str] | None = None,
    *,
    masses: dict[str, float] | None = None,
    fixed: Sequence[str] = (),
) -> dict[str, UnloadStep]:
    """What taking out each candidate would do in a fresh world rebuilt from the scene's poses.

    Every box of ``scene`` (detected or not) is put in a new physics world at its pose, with
    its mass (the settings' mean where it has none), the world settles for
    :data:`RESETTLE_SECONDS`, and each candidate's removal is tried there as
    :func:`probe_removals` tries it. This is an oracle that knows the whole pile's poses and
    masses but not its state (velocities, contacts, a creep under way): beside the physics
    look-ahead (the world itself) it measures how much of the look-ahead's edge any
    perception of poses could reach.

    Parameters
    ----------
    scene : Scene
        A scene with every box of the pile (the container experiment hands its policies one)
        and simulation settings in its metadata.
    candidates : sequence of str, optional
        Boxes to try (default: the scene's detected boxes).
    masses : dict of str to float, optional
        The mass of each box (kg) instead of its own (the settings' mean mass for every box,
        or a draw: what a robot that sees every pose but weighs nothing would build).
    fixed : sequence of str
        Boxes put in as static bodies: the space they fill is known, what they would do is not.

    Returns
    -------
    dict of str to UnloadStep

    Examples
    --------
    >>> from unstack.scene import load_scene
    >>> outcomes = rebuilt_removals(load_scene("examples/pile5.scene.json"), ["b04"])
    >>> "b14" in outcomes["b04"].moved   # b14 rests on b04
    True
    """
    from unstack.sim.world import PhysicsWorld

    settings = _scene_settings(scene)
    tried = list(scene.detected if candidates is None else candidates)
    unknown = [box_id for box_id in tried if box_id not in scene.box_ids]
    if unknown:
        raise UnstackError(f"{scene.source}: candidates {unknown} are not boxes of the scene")
    with PhysicsWorld(settings, door=False) as world:
        typical = float(np.mean(settings.pile.mass_range))
        for box in scene.boxes:
            mass = (box.mass if box.mass is not None else typical) if masses is None else masses[box.id]
            world.add_box(box.size, box.position, box.orientation_xyzw, mass=0.0 if box.id in fixed else mass)
        world.step(RESETTLE_SECONDS)
        return probe_removals(scene, world, scene.box_ids, tried)


def fallen_boxes(before: np.ndarray, before_turn: np.ndarray, after: np.ndarray, after_turn: np.ndarray) -> np.ndarray:
    """Which boxes dropped more than :data:`FALL_DROP` or tipped more than :data:`FALL_TILT_DEG`.

    Positions and quaternions (``x, y, z, w``) per row, before and after a removal. Turning
    about the vertical does not count: only the body axis that stood most upright is followed.

    Examples
    --------
    >>> still = np.array([[0.0, 0.0, 0.0, 1.0]] * 3)
    >>> turned = np.array([[0.0, 0.0, 0.0, 1.0], [0.0, 0.0, 0.7071, 0.7071], [0.7071, 0.0, 0.0, 0.7071]])
    >>> at = np.zeros((3, 3)); dropped = at - [[0.0, 0.0, 0.3], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]]
    >>> fallen_boxes(at, still, dropped, turned).tolist()
    [True, False, True]
    """
    from unstack.geometry import rotation_matrix

    dropped = before[:, 2] - after[:, 2] > FALL_DROP
    tipped = np.zeros(len(before), dtype=bool)
    for k in range(len(before)):
        rotation_before = rotation_matrix(before_turn[k] / np.linalg.norm(before_turn[k]))
        rotation_after = rotation_matrix(after_turn[k] / np.linalg.norm(after_turn[k]))
        up = int(np.argmax(np.abs(rotation_before[2])))  # the body axis that stood most upright
        tilt_before = np.degrees(np.arccos(np.clip(abs(rotation_before[2, up]), 0.0, 1.0)))
        tilt_after = np.degrees(np.arccos(np.clip(abs(rotation_after[2, up]), 0.0, 1.0)))
        tipped[k] = tilt_after - tilt_before > FALL_TILT_DEG
    return np.asarray(dropped | tipped)
