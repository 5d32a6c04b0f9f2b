"""Piles of boxes dropped into a container section (§V-A).

Boxes fall in waves behind a temporary door wall: each wave's boxes start just above the
boxes under them, at the lowest of several random spots whose bounding circles do not
overlap, with a random yaw and roll and pitch up to ``max_tilt_deg``. After the waves the
pile settles, the door is taken away, the pile settles again, boxes that fell out of the
container are deleted, and the missing ones are dropped again (door back in place) until
the pile has the requested number of boxes.

Examples
--------
>>> from unstack.sim.settings import Container, SimulationSettings
>>> settings = SimulationSettings(boxes=(4, 4), container=Container(depth=1.0))
>>> with build_pile(settings, count=4, seed=1) as pile:
...     len(pile.world.boxes)
4
"""

from __future__ import annotations

from dataclasses import dataclass, field
from types import TracebackType

import numpy as np

from unstack.sim.settings import InvalidSettings, SimulationSettings
from unstack.sim.world import PhysicsWorld

__all__ = ["Pile", "PileBox", "build_pile", "random_orientation_xyzw"]

#: Vertical gap between the top of the pile and the lowest point of a dropped box (m).
DROP_GAP = 0.05
#: Margin kept between a dropped box and the walls (m).
WALL_MARGIN = 0.02
#: Margin kept between a dropped box and the door (m): fewer boxes lean on the door and
#: fall out when it opens, so fewer refills.
DOOR_MARGIN = 0.2
#: Random spots tried for each dropped box; the lowest one that keeps clear of the wave wins.
CANDIDATES = 12


@dataclass
class PileBox:
    """A box of the pile: its body in the world and what it is."""

    body: int
    size: np.ndarray
    mass: float


@dataclass
class Pile:
    """A settled pile, with the door open, still alive in its physics world."""

    world: PhysicsWorld
    boxes: list[PileBox] = field(default_factory=list)
    simulated_seconds: float = 0.0
    refills: int = 0

    def close(self) -> None:
        """Close the physics world."""
        self.world.close()

    def __enter__(self) -> Pile:
        return self

    def __exit__(
        self, kind: type[BaseException] | None, value: BaseException | None, traceback: TracebackType | None
    ) -> None:
        self.close()


def random_orientation_xyzw(rng: np.random.Generator, max_tilt_deg: float) -> np.ndarray:
    """Uniform yaw, roll and pitch uniform in ``±max_tilt_deg``, as a quaternion ``xyzw``."""
    from scipy.spatial.transform import Rotation

    tilt = np.radians(max_tilt_deg)
    roll, pitch = rng.uniform(-tilt, tilt, size=2)
    yaw = rng.uniform(-np.pi, np.pi)
    return np.asarray(Rotation.from_euler("xyz", [roll, pitch, yaw]).as_quat(), dtype=np.float64)


def _footprints(world: PhysicsWorld) -> np.ndarray:
    """Axis-aligned bounding boxes of the boxes in the world, (k, 6): min xyz, max xyz."""
    boxes = [world.client.getAABB(body) for body in world.boxes]
    return np.array([[*low, *high] for low, high in boxes], dtype=np.float64).reshape(-1, 6)


def _local_top(footprints: np.ndarray, x: float, y: float, radius: float) -> float:
    """Highest top of the boxes whose footprint meets the square of side 2 radius at (x, y)."""
    if len(footprints) == 0:
        return 0.0
    meets = (
        (footprints[:, 0] < x + radius)
        & (footprints[:, 3] > x - radius)
        & (footprints[:, 1] < y + radius)
        & (footprints[:, 4] > y - radius)
    )
    return float(footprints[meets, 5].max()) if meets.any() else 0.0


def _drop_wave(world: PhysicsWorld, pile: Pile, count: int, rng: np.random.Generator) -> int:
    """Drop up to ``count`` boxes as one wave; returns how many were placed.

    Each box goes to the lowest of :data:`CANDIDATES` random spots that keep clear of the
    wave's other boxes, just above the boxes under that spot: low places fill first, as when
    a pile is loaded by hand.
    """
    settings = world.settings
    container = settings.container
    sizes = settings.box_sizes()
    footprints = _footprints(world)
    placed: list[tuple[float, float, float]] = []  # x, y, radius
    for _ in range(count):
        size = sizes[rng.integers(len(sizes))]
        mass = float(rng.uniform(*settings.pile.mass_range))
        orientation = random_orientation_xyzw(rng, settings.pile.max_tilt_deg)
        radius = float(np.linalg.norm(size)) / 2.0
        low_x, high_x = radius + DOOR_MARGIN, container.depth - radius - WALL_MARGIN
        low_y, high_y = -container.width / 2.0 + radius + WALL_MARGIN, container.width / 2.0 - radius - WALL_MARGIN
        if low_x > high_x:
            low_x, high_x = radius + WALL_MARGIN, container.depth - radius - WALL_MARGIN
        if low_x > high_x or low_y > high_y:
            low_x = high_x = container.depth / 2.0
            low_y = high_y = 0.0
        best: tuple[float, float, float] | None = None
        for _candidate in range(CANDIDATES):
            x, y = float(rng.uniform(low_x, high_x)), float(rng.uniform(low_y, high_y))
            if not all((x - px) ** 2 + (y - py) ** 2 > (radius + pr) ** 2 for px, py, pr in placed):
                continue
            top = _local_top(footprints, x, y, radius)
            if best is None or top < best[2]:
                best = (x, y, top)
        if best is None:
            continue
        x, y, top = best
        z = top + DROP_GAP + radius
        if z + radius > container.height - WALL_MARGIN:
            continue
        placed.append((x, y, radius))
        body = world.add_box(size, [x, y, z], orientation, mass=mass)
        pile.boxes.append(PileBox(body, size.copy(), mass))
    return len(placed)


def _delete_fallen(world: PhysicsWorld, pile: Pile) -> int:
    """Delete the boxes whose centroid left the container; returns how many."""
    container = world.settings.container
    positions, _ = world.poses([box.body for box in pile.boxes])
    inside = (
        (positions[:, 0] > 0.0)
        & (positions[:, 0] < container.depth)
        & (np.abs(positions[:, 1]) < container.width / 2.0)
        & (positions[:, 2] > 0.0)
        & (positions[:, 2] < container.height)
    )
    for box, keep in zip(list(pile.boxes), inside, strict=True):
        if not keep:
            world.remove_box(box.body)
            pile.boxes.remove(box)
    return int(np.count_nonzero(~inside))


def build_pile(settings: SimulationSettings, *, count: int, seed: int | np.random.SeedSequence) -> Pile:
    """Drop, settle, open the door and refill until the pile holds ``count`` boxes.

    Parameters
    ----------
    settings : SimulationSettings
    count : int
        Boxes in the finished pile.
    seed : int or numpy.random.SeedSequence
        The same seed and settings give bit-identical poses.

    Returns
    -------
    Pile
        With the door open and the world still alive (close it, or use ``with``).

    Raises
    ------
    InvalidSettings
        The container cannot hold ``count`` boxes within ``max_refills`` rounds.
    """
    rng = np.random.default_rng(seed)
    world = PhysicsWorld(settings, door=True)
    pile = Pile(world)
    try:
        for round_index in range(settings.pile.max_refills + 1):
            stalled = 0
            while len(pile.boxes) < count:
                dropped = _drop_wave(world, pile, min(settings.pile.wave_size, count - len(pile.boxes)), rng)
                pile.simulated_seconds += world.settle()
                stalled = stalled + 1 if dropped == 0 else 0
                if stalled >= 3:
                    break
            world.open_door()
            pile.simulated_seconds += world.settle()
            fallen = _delete_fallen(world, pile)
            if fallen:
                pile.simulated_seconds += world.settle()
            if len(pile.boxes) == count:
                pile.refills = round_index
                return pile
            world.close_door()
        raise InvalidSettings(
            f"could not pile {count} boxes of size set {settings.sizes!r} into the container "
            f"within {settings.pile.max_refills} refills (got {len(pile.boxes)})"
        )
    except BaseException:
        world.close()
        raise
