"""A point cloud and box detections, as a 3-D detector hands them over (issue 36, part 1b).

* :func:`load_cloud` reads ``.npy`` and ``.ply`` (through :func:`unstack.scene.load_points`) and
  ``.pcd`` (the Point Cloud Library's format, ASCII or binary; ``binary_compressed`` is refused
  in one line: convert it with ``pcl_convert_pcd_ascii_binary``);
* :func:`load_detections` reads boxes ``{"id", "center", "size", "yaw_deg"}`` (or
  ``"orientation_xyzw"`` instead of the yaw) in the cloud's frame, a list or ``{"boxes": [...]}``;
* :func:`scene_from_cloud` finds gravity and the floor from the cloud's horizontal planes
  (:func:`unstack.camera.planes.gravity_frame`), moves cloud and boxes into that frame and
  levels each box that stands within :data:`~unstack.camera.boxes.TILT_MIN_DEG` of upright in
  the detector's frame or in the gravity frame: a detector's frame tilted against gravity tilts
  its boxes with it (or a detector reports boxes upright in its own frame), so only each box's
  heading about the gravity frame's z is kept. A box given tilted further than that in both
  frames (as a box dropped on others lies) keeps its whole orientation, in the gravity frame.

Examples
--------
>>> rng = np.random.default_rng(0)
>>> floor = np.column_stack([rng.uniform(-1, 1, 3000), rng.uniform(-1, 1, 3000), np.zeros(3000)])
>>> built = scene_from_cloud(floor, [{"id": "a", "center": [0, 0, 0.15], "size": [0.4, 0.3, 0.3], "yaw_deg": 30}])
>>> built.scene.detected, round(float(built.scene.box("a").position[2]), 2)
(('a',), 0.15)
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from unstack.camera.build import CameraScene
from unstack.camera.files import read_json_file
from unstack.camera.planes import check_gravity, gravity_frame
from unstack.checks import check_quaternion_xyzw, check_vector, finite_number, number_text
from unstack.errors import InvalidFile, UnstackError
from unstack.jsonio import refuse_special_file
from unstack.scene import Box, Scene

__all__ = ["load_cloud", "load_detections", "scene_from_cloud"]

#: The largest yaw a detection may give (degrees, either way): ten turns; beyond, a typing slip.
MAX_YAW_DEG = 3600.0
#: A cloud whose points reach further than this from the origin (median) holds no coordinates in
#: metres, nor in millimetres of a container: a byte order or field mix-up.
MILLIMETRE_CLOUD = 1e5
#: What a detection is read from (the yaw or the quaternion, not both).
DETECTION_KEYS = ("id", "center", "size", "yaw_deg", "orientation_xyzw")
_PCD_TYPES = {("F", 4): "<f4", ("F", 8): "<f8", ("I", 1): "<i1", ("I", 2): "<i2", ("I", 4): "<i4",
              ("U", 1): "<u1", ("U", 2): "<u2", ("U", 4): "<u4"}  # fmt: skip


def _load_pcd(file: Path) -> np.ndarray:
    source = str(file)
    raw = file.read_bytes()
    header: dict[str, list[str]] = {}
    offset = 0
    while True:
        end = raw.find(b"\n", offset)
        if end < 0:
            raise InvalidFile(source, "$", "expected a PCD header ending with a DATA line")
        line = raw[offset:end].decode("ascii", errors="replace").strip()
        offset = end + 1
        if not line or line.startswith("#"):
            continue
        key, *values = line.split()
        if key.upper() in header:
            raise InvalidFile(source, "$", f"the PCD header gives {key.upper()} twice")
        header[key.upper()] = values
        if key.upper() == "DATA":
            break
    try:
        fields = header["FIELDS"]
        sizes = [int(value) for value in header["SIZE"]]
        types = header["TYPE"]
        counts = [int(value) for value in header.get("COUNT", ["1"] * len(fields))]
        points = int(header["POINTS"][0])
        data = header["DATA"][0].lower()
    except (KeyError, IndexError, ValueError):
        raise InvalidFile(source, "$", "expected a PCD header with FIELDS, SIZE, TYPE, POINTS and DATA") from None
    if not {"x", "y", "z"} <= set(fields):
        raise InvalidFile(source, "$", f"expected the fields x, y and z, got {' '.join(fields)}")
    if not len(sizes) == len(types) == len(counts) == len(fields) or min(counts) < 1:
        raise InvalidFile(
            source, "$", f"expected one SIZE, TYPE and COUNT (at least 1) for each of the {len(fields)} FIELDS"
        )
    if points < 0:
        raise InvalidFile(source, "$", f"expected a POINTS count of at least 0, got {points}")
    columns = np.cumsum([0, *counts])
    if data == "ascii":
        rows = [line for line in raw[offset:].decode("ascii", errors="replace").splitlines() if line.strip()]
        if len(rows) != points:
            raise InvalidFile(source, "$", f"the header gives {points} POINTS, the ascii data holds {len(rows)} rows")
        _check_pcd_layout(header, points, source)
        if points == 0:
            return np.zeros((0, 3))
        try:
            table = np.loadtxt(rows, ndmin=2)
        except ValueError:
            raise InvalidFile(source, "$", f"expected ascii rows of {columns[-1]} numbers each") from None
        if table.shape[1] != columns[-1]:
            raise InvalidFile(source, "$", f"expected ascii rows of {columns[-1]} numbers each, got {table.shape[1]}")
        picked = [table[:, columns[fields.index(name)]] for name in ("x", "y", "z")]
        return np.column_stack(picked)
    if data != "binary":
        raise InvalidFile(source, "$", f"PCD data {data!r} is not read; save the cloud as ascii or binary PCD")
    unknown = [f"{kind}{size}" for kind, size in zip(types, sizes, strict=True) if (kind, size) not in _PCD_TYPES]
    if unknown:
        read = ", ".join(f"{kind}{size}" for kind, size in _PCD_TYPES)
        raise InvalidFile(source, "$", f"expected PCD fields of TYPE and SIZE {read}, got {unknown[0]}")
    # positional names: PCL pads with fields all called "_"; x, y and z are their first fields of that name
    kinds = [_PCD_TYPES[(kind, size)] for kind, size in zip(types, sizes, strict=True)]
    dtype = np.dtype([(f"f{k}", kind, (count,)) if count > 1 else (f"f{k}", kind)
                      for k, (kind, count) in enumerate(zip(kinds, counts, strict=True))])  # fmt: skip
    held = (len(raw) - offset) // dtype.itemsize
    if held < points:
        raise InvalidFile(source, "$", f"the header gives {points} POINTS, the binary data holds {held}")
    _check_pcd_layout(header, points, source)
    records = np.frombuffer(raw, dtype=dtype, count=points, offset=offset)
    picked = [records[f"f{fields.index(name)}"] for name in ("x", "y", "z")]
    with np.errstate(invalid="ignore", over="ignore"):  # garbage (a wrong byte order) becomes NaN, said below
        return np.column_stack([(values[:, 0] if values.ndim == 2 else values).astype(np.float64) for values in picked])


def _check_pcd_layout(header: dict[str, list[str]], points: int, source: str) -> None:
    """WIDTH x HEIGHT must be POINTS; a VIEWPOINT other than the identity is not applied (warned)."""
    try:
        width, height = int(header.get("WIDTH", [str(points)])[0]), int(header.get("HEIGHT", ["1"])[0])
    except (IndexError, ValueError):
        raise InvalidFile(source, "$", "expected whole numbers for the PCD header's WIDTH and HEIGHT") from None
    if width * height != points:
        raise InvalidFile(
            source, "$", f"the PCD header's WIDTH x HEIGHT ({width} x {height}) is not its {points} POINTS"
        )
    viewpoint = header.get("VIEWPOINT", ["0", "0", "0", "1", "0", "0", "0"])
    try:
        identity = [float(value) for value in viewpoint] == [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0]
    except ValueError:
        identity = False
    if not identity:
        given = " ".join(viewpoint)
        warnings.warn(f"{source}: the PCD header's VIEWPOINT {given} is not applied: the points are taken as they "
                      "are (--pose moves a cloud into the container's frame)", stacklevel=3)  # fmt: skip


def load_cloud(path: str | os.PathLike[str]) -> np.ndarray:
    """A point cloud as (N, 3) float64 metres from ``.npy``, ``.ply`` or ``.pcd``; points without a
    finite reading (NaN or infinite) are left out with a warning, in every format."""
    from unstack.checks import check_points
    from unstack.scene import MAX_CLOUD_FILE_BYTES, MAX_POINTS, finite_points, load_points

    file = Path(path)
    if file.suffix.lower() not in (".npy", ".ply", ".pcd"):
        raise InvalidFile(str(file), "$", f"expected a .npy, .ply or .pcd point cloud file, got {file.name!r}")
    if file.suffix.lower() != ".pcd":
        return _in_metres(np.asarray(load_points(file, source=str(file), json_path="$", drop_non_finite=True)), file)
    refuse_special_file(file)
    if not file.is_file():
        raise InvalidFile(str(file), "$", "the point cloud file does not exist")
    size = file.stat().st_size
    if size > MAX_CLOUD_FILE_BYTES:
        raise InvalidFile(
            str(file),
            "$",
            f"expected a point cloud file of at most {MAX_CLOUD_FILE_BYTES // 2**20} MiB, got {size / 2**20:,.1f} MiB",
        )
    cloud = _load_pcd(file)
    if len(cloud) > MAX_POINTS:
        raise InvalidFile(str(file), "$", f"expected at most {MAX_POINTS:,} points, got {len(cloud):,}")
    return _in_metres(check_points(finite_points(cloud, str(file)), source=str(file), path="$"), file)


def _in_metres(cloud: np.ndarray, file: Path) -> np.ndarray:
    """``cloud`` when its points lie within :data:`~unstack.checks.MAX_COORDINATE` of the
    origin, as a scene's must; otherwise one line saying what the values look like."""
    from unstack.checks import MAX_COORDINATE

    if len(cloud) == 0:
        return cloud
    reach = np.abs(cloud).max(axis=1)
    far = reach > MAX_COORDINATE
    if not far.any():
        return cloud
    typical = float(np.median(reach))
    if typical > MILLIMETRE_CLOUD:
        hint = "no coordinates in metres: the wrong byte order, or fields other than x, y and z?"
    elif typical > MAX_COORDINATE / 10:
        hint = "a cloud in millimetres? unstack works in metres"
    else:
        hint = "points further away than any container: leave them out"
    raise InvalidFile(
        str(file),
        "$",
        f"{int(far.sum()):,} of {len(cloud):,} points lie beyond {MAX_COORDINATE:g} m of the origin (the points' "
        f"median reach {typical:,.4g}): {hint}",
    )


def load_detections(path: str | os.PathLike[str]) -> list[dict[str, Any]]:
    """Box detections from JSON (see the module docstring), checked field by field; keys other
    than a box's are left out (with a warning)."""
    data, source = read_json_file(path, "detections file")
    base = "$"
    if isinstance(data, dict):
        others = sorted(str(key) for key in data if key != "boxes")
        if others:
            warnings.warn(f"{source}: keys passed over (the boxes are read from 'boxes' alone): {', '.join(others)}",
                          stacklevel=2)  # fmt: skip
        data, base = data.get("boxes"), "$.boxes"
    if not isinstance(data, list) or not data:
        raise InvalidFile(source, base, "expected a non-empty list of boxes {id, center, size, yaw_deg}")
    check_detections(data, source=source, base=base)
    return [{key: value for key, value in item.items() if key in DETECTION_KEYS} for item in data]


def check_detections(detections: Sequence[Any], *, source: str = "<detections>", base: str = "$") -> None:
    """Raise :class:`~unstack.errors.InvalidFile` at the first detection that is not a box.

    Keys other than a box's (a detector's ``score`` or ``label``) are passed over, with one
    warning naming them.
    """
    seen = set()
    ignored: set[str] = set()
    for index, item in enumerate(detections):
        where = f"{base}[{index}]"
        if not isinstance(item, dict) or not isinstance(item.get("id"), str) or not item["id"]:
            raise InvalidFile(source, where, "expected an object with a non-empty string id")
        if item["id"] in seen:
            raise InvalidFile(source, f"{where}.id", f"box id {item['id']!r} appears twice")
        seen.add(item["id"])
        for name in ("center", "size"):
            if name not in item:
                raise InvalidFile(source, f"{where}.{name}", "expected 3 finite numbers (metres), got none")
            check_vector(item[name], 3, positive=name == "size", source=source, path=f"{where}.{name}",
                         error=InvalidFile)  # fmt: skip
        if "orientation_xyzw" in item and "yaw_deg" in item:
            raise InvalidFile(source, where, "expected yaw_deg or orientation_xyzw, not both")
        if "orientation_xyzw" in item:
            check_quaternion_xyzw(item["orientation_xyzw"], source=source, path=f"{where}.orientation_xyzw",
                                  error=InvalidFile)  # fmt: skip
        elif "yaw_deg" in item:
            yaw = finite_number(item["yaw_deg"])
            if yaw is None:
                raise InvalidFile(
                    source,
                    f"{where}.yaw_deg",
                    f"expected a finite number of degrees, got {number_text(item['yaw_deg'])}",
                )
            if abs(yaw) > MAX_YAW_DEG:
                raise InvalidFile(
                    source, f"{where}.yaw_deg", f"expected a yaw within {MAX_YAW_DEG:g} degrees either way, got {yaw:g}"
                )
        try:  # the edges and coordinates a scene's box may have, at the detection's own path
            Box(item["id"], item["size"], item["center"], source=source, path=where)
        except InvalidFile as error:
            raise InvalidFile(source, error.json_path.replace(".position", ".center"), error.message) from None
        ignored.update(str(key) for key in item if key not in DETECTION_KEYS)
    if ignored:
        warnings.warn(f"{source}: detection keys passed over (a box is read from {', '.join(DETECTION_KEYS)}): "
                      f"{', '.join(sorted(ignored))}", stacklevel=2)  # fmt: skip


def _heading(rotation: np.ndarray, size: np.ndarray) -> tuple[float, np.ndarray]:
    """The yaw of a box's longest horizontal edge and its size (long, short, vertical) once levelled."""
    vertical = int(np.argmax(np.abs(rotation[2])))  # the box axis standing most upright
    horizontal = [axis for axis in range(3) if axis != vertical]
    longest = max(horizontal, key=lambda axis: size[axis])
    other = horizontal[0] if horizontal[1] == longest else horizontal[1]
    direction = rotation[:, longest]
    return float(np.arctan2(direction[1], direction[0])), np.array([size[longest], size[other], size[vertical]])


def scene_from_cloud(
    points: np.ndarray,
    detections: Sequence[dict[str, Any]],
    *,
    door: Sequence[float] | None = None,
    seed: int = 0,
    gravity: str = "planes",
) -> CameraScene:
    """Build a scene from a cloud and box detections in the same frame (z roughly up).

    ``gravity="pose"`` takes the frame's z as up (see
    :func:`~unstack.camera.planes.gravity_frame`); the cloud's planes give the floor.
    """
    from scipy.spatial.transform import Rotation

    from unstack.camera.boxes import TILT_MIN_DEG
    from unstack.checks import check_points
    from unstack.geometry import rotation_matrix, rotation_tilt_deg
    from unstack.scene import finite_points

    gravity = check_gravity(gravity)
    check_detections(detections)
    cloud = check_points(finite_points(points, "<cloud>"), source="<cloud>", path="$")  # NaN left out, with a warning
    if len(cloud) < 100:
        raise UnstackError(f"the cloud holds {len(cloud)} points; at least 100 are needed for gravity and the floor")
    direction = None if door is None else np.asarray(door, dtype=np.float64)
    frame = gravity_frame(cloud, door=direction, seed=seed, gravity=gravity)
    boxes = []
    for item in detections:
        if "orientation_xyzw" in item:
            quaternion = np.asarray(item["orientation_xyzw"], dtype=np.float64)
            rotation = rotation_matrix(quaternion / np.linalg.norm(quaternion))
        else:
            yaw = np.radians(float(item.get("yaw_deg", 0.0)))
            rotation = np.array([[np.cos(yaw), -np.sin(yaw), 0.0], [np.sin(yaw), np.cos(yaw), 0.0], [0.0, 0.0, 1.0]])
        size = np.asarray(item["size"], dtype=np.float64)
        turned = frame.rotation @ rotation
        if min(rotation_tilt_deg(rotation), rotation_tilt_deg(turned)) >= TILT_MIN_DEG:  # lying tilted, in both frames
            orientation = Rotation.from_matrix(turned).as_quat()
        else:
            heading, size = _heading(turned, size)
            orientation = np.array([0.0, 0.0, np.sin(heading / 2), np.cos(heading / 2)])
        centre = frame.apply(np.asarray(item["center"], dtype=np.float64)[None])[0]
        try:
            boxes.append(Box(item["id"], size, centre, orientation))
        except InvalidFile as error:  # the detection was checked: the cloud's frame put it there
            raise UnstackError(
                f"detection {item['id']!r}, moved into the gravity frame the cloud gives: {error.json_path[2:]}: "
                f"{error.message}; are the cloud and the detections in one frame?"
            ) from None
    metadata = {"camera": {"gravity": frame.gravity, "tilt_deg": frame.tilt_deg,
                           "gravity_rotation": frame.rotation.tolist(),
                           "gravity_translation": frame.translation.tolist()}}  # fmt: skip
    scene = Scene(boxes, frame.apply(cloud), [box.id for box in boxes], metadata=metadata, source="<cloud>")
    return CameraScene(scene, frame, (), door_given=door is not None)
