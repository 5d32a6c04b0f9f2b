"""Ground-truth support by removal (§V-A): X supports Y when taking X away moves Y.

The settled state is saved once. For every box X the state is restored, X is moved far
away (``removeBody`` would break ``restoreState``), the world runs for a horizon, and
every other box's displacement and rotation are kept. ``Y`` is labelled supported by
``X`` when it moved more than ``displacement_threshold`` or turned more than
``rotation_threshold_deg``; the raw values are kept so that other thresholds need no new
simulation. A baseline run without removal measures the pile's own drift (creep).

Removal labels are not transitive in general (a box may rest on two others and survive
the removal of either); :func:`transitivity_violations` measures how often.

Examples
--------
>>> truth = np.array([[0, 1, 0], [0, 0, 1], [0, 0, 0]])
>>> transitivity_violations(truth)
(1, 1)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from unstack.geometry import rotation_angles_deg
from unstack.sim.settings import DISPLACEMENT_THRESHOLD, ROTATION_THRESHOLD_DEG, GroundTruthSettings
from unstack.sim.world import PhysicsWorld

__all__ = ["RemovalResponse", "removal_responses", "support_labels", "transitivity_violations"]

#: Where a removed box is parked: far below and beside the container, one slot per box.
PARKING = np.array([0.0, 1000.0, -1000.0])


@dataclass(frozen=True)
class RemovalResponse:
    """What removing each box did to every other box.

    Attributes
    ----------
    displacement : numpy.ndarray, shape (n, n)
        ``[x, y]``: how far box y moved (metres) when box x was removed; diagonal 0.
    rotation_deg : numpy.ndarray, shape (n, n)
        ``[x, y]``: how far box y turned (degrees).
    baseline_displacement, baseline_rotation_deg : float
        Largest drift of any box over the same horizon without removal (creep).
    """

    displacement: np.ndarray
    rotation_deg: np.ndarray
    baseline_displacement: float
    baseline_rotation_deg: float


def run_horizon(world: PhysicsWorld, settings: GroundTruthSettings, watched: list[int]) -> float:
    """Step for the horizon, leaving early once every watched box is slow."""
    time_step = world.settings.pile.time_step
    steps = max(1, round(settings.horizon / time_step))
    check_every = max(1, round(0.05 / time_step))
    for index in range(1, steps + 1):
        world.client.stepSimulation()
        elapsed = index * time_step
        checking = elapsed >= settings.early_exit_after and index % check_every == 0
        if checking and float(np.max(world.speeds(watched), initial=0.0)) < settings.early_exit_speed:
            return elapsed
    return steps * time_step


def removal_responses(world: PhysicsWorld, settings: GroundTruthSettings) -> RemovalResponse:
    """Remove each box in turn from the settled pile and measure every other box.

    The world must hold a settled pile with its door open; it is left in the settled state.
    """
    client = world.client
    bodies = list(world.boxes)
    n = len(bodies)
    state = client.saveState()
    start_positions, start_orientations = world.poses(bodies)
    displacement = np.zeros((n, n))
    rotation = np.zeros((n, n))
    run_horizon(world, settings, bodies)
    positions, orientations = world.poses(bodies)
    baseline_displacement = float(np.max(np.linalg.norm(positions - start_positions, axis=1), initial=0.0))
    baseline_rotation = float(np.max(rotation_angles_deg(start_orientations, orientations), initial=0.0))
    for x, body in enumerate(bodies):
        client.restoreState(stateId=state)
        parking = PARKING + np.array([10.0 * x, 0.0, 0.0])
        client.resetBasePositionAndOrientation(body, parking.tolist(), [0.0, 0.0, 0.0, 1.0])
        client.resetBaseVelocity(body, [0.0, 0.0, 0.0], [0.0, 0.0, 0.0])
        others = bodies[:x] + bodies[x + 1 :]
        run_horizon(world, settings, others)
        positions, orientations = world.poses(bodies)
        moved = np.linalg.norm(positions - start_positions, axis=1)
        turned = rotation_angles_deg(start_orientations, orientations)
        moved[x] = turned[x] = 0.0
        displacement[x] = moved
        rotation[x] = turned
    client.restoreState(stateId=state)
    client.removeState(state)
    return RemovalResponse(displacement, rotation, baseline_displacement, baseline_rotation)


def support_labels(
    displacement: np.ndarray,
    rotation_deg: np.ndarray,
    *,
    displacement_threshold: float = DISPLACEMENT_THRESHOLD,
    rotation_threshold_deg: float = ROTATION_THRESHOLD_DEG,
) -> np.ndarray:
    """0/1 support matrix from raw removal responses: ``[x, y] = 1`` iff y moved or turned.

    Examples
    --------
    >>> moved = np.array([[0.0, 0.3], [0.001, 0.0]])
    >>> support_labels(moved, np.zeros((2, 2))).tolist()
    [[0, 1], [0, 0]]
    """
    labels = (displacement > displacement_threshold) | (rotation_deg > rotation_threshold_deg)
    np.fill_diagonal(labels, False)
    return labels.astype(np.int64)


def transitivity_violations(support: np.ndarray) -> tuple[int, int]:
    """``(violated, premises)``: of the triples with x->y and y->z (x, y, z distinct),
    how many lack x->z.

    Examples
    --------
    >>> transitivity_violations(np.array([[0, 1, 1], [0, 0, 1], [0, 0, 0]]))
    (0, 1)
    """
    relation = np.asarray(support, dtype=np.int64).copy()
    np.fill_diagonal(relation, 0)
    paths = relation @ relation  # [x, z] = number of y with x->y->z
    np.fill_diagonal(paths, 0)
    premises = int(paths.sum())
    violated = int(paths[relation == 0].sum())
    return violated, premises
