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

Settings read from a file are checked field by field, with the file and JSON path in the
error (:func:`settings_from_json`).
"""

from __future__ import annotations

import dataclasses
import numbers
import typing
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from unstack.checks import finite_number, number_text
from unstack.errors import InvalidArgument, InvalidFile, InvalidScene, UnstackError

__all__ = [
    "ARRANGEMENTS",
    "DISPLACEMENT_THRESHOLD",
    "FAMILIES",
    "MIN_PILE_BOXES",
    "ROTATION_THRESHOLD_DEG",
    "SIZE_SETS",
    "Container",
    "GroundTruthSettings",
    "InvalidSettings",
    "PileSettings",
    "SensorSettings",
    "SimulationSettings",
    "check_setting",
    "family_settings",
    "scene_settings",
    "settings_from_json",
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
#: A data set's piles hold at least this many boxes: a pile of one box supports nothing.
MIN_PILE_BOXES = 2
#: ... or turned more than this (degrees).
ROTATION_THRESHOLD_DEG = 5.0


@dataclass(frozen=True)
class GroundTruthSettings:
    """Support by removal: X supports Y when taking X away makes Y move.

    The ``ground_truth`` of :class:`SimulationSettings`; the same thresholds say which boxes a
    pick moved in the unloading experiments and in physics on the belief.

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
        def refuse(where: str, message: str) -> typing.NoReturn:
            raise InvalidSettings(f"{where}: {message}")

        _values(SimulationSettings, json_ready(dataclasses.asdict(self)), "settings", refuse)
        _check_pairs(self.pile, self.sensor, "settings", refuse)
        low, high = self.boxes
        if low > high:
            raise InvalidSettings(
                f"settings.boxes: the range {low}-{high} is reversed; expected LOW-HIGH with LOW <= HIGH"
            )
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
        sizes = self.box_sizes()
        if np.any(sizes.min(axis=1) > min(container.depth, container.width)) or np.any(
            sizes.min(axis=1) > container.height
        ):
            raise InvalidSettings(
                f"boxes of size set {self.sizes!r} do not all fit a {container.depth:g} x {container.width:g} x "
                f"{container.height:g} m container (depth x width x height): one's smallest edge is "
                f"{sizes.min(axis=1).max():g} m"
            )
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
        """Inverse of :meth:`to_dict`, every field checked (:func:`settings_from_json`)."""
        return settings_from_json(data)


#: The settings classes by name, for :func:`check_setting`.
_PARTS: dict[str, type] = {
    part.__name__: part for part in (Container, PileSettings, GroundTruthSettings, SensorSettings, SimulationSettings)
}
#: What a settings field (``Class.field``) may hold beyond its type: ``"positive"``, ``"at least
#: 0"``, ``"at least 1"``, ``(low, high)`` with both ends in, ``"extent"`` and ``"coordinate"``
#: (within :data:`MAX_EXTENT`), ``"time step"`` (:data:`TIME_STEPS`). Bounds that keep
#: a physics world sane and its run finite: a coarser step lets boxes pass through each other,
#: a horizon of hours or an image of a billion pixels is a typing slip, not a setting.
FIELD_LIMITS: dict[str, Any] = {
    "Container.depth": "extent", "Container.width": "extent", "Container.height": "extent",
    "PileSettings.wave_size": (1, 1000), "PileSettings.max_tilt_deg": (0.0, 90.0),
    "PileSettings.mass_range": (0.01, 1000.0), "PileSettings.friction": (0.0, 10.0),
    "PileSettings.time_step": "time step", "PileSettings.settle_window": (0.001, 10.0),
    "PileSettings.settle_displacement": "positive", "PileSettings.settle_rotation_deg": "positive",
    "PileSettings.settle_windows": (1, 100), "PileSettings.settle_max_time": (0.001, 60.0),
    "PileSettings.max_refills": (0, 100), "PileSettings.fallen_share": (0.0, 1.0),
    "GroundTruthSettings.horizon": (0.001, 10.0), "GroundTruthSettings.early_exit_after": (0.0, 10.0),
    "GroundTruthSettings.early_exit_speed": "at least 0",
    "GroundTruthSettings.displacement_threshold": (0.0001, 1.0),
    "GroundTruthSettings.rotation_threshold_deg": (0.01, 90.0), "GroundTruthSettings.creep_displacement": "positive",
    "GroundTruthSettings.creep_rotation_deg": "positive",
    "SensorSettings.position": "coordinate", "SensorSettings.target": "coordinate",
    "SensorSettings.vertical_fov_deg": (1.0, 179.0), "SensorSettings.width": (1, 8192),
    "SensorSettings.height": (1, 8192), "SensorSettings.near": "positive", "SensorSettings.far": "positive",
    "SensorSettings.min_pixels": "at least 1", "SensorSettings.position_jitter": (0.0, 1.0),
    "SensorSettings.noise_coefficients": (0.0, 10.0),
    "SimulationSettings.boxes": "at least 1",
}  # fmt: skip
#: The finest and the coarsest physics step a settings file may ask for (seconds; the default is
#: 1/240): a finer one makes a removal's horizon millions of steps, a run that does not end.
TIME_STEPS = (0.0005, 0.02)
#: The largest container extent a settings file may give (metres; a 53-foot trailer is 16 m deep).
MAX_EXTENT = 100.0


def _field_value(value: Any, kind: Any, name: str, where: str, fail: Any) -> Any:
    """One field's value checked against its annotated type and :data:`FIELD_LIMITS`."""
    if typing.get_origin(kind) is tuple:
        items = typing.get_args(kind)
        if not isinstance(value, list | tuple) or len(value) != len(items):
            fail(where, f"expected a list of {len(items)} numbers, got {value!r:.40}")
        return tuple(
            _field_value(item, inner, name, f"{where}[{k}]", fail)
            for k, (item, inner) in enumerate(zip(value, items, strict=True))
        )
    if kind is bool or kind is str:
        if not isinstance(value, kind):
            fail(where, f"expected {'true or false' if kind is bool else 'a string'}, got {value!r:.40}")
        return value
    number = isinstance(value, numbers.Real) and not isinstance(value, bool | np.bool_)
    if number and finite_number(value) is None:  # NaN, an infinity, an integer too large for a float
        fail(where, f"expected a finite number, got {number_text(value):.40}")
    if kind is int and not (number and float(value).is_integer()):
        fail(where, f"expected a whole number, got {value!r:.40}")
    if not number:
        fail(where, f"expected a finite number, got {value!r:.40}")
    limit = FIELD_LIMITS.get(name)
    if limit == "extent" and not 0.0 < value <= MAX_EXTENT:
        fail(where, f"expected a positive extent of at most {MAX_EXTENT:g} m, got {value}")
    if limit == "coordinate" and abs(value) > MAX_EXTENT:
        fail(where, f"expected a coordinate within {MAX_EXTENT:g} m of the door, got {value}")
    if limit == "time step" and not TIME_STEPS[0] <= value <= TIME_STEPS[1]:
        fail(where, f"expected a physics step from {TIME_STEPS[0]:g} to {TIME_STEPS[1]:g} s, got {value}")
    if limit == "positive" and value <= 0:
        fail(where, f"expected a positive number, got {value}")
    if limit in ("at least 0", "at least 1") and value < int(limit[-1]):
        fail(where, f"expected a number {limit}, got {value}")
    if isinstance(limit, tuple) and not limit[0] <= value <= limit[1]:
        fail(where, f"expected a number from {limit[0]:g} to {limit[1]:g}, got {value}")
    return int(value) if kind is int else float(value)


def _values(cls: type, data: Any, where: str, fail: Any) -> dict[str, Any]:
    """The checked field values of a settings dataclass given as a JSON object: unknown keys
    refused, missing ones left to their defaults, parts (nested settings) built."""
    if not isinstance(data, dict):
        fail(where, f"expected an object, got {data!r:.40}")
    kinds = typing.get_type_hints(cls)
    unknown = sorted(set(data) - set(kinds))
    if unknown:
        fail(where, f"unknown key {unknown[0]!r}; expected keys among {', '.join(kinds)}")
    values = {}
    for name, value in data.items():
        kind = kinds[name]
        inner = f"{where}.{name}"
        values[name] = (
            kind(**_values(kind, value, inner, fail))
            if isinstance(kind, type) and dataclasses.is_dataclass(kind)
            else _field_value(value, kind, f"{cls.__name__}.{name}", inner, fail)
        )
    return values


def _check_pairs(pile: PileSettings, sensor: SensorSettings, where: str, fail: Any) -> None:
    """The settings whose limits depend on another field: the mass range's order, far beyond near,
    a box's pixels within the image."""
    if not sensor.near < sensor.far:
        fail(f"{where}.sensor.far", f"expected beyond near ({sensor.near}), got {sensor.far}")
    if sensor.min_pixels > sensor.width * sensor.height:
        fail(
            f"{where}.sensor.min_pixels",
            f"expected at most the image's {sensor.width * sensor.height:,} pixels ({sensor.width} x "
            f"{sensor.height}): no box could be detected, got {sensor.min_pixels:,}",
        )
    low, high = pile.mass_range
    if low > high:
        fail(f"{where}.pile.mass_range", f"expected [low, high] with low <= high, got [{low}, {high}]")


def check_setting(value: Any, field: str) -> Any:
    """One settings field's value checked as in a settings file (:data:`FIELD_LIMITS`).

    Parameters
    ----------
    value : object
    field : str
        ``Class.field``, such as ``"GroundTruthSettings.horizon"``.

    Returns
    -------
    object
        The canonical value (``float``, ``int``, a tuple of them, ``bool`` or ``str``).

    Raises
    ------
    InvalidArgument
        What was expected and what was given (the command line shows it for the option).

    Examples
    --------
    >>> check_setting(2, "GroundTruthSettings.horizon"), check_setting([0, 0.5, 1], "SensorSettings.target")
    (2.0, (0.0, 0.5, 1.0))
    """
    part, name = field.split(".")
    kind = typing.get_type_hints(_PARTS[part])[name]

    def fail(where: str, message: str) -> typing.NoReturn:
        raise InvalidArgument(message)

    return _field_value(value, kind, field, name, fail)


def settings_from_json(
    data: Any, *, source: str = "<settings>", path: str = "$", error: type[InvalidFile] = InvalidFile
) -> SimulationSettings:
    """Simulation settings read from JSON (:meth:`SimulationSettings.to_dict`), every field checked.

    Keys left out take their defaults; an unknown key, a value of the wrong type, a number
    that is not finite or out of its range (:data:`FIELD_LIMITS`) and settings that cannot
    make a pile (:class:`SimulationSettings` refuses them) raise ``error`` with ``source`` and
    the JSON path of the field below ``path``.

    Examples
    --------
    >>> settings_from_json({"pile": {"friction": 0.8}}).pile.friction
    0.8
    >>> settings_from_json({"pile": {"time_step": -1}}, source="a.json", path="$.m")
    Traceback (most recent call last):
    unstack.errors.InvalidFile: a.json: $.m.pile.time_step: expected a physics step from 0.0005 to 0.02 s, got -1
    """

    def fail(where: str, message: str) -> typing.NoReturn:
        raise error(source, where, message)

    values = _values(SimulationSettings, data, path, fail)
    _check_pairs(values.get("pile", PileSettings()), values.get("sensor", SensorSettings()), path, fail)
    try:
        return SimulationSettings(**values)
    except InvalidSettings as refused:
        fail(path, str(refused))


def scene_settings(scene: Any) -> SimulationSettings | None:
    """The simulation settings a scene carries (``metadata.settings``), checked; None without them.

    Raises
    ------
    InvalidScene
        ``metadata.settings`` is there but not valid settings (file and JSON path named).

    Examples
    --------
    >>> import unstack
    >>> scene_settings(unstack.load("examples/pile5.scene.json")).container.depth
    2.0
    >>> scene_settings(unstack.load("examples/leaning.scene.json")) is None
    True
    """
    if "settings" not in scene.metadata:
        return None
    return settings_from_json(
        scene.metadata["settings"], source=scene.source, path="$.metadata.settings", error=InvalidScene
    )


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
