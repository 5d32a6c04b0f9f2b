"""A simulated configuration: a valid scene with ground truth, and bit-identical for a seed."""

from __future__ import annotations

import hashlib
import json
import subprocess
import sys

import numpy as np
import pytest

from tests.sim.conftest import small_settings
from unstack.sim.configuration import simulate_configuration
from unstack.sim.settings import SimulationSettings

pytestmark = pytest.mark.slow  # builds physics worlds


def fingerprint(settings: SimulationSettings, seed: int, index: int) -> str:
    """SHA-256 of the scene's JSON and the exact bytes of its point cloud."""
    result = simulate_configuration(settings, seed=seed, index=index)
    scene = result.scene
    return hashlib.sha256(json.dumps(scene.to_dict(points_file="p.npy")).encode() + scene.points.tobytes()).hexdigest()


def test_a_configuration_is_a_valid_scene(settings: SimulationSettings) -> None:
    result = simulate_configuration(settings, seed=1, index=0)
    scene = result.scene
    low, high = settings.boxes
    assert low <= len(scene.boxes) <= high
    assert scene.ground_truth is not None and scene.ground_truth.shape == (len(scene.boxes),) * 2
    assert set(scene.detected) <= set(scene.box_ids) and len(scene.points) == len(result.point_boxes)
    simulation = scene.metadata["simulation"]
    n = len(scene.boxes)
    assert np.asarray(simulation["removal"]["displacement_m"]).shape == (n, n)
    assert simulation["transitivity"]["premises"] >= simulation["transitivity"]["violated"] >= 0
    assert set(result.timings) == {"generation", "ground_truth", "scan"}


def test_same_seed_same_configuration_in_any_order(settings: SimulationSettings) -> None:
    forward = [fingerprint(settings, 9, index) for index in (0, 1)]
    backward = [fingerprint(settings, 9, index) for index in (1, 0)][::-1]
    assert forward == backward
    assert forward[0] != forward[1]
    assert fingerprint(settings, 10, 0) != forward[0]


PROBE = """
from tests.sim.conftest import small_settings
from tests.sim.test_configuration import fingerprint
print(fingerprint(small_settings(), 9, 0))
"""


def test_same_seed_same_configuration_in_a_fresh_process(repo: object) -> None:
    fresh = subprocess.run([sys.executable, "-c", PROBE], capture_output=True, text=True, check=True, cwd=str(repo))
    assert fresh.stdout.strip() == fingerprint(small_settings(), 9, 0)
