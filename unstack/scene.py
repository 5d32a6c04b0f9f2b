"""Boxes and scenes: the data model of a pile in a container (``unstack.scene/1``).

Units are metres and kilograms; the world frame has z up and x pointing from the
container door into the container; quaternions are scalar-last ``[x, y, z, w]``.

Examples
--------
>>> from unstack.scene import Box, Scene
>>> floor_box = Box("b1", size=[0.6, 0.4, 0.4], position=[1.0, 0.0, 0.2])
>>> top_box = Box("b2", size=[0.4, 0.3, 0.3], position=[1.0, 0.0, 0.55])
>>> scene = Scene([floor_box, top_box], points=[[0.7, 0.0, 0.5]], detected=["b2", "b1"])
>>> scene.detected
('b2', 'b1')
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from unstack.atomic import atomic_save_array, atomic_write_text
from unstack.checks import (
    MAX_BOX_EDGE,
    MAX_COORDINATE,
    MAX_ID_LENGTH,
    MAX_MASS,
    MIN_BOX_EDGE,
    REFUSED_OVERLAP,
    check_ids,
    check_metadata,
    check_points,
    check_quaternion_xyzw,
    check_vector,
    finite_number,
    long_id,
    number_text,
)
from unstack.errors import InvalidScene
from unstack.frozen import read_only, set_frozen_fields
from unstack.geometry import overlapping_pairs
from unstack.jsonio import Document, read_document, refuse_special_file, validate_document

__all__ = ["MAX_CLOUD_FILE_BYTES", "MAX_POINTS", "SCENE_FORMAT", "Box", "Scene", "load_points", "load_scene"]

SCENE_FORMAT = "unstack.scene/1"
#: Most points a cloud file may hold (``.npy`` files are refused from their header, unread).
MAX_POINTS = 5_000_000
#: Largest point cloud file read, in bytes (a ``.ply`` in ASCII of 5 million points is about 150 MiB).
MAX_CLOUD_FILE_BYTES = 256 * 2**20


def _check_mass(mass: float | None, source: str, path: str) -> float | None:
    """A box's mass as a positive float, or None when not given."""
    if mass is None:
        return None
    number = finite_number(mass)
    if number is None or number <= 0:
        raise InvalidScene(source, path, f"expected a positive, finite number of kg, got {number_text(mass)}")
    if number > MAX_MASS:
        raise InvalidScene(source, path, f"expected at most {MAX_MASS:,.0f} kg (a carton; kg?), got {number:g}")
    return number


def _check_edges(size: np.ndarray, source: str, path: str) -> np.ndarray:
    """Refuse box edges no carton has (the unit is metres)."""
    for k, edge in enumerate(size):
        if not MIN_BOX_EDGE <= edge <= MAX_BOX_EDGE:
            raise InvalidScene(
                source,
                f"{path}[{k}]",
                f"expected a box edge between {MIN_BOX_EDGE:g} and {MAX_BOX_EDGE:g} m (unstack works in metres), "
                f"got {edge:g}",
            )
    return size


def _check_coordinates(values: np.ndarray, source: str, path: str) -> np.ndarray:
    """Refuse coordinates farther than :data:`unstack.checks.MAX_COORDINATE` from the origin."""
    far = np.argwhere(np.abs(values) > MAX_COORDINATE)
    if far.size:
        where = "".join(f"[{k}]" for k in far[0])
        raise InvalidScene(
            source,
            f"{path}{where}",
            f"expected a coordinate within {MAX_COORDINATE:g} m of the origin (unstack works in metres), "
            f"got {values[tuple(far[0])]:g}",
        )
    return values


@dataclass(frozen=True, eq=False)
class Box:
    """A carton box: a cuboid with a pose.

    Parameters
    ----------
    id : str
        Unique in its scene.
    size : array-like, shape (3,)
        Full edge lengths along the box's own axes, metres, all positive.
    position : array-like, shape (3,)
        Centroid in the world frame, metres.
    orientation_xyzw : array-like, shape (4,), optional
        Unit quaternion, scalar last; identity by default. Normalised if within
        :data:`unstack.checks.QUATERNION_NORM_TOLERANCE` of unit norm.
    mass : float, optional
        Kilograms.

    Examples
    --------
    >>> Box("b1", [0.6, 0.4, 0.4], [1.0, 0.0, 0.2]).orientation_xyzw
    array([0., 0., 0., 1.])
    """

    id: str
    size: np.ndarray
    position: np.ndarray
    orientation_xyzw: np.ndarray
    mass: float | None

    def __init__(
        self,
        id: str,  # noqa: A002 - the JSON key
        size: Any,
        position: Any,
        orientation_xyzw: Any = (0.0, 0.0, 0.0, 1.0),
        mass: float | None = None,
        *,
        source: str = "<array>",
        path: str = "$",
    ) -> None:
        if not isinstance(id, str) or not id:
            raise InvalidScene(source, f"{path}.id", f"expected a non-empty string id, got {id!r}")
        if len(id) > MAX_ID_LENGTH:
            raise InvalidScene(source, f"{path}.id", long_id(id))
        set_frozen_fields(  # checked in this order: the first error found is the one raised
            self,
            id=id,
            size=_check_edges(
                check_vector(size, 3, positive=True, source=source, path=f"{path}.size"), source, f"{path}.size"
            ),
            position=_check_coordinates(
                check_vector(position, 3, source=source, path=f"{path}.position"), source, f"{path}.position"
            ),
            orientation_xyzw=check_quaternion_xyzw(orientation_xyzw, source=source, path=f"{path}.orientation_xyzw"),
            mass=_check_mass(mass, source, f"{path}.mass"),
        )

    def to_dict(self) -> dict[str, Any]:
        """The box as a JSON object of ``unstack.scene/1``."""
        data: dict[str, Any] = {
            "id": self.id,
            "size": self.size.tolist(),
            "position": self.position.tolist(),
            "orientation_xyzw": self.orientation_xyzw.tolist(),
        }
        if self.mass is not None:
            data["mass"] = self.mass
        return data


#: A PLY header is read from at most this many first bytes of the file.
MAX_PLY_HEADER = 65_536


def load_points(
    path: str | os.PathLike[str],
    *,
    source: str = "<file>",
    json_path: str = "$.points_file",
    drop_non_finite: bool = False,
) -> np.ndarray:
    """Read a point cloud from ``.npy`` (N x 3 numbers) or ``.ply`` (vertex x, y, z).

    ``.npy`` files are read with ``allow_pickle=False``: loading never runs code. With
    ``drop_non_finite`` the points holding NaN or infinity (a camera's organised cloud marks
    pixels without a reading so) are left out with a warning; else they are refused.

    Raises
    ------
    InvalidScene
        The file is missing, a directory, unreadable or not an N x 3 cloud.
    """
    file = Path(path)
    refuse_special_file(file, InvalidScene, source=source, json_path=json_path)
    if file.is_dir():
        raise InvalidScene(source, json_path, f"expected a point cloud file, got the directory {str(file)!r}")
    if not file.exists():
        raise InvalidScene(source, json_path, f"point cloud file {str(file)!r} does not exist")
    size = file.stat().st_size
    if size > MAX_CLOUD_FILE_BYTES:
        raise InvalidScene(
            source, json_path, f"expected a point cloud file of at most {MAX_CLOUD_FILE_BYTES // 2**20} MiB, "
            f"{file.name!r} has {size / 2**20:,.1f} MiB"
        )  # fmt: skip
    try:
        if file.suffix.lower() == ".npy":
            _refuse_large_npy(file, source, json_path)
            try:
                array = np.load(file, allow_pickle=False)
            except ValueError:  # numpy's words suggest allowing pickle: never, for a user's file
                raise InvalidScene(
                    source, json_path, f"expected a .npy array of N x 3 numbers, {file.name!r} is not one"
                ) from None
        elif file.suffix.lower() == ".ply":
            from plyfile import PlyData

            declared = _ply_vertices(file, source, json_path)  # before plyfile allocates what a header claims
            ply = PlyData.read(str(file))
            if "vertex" not in ply or not {"x", "y", "z"} <= set(ply["vertex"].data.dtype.names or ()):
                raise InvalidScene(source, json_path, f"expected a vertex element with x, y, z in {file.name!r}")
            vertices = ply["vertex"]
            if any(vertices.data.dtype[name].shape or vertices.data.dtype[name].kind == "O" for name in "xyz"):
                raise InvalidScene(source, json_path, f"expected one number per vertex for x, y and z in {file.name!r}")
            array = np.column_stack([vertices["x"], vertices["y"], vertices["z"]])
            if declared is not None and ply.text is False and len(ply.elements) == 1:
                extra = size - declared[1] - vertices.data.dtype.itemsize * len(array)
                if extra:
                    raise InvalidScene(source, json_path, f"{_named(file, source)}the binary data holds {extra:,} "
                                       f"bytes beyond the header's {declared[0]:,} vertices")  # fmt: skip
        else:
            raise InvalidScene(source, json_path, f"expected a .npy or .ply file, got {file.name!r}")
    except InvalidScene:
        raise
    except Exception as error:  # noqa: BLE001 - any reader failure is the file's fault
        raise InvalidScene(source, json_path, f"cannot read point cloud {file.name!r}: {error}") from None
    if array.ndim and len(array) > MAX_POINTS:  # a 0-d array (one number) is refused by check_points
        raise InvalidScene(
            source, json_path, f"expected at most {MAX_POINTS:,} points, {file.name!r} has {len(array):,}"
        )
    if drop_non_finite:
        array = finite_points(array, source)
    return check_points(array, source=source, path=json_path)


def _named(file: Path, source: str) -> str:
    """``file``'s name for a message whose source is another file (a scene naming its cloud)."""
    return "" if source == str(file) else f"{file.name!r}: "


def _ply_vertices(file: Path, source: str, json_path: str) -> tuple[int, int] | None:
    """The vertex count a PLY header declares and where its data starts, refused when the count
    is negative or above :data:`MAX_POINTS`, and, for an ascii file of vertices alone, when the
    data's rows are another count (``None`` without a header plyfile would read)."""
    with file.open("rb") as stream:
        head = stream.read(MAX_PLY_HEADER)
    end = head.find(b"end_header")
    if end < 0:
        return None  # plyfile says what is wrong
    start = head.find(b"\n", end) + 1
    lines = head[:end].decode("ascii", errors="replace").splitlines()
    elements = [line.split() for line in lines if line.startswith("element")]
    counts = {parts[1]: parts[2] for parts in elements if len(parts) == 3}
    named = _named(file, source)
    try:
        declared = int(counts.get("vertex", "0"))
    except ValueError:
        raise InvalidScene(source, json_path, f"{named}expected a vertex count, got {counts['vertex']!r}") from None
    if not 0 <= declared <= MAX_POINTS:
        raise InvalidScene(
            source, json_path, f"{named}expected a vertex count from 0 to {MAX_POINTS:,}, got {declared:,}"
        )
    data_bytes = file.stat().st_size - start
    for name, count in counts.items():  # every row of any element takes a byte at least: plyfile allocates first
        if not count.isdigit():
            raise InvalidScene(
                source, json_path, f"{named}expected a row count of element {name[:40]!r}, got {count[:20]!r}"
            )
        if int(count) > data_bytes:
            raise InvalidScene(source, json_path, f"{named}the header declares {int(count):,} rows of element "
                               f"{name[:40]!r}, more than the {data_bytes:,} bytes of data after it")  # fmt: skip
    ascii_data = any(line.split()[1:2] == ["ascii"] for line in lines if line.startswith("format"))
    if ascii_data and len(elements) == 1:
        rows = sum(1 for line in file.read_bytes()[start:].splitlines() if line.strip())
        if rows != declared:
            raise InvalidScene(source, json_path, f"{named}the header gives {declared:,} vertices, the data {rows:,}")
    return declared, start


def finite_points(cloud: Any, source: str) -> np.ndarray:
    """The points of ``cloud`` whose coordinates are all finite, warning how many were left out
    (a camera's organised cloud marks pixels without a reading with NaN); ``cloud`` as given when
    it is not an N x 3 array of floats (:func:`~unstack.checks.check_points` then says why)."""
    array = np.asarray(cloud)
    if array.ndim != 2 or array.shape[-1:] != (3,) or not np.issubdtype(array.dtype, np.floating):
        return array
    finite = np.all(np.isfinite(array), axis=1)
    if not finite.all():
        warnings.warn(
            f"{source}: {int((~finite).sum()):,} of {len(array):,} points without a finite reading (NaN or infinite) "
            "left out",
            stacklevel=3,
        )
    return array[finite]


def _refuse_large_npy(file: Path, source: str, json_path: str) -> None:
    """Refuse a ``.npy`` cloud of more than :data:`MAX_POINTS` rows from its header, before reading it."""
    with file.open("rb") as handle:
        try:
            version = np.lib.format.read_magic(handle)
            read_header = (
                np.lib.format.read_array_header_1_0 if version == (1, 0) else np.lib.format.read_array_header_2_0
            )
            shape = read_header(handle)[0]  # the header only: no data is read
        except (ValueError, OSError, SyntaxError):
            return  # not a valid header: np.load says so in its own words below
    if shape and shape[0] > MAX_POINTS:
        raise InvalidScene(source, json_path, f"expected at most {MAX_POINTS:,} points, {file.name!r} has {shape[0]:,}")


def _refuse_overlaps(boxes: tuple[Box, ...], source: str) -> None:
    """Two boxes cannot share more than half of the smaller one's volume."""
    pairs = overlapping_pairs(boxes, REFUSED_OVERLAP)
    if pairs:
        i, j, share = pairs[0]
        raise InvalidScene(
            source,
            f"$.boxes[{j}]",
            f"box {boxes[j].id!r} shares {100 * share:.0f} % of the smaller one's volume with box {boxes[i].id!r} "
            f"($.boxes[{i}]); expected boxes that overlap by at most {100 * REFUSED_OVERLAP:.0f} %",
        )


@dataclass(frozen=True, eq=False)
class Scene:
    """A pile of boxes, its point cloud, the detected boxes and optional ground truth.

    Parameters
    ----------
    boxes : sequence of Box
        Every box of the scene; ids unique.
    points : array-like, shape (N, 3)
        The scene's point cloud, world frame (may be empty).
    detected : sequence of str
        Ids of the detected boxes (the ISet), in the reasoner's order.
    ground_truth : array-like, shape (n_boxes, n_boxes), optional
        0/1 support matrix aligned with ``boxes``: ``[i, j] = 1`` iff box i supports box j.
    metadata : dict, optional
        Free-form information kept when saving.
    source : str, optional
        Where the scene came from, for error messages.
    """

    boxes: tuple[Box, ...]
    points: np.ndarray
    detected: tuple[str, ...]
    ground_truth: np.ndarray | None
    metadata: dict[str, Any]
    source: str

    def __init__(
        self,
        boxes: Sequence[Box],
        points: Any,
        detected: Sequence[str],
        ground_truth: Any = None,
        metadata: dict[str, Any] | None = None,
        source: str = "<array>",
        *,
        points_path: str = "$.points",
    ) -> None:
        if isinstance(boxes, str | bytes) or not isinstance(boxes, Iterable):
            raise InvalidScene(source, "$.boxes", f"expected a list of boxes, got {type(boxes).__name__}")
        boxes = tuple(boxes)
        if not boxes:
            raise InvalidScene(source, "$.boxes", "expected at least one box, got an empty list")
        ids: dict[str, int] = {}
        for index, box in enumerate(boxes):
            if not isinstance(box, Box):
                raise InvalidScene(source, f"$.boxes[{index}]", f"expected a Box, got {type(box).__name__} "
                                   "(Scene.from_document and unstack.load read JSON boxes)")  # fmt: skip
            if box.id in ids:
                raise InvalidScene(
                    source, f"$.boxes[{index}].id", f"duplicate id {box.id!r} (also at index {ids[box.id]})"
                )
            ids[box.id] = index
        detected_ids = check_ids(detected, source=source, path="$.detected", error=InvalidScene)
        for index, object_id in enumerate(detected_ids):
            if object_id not in ids:
                raise InvalidScene(
                    source, f"$.detected[{index}]", f"expected the id of a box, got unknown id {object_id!r}"
                )
        truth = None
        if ground_truth is not None:
            from unstack.checks import check_probability_matrix

            truth = check_probability_matrix(
                ground_truth, len(boxes), source=source, path="$.ground_truth.support", error=InvalidScene
            )
            bad = np.argwhere((truth != 0) & (truth != 1))
            if bad.size:
                i, j = bad[0]
                raise InvalidScene(source, f"$.ground_truth.support[{i}][{j}]", f"expected 0 or 1, got {truth[i, j]}")
            truth = read_only(truth, ground_truth)
        cloud = _check_coordinates(check_points(points, source=source, path=points_path), source, points_path)
        cloud = read_only(cloud, points)
        _refuse_overlaps(boxes, source)
        set_frozen_fields(
            self,
            boxes=boxes,
            points=cloud,
            detected=detected_ids,
            ground_truth=truth,
            metadata=check_metadata(metadata, source=source),
            source=source,
        )

    @property
    def box_ids(self) -> tuple[str, ...]:
        """Ids of all boxes, in order."""
        return tuple(box.id for box in self.boxes)

    def box(self, box_id: str) -> Box:
        """The box with this id."""
        for box in self.boxes:
            if box.id == box_id:
                return box
        raise KeyError(f"unknown box id {box_id!r}")

    def detected_ground_truth(self) -> np.ndarray | None:
        """The ground-truth support matrix restricted to the detected boxes, in their order."""
        if self.ground_truth is None:
            return None
        order = [self.box_ids.index(object_id) for object_id in self.detected]
        return self.ground_truth[np.ix_(order, order)]

    def to_dict(self, points_file: str | None = None) -> dict[str, Any]:
        """The ``unstack.scene/1`` JSON object (points inline unless ``points_file`` is given)."""
        data: dict[str, Any] = {"format": SCENE_FORMAT, "boxes": [box.to_dict() for box in self.boxes]}
        if points_file is None:
            data["points"] = self.points.tolist()
        else:
            data["points_file"] = points_file
        data["detected"] = list(self.detected)
        if self.ground_truth is not None:
            data["ground_truth"] = {"support": self.ground_truth.astype(int).tolist()}
        if self.metadata:
            data["metadata"] = self.metadata
        return data

    def save(self, path: str | os.PathLike[str], *, points_file: str | None = None) -> None:
        """Write the scene atomically; with ``points_file`` the cloud goes to that ``.npy`` beside it."""
        from unstack.errors import InvalidArgument
        from unstack.jsonio import document_text

        target = Path(path)
        if points_file is not None:
            cloud_name = Path(points_file)
            if cloud_name.suffix.lower() != ".npy" or os.path.realpath(target.parent / cloud_name) == os.path.realpath(
                target
            ):
                raise InvalidArgument(
                    f"{target}: points_file must name a .npy file beside the scene, not the scene itself; "
                    f"got {points_file!r}"
                )
        advice = "" if points_file else "save the cloud to a .npy file beside it (points_file)"
        text = document_text(self.to_dict(points_file), str(target), advice)
        if points_file is not None:
            cloud_path = target.parent / points_file
            atomic_save_array(cloud_path, self.points)
        atomic_write_text(target, text)

    @classmethod
    def from_document(cls, document: Document) -> Scene:
        """Build from a parsed document: schema first, then the semantic checks."""
        validate_document(document, [SCENE_FORMAT], InvalidScene)
        data = document.data
        source = document.source
        boxes = [
            Box(
                item["id"],
                item["size"],
                item["position"],
                item["orientation_xyzw"],
                item.get("mass"),
                source=source,
                path=f"$.boxes[{index}]",
            )
            for index, item in enumerate(data["boxes"])
        ]
        if "points_file" in data:
            points = load_points(document.base_dir / data["points_file"], source=source)
            points_path = "$.points_file"
        else:
            points = check_points(data["points"], source=source)
            points_path = "$.points"
        truth = data.get("ground_truth", {}).get("support")
        return cls(boxes, points, data["detected"], truth, data.get("metadata"), source, points_path=points_path)


def load_scene(path: str | os.PathLike[str]) -> Scene:
    """Read an ``unstack.scene/1`` file (``"-"`` reads standard input).

    A ``points_file`` is resolved relative to the JSON file (to the working folder for
    standard input).

    Raises
    ------
    InvalidFile
        With the file name, the JSON path and what was expected.
    """
    return Scene.from_document(read_document(path))
