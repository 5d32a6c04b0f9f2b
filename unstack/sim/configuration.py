"""One simulated configuration: pile, ground truth, scan, as an ``unstack.scene/1`` scene.

Every configuration of a data set has its own seed, derived from the data set's seed and
the configuration's index (``SeedSequence(seed, spawn_key=(index,))``), so a
configuration comes out bit-identical whichever worker makes it and in whatever order.

Examples
--------
>>> from unstack.sim.settings import Container, SensorSettings, SimulationSettings
>>> settings = SimulationSettings(boxes=(3, 3), container=Container(depth=1.0),
...                               sensor=SensorSettings(width=80, height=60, min_pixels=5))
>>> result = simulate_configuration(settings, seed=7, index=0)
>>> len(result.scene.boxes), result.scene.ground_truth.shape
(3, (3, 3))
"""

from __future__ import annotations

import time
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from unstack.dataset_folders import config_name
from unstack.provenance import package_versions
from unstack.scene import Box, Scene
from unstack.sim.ground_truth import RemovalResponse, removal_responses, support_labels, transitivity_violations
from unstack.sim.piles import Pile, build_pile
from unstack.sim.sensor import scan_pile
from unstack.sim.settings import SensorSettings, SimulationSettings

__all__ = [
    "SimulatedConfiguration",
    "configuration_seed",
    "jittered_sensor",
    "simulate_configuration",
]

#: Re-settling rounds for a pile that creeps before it is rejected and rebuilt.
CREEP_RESETTLES = 2
#: Piles built for one configuration before giving up on a creep-free one.
MAX_PILES = 4


@dataclass(frozen=True)
class SimulatedConfiguration:
    """A finished configuration.

    Returned by :func:`simulate_configuration` for one seed and index: a pile that settled
    without creeping, its removal responses, and the scan of it.

    Attributes
    ----------
    index : int
        Its index in the data set.
    scene : Scene
        Boxes, point cloud, detectable boxes (as ``detected``), ground truth, and in
        ``metadata["simulation"]`` the raw removal responses and the settings' seed.
    point_boxes : numpy.ndarray, shape (N,)
        Box index of every point (-1: container).
    timings : dict
        CPU seconds of each phase (not part of the scene: they differ between runs).
    """

    index: int
    scene: Scene
    point_boxes: np.ndarray
    timings: dict[str, float]


def configuration_seed(seed: int, index: int) -> np.random.SeedSequence:
    """The seed of configuration ``index`` of a data set seeded with ``seed``."""
    return np.random.SeedSequence(seed, spawn_key=(index,))


#: Packages whose versions a simulated scene and a data set record.
SIMULATION_PACKAGES = ("unstack", "pybullet", "numpy")


def jittered_sensor(sensor: SensorSettings, seed: np.random.SeedSequence | int) -> SensorSettings:
    """The sensor moved by its ``position_jitter`` (uniform per axis), its target by half as much.

    Examples
    --------
    >>> from unstack.sim.settings import SensorSettings
    >>> jittered_sensor(SensorSettings(), 0) == SensorSettings()
    True
    >>> moved = jittered_sensor(SensorSettings(position_jitter=0.2), 0)
    >>> bool(max(abs(a - b) for a, b in zip(moved.position, SensorSettings().position)) <= 0.2)
    True
    """
    if sensor.position_jitter == 0.0:
        return sensor
    rng = np.random.default_rng(seed)
    shift = rng.uniform(-sensor.position_jitter, sensor.position_jitter, size=(2, 3)) * np.array([[1.0], [0.5]])
    position = tuple(float(value) for value in np.asarray(sensor.position) + shift[0])
    target = tuple(float(value) for value in np.asarray(sensor.target) + shift[1])
    return replace(sensor, position=position, target=target)  # type: ignore[arg-type]


def _creep_free_responses(pile: Pile, settings: SimulationSettings) -> tuple[RemovalResponse, int] | None:
    truth = settings.ground_truth
    for resettle in range(CREEP_RESETTLES + 1):
        if resettle:
            pile.world.settle()
        response = removal_responses(pile.world, truth)
        if (
            response.baseline_displacement <= truth.creep_displacement
            and response.baseline_rotation_deg <= truth.creep_rotation_deg
        ):
            return response, resettle
    return None


def simulate_configuration(settings: SimulationSettings, *, seed: int, index: int) -> SimulatedConfiguration:
    """Build, label and scan configuration ``index`` of the data set seeded with ``seed``.

    Raises
    ------
    InvalidSettings
        No creep-free pile in :data:`MAX_PILES` attempts, or the pile cannot be built.
    """
    from unstack.sim.settings import InvalidSettings

    count_seed, *pile_seeds = configuration_seed(seed, index).spawn(MAX_PILES + 1)
    low, high = settings.boxes
    count = int(np.random.default_rng(count_seed).integers(low, high + 1))
    timings: dict[str, float] = {"generation": 0.0, "ground_truth": 0.0, "scan": 0.0}
    for attempt, pile_seed in enumerate(pile_seeds):
        clock = time.process_time()
        try:
            pile = build_pile(settings, count=count, seed=pile_seed)
        except InvalidSettings:
            timings["generation"] += time.process_time() - clock
            continue  # an unlucky pile that would not take all its boxes: try the next seed
        with pile:
            timings["generation"] += time.process_time() - clock
            clock = time.process_time()
            found = _creep_free_responses(pile, settings)
            timings["ground_truth"] += time.process_time() - clock
            if found is None:
                continue
            response, resettles = found
            clock = time.process_time()
            scan_seed, jitter_seed = pile_seed.spawn(2)
            sensor = jittered_sensor(settings.sensor, jitter_seed)
            scan = scan_pile(pile.world, sensor, seed=scan_seed)
            timings["scan"] = time.process_time() - clock
            positions, orientations = pile.world.poses([box.body for box in pile.boxes])
            scene = _scene(settings, seed, index, attempt, resettles, pile, response, scan, positions, orientations)
            if sensor != settings.sensor:
                scene.metadata["simulation"]["sensor_position"] = list(sensor.position)
                scene.metadata["simulation"]["sensor_target"] = list(sensor.target)
            return SimulatedConfiguration(index, scene, scan.point_boxes, timings)
    raise InvalidSettings(
        f"configuration {index}: none of {MAX_PILES} piles of {count} boxes both took all its boxes and "
        "stopped creeping; use fewer boxes or a larger container"
    )


def _scene(
    settings: SimulationSettings,
    seed: int,
    index: int,
    attempt: int,
    resettles: int,
    pile: Pile,
    response: RemovalResponse,
    scan: Any,
    positions: np.ndarray,
    orientations: np.ndarray,
) -> Scene:
    width = max(2, len(str(len(pile.boxes) - 1)))
    ids = [f"b{k:0{width}d}" for k in range(len(pile.boxes))]
    boxes = [
        Box(ids[k], box.size, positions[k], orientations[k] / np.linalg.norm(orientations[k]), box.mass)
        for k, box in enumerate(pile.boxes)
    ]
    truth_settings = settings.ground_truth
    labels = support_labels(
        response.displacement,
        response.rotation_deg,
        displacement_threshold=truth_settings.displacement_threshold,
        rotation_threshold_deg=truth_settings.rotation_threshold_deg,
    )
    detectable = [ids[k] for k in np.flatnonzero(scan.pixel_counts >= settings.sensor.min_pixels)]
    violated, premises = transitivity_violations(labels)
    simulation = {
        "seed": seed,
        "index": index,
        "pile_attempt": attempt,
        "creep_resettles": resettles,
        "refills": pile.refills,
        "pixel_counts": scan.pixel_counts.tolist(),
        "removal": {
            "displacement_m": response.displacement.tolist(),
            "rotation_deg": response.rotation_deg.tolist(),
            "baseline_displacement_m": response.baseline_displacement,
            "baseline_rotation_deg": response.baseline_rotation_deg,
        },
        "transitivity": {"violated": violated, "premises": premises},
        "versions": package_versions(*SIMULATION_PACKAGES),
    }
    return Scene(
        boxes,
        scan.points,
        detectable or ids[:1],
        labels,
        metadata={
            "simulation": simulation,
            "settings": settings.to_dict(),
            "point_boxes_file": f"{config_name(index)}.point_boxes.npy",
        },
    )
