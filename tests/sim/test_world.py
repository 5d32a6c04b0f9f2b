"""The physics world: own client, settling, no sleeping, the container holds boxes."""

from __future__ import annotations

import numpy as np
import pytest

from unstack.geometry import rotation_angles_deg
from unstack.sim.piles import build_pile
from unstack.sim.settings import SimulationSettings
from unstack.sim.world import PhysicsWorld

pytestmark = pytest.mark.slow  # steps the physics engine


def stack(world: PhysicsWorld) -> tuple[int, int]:
    bottom = world.add_box([0.4, 0.3, 0.3], [0.5, 0.0, 0.15], [0, 0, 0, 1], mass=10.0)
    top = world.add_box([0.4, 0.3, 0.3], [0.5, 0.0, 0.45], [0, 0, 0, 1], mass=5.0)
    world.settle()
    return bottom, top


def test_a_box_rests_on_the_floor(settings: SimulationSettings) -> None:
    with PhysicsWorld(settings, door=False) as world:
        world.add_box([0.6, 0.4, 0.4], [0.5, 0.0, 0.3], [0, 0, 0, 1], mass=8.0)
        world.settle()
        positions, _ = world.poses()
    assert abs(positions[0, 2] - 0.2) < 2e-3


def test_sleeping_is_disabled_so_removing_a_support_drops_the_box(settings: SimulationSettings) -> None:
    with PhysicsWorld(settings, door=False) as world:
        bottom, top = stack(world)
        world.step(2.0)  # long enough for bodies to fall asleep if sleeping were on
        world.client.resetBasePositionAndOrientation(bottom, [50.0, 50.0, -50.0], [0, 0, 0, 1])
        world.step(0.5)
        positions, _ = world.poses([top])
    assert positions[0, 2] < 0.2


def test_each_world_has_its_own_client(settings: SimulationSettings) -> None:
    with PhysicsWorld(settings) as first, PhysicsWorld(settings) as second:
        assert first.client._client != second.client._client
        first.add_box([0.4, 0.3, 0.3], [0.5, 0.0, 1.0], [0, 0, 0, 1], mass=5.0)
        first.step(0.5)
        assert second.boxes == []
        assert first.client.getNumBodies() == second.client.getNumBodies() + 1


def test_a_pile_has_the_requested_boxes_inside_the_container(settings: SimulationSettings) -> None:
    with build_pile(settings, count=5, seed=11) as pile:
        positions, _ = pile.world.poses()
        assert len(pile.boxes) == 5 and pile.world.door is None
    container = settings.container
    assert np.all((positions[:, 0] > 0) & (positions[:, 0] < container.depth))
    assert np.all(np.abs(positions[:, 1]) < container.width / 2)
    assert np.all(positions[:, 2] > 0)


def test_rotation_angle_of_a_quarter_turn() -> None:
    quarter = np.array([[0.0, 0.0, np.sin(np.pi / 4), np.cos(np.pi / 4)]])
    assert np.allclose(rotation_angles_deg(np.array([[0.0, 0.0, 0.0, 1.0]]), quarter), 90.0)


def test_fixed_blocks_of_several_sizes_stand_where_given_and_hold_a_box(settings: SimulationSettings) -> None:
    sizes = [[0.3, 0.3, 0.2], [0.2, 0.2, 0.2], [0.3, 0.3, 0.2], [0.3, 0.3, 0.4]]
    centres = [[0.5, -0.6, 0.1], [0.5, 0.0, 0.1], [0.5, 0.6, 0.1], [1.2, 0.0, 0.2]]
    with PhysicsWorld(settings, door=False) as world:
        blocks = world.add_fixed_blocks(sizes, centres)
        on_block = world.add_box([0.2, 0.2, 0.2], [1.2, 0.0, 0.55], [0, 0, 0, 1], mass=5.0)
        world.settle()
        resting, _ = world.poses([on_block])
        standing = [world.client.getBasePositionAndOrientation(body)[0] for body in blocks]
    assert len(set(blocks)) == 4 and world.static[-len(blocks) :] == blocks
    np.testing.assert_allclose(standing, centres)
    assert abs(resting[0, 2] - 0.5) < 2e-3  # on the tall block: 0.4 m + half its 0.2 m


def test_fixed_blocks_need_a_centre_for_each_size(settings: SimulationSettings) -> None:
    with PhysicsWorld(settings, door=False) as world, pytest.raises(ValueError, match=r"2 block sizes for 1 centres"):
        world.add_fixed_blocks([[0.2, 0.2, 0.2]] * 2, [[0.5, 0.0, 0.1]])
