"""Settings of a simulated data set: container, box sizes, piles, ground truth, sensor.

Every number of the simulator is a field here, with the default measured for it (see
the docs page on simulation). Settings are plain frozen dataclasses that round-trip
through JSON, so a data set's manifest records exactly what made it, and a re-run with
other settings into the same folder is refused.

Examples
--------
>>> settings = SimulationSettings(boxes=(10, 20), sizes="four", container=Container(depth=1.0))
>>> settings.box_sizes().shape
(4, 3)
>>> SimulationSettings.from_dict(settings.to_dict()) == settings
True
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from unstack.errors import UnstackError

__all__ = [
    "ARRANGEMENTS",
    "DISPLACEMENT_THRESHOLD",
    "FAMILIES",
    "ROTATION_THRESHOLD_DEG",
    "SIZE_SETS",
    "Container",
    "GroundTruthSettings",
    "InvalidSettings",
    "PileSettings",
    "SensorSettings",
    "SimulationSettings",
    "family_settings",
]

#: Named box-size sets: full edge lengths in metres. ``paper2`` are the paper's two sizes
#: (§V-A1); ``four`` adds two more for the paper's "real" setting (§V-A2).
SIZE_SETS: dict[str, tuple[tuple[float, float, float], ...]] = {
    "paper2": ((0.6, 0.4, 0.4), (0.4, 0.3, 0.3)),
    "four": ((0.6, 0.4, 0.4), (0.4, 0.3, 0.3), (0.5, 0.5, 0.3), (0.3, 0.3, 0.2)),
    "mixed": ((0.8, 0.6, 0.5), (0.6, 0.4, 0.4), (0.4, 0.3, 0.3), (0.5, 0.5, 0.3), (0.3, 0.2, 0.2), (0.25, 0.25, 0.15)),
    # Twelve common carton shapes: large, cubes, flat (a tenth of a metre thick) and small.
    "cartons": (
        (0.8, 0.6, 0.5),
        (0.6, 0.4, 0.4),
        (0.6, 0.4, 0.12),
        (0.5, 0.5, 0.3),
        (0.5, 0.3, 0.25),
        (0.45, 0.35, 0.1),
        (0.4, 0.3, 0.3),
        (0.4, 0.3, 0.15),
        (0.3, 0.3, 0.3),
        (0.3, 0.2, 0.2),
        (0.25, 0.25, 0.15),
        (0.22, 0.16, 0.1),
    ),
}
#: How a pile is made: boxes dropped in waves (the paper's piles), or stacked in columns and
#: rows from the back wall towards the door, as trailers are loaded (see :mod:`unstack.sim.piles`).
ARRANGEMENTS = ("dropped", "wall", "structures")


class InvalidSettings(UnstackError):
    """Simulation settings that cannot produce a data set."""


@dataclass(frozen=True)
class Container:
    """A section of a shipping container; the door is the plane x = 0, x points inward.

    Attributes
    ----------
    depth, width, height : float
        Inner extent along x, y and z in metres.
    """

    depth: float = 2.0
    width: float = 2.35
    height: float = 2.39


@dataclass(frozen=True)
class PileSettings:
    """How a pile is dropped and when it counts as settled.

    Attributes
    ----------
    wave_size : int
        Boxes dropped together in one wave.
    max_tilt_deg : float
        Roll and pitch of a dropped box are uniform in ``±max_tilt_deg``; yaw is uniform.
    mass_range : tuple of float
        Box masses are uniform in this range (kg).
    friction : float
        Lateral friction of boxes and container.
    time_step : float
        Physics step in seconds.
    settle_window : float
        Length of one settle window in seconds.
    settle_displacement : float
        A window is still if no box moved more than this (metres) ...
    settle_rotation_deg : float
        ... nor turned more than this (degrees) during it.
    settle_windows : int
        Still windows in a row that make a pile settled.
    settle_max_time : float
        Cap on one settling phase (seconds of simulated time).
    max_refills : int
        Rounds of "drop, open the door, delete the boxes that fell out" before giving up.
    arrangement : {"dropped", "wall", "structures"}
        Dropped in waves, stacked in columns and rows from the back wall, or set down by
        hand as small structures on the floor (:mod:`unstack.sim.structures`; a key of
        :data:`ARRANGEMENTS`).
    fallen_share : float
        For walls: the expected share of boxes that are not stacked but dropped in front
        of the wall (fallen boxes).
    """

    wave_size: int = 6
    max_tilt_deg: float = 25.0
    mass_range: tuple[float, float] = (5.0, 15.0)
    friction: float = 0.5
    time_step: float = 1.0 / 240.0
    settle_window: float = 0.25
    settle_displacement: float = 0.0005
    settle_rotation_deg: float = 0.1
    settle_windows: int = 2
    settle_max_time: float = 6.0
    max_refills: int = 6
    arrangement: str = "dropped"
    fallen_share: float = 0.1


#: A box that moved more than this (metres) was disturbed: by a removal (ground truth,
#: Section V) or by a pick (unloading, decisions). The one home of the 2 cm threshold.
DISPLACEMENT_THRESHOLD = 0.02
#: ... or turned more than this (degrees).
ROTATION_THRESHOLD_DEG = 5.0


@dataclass(frozen=True)
class GroundTruthSettings:
    """Support by removal: X supports Y when taking X away makes Y move.

    Attributes
    ----------
    horizon : float
        Seconds simulated after a removal.
    early_exit_after : float
        Stop early once this much time has passed ...
    early_exit_speed : float
        ... and every box is slower than this (m/s).
    displacement_threshold : float
        Y is supported by X if it moved more than this (metres) ...
    rotation_threshold_deg : float
        ... or turned more than this (degrees).
    creep_displacement : float
        A pile whose boxes drift more than this without any removal (metres) ...
    creep_rotation_deg : float
        ... or turn more than this (degrees) is settled again.
    """

    horizon: float = 1.0
    early_exit_after: float = 0.15
    early_exit_speed: float = 0.01
    displacement_threshold: float = DISPLACEMENT_THRESHOLD
    rotation_threshold_deg: float = ROTATION_THRESHOLD_DEG
    creep_displacement: float = 0.002
    creep_rotation_deg: float = 0.5


@dataclass(frozen=True)
class SensorSettings:
    """A pinhole range sensor at the door, rendered with pybullet's tiny renderer.

    Attributes
    ----------
    position, target : tuple of float
        Camera centre and the point it looks at (world frame, metres).
    vertical_fov_deg : float
        Vertical field of view.
    width, height : int
        Image size in pixels.
    near, far : float
        Clipping planes (metres).
    noise : bool
        Add depth noise with a Kinect-like model: sigma = a + b (z - c)^2 along each ray.
    noise_coefficients : tuple of float
        ``(a, b, c)`` of that model (metres), from Nguyen, Izadi and Lovell (2012).
    min_pixels : int
        A box is detectable when at least this many pixels see it.
    position_jitter : float
        Each configuration moves the sensor by a uniform offset of up to this much along
        each axis (metres), and its target by half as much: viewpoint variation.
    """

    position: tuple[float, float, float] = (-2.8, 0.0, 1.3)
    target: tuple[float, float, float] = (1.0, 0.0, 0.9)
    vertical_fov_deg: float = 43.0
    width: int = 640
    height: int = 480
    near: float = 0.1
    far: float = 10.0
    noise: bool = False
    noise_coefficients: tuple[float, float, float] = (0.0012, 0.0019, 0.4)
    min_pixels: int = 50
    position_jitter: float = 0.0


@dataclass(frozen=True)
class SimulationSettings:
    """Everything that determines a simulated data set, besides the seed.

    Attributes
    ----------
    boxes : tuple of int
        Inclusive range of the number of boxes per configuration.
    sizes : str
        A key of :data:`SIZE_SETS`.
    container, pile, ground_truth, sensor
        The parts' settings.
    """

    boxes: tuple[int, int] = (30, 40)
    sizes: str = "paper2"
    container: Container = field(default_factory=Container)
    pile: PileSettings = field(default_factory=PileSettings)
    ground_truth: GroundTruthSettings = field(default_factory=GroundTruthSettings)
    sensor: SensorSettings = field(default_factory=SensorSettings)

    def __post_init__(self) -> None:
        low, high = self.boxes
        if low < 1 or high < 1:
            raise InvalidSettings(f"box counts must be positive, got {low}-{high}")
        if low > high:
            raise InvalidSettings(f"box range {low}-{high} is reversed; expected LOW-HIGH with LOW <= HIGH")
        if self.pile.arrangement not in ARRANGEMENTS:
            raise InvalidSettings(
                f"unknown arrangement {self.pile.arrangement!r}; expected one of {', '.join(ARRANGEMENTS)}"
            )
        if not 0.0 <= self.pile.fallen_share < 1.0:
            raise InvalidSettings(f"fallen_share must be in [0, 1), got {self.pile.fallen_share}")
        if not 0.0 <= self.sensor.position_jitter <= 1.0:
            raise InvalidSettings(f"sensor position jitter must be in [0, 1] m, got {self.sensor.position_jitter}")
        if self.sizes not in SIZE_SETS:
            raise InvalidSettings(f"unknown size set {self.sizes!r}; expected one of {', '.join(SIZE_SETS)}")
        container = self.container
        if min(container.depth, container.width, container.height) <= 0:
            raise InvalidSettings(f"container extents must be positive, got {dataclasses.astuple(container)}")
        sizes = self.box_sizes()
        if np.any(sizes.min(axis=1) > min(container.depth, container.width)) or np.any(
            sizes.min(axis=1) > container.height
        ):
            raise InvalidSettings(f"boxes of size set {self.sizes!r} do not fit a {container.depth} m container")
        capacity = self.capacity()
        if high > capacity:
            raise InvalidSettings(
                f"{high} boxes of size set {self.sizes!r} do not fit a {container.depth} x {container.width} x "
                f"{container.height} m container (about {capacity} fit as a loose pile)"
            )

    def box_sizes(self) -> np.ndarray:
        """The size set as a (k, 3) float64 array of full edge lengths."""
        return np.array(SIZE_SETS[self.sizes], dtype=np.float64)

    def capacity(self) -> int:
        """A generous upper bound on the boxes a loose pile fits: a third of the volume."""
        container = self.container
        volume = container.depth * container.width * container.height
        mean_box = float(np.prod(self.box_sizes(), axis=1).mean())
        return int(volume / 3.0 / mean_box)

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON-able dict (tuples become lists)."""
        data: dict[str, Any] = json_ready(dataclasses.asdict(self))
        return data

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> SimulationSettings:
        """Inverse of :meth:`to_dict`."""
        return cls(
            boxes=(int(data["boxes"][0]), int(data["boxes"][1])),
            sizes=data["sizes"],
            container=Container(**data["container"]),
            pile=PileSettings(**_tuples(data["pile"])),
            ground_truth=GroundTruthSettings(**data["ground_truth"]),
            sensor=SensorSettings(**_tuples(data["sensor"])),
        )


def _tuples(data: dict[str, Any]) -> dict[str, Any]:
    return {key: tuple(value) if isinstance(value, list) else value for key, value in data.items()}


def json_ready(value: Any) -> Any:
    """Tuples to lists, recursively, so that a dict compares equal after a JSON round trip."""
    if isinstance(value, dict):
        return {key: json_ready(item) for key, item in value.items()}
    if isinstance(value, list | tuple):
        return [json_ready(item) for item in value]
    return value


#: Pile families: name -> (what it is, the settings that make it). ``unstack simulate
#: --family NAME`` starts from these; explicit options override them.
FAMILIES: dict[str, str] = {
    "dropped": "the paper's piles: 30-40 boxes of two sizes dropped into a 2 m section",
    "four": "20-30 boxes of four sizes dropped into a 2 m section",
    "stacked": "10-16 boxes of four sizes dropped into a narrow 1.0 m x 1.2 m section: high stacks",
    "wall": "20-36 boxes of four sizes stacked in columns and rows from the back wall, as trailers are loaded, "
    "with gaps between columns and some fallen boxes in front",
    "mixed": "20-30 boxes of six sizes (large and small) and masses of 2-25 kg dropped into a 2 m section",
    "staged": "6-14 boxes of twelve carton sizes set down by hand on the floor of a 3 m section: columns, "
    "boxes leaning on columns, bridges across two columns, boxes across two",
}


def family_settings(family: str) -> SimulationSettings:
    """The simulation settings of a pile family (a key of :data:`FAMILIES`).

    Examples
    --------
    >>> family_settings("wall").pile.arrangement
    'wall'
    >>> family_settings("stacked").container.width
    1.2
    """
    if family == "dropped":
        return SimulationSettings()
    if family == "four":
        return SimulationSettings(boxes=(20, 30), sizes="four")
    if family == "stacked":
        return SimulationSettings(boxes=(10, 16), sizes="four", container=Container(depth=1.0, width=1.2))
    if family == "wall":
        return SimulationSettings(
            boxes=(20, 36),
            sizes="four",
            pile=PileSettings(arrangement="wall", max_tilt_deg=3.0),
        )
    if family == "mixed":
        return SimulationSettings(boxes=(20, 30), sizes="mixed", pile=PileSettings(mass_range=(2.0, 25.0)))
    if family == "staged":
        return SimulationSettings(
            boxes=(6, 14),
            sizes="cartons",
            container=Container(depth=3.0),
            pile=PileSettings(arrangement="structures", mass_range=(2.0, 25.0)),
        )
    raise InvalidSettings(f"unknown pile family {family!r}; expected one of {', '.join(FAMILIES)}")
