"""Staged piles: boxes set down by hand on the floor as small structures, not dropped.

A robot's first scenes are often not a container's dropped pile but boxes put down on
purpose: a column, a box leaning on a column, a long box bridging two columns, a box
resting across two side by side, a box standing alone. ``arrangement="structures"`` builds
such piles: structures of random kind, box sizes (the settings' size set -- ``cartons``
for the ``staged`` family -- each box lying either way round), heights, gaps, tilt and
yaw, each at a random free spot on the section's floor, until the pile holds its boxes.
The pile then settles with the door open (what does not stand falls as physics says); the
ground truth comes from removals, as for every pile.

Kinds (:data:`STRUCTURE_KINDS`): ``column`` (1-4 boxes, each a few centimetres off the one
under it), ``lean`` (a column of 1-3 boxes and a box standing on its end on the floor,
tipped onto the column's face 4-20 degrees past the angle at which it would right itself),
``bridge`` (two columns of equal height, 1-2 boxes, a gap of 5-25 cm, the longest box
across both), ``across`` (two boxes side by side, touching or a few centimetres apart,
one box resting across both).

Examples
--------
>>> from unstack.sim.settings import family_settings
>>> with build_structures(family_settings("staged"), count=6, seed=3) as pile:
...     len(pile.boxes)
6
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from unstack.sim.pile_bodies import Pile, PileBox, delete_fallen
from unstack.sim.settings import Container, InvalidSettings, SimulationSettings
from unstack.sim.world import PhysicsWorld

__all__ = ["STRUCTURE_KINDS", "build_structures"]

#: The kinds of structure a staged pile is made of.
STRUCTURE_KINDS = ("column", "lean", "bridge", "across")
#: Margin kept between a structure and the section's walls and door (metres).
MARGIN = 0.05
#: Free spots tried for each structure before the pile is given up as full.
SPOT_TRIES = 40
#: Largest horizontal offset of a stacked box from the one under it (metres).
STACK_OFFSET = 0.04

#: The corners of a unit box centred at the origin, times a size over 2.
_SIGNS = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], dtype=np.float64)
#: A box in the structure's own frame: size, centre, rotation (about the structure's origin).
_Placed = tuple[np.ndarray, np.ndarray, Rotation]


def _lying(size: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """A box lying on its largest face, either way round (x and y swapped at random)."""
    ordered = np.sort(size)[::-1]
    footprint = ordered[:2] if rng.random() < 0.5 else ordered[1::-1]
    return np.array([footprint[0], footprint[1], ordered[2]])


def _column(sizes: np.ndarray, levels: int, rng: np.random.Generator, y: float = 0.0) -> list[_Placed]:
    placed: list[_Placed] = []
    top = 0.0
    for level in range(levels):
        size = _lying(sizes[rng.integers(len(sizes))], rng)
        offset = rng.uniform(-STACK_OFFSET, STACK_OFFSET, size=2) if level else np.zeros(2)
        yaw = Rotation.from_euler("z", float(rng.uniform(-4.0, 4.0)), degrees=True)
        placed.append((size, np.array([offset[0], y + offset[1], top + size[2] / 2.0 + 0.002]), yaw))
        top += float(size[2]) + 0.002
    return placed


def _lean(sizes: np.ndarray, levels: int, rng: np.random.Generator) -> list[_Placed]:
    """A column and a box standing in front of it (towards -x), tipped onto its face."""
    column = _column(sizes, levels, rng)
    size = np.sort(sizes[rng.integers(len(sizes))])  # thin along x, tall along z
    # Tipped less than its corner's angle, a box rights itself; past it, it leans.
    rights_itself = float(np.degrees(np.arctan2(size[0], size[2])))
    tipped = Rotation.from_euler("y", min(60.0, rights_itself + float(rng.uniform(4.0, 20.0))), degrees=True)
    corners = tipped.apply(_SIGNS * size / 2.0)
    reach = float(corners[:, 2].max() - corners[:, 2].min())  # how high the tipped box reaches
    # It rests on the column's front face: the most protruding box below the height it reaches.
    front = min(
        float((centre + rotation.apply(_SIGNS * box / 2.0))[:, 0].min())
        for box, centre, rotation in column
        if centre[2] - box[2] / 2.0 < reach
    )
    y = float(rng.uniform(-0.5, 0.5)) * float(column[0][0][1]) / 2.0
    centre = np.array([front - float(corners[:, 0].max()) - 0.003, y, -float(corners[:, 2].min()) + 0.002])
    return [*column, (size, centre, tipped)]


def _bridge(sizes: np.ndarray, levels: int, rng: np.random.Generator) -> list[_Placed]:
    """Two columns of the same boxes, a gap between them, the longest box across both."""
    span = np.sort(sizes[np.argmax(sizes.max(axis=1))])[::-1]
    span = np.array([span[1], span[0], span[2]])  # its longest edge across the gap (along y)
    pillars = [_lying(sizes[rng.integers(len(sizes))], rng) for _ in range(levels)]
    width = max(float(size[1]) for size in pillars)
    gap = float(rng.uniform(0.05, max(0.06, min(0.25, float(span[1]) - 1.2 * width))))
    placed: list[_Placed] = []
    for side in (-1.0, 1.0):
        top = 0.0
        for size in pillars:
            yaw = Rotation.from_euler("z", float(rng.uniform(-3.0, 3.0)), degrees=True)
            placed.append((size, np.array([0.0, side * (gap + width) / 2.0, top + size[2] / 2.0 + 0.002]), yaw))
            top += float(size[2]) + 0.002
    placed.append((span, np.array([0.0, 0.0, top + span[2] / 2.0 + 0.002]), Rotation.identity()))
    return placed


def _across(sizes: np.ndarray, rng: np.random.Generator) -> list[_Placed]:
    """Two boxes side by side and one resting across both."""
    under = _lying(sizes[rng.integers(len(sizes))], rng)
    gap = float(rng.uniform(0.0, 0.05))
    placed: list[_Placed] = [
        (under, np.array([0.0, side * (under[1] + gap) / 2.0, under[2] / 2.0 + 0.002]), Rotation.identity())
        for side in (-1.0, 1.0)
    ]
    top = _lying(sizes[rng.integers(len(sizes))], rng)
    yaw = Rotation.from_euler("z", float(rng.uniform(-10.0, 10.0)), degrees=True)
    placed.append((top, np.array([0.0, 0.0, under[2] + top[2] / 2.0 + 0.004]), yaw))
    return placed


def _structure(kind: str, sizes: np.ndarray, rng: np.random.Generator) -> list[_Placed]:
    if kind == "column":
        return _column(sizes, int(rng.integers(1, 5)), rng)
    if kind == "lean":
        return _lean(sizes, int(rng.integers(1, 4)), rng)
    if kind == "bridge":
        return _bridge(sizes, int(rng.integers(1, 3)), rng)
    return _across(sizes, rng)


def _extent(placed: list[_Placed], turn: Rotation) -> np.ndarray:
    """The structure's footprint turned by ``turn``, as an axis-aligned box: min x, min y, max x, max y."""
    corners = np.vstack([turn.apply(centre + rotation.apply(_SIGNS * size / 2.0)) for size, centre, rotation in placed])
    return np.array([*corners[:, :2].min(axis=0), *corners[:, :2].max(axis=0)])


def _free_spot(
    extent: np.ndarray, taken: list[np.ndarray], container: Container, rng: np.random.Generator
) -> np.ndarray | None:
    """A random shift of ``extent`` that keeps it on the floor and clear of ``taken``, or None."""
    depth, width = container.depth, container.width
    low = np.array([MARGIN - extent[0], -width / 2.0 + MARGIN - extent[1]])
    high = np.array([depth - MARGIN - extent[2], width / 2.0 - MARGIN - extent[3]])
    if np.any(low > high):
        return None
    for _ in range(SPOT_TRIES):
        shift = rng.uniform(low, high)
        box = extent + np.concatenate([shift, shift])
        if all(
            box[0] > other[2] + MARGIN or box[2] < other[0] - MARGIN or box[1] > other[3] + MARGIN
            or box[3] < other[1] - MARGIN
            for other in taken
        ):  # fmt: skip
            return shift
    return None


def build_structures(settings: SimulationSettings, *, count: int, seed: int | np.random.SeedSequence) -> Pile:
    """Set ``count`` boxes down as structures on the section's floor and let them settle.

    Parameters
    ----------
    settings : SimulationSettings
        The section and the size set; ``settings.pile`` settles the pile.
    count : int
        Boxes in the finished pile (the last structure is cut short to fit).
    seed : int or numpy.random.SeedSequence
        The same seed and settings give bit-identical poses.

    Returns
    -------
    Pile
        Settled, with the door open and the world alive.

    Raises
    ------
    InvalidSettings
        The floor has no room for ``count`` boxes, or boxes left the section.
    """
    rng = np.random.default_rng(seed)
    container = settings.container
    sizes = settings.box_sizes()
    world = PhysicsWorld(settings, door=False)
    pile = Pile(world)
    taken: list[np.ndarray] = []
    try:
        while len(pile.boxes) < count:
            left = count - len(pile.boxes)
            placed = _structure(STRUCTURE_KINDS[int(rng.integers(len(STRUCTURE_KINDS)))], sizes, rng)[:left]
            # Square to the section, give or take 10 degrees: structures pack as a robot finds them.
            yaw_deg = float(rng.integers(4)) * 90.0 + float(rng.uniform(-10.0, 10.0))
            turn = Rotation.from_euler("z", yaw_deg, degrees=True)
            extent = _extent(placed, turn)
            shift = _free_spot(extent, taken, container, rng)
            if shift is None:  # no room for it: a column of what is left, up to 4 boxes
                placed = _column(sizes, min(left, 4), rng)
                extent = _extent(placed, turn)
                shift = _free_spot(extent, taken, container, rng)
            if shift is None:
                raise InvalidSettings(
                    f"no room on a {container.depth} m x {container.width} m floor for {count} staged boxes "
                    f"(placed {len(pile.boxes)})"
                )
            taken.append(extent + np.concatenate([shift, shift]))
            for size, centre, rotation in placed:
                position = turn.apply(centre) + np.array([shift[0], shift[1], 0.0])
                mass = float(rng.uniform(*settings.pile.mass_range))
                body = world.add_box(size, position, (turn * rotation).as_quat(), mass=mass)
                pile.boxes.append(PileBox(body, size.copy(), mass))
        world.settle()
        if delete_fallen(world, pile):
            raise InvalidSettings("a staged box left the section while settling")
        return pile
    except BaseException:
        world.close()
        raise
