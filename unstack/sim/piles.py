"""Piles of boxes in a container section (§V-A): dropped in waves, or stacked as walls.

Boxes fall in waves behind a temporary door wall: each wave's boxes start just above the
boxes under them, at the lowest of several random spots whose bounding circles do not
overlap, with a random yaw and roll and pitch up to ``max_tilt_deg``. After the waves the
pile settles, the door is taken away, the pile settles again, boxes that fell out of the
container are deleted, and the missing ones are dropped again (door back in place) until
the pile has the requested number of boxes.

Walls (``arrangement="wall"``) are loaded as trailers are: columns of boxes standing side
by side across the container, rows of columns from the back wall towards the door, each box
placed on the one under it with a small random offset and yaw, a few centimetres of gap
between columns, columns of random height; a share of the boxes (``fallen_share``) is not
stacked: about half of them stand on the floor leaning 10-30 degrees onto the front of the
wall, the others are dropped in front of it, tumbling as boxes that fell off. The wall then
settles with the door open.

Examples
--------
>>> from unstack.sim.settings import Container, SimulationSettings
>>> settings = SimulationSettings(boxes=(4, 4), container=Container(depth=1.0))
>>> with build_pile(settings, count=4, seed=1) as pile:
...     len(pile.world.boxes)
4
"""

from __future__ import annotations

import numpy as np

from unstack.sim.pile_bodies import Pile, PileBox, delete_fallen
from unstack.sim.settings import InvalidSettings, SimulationSettings
from unstack.sim.structures import build_structures
from unstack.sim.world import PhysicsWorld

__all__ = ["Pile", "PileBox", "build_pile", "build_wall", "random_orientation_xyzw"]

#: Vertical gap between the top of the pile and the lowest point of a dropped box (m).
DROP_GAP = 0.05
#: Margin kept between a dropped box and the walls (m).
WALL_MARGIN = 0.02
#: Margin kept between a dropped box and the door (m): fewer boxes lean on the door and
#: fall out when it opens, so fewer refills.
DOOR_MARGIN = 0.2
#: Random spots tried for each dropped box; the lowest one that keeps clear of the wave wins.
CANDIDATES = 12
#: Largest gap between two columns of a wall, and between two rows (metres).
WALL_GAP = 0.06
#: Largest horizontal offset of a stacked box from the centre of the one under it (metres).
WALL_OFFSET = 0.04
#: Largest yaw of a stacked box away from the container's axes (degrees).
WALL_YAW_DEG = 4.0


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
    if settings.pile.arrangement == "wall":
        return build_wall(settings, count=count, seed=seed)
    if settings.pile.arrangement == "structures":
        return build_structures(settings, count=count, seed=seed)
    rng = np.random.default_rng(seed)
    world = PhysicsWorld(settings, door=True)
    pile = Pile(world)
    try:
        for round_index in range(settings.pile.max_refills + 1):
            stalled = 0
            while len(pile.boxes) < count:
                dropped = _drop_wave(world, pile, min(settings.pile.wave_size, count - len(pile.boxes)), rng)
                world.settle()
                stalled = stalled + 1 if dropped == 0 else 0
                if stalled >= 3:
                    break
            world.open_door()
            world.settle()
            fallen = delete_fallen(world, pile)
            if fallen:
                world.settle()
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


def _yaw_xyzw(yaw: float) -> np.ndarray:
    return np.array([0.0, 0.0, np.sin(yaw / 2.0), np.cos(yaw / 2.0)])


def _wall_layout(
    settings: SimulationSettings, count: int, rng: np.random.Generator
) -> list[tuple[np.ndarray, np.ndarray, float]]:
    """Sizes, centres and yaws of ``count`` stacked boxes, back row first, bottom up."""
    container = settings.container
    sizes = settings.box_sizes()
    placed: list[tuple[np.ndarray, np.ndarray, float]] = []
    row_back = container.depth - WALL_MARGIN
    while len(placed) < count:
        row_depth = 0.0
        y_cursor = -container.width / 2.0 + WALL_MARGIN
        while len(placed) < count:
            size = sizes[rng.integers(len(sizes))].copy()
            turned = bool(rng.integers(2))
            footprint = size[[1, 0]] if turned else size[:2]
            if y_cursor + footprint[1] > container.width / 2.0 - WALL_MARGIN:
                break
            if row_back - footprint[0] < DOOR_MARGIN:
                raise InvalidSettings(
                    f"a wall of {count} boxes of size set {settings.sizes!r} does not fit a {container.depth} m section"
                )
            centre_y = y_cursor + footprint[1] / 2.0
            centre_x = row_back - footprint[0] / 2.0
            levels = int(rng.integers(1, 1 + max(1, int(container.height // float(size[2])))))
            top = 0.0
            for level in range(levels):
                if len(placed) >= count:
                    break
                box_size = size if level == 0 else sizes[rng.integers(len(sizes))].copy()
                if top + box_size[2] > container.height - WALL_MARGIN:
                    break
                yaw = (np.pi / 2.0 if turned else 0.0) + np.radians(rng.uniform(-WALL_YAW_DEG, WALL_YAW_DEG))
                offset = rng.uniform(-WALL_OFFSET, WALL_OFFSET, size=2) if level else np.zeros(2)
                centre = np.array([centre_x + offset[0], centre_y + offset[1], top + box_size[2] / 2.0 + 0.002])
                footprint_depth = box_size[1] if turned else box_size[0]
                centre[0] = min(centre[0], container.depth - WALL_MARGIN - footprint_depth / 2.0)
                placed.append((box_size, centre, float(yaw)))
                top += float(box_size[2]) + 0.002
            row_depth = max(row_depth, float(footprint[0]))
            y_cursor += float(footprint[1]) + float(rng.uniform(0.0, WALL_GAP))
        row_back -= row_depth + float(rng.uniform(0.0, WALL_GAP))
    return placed


def _lean_on_wall(world: PhysicsWorld, pile: Pile, rng: np.random.Generator) -> None:
    """Stand a box on the floor in front of the wall, tipped 10-30 degrees onto a front box."""
    from scipy.spatial.transform import Rotation

    footprints = _footprints(world)
    if len(footprints) == 0:
        return
    low_boxes = footprints[footprints[:, 2] < 0.05]
    target = low_boxes[np.argmin(low_boxes[:, 0])] if len(low_boxes) else footprints[np.argmin(footprints[:, 0])]
    size = np.sort(
        world.settings.box_sizes()[rng.integers(len(world.settings.box_sizes()))]
    )  # thin along x, tall along z
    angle = float(rng.uniform(10.0, 30.0))
    rotation = Rotation.from_euler("y", angle, degrees=True)
    signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], dtype=np.float64)
    corners = rotation.apply(signs * size / 2.0)
    y = float(rng.uniform(target[1], target[4]))
    position = [float(target[0] - corners[:, 0].max() - 0.003), y, float(-corners[:, 2].min() + 0.002)]
    if position[0] - size.max() < 0.0:
        return  # no room in front of the wall
    mass = float(rng.uniform(*world.settings.pile.mass_range))
    body = world.add_box(size, position, rotation.as_quat(), mass=mass)
    pile.boxes.append(PileBox(body, size.copy(), mass))


def build_wall(settings: SimulationSettings, *, count: int, seed: int | np.random.SeedSequence) -> Pile:
    """Stack ``count`` boxes as a wall from the back of the section, drop some in front, settle.

    Parameters
    ----------
    settings : SimulationSettings
        ``settings.pile.fallen_share`` of the boxes (in expectation) fall in front.
    count : int
        Boxes in the finished pile.
    seed : int or numpy.random.SeedSequence

    Returns
    -------
    Pile
        Settled, door open; boxes that left the container are replaced by dropped ones.

    Raises
    ------
    InvalidSettings
        The section cannot hold the wall.

    Examples
    --------
    >>> from unstack.sim.settings import family_settings
    >>> with build_wall(family_settings("wall"), count=8, seed=2) as pile:
    ...     len(pile.boxes)
    8
    """
    rng = np.random.default_rng(seed)
    fallen = int(rng.binomial(count, settings.pile.fallen_share)) if count > 2 else 0
    world = PhysicsWorld(settings, door=False)
    pile = Pile(world)
    try:
        for size, centre, yaw in _wall_layout(settings, count - fallen, rng):
            mass = float(rng.uniform(*settings.pile.mass_range))
            body = world.add_box(size, centre, _yaw_xyzw(yaw), mass=mass)
            pile.boxes.append(PileBox(body, size.copy(), mass))
        world.settle()
        for _ in range(int(rng.binomial(fallen, 0.5))):
            _lean_on_wall(world, pile, rng)
        world.settle()
        world.close_door()
        for round_index in range(settings.pile.max_refills + 1):
            while len(pile.boxes) < count:
                if _drop_wave(world, pile, count - len(pile.boxes), rng) == 0:
                    break
                world.settle()
            world.open_door()
            world.settle()
            if delete_fallen(world, pile):
                world.settle()
            if len(pile.boxes) == count:
                pile.refills = round_index
                return pile
            world.close_door()
        raise InvalidSettings(f"could not stack a wall of {count} boxes within {settings.pile.max_refills} refills")
    except BaseException:
        world.close()
        raise
