"""Staged piles: structures set down by hand, settled, with removal ground truth."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from unstack.sim.ground_truth import removal_responses, support_labels
from unstack.sim.settings import FAMILIES, GroundTruthSettings, InvalidSettings, family_settings
from unstack.sim.structures import _lean, build_structures
from unstack.sim.world import PhysicsWorld


def _tilts_deg(orientations: np.ndarray) -> np.ndarray:
    """How far each box is from resting on one of its faces (0 when square to the floor)."""
    up_components = np.abs(Rotation.from_quat(orientations).as_matrix()[:, 2, :])
    tilts: np.ndarray = np.degrees(np.arccos(np.clip(up_components.max(axis=1), -1.0, 1.0)))
    return tilts


def test_staged_is_a_family_of_the_simulate_command() -> None:
    assert "staged" in FAMILIES
    assert family_settings("staged").pile.arrangement == "structures"


@pytest.mark.parametrize("seed", range(4))
def test_a_staged_pile_holds_its_boxes_inside_the_section(seed: int) -> None:
    settings = family_settings("staged")
    count = 6 + 2 * seed
    with build_structures(settings, count=count, seed=seed) as pile:
        positions, _ = pile.world.poses([box.body for box in pile.boxes])
    assert len(positions) == count
    assert np.all(positions[:, 0] > 0) and np.all(positions[:, 0] < settings.container.depth)
    assert np.all(np.abs(positions[:, 1]) < settings.container.width / 2)
    assert np.all(positions[:, 2] > 0)


def test_the_same_seed_builds_the_same_pile() -> None:
    settings = family_settings("staged")
    poses = []
    for _ in range(2):
        with build_structures(settings, count=8, seed=11) as pile:
            poses.append(np.hstack(pile.world.poses([box.body for box in pile.boxes])))
    np.testing.assert_array_equal(poses[0], poses[1])


def test_staged_piles_hold_boxes_that_stay_leaning() -> None:
    settings = family_settings("staged")
    leaning = 0
    for seed in range(8):
        with build_structures(settings, count=10, seed=seed) as pile:
            _, orientations = pile.world.poses([box.body for box in pile.boxes])
        tilts = _tilts_deg(orientations)
        leaning += int(np.count_nonzero((tilts > 5.0) & (tilts < 80.0)))
    assert leaning >= 2


@pytest.mark.parametrize("seed", range(3))
def test_a_box_leaning_on_a_column_is_supported_by_it(seed: int) -> None:
    settings = family_settings("staged")
    rng = np.random.default_rng(seed)
    placed = _lean(settings.box_sizes(), 1, rng)  # one column box and the box leaning on it
    with PhysicsWorld(settings, door=False) as world:
        for size, centre, rotation in placed:
            world.add_box(size, centre + np.array([1.5, 0.0, 0.0]), rotation.as_quat(), mass=5.0)
        world.settle()
        _, orientations = world.poses()
        assert 5.0 < _tilts_deg(orientations)[1] < 80.0  # it still leans after settling
        truth = GroundTruthSettings()
        response = removal_responses(world, truth)
    labels = support_labels(
        response.displacement, response.rotation_deg,
        displacement_threshold=truth.displacement_threshold, rotation_threshold_deg=truth.rotation_threshold_deg,
    )  # fmt: skip
    assert labels[0, 1] and not labels[1, 0]


def test_a_floor_too_small_is_a_one_line_error() -> None:
    from dataclasses import replace

    from unstack.sim.settings import Container

    settings = replace(family_settings("staged"), container=Container(depth=1.0, width=1.0))
    with pytest.raises(InvalidSettings, match=r"no room on a 1\.0 m x 1\.0 m floor for 14 staged boxes \(placed \d+\)"):
        build_structures(settings, count=14, seed=0)
