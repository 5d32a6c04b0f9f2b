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

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from unstack.errors import UnstackError
from unstack.scene import Scene

__all__ = ["UnloadRun", "UnloadStep", "execute_policy", "execute_unloading"]

#: Seconds of simulation to let a rebuilt pile find its contacts before the first removal.
RESETTLE_SECONDS = 0.5


@dataclass(frozen=True)
class UnloadStep:
    """One removal: the box taken out and what it did to the boxes still in place."""

    box: str
    moved: tuple[str, ...]
    displacement_m: float
    max_displacement_m: float

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
        }


@dataclass(frozen=True)
class UnloadRun:
    """An executed order: its steps and the drift of the rebuilt pile before the first step."""

    order: tuple[str, ...]
    steps: tuple[UnloadStep, ...]
    resettle_drift_m: float

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
            "steps": [step.to_dict() for step in self.steps],
        }


def _scene_settings(scene: Scene) -> Any:
    from unstack.sim.settings import SimulationSettings

    data = scene.metadata.get("settings")
    if not isinstance(data, dict):
        raise UnstackError(f"{scene.source}: $.metadata.settings: executing an order needs a simulated scene")
    return SimulationSettings.from_dict(data)


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
    return _execute(scene, len(order), lambda number, _world, _in_place: order[number])


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
    from unstack.scene import Box
    from unstack.sim.sensor import scan_pile

    settings = _scene_settings(scene)
    remaining = list(boxes)

    def sense_and_pick(number: int, world: Any, in_place: list[str]) -> str:
        positions, orientations = world.poses([world.boxes[scene.box_ids.index(box_id)] for box_id in in_place])
        current_boxes = [
            Box(box_id, scene.box(box_id).size, position, orientation, mass=scene.box(box_id).mass)
            for box_id, position, orientation in zip(in_place, positions, orientations / np.linalg.norm(
                orientations, axis=1, keepdims=True), strict=True)
        ]  # fmt: skip
        scan = scan_pile(world, settings.sensor, seed=number)
        current = Scene(current_boxes, scan.points, remaining, metadata=scene.metadata, source=scene.source)
        choice = policy(current)
        if choice not in remaining:
            raise UnstackError(f"{scene.source}: the policy picked {choice!r}, not one of the boxes left to unload")
        remaining.remove(choice)
        return choice

    return _execute(scene, len(remaining), sense_and_pick)


def _execute(scene: Scene, count: int, next_box: Callable[[int, Any, list[str]], str]) -> UnloadRun:
    """Rebuild the pile, then ``count`` times: take out ``next_box(step, world, in_place)`` and measure."""
    from unstack.geometry import rotation_angles_deg
    from unstack.sim.ground_truth import PARKING, run_horizon
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
        in_place = list(scene.box_ids)
        steps = []
        order = []
        for number in range(count):
            box_id = next_box(number, world, list(in_place))
            order.append(box_id)
            in_place.remove(box_id)
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
            steps.append(
                UnloadStep(
                    box_id,
                    tuple(in_place[k] for k in np.flatnonzero(disturbed)),
                    float(moved[disturbed].sum()),
                    float(moved.max(initial=0.0)),
                )
            )
    return UnloadRun(tuple(order), tuple(steps), drift)
