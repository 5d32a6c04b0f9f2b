"""Hand-made canonical scenes: the generalisation suite's kinds, drawn at random.

Each kind builds a small scene a robot engineer might meet on the first day -- a tower, a
bridge, a wall, a staircase, a box leaning on another, load nobody detected, boxes against
the container's walls, a carton kept from tipping by the tall box beside it -- with random
box sizes, gaps, positions and yaw from a seed, so that a test or a check draws as many
variants of a kind as it likes. A scene says which detected boxes may be picked (those that
hold up nothing, detected or not) and which carry load, with how many boxes each holds up.

Examples
--------
>>> case = build_case("tower_beside_free", seed=0)
>>> case.pickable, sorted(case.holds)
(('free', 'top'), ['bottom', 'middle'])
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from unstack.scene import Box

__all__ = ["CANONICAL_KINDS", "CanonicalCase", "build_case"]

#: Where the scenes stand: deep in the container section, centred across it (metres).
ORIGIN_X = 1.3


@dataclass(frozen=True)
class CanonicalCase:
    """One canonical scene with what a right decision must respect.

    Drawn by :func:`build_case`; the generalisation suite checks a decision's first pick
    against ``pickable`` and its expected costs against ``holds``.

    Attributes
    ----------
    kind : str
    boxes : tuple of Box
        Every box, detected or not.
    detected : tuple of str
        The boxes the detector found (the decision's objects).
    pickable : tuple of str
        Detected boxes that hold up nothing: the right first picks.
    holds : dict of str to int
        Detected boxes that hold up others, and how many boxes (detected or not) rest on
        them directly or through others.
    load : dict of str to float
        The same boxes and the load they carry when a box resting on m boxes weighs 1/m
        on each (with what rests on it): ``load(X) = sum over Y on X of (1 + load(Y)) / m_Y``.
        A tower's bottom box carries every box above it; each of two boxes under a bridge
        carries half of it.
    in_container : bool
        Whether the scene stands in a container section (walls, ceiling) or in the open.
    hidden_load : tuple of str
        Detected boxes whose only load is undetected (only the cloud shows it).
    rests_on : dict of str to tuple of str
        The boxes each box rests on directly (the floor: none).
    """

    kind: str
    boxes: tuple[Box, ...]
    detected: tuple[str, ...]
    pickable: tuple[str, ...]
    holds: dict[str, int] = field(default_factory=dict)
    load: dict[str, float] = field(default_factory=dict)
    in_container: bool = True
    hidden_load: tuple[str, ...] = ()
    rests_on: dict[str, tuple[str, ...]] = field(default_factory=dict)


def _yaw(degrees: float) -> list[float]:
    half = np.radians(degrees) / 2.0
    return [0.0, 0.0, float(np.sin(half)), float(np.cos(half))]


class _Builder:
    """Places boxes on the floor or on one another; records who rests on whom."""

    def __init__(self, rng: np.random.Generator, *, max_yaw: float = 3.0) -> None:
        self.rng = rng
        self.max_yaw = max_yaw
        self.boxes: dict[str, Box] = {}
        self.tops: dict[str, float] = {}
        self.rests_on: dict[str, list[str]] = {}

    def size(
        self, low: tuple[float, float, float] = (0.3, 0.25, 0.2), high: tuple[float, float, float] = (0.5, 0.4, 0.35)
    ) -> np.ndarray:
        return self.rng.uniform(low, high)

    def place(
        self, name: str, size: np.ndarray, x: float, y: float, on: list[str] | None = None, yaw: float | None = None
    ) -> str:
        """Put a box with its bottom on the floor or on the highest top of the boxes ``on``."""
        on = on or []
        bottom = max((self.tops[other] for other in on), default=0.0)
        yaw_deg = float(self.rng.uniform(-self.max_yaw, self.max_yaw)) if yaw is None else yaw
        self.boxes[name] = Box(name, size, [x, y, bottom + size[2] / 2.0 + 0.001], _yaw(yaw_deg))
        self.tops[name] = bottom + float(size[2]) + 0.001
        self.rests_on[name] = list(on)
        return name

    def column(self, prefix: str, x: float, y: float, levels: int, size: np.ndarray | None = None) -> list[str]:
        names: list[str] = []
        for level in range(levels):
            box_size = self.size() if size is None else size
            jitter = self.rng.uniform(-0.02, 0.02, size=2)
            names.append(self.place(f"{prefix}{level}", box_size, x + jitter[0], y + jitter[1], names[-1:]))
        return names

    def held(self, name: str) -> set[str]:
        """Every box resting on ``name``, directly or through others."""
        above = {other for other, under in self.rests_on.items() if name in under}
        for other in list(above):
            above |= self.held(other)
        return above

    def carried(self, name: str) -> float:
        """The load on ``name`` when each box weighs equally on the boxes it rests on."""
        return sum((1.0 + self.carried(other)) / len(under) for other, under in self.rests_on.items() if name in under)

    def case(self, kind: str, *, detected: list[str] | None = None, in_container: bool = True) -> CanonicalCase:
        names = list(self.boxes)
        chosen = names if detected is None else detected
        holds = {name: len(self.held(name)) for name in chosen if self.held(name)}
        hidden = tuple(sorted(name for name in holds if not (self.held(name) & set(chosen))))
        return CanonicalCase(
            kind=kind,
            boxes=tuple(self.boxes.values()),
            detected=tuple(chosen),
            pickable=tuple(sorted(name for name in chosen if name not in holds)),
            holds=holds,
            load={name: self.carried(name) for name in holds},
            in_container=in_container,
            hidden_load=hidden,
            rests_on={name: tuple(under) for name, under in self.rests_on.items()},
        )


def _plain_stack(builder: _Builder, in_container: bool) -> CanonicalCase:
    builder.column("s", ORIGIN_X, 0.0, int(builder.rng.integers(3, 5)))
    return builder.case("plain_stack", in_container=in_container)


def _tower_beside_free(builder: _Builder, in_container: bool) -> CanonicalCase:
    y = float(builder.rng.uniform(0.35, 0.6))
    size = builder.size()
    bottom = builder.place("bottom", size, ORIGIN_X, -y / 2)
    middle = builder.place("middle", builder.size(), ORIGIN_X, -y / 2, [bottom])
    builder.place("top", builder.size(), ORIGIN_X, -y / 2, [middle])
    builder.place("free", builder.size(), ORIGIN_X, y / 2 + 0.15)
    return builder.case("tower_beside_free", in_container=in_container)


def _bridge(builder: _Builder, in_container: bool) -> CanonicalCase:
    levels = int(builder.rng.integers(1, 3))
    size = builder.size((0.3, 0.3, 0.25), (0.4, 0.35, 0.3))
    gap = float(builder.rng.uniform(0.1, 0.25))
    offset = (size[1] + gap) / 2.0
    left = builder.column("left", ORIGIN_X, -offset, levels, size)
    right = builder.column("right", ORIGIN_X, offset, levels, size)
    span = np.array([size[0], 2 * offset + size[1] * 0.8, float(builder.rng.uniform(0.2, 0.3))])
    builder.place("bridge", span, ORIGIN_X, 0.0, [left[-1], right[-1]])
    return builder.case("bridge", in_container=in_container)


def _wall(builder: _Builder, in_container: bool) -> CanonicalCase:
    columns, rows = int(builder.rng.integers(3, 5)), int(builder.rng.integers(2, 4))
    size = builder.size((0.35, 0.3, 0.25), (0.45, 0.4, 0.35))
    for column in range(columns):
        y = (column - (columns - 1) / 2.0) * (size[1] + float(builder.rng.uniform(0.01, 0.05)))
        builder.column(f"c{column}r", ORIGIN_X, y, rows, size)
    return builder.case("wall", in_container=in_container)


def _staircase(builder: _Builder, in_container: bool) -> CanonicalCase:
    size = builder.size((0.35, 0.3, 0.25), (0.45, 0.4, 0.3))
    for step in range(3):
        builder.column(f"step{step}_", ORIGIN_X, (step - 1) * (size[1] + 0.04), step + 1, size)
    return builder.case("staircase", in_container=in_container)


def _pyramid(builder: _Builder, in_container: bool) -> CanonicalCase:
    size = builder.size((0.3, 0.3, 0.22), (0.4, 0.35, 0.3))
    gap = float(builder.rng.uniform(0.04, 0.12))
    pitch = size[1] + gap
    base = [builder.place(f"base{k}", size, ORIGIN_X, (k - 1) * pitch) for k in range(3)]
    middle = [builder.place(f"mid{k}", size, ORIGIN_X, (k - 0.5) * pitch, [base[k], base[k + 1]]) for k in range(2)]
    builder.place("apex", size, ORIGIN_X, 0.0, middle)
    return builder.case("pyramid", in_container=in_container)


def _in_front_of_column(builder: _Builder, in_container: bool) -> CanonicalCase:
    size = builder.size()
    builder.column("col", ORIGIN_X + 0.2, 0.0, int(builder.rng.integers(2, 4)), size)
    front = builder.size((0.3, 0.3, 0.2), (0.4, 0.4, 0.35))
    builder.place(
        "front", front, ORIGIN_X + 0.2 - size[0] / 2 - front[0] / 2 - float(builder.rng.uniform(0.02, 0.1)), 0.0
    )
    return builder.case("in_front_of_column", in_container=in_container)


def _wide_on_cubes(builder: _Builder, in_container: bool) -> CanonicalCase:
    count = int(builder.rng.integers(2, 5))
    cube = float(builder.rng.uniform(0.2, 0.3))
    spacing = cube + float(builder.rng.uniform(0.05, 0.15))
    rows = 2 if count > 2 else 1
    cubes = []
    for k in range(count):
        x = ORIGIN_X + ((k // 2) - (rows - 1) / 2) * spacing
        cubes.append(builder.place(f"cube{k}", np.array([cube, cube, cube]), x, (k % 2 - 0.5) * spacing))
    extent = [
        spacing * rows + cube * 0.6 - (rows == 1) * spacing,
        spacing + cube * 0.6,
        float(builder.rng.uniform(0.08, 0.15)),
    ]
    builder.place("wide", np.array(extent), ORIGIN_X, 0.0, cubes)
    return builder.case("wide_on_cubes", in_container=in_container)


def _tall_alone(builder: _Builder, in_container: bool) -> CanonicalCase:
    tall = np.array([0.3, 0.3, float(builder.rng.uniform(0.7, 1.0))])
    builder.place("tall", tall, ORIGIN_X, -0.4)
    bottom = builder.place("low", builder.size(), ORIGIN_X, 0.3)
    builder.place("on_low", builder.size(), ORIGIN_X, 0.3, [bottom])
    return builder.case("tall_alone", in_container=in_container)


def _reach_below(section: np.ndarray, height: float) -> float:
    """The largest x of a convex xz section (its corners) at heights up to ``height``."""
    from unstack.geometry import convex_hull_2d

    hull = convex_hull_2d(section)
    reach = [float(x) for x, z in hull if z <= height]
    for (x0, z0), (x1, z1) in zip(hull, np.roll(hull, -1, axis=0), strict=True):
        if (z0 - height) * (z1 - height) < 0:  # the edge crosses the height
            reach.append(float(x0 + (x1 - x0) * (height - z0) / (z1 - z0)))
    return max(reach)


def _leaning(builder: _Builder, in_container: bool) -> CanonicalCase:
    wall_size = np.array([0.4, 0.5, float(builder.rng.uniform(0.5, 0.7))])
    builder.place("upright", wall_size, ORIGIN_X + 0.3, 0.0)
    lean = np.array([0.15, 0.4, float(builder.rng.uniform(0.5, 0.7))])
    # Tipped past its corner's angle (by 4 degrees at least), or it would right itself.
    corner = np.degrees(np.arctan2(lean[0], lean[2]))
    angle = np.radians(max(float(builder.rng.uniform(15.0, 25.0)), corner + 4.0))
    # Rotated about y so that its top tips towards +x onto the upright box's front face.
    quaternion = [0.0, float(np.sin(angle / 2)), 0.0, float(np.cos(angle / 2))]
    from unstack.geometry import box_corners

    corners = box_corners(Box("lean", lean, [0.0, 0.0, 0.0], quaternion))
    lift = -float(corners[:, 2].min()) + 0.001  # its lowest edge on the floor
    front_face = ORIGIN_X + 0.3 - wall_size[0] / 2
    # It touches the upright box's front face, or that face's top edge when it is the taller.
    reach = _reach_below(corners[:, [0, 2]] + [0.0, lift], builder.tops["upright"])
    position = [front_face - reach - 0.002, 0.0, lift]
    builder.boxes["lean"] = Box("lean", lean, position, quaternion)
    builder.tops["lean"] = position[2] + float(corners[:, 2].max())
    builder.rests_on["lean"] = ["upright"]
    builder.place("free", builder.size(), ORIGIN_X, -0.6)
    return builder.case("leaning", in_container=in_container)


def _turned(builder: _Builder, in_container: bool) -> CanonicalCase:
    yaw = float(builder.rng.uniform(30.0, 45.0)) * (1 if builder.rng.random() < 0.5 else -1)
    size = builder.size((0.4, 0.35, 0.25), (0.5, 0.45, 0.35))
    bottom = builder.place("turned_bottom", size, ORIGIN_X, -0.3, yaw=yaw)
    builder.place("turned_top", builder.size((0.3, 0.25, 0.2), (0.35, 0.3, 0.3)), ORIGIN_X, -0.3, [bottom],
                  yaw=yaw + float(builder.rng.uniform(-15, 15)))  # fmt: skip
    builder.place("turned_free", builder.size(), ORIGIN_X, 0.4, yaw=-yaw)
    return builder.case("turned", in_container=in_container)


def _side_by_side(builder: _Builder, in_container: bool) -> CanonicalCase:
    size = builder.size()
    for k in range(int(builder.rng.integers(2, 4))):
        builder.place(f"side{k}", size, ORIGIN_X, (k - 1) * (size[1] + 0.001), yaw=0.0)
    return builder.case("side_by_side", in_container=in_container)


def _hidden_load(builder: _Builder, in_container: bool) -> CanonicalCase:
    loaded = builder.place("loaded", builder.size(), ORIGIN_X, -0.3)
    builder.place("unseen", builder.size(), ORIGIN_X, -0.3, [loaded])
    builder.place("free", builder.size(), ORIGIN_X, 0.35)
    return builder.case("hidden_load", detected=["loaded", "free"], in_container=in_container)


def _hidden_middle(builder: _Builder, in_container: bool) -> CanonicalCase:
    size = builder.size()
    names = builder.column("h", ORIGIN_X, -0.3, 3, size)
    builder.place("free", builder.size(), ORIGIN_X, 0.35)
    return builder.case("hidden_middle", detected=[names[0], names[2], "free"], in_container=in_container)


def _across_two(builder: _Builder, in_container: bool) -> CanonicalCase:
    size = builder.size((0.3, 0.25, 0.25), (0.4, 0.3, 0.35))
    pitch = size[1] + float(builder.rng.uniform(0.0, 0.05))
    left = builder.place("under_left", size, ORIGIN_X, -pitch / 2)
    right = builder.place("under_right", size, ORIGIN_X, pitch / 2)
    builder.place("across", builder.size((0.35, 0.4, 0.2), (0.45, 0.5, 0.3)), ORIGIN_X, 0.0, [left, right])
    return builder.case("across_two", in_container=in_container)


def _mixed_sizes(builder: _Builder, in_container: bool) -> CanonicalCase:
    big = builder.place("big", np.array([0.7, 0.6, 0.5]), ORIGIN_X + 0.1, -0.35)
    small = builder.place("small_on_big", np.array([0.25, 0.2, 0.15]), ORIGIN_X + 0.1, -0.35, [big])
    builder.place("tiny_on_small", np.array([0.2, 0.15, 0.12]), ORIGIN_X + 0.1, -0.35, [small])
    builder.place("flat", np.array([0.5, 0.4, 0.1]), ORIGIN_X, 0.4)
    return builder.case("mixed_sizes", in_container=in_container)


def _against_the_walls(builder: _Builder, in_container: bool) -> CanonicalCase:
    from unstack.sim.settings import Container

    container = Container()

    def touching(name: str, size: np.ndarray, y: float, on: list[str] | None = None) -> str:
        """Place a box turned a little about z with its deepest corner on the back wall."""
        yaw = float(builder.rng.uniform(-builder.max_yaw, builder.max_yaw))
        turn = np.radians(yaw)
        half_depth = (size[0] * np.cos(turn) + size[1] * abs(np.sin(turn))) / 2.0
        return builder.place(name, size, container.depth - half_depth, y, on, yaw=yaw)

    bottom = touching("back0", builder.size(), 0.3)
    touching("back1", builder.size((0.3, 0.25, 0.2), (0.45, 0.4, 0.35)), 0.3, [bottom])
    free = builder.size()
    touching("corner", free, -container.width / 2 + free[1] / 2 + 0.02)  # near the side wall too
    return builder.case("against_the_walls", in_container=in_container)


def _overhang(builder: _Builder, in_container: bool) -> CanonicalCase:
    """A carton upright on a short box, its centre past that box's edge, kept from tipping by a
    tall box whose side it touches: the tall box is the highest and holds the carton up."""
    short = builder.size((0.35, 0.25, 0.15), (0.45, 0.35, 0.25))
    builder.place("short", short, ORIGIN_X, -0.35, yaw=0.0)
    carton = builder.size((0.35, 0.45, 0.25), (0.45, 0.55, 0.32))
    # past the short box's edge, by less than pushes the tall box away (physical_check: stable)
    centre = -0.35 + short[1] / 2 + float(builder.rng.uniform(0.05, 0.065))
    tall = np.array([0.45, 0.45, float(builder.rng.uniform(0.75, 0.9))])
    builder.place("tall", tall, ORIGIN_X, centre + carton[1] / 2 + tall[1] / 2 + 0.002, yaw=0.0)
    bottom = builder.tops["short"]
    builder.boxes["carton"] = Box("carton", carton, [ORIGIN_X, centre, bottom + carton[2] / 2 + 0.001], _yaw(0.0))
    builder.tops["carton"] = bottom + float(carton[2]) + 0.001
    builder.rests_on["carton"] = ["short", "tall"]
    builder.place("free", builder.size(), ORIGIN_X, -0.85)
    return builder.case("overhang", in_container=in_container)


#: The kinds of the suite: name -> builder (takes a seeded builder and where the scene stands).
CANONICAL_KINDS: dict[str, Callable[[_Builder, bool], CanonicalCase]] = {
    "plain_stack": _plain_stack,
    "tower_beside_free": _tower_beside_free,
    "bridge": _bridge,
    "wall": _wall,
    "staircase": _staircase,
    "pyramid": _pyramid,
    "in_front_of_column": _in_front_of_column,
    "wide_on_cubes": _wide_on_cubes,
    "tall_alone": _tall_alone,
    "leaning": _leaning,
    "turned": _turned,
    "side_by_side": _side_by_side,
    "hidden_load": _hidden_load,
    "hidden_middle": _hidden_middle,
    "across_two": _across_two,
    "mixed_sizes": _mixed_sizes,
    "against_the_walls": _against_the_walls,
    "overhang": _overhang,
}


def build_case(kind: str, *, seed: int, in_container: bool | None = None) -> CanonicalCase:
    """Draw a scene of ``kind`` (a key of :data:`CANONICAL_KINDS`).

    Parameters
    ----------
    kind : str
    seed : int
        The same seed gives the same scene.
    in_container : bool, optional
        Where it stands; by default drawn from the seed (half and half).

    Returns
    -------
    CanonicalCase
    """
    from unstack.errors import UnstackError

    if kind not in CANONICAL_KINDS:
        raise UnstackError(f"unknown canonical scene kind {kind!r}; expected one of {', '.join(CANONICAL_KINDS)}")
    rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(list(CANONICAL_KINDS).index(kind),)))
    where = bool(rng.random() < 0.5) if in_container is None else in_container
    return CANONICAL_KINDS[kind](_Builder(rng), where)
