"""Simulation (§V): pybullet container piles, ground truth by removal, range sensor, data sets.

Needs the ``sim`` extra (``pip install "unstack[sim]"``): pybullet and dask.distributed.
Importing this package does not import pybullet; building a world does.

Examples
--------
>>> from unstack.sim import Container, SimulationSettings
>>> SimulationSettings(boxes=(10, 20), sizes="four", container=Container(depth=1.0)).boxes
(10, 20)
"""

from unstack.sim.configuration import SimulatedConfiguration, configuration_seed, simulate_configuration
from unstack.sim.dataset import DatasetConflict, SchedulerUnavailable, simulate_dataset
from unstack.sim.ground_truth import RemovalResponse, removal_responses, support_labels, transitivity_violations
from unstack.sim.piles import Pile, build_pile
from unstack.sim.sensor import Scan, scan_pile
from unstack.sim.settings import (
    SIZE_SETS,
    Container,
    GroundTruthSettings,
    InvalidSettings,
    PileSettings,
    SensorSettings,
    SimulationSettings,
)
from unstack.sim.world import PhysicsWorld

__all__ = [
    "SIZE_SETS",
    "Container",
    "DatasetConflict",
    "GroundTruthSettings",
    "InvalidSettings",
    "PhysicsWorld",
    "Pile",
    "PileSettings",
    "RemovalResponse",
    "Scan",
    "SchedulerUnavailable",
    "SensorSettings",
    "SimulatedConfiguration",
    "SimulationSettings",
    "build_pile",
    "configuration_seed",
    "removal_responses",
    "scan_pile",
    "simulate_configuration",
    "simulate_dataset",
    "support_labels",
    "transitivity_violations",
]
