"""A camera's files: depth image, pinhole intrinsics, camera pose, instance masks.

Every reader returns canonical arrays (float64 metres for depth, a 4 x 4 float64 pose, bool
masks) or raises :class:`~unstack.errors.InvalidFile` naming the file, the JSON path and
what was expected. Depth units are checked, not assumed: a 16-bit PNG declared in
millimetres whose readings are all below :data:`MAX_DEPTH_M` is refused as "metres", and a
float image declared in metres whose median is above it is refused as "millimetres".

Examples
--------
>>> import json, tempfile, pathlib
>>> folder = pathlib.Path(tempfile.mkdtemp())
>>> _ = (folder / "k.json").write_text(json.dumps({"fx": 600, "fy": 600, "cx": 320, "cy": 240,
...                                                  "width": 640, "height": 480}))
>>> load_intrinsics(folder / "k.json").cx
320.0
"""

from __future__ import annotations

import math
import os
import warnings
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from unstack.checks import MAX_COORDINATE, finite_number, number_text
from unstack.errors import InvalidFile
from unstack.jsonio import parse_json, refuse_special_file

__all__ = [
    "DEPTH_UNITS",
    "MAX_DEPTH_M",
    "Intrinsics",
    "check_pose",
    "depth_scale",
    "load_depth",
    "load_intrinsics",
    "load_label_masks",
    "load_mask",
    "load_pose",
    "read_json_file",
]

#: Units a depth image can be declared in, and metres per unit.
DEPTH_UNITS = {"mm": 0.001, "m": 1.0}
#: The finest depth unit taken (metres): a micrometre; depth cameras' scales are 0.1-1 mm.
MIN_DEPTH_SCALE = 1e-6
#: A mask of whole numbers in which two values or more each cover this share of its pixels
#: looks like a label image (a value per box), and the reading warns.
LABEL_SHARE = 0.1
#: A label covering more than this share of a label image and reaching all its edges is its background.
BACKGROUND_SHARE = 0.5
#: The largest label value read (a float image's whole numbers are exact up to 2^53).
MAX_LABEL_VALUE = 2**53
#: Thin labels named one by one in the warning that leaves them out, before "and N more".
NAMED_SLIVERS = 5
#: The most labels a label image may hold: more boxes than a container holds is another image.
MAX_LABELS = 1000
#: No depth camera in a container or a cell reads further than this (metres).
MAX_DEPTH_M = 20.0
#: The fields of view (degrees, across the image's width and height) a pinhole camera's
#: intrinsics may give: beyond them a focal length is a typing slip (a depth camera sees 40-90).
FIELD_OF_VIEW = (1.0, 170.0)
#: The widest and tallest depth image read (pixels; depth cameras give 1-2 thousand).
MAX_PIXELS = 16384
#: Pixels this much taller than wide (or wider than tall) are no depth camera's: fx / fy is 1
#: within a percent on the cameras in use.
MAX_PIXEL_ASPECT = 2.0
#: The keys of a pinhole camera's intrinsics.
INTRINSICS_KEYS = ("fx", "fy", "cx", "cy", "width", "height")
#: Keys that give a lens distortion (OpenCV's and ROS's names, in lower case).
DISTORTION_KEYS = frozenset(
    {"k1", "k2", "k3", "k4", "k5", "k6", "p1", "p2", "s1", "s2", "s3", "s4", "d", "dist", "distortion",
     "dist_coeffs", "distortion_coefficients", "coeffs"}
)  # fmt: skip


@dataclass(frozen=True)
class Intrinsics:
    """A pinhole camera: focal lengths and principal point in pixels, image size.

    A pixel (row ``v``, column ``u``) with depth ``z`` along the optical axis is the camera-frame
    point ``((u - cx) z / fx, (v - cy) z / fy, z)`` (x right, y down, z forward: OpenCV's).
    """

    fx: float
    fy: float
    cx: float
    cy: float
    width: int
    height: int


def _file_path(path: Any) -> Path:
    """``path`` (text or a path-like object) as a :class:`~pathlib.Path`; anything else is refused."""
    from unstack.errors import InvalidArgument

    if not isinstance(path, str | os.PathLike) or isinstance(os.fspath(path), bytes):
        raise InvalidArgument(f"expected a file name (text or a path), got {type(path).__name__} {path!r}")
    return Path(path)


def read_json_file(path: str | os.PathLike[str], what: str = "file") -> tuple[Any, str]:
    """The JSON value of a camera's file (``what`` it is, for the messages) and its name: read
    as every document is (:func:`unstack.jsonio.parse_json`), in one-line errors.

    Examples
    --------
    >>> read_json_file("missing.json", "detections file")
    Traceback (most recent call last):
    ...
    unstack.errors.InvalidFile: missing.json: $: the detections file does not exist
    """
    file = _file_path(path)
    source = str(file)
    if source == "-":
        raise InvalidFile(source, "$", f"expected the name of the {what}: standard input is not read for it")
    refuse_special_file(file)
    try:
        text = file.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise InvalidFile(source, "$", f"the {what} does not exist") from None
    except (OSError, UnicodeDecodeError) as error:
        raise InvalidFile(source, "$", f"expected a JSON file: {error}") from None
    return parse_json(text, source), source


def load_intrinsics(path: str | os.PathLike[str]) -> Intrinsics:
    """Read ``{"fx", "fy", "cx", "cy", "width", "height"}`` (pixels) from a JSON file.

    RealSense's names (``ppx``, ``ppy`` for ``cx``, ``cy``) and a ROS ``CameraInfo``'s camera
    matrix (``K`` or ``k``, with its ``width`` and ``height``) are read as well.

    The camera is a pinhole: distortion coefficients other than 0 (``k1`` ... ``k6``,
    ``p1``, ``p2``, ``D``, ...) are refused, since nothing here would undo them; other keys
    are passed over with a warning naming them.
    """
    data, source = read_json_file(path)
    if not isinstance(data, dict):
        bare = (
            isinstance(data, list) and len(data) == 3 and all(isinstance(row, list) and len(row) == 3 for row in data)
        )
        size = ": a bare 3 x 3 matrix gives no image size" if bare else ""
        raise InvalidFile(source, "$", f"expected an object with fx, fy, cx, cy, width and height{size}")
    _refuse_distortion(data, source)
    data = _pinhole_keys(data, source)
    values = {}
    for name in INTRINSICS_KEYS:
        if name not in data:
            raise InvalidFile(source, "$", f"missing required key {name!r} (expected {', '.join(INTRINSICS_KEYS)})")
        value = finite_number(data[name])
        if value is None or value <= 0:
            raise InvalidFile(
                source, f"$.{name}", f"expected a positive number of pixels, got {number_text(data[name])}"
            )
        values[name] = value
    if values["width"] != int(values["width"]) or values["height"] != int(values["height"]):
        raise InvalidFile(source, "$.width", "expected whole numbers of pixels for width and height")
    for focal, centre, side in (("fx", "cx", "width"), ("fy", "cy", "height")):
        if values[side] > MAX_PIXELS:
            raise InvalidFile(source, f"$.{side}", f"expected at most {MAX_PIXELS} pixels, got {values[side]:g}")
        if values[centre] > values[side]:
            raise InvalidFile(
                source,
                f"$.{centre}",
                f"expected a principal point inside the image (0 to {values[side]:g} px), got {values[centre]:g}",
            )
        low, high = (values[side] / (2.0 * math.tan(math.radians(angle) / 2.0)) for angle in FIELD_OF_VIEW[::-1])
        if not low <= values[focal] <= high:
            raise InvalidFile(
                source,
                f"$.{focal}",
                f"expected a focal length that sees {FIELD_OF_VIEW[0]:g} to {FIELD_OF_VIEW[1]:g} degrees across "
                f"{values[side]:g} px ({low:.3g} to {high:.3g} px), got {values[focal]:g}",
            )
    aspect = values["fx"] / values["fy"]
    if not 1.0 / MAX_PIXEL_ASPECT <= aspect <= MAX_PIXEL_ASPECT:
        raise InvalidFile(
            source,
            "$.fy",
            f"expected square-ish pixels (fx / fy between {1 / MAX_PIXEL_ASPECT:g} and {MAX_PIXEL_ASPECT:g}), "
            f"got fx {values['fx']:g} and fy {values['fy']:g}",
        )
    ignored = sorted(str(key) for key in data if key not in INTRINSICS_KEYS and str(key).lower() not in DISTORTION_KEYS)
    if ignored:
        warnings.warn(f"{source}: keys passed over (a pinhole camera needs only {', '.join(INTRINSICS_KEYS)}): "
                      f"{', '.join(ignored)}", stacklevel=2)  # fmt: skip
    return Intrinsics(
        values["fx"], values["fy"], values["cx"], values["cy"], int(values["width"]), int(values["height"])
    )


def _pinhole_keys(data: dict[str, Any], source: str) -> dict[str, Any]:
    """The intrinsics under :data:`INTRINSICS_KEYS`: RealSense's ``ppx``, ``ppy`` are ``cx``, ``cy``;
    a ROS ``CameraInfo``'s ``K`` (``k`` in ROS 2; nine numbers, row by row) gives ``fx``,
    ``fy``, ``cx``, ``cy``. Keys under both names, or a camera matrix that is not a pinhole's, are refused.

    Examples
    --------
    >>> realsense = {"width": 640, "height": 480, "ppx": 321.5, "ppy": 240.2, "fx": 615.0, "fy": 615.1}
    >>> _pinhole_keys(realsense, "rs.json")["cx"]
    321.5
    >>> ros = {"width": 640, "height": 480, "K": [615.0, 0, 321.5, 0, 615.1, 240.2, 0, 0, 1]}
    >>> [_pinhole_keys(ros, "info.json")[key] for key in ("fx", "fy", "cx", "cy")]
    [615.0, 615.1, 321.5, 240.2]
    """
    given = dict(data)
    for vendor, ours in (("ppx", "cx"), ("ppy", "cy")):
        if vendor in given:
            if ours in given:
                raise InvalidFile(
                    source, f"$.{vendor}", f"expected {ours} or {vendor} (RealSense's name for it), not both"
                )
            given[ours] = given.pop(vendor)
    keys = [key for key in ("K", "k") if key in given]
    if len(keys) == 2:
        raise InvalidFile(source, "$.k", "expected the camera matrix once, as K (ROS) or k (ROS 2), not both")
    if not keys:
        return given
    matrix_key = keys[0]
    clash = [key for key in ("fx", "fy", "cx", "cy") if key in given]
    if clash:
        raise InvalidFile(
            source, f"$.{matrix_key}", f"expected the camera matrix {matrix_key} or {', '.join(clash)}, not both"
        )
    matrix = given.pop(matrix_key)
    rows = isinstance(matrix, list) and len(matrix) == 3 and all(isinstance(row, list) for row in matrix)
    entries = [entry for row in matrix for entry in row] if rows else matrix  # 3 x 3 nested, or 9 flat
    numbers = [finite_number(entry) for entry in entries] if isinstance(entries, list) else []
    if len(numbers) != 9 or any(number is None for number in numbers):
        raise InvalidFile(
            source, f"$.{matrix_key}", f"expected 9 numbers (a 3 x 3 camera matrix, row by row), got {matrix!r}"
        )
    fx, skew, cx, low, fy, cy, bottom_x, bottom_y, one = numbers
    if skew != 0 or low != 0 or bottom_x != 0 or bottom_y != 0 or one != 1:
        raise InvalidFile(
            source,
            f"$.{matrix_key}",
            f"expected a pinhole camera matrix [fx, 0, cx, 0, fy, cy, 0, 0, 1], got {matrix!r}",
        )
    given.update(fx=fx, fy=fy, cx=cx, cy=cy)
    return given


def _refuse_distortion(data: dict[str, Any], source: str) -> None:
    """Raise where the intrinsics give a lens distortion other than none."""
    for key, value in data.items():
        if str(key).lower() not in DISTORTION_KEYS:
            continue
        coefficients = value if isinstance(value, list) else [value]
        numbers = [entry for entry in coefficients if isinstance(entry, int | float) and not isinstance(entry, bool)]
        if len(numbers) != len(coefficients) or any(entry != 0 for entry in numbers):
            raise InvalidFile(
                source, f"$.{key}", f"expected no lens distortion (a pinhole camera), got {value!r}: undistort the "
                "depth image and the masks first (OpenCV's undistort) and give the new camera's intrinsics"
            )  # fmt: skip


def check_pose(matrix: Any, *, source: str = "<camera_to_world>", json_path: str = "$") -> np.ndarray:
    """Check a 4 x 4 camera-to-world transform and return it as float64.

    The rotation part must be a rotation (orthonormal, determinant 1, within 1e-3), the
    translation within :data:`~unstack.checks.MAX_COORDINATE` metres and the last row ``0 0 0 1``;
    anything else raises :class:`~unstack.errors.InvalidFile` naming ``source`` and the entry.

    Examples
    --------
    >>> check_pose(np.eye(4)).dtype
    dtype('float64')
    >>> check_pose(np.diag([2.0, 2.0, 2.0, 1.0]))
    Traceback (most recent call last):
    ...
    unstack.errors.InvalidFile: <camera_to_world>: $: expected a rotation in the upper 3 x 3 block (orthonormal, det 1)
    """
    from unstack.checks import float_array

    if np.ma.isMaskedArray(matrix):
        raise InvalidFile(source, json_path, "expected a plain array, got a masked array: fill its masked cells first")
    expected = "expected a 4 x 4 matrix of finite numbers"
    try:
        raw = np.asarray(matrix)
        if raw.dtype == object:  # integers too large for a float, or anything mixed in
            raw = float_array(matrix, source=source, path=json_path, error=InvalidFile)
    except (TypeError, ValueError):
        raise InvalidFile(source, json_path, f"{expected}, got {type(matrix).__name__}") from None
    if raw.dtype.kind not in "iuf":
        kind = {"U": "text", "S": "text", "b": "true or false", "c": "complex numbers"}.get(
            raw.dtype.kind, str(raw.dtype)
        )
        raise InvalidFile(source, json_path, f"{expected}, got {kind}")
    pose = raw.astype(np.float64)
    if pose.shape != (4, 4):
        raise InvalidFile(source, json_path, f"{expected}, got {pose.shape}")
    bad = np.argwhere(~np.isfinite(pose))
    if len(bad):
        row, column = (int(index) for index in bad[0])
        raise InvalidFile(source, f"{json_path}[{row}][{column}]", f"expected a finite number, got {pose[row, column]}")
    rotation = pose[:3, :3]
    far = np.flatnonzero(np.abs(pose[:3, 3]) > MAX_COORDINATE)
    if far.size:
        row = int(far[0])
        raise InvalidFile(
            source, f"{json_path}[{row}][3]", f"expected a translation within {MAX_COORDINATE:g} m (metres?), "
            f"got {pose[row, 3]:g}"
        )  # fmt: skip
    if not np.allclose(pose[3], [0.0, 0.0, 0.0, 1.0]):
        raise InvalidFile(source, f"{json_path}[3]", "expected the last row 0 0 0 1")
    if not np.allclose(rotation.T @ rotation, np.eye(3), atol=1e-3) or not np.isclose(
        np.linalg.det(rotation), 1.0, atol=1e-3
    ):
        raise InvalidFile(source, json_path, "expected a rotation in the upper 3 x 3 block (orthonormal, det 1)")
    return pose


def load_pose(path: str | os.PathLike[str]) -> np.ndarray:
    """Read a 4 x 4 camera-to-world transform: a JSON matrix, or an object holding one matrix,
    checked by :func:`check_pose`."""
    data, source = read_json_file(path)
    json_path = "$"
    if isinstance(data, dict):
        matrices = [key for key, value in data.items() if isinstance(value, list)]
        if len(matrices) != 1:
            raise InvalidFile(source, "$", "expected a 4 x 4 matrix, or an object with exactly one matrix")
        json_path = f"$.{matrices[0]}"
        data = data[matrices[0]]
    rows = data if isinstance(data, list) else []
    if len(rows) != 4 or not all(isinstance(row, list) and len(row) == 4 for row in rows):
        shape = np.shape(data) if isinstance(data, list) and data and isinstance(data[0], list) else "not a matrix"
        raise InvalidFile(source, json_path, f"expected a 4 x 4 matrix of finite numbers, got {shape}")
    for row, entries in enumerate(rows):
        for column, entry in enumerate(entries):
            if finite_number(entry) is None:
                raise InvalidFile(
                    source, f"{json_path}[{row}][{column}]", f"expected a finite number, got {number_text(entry)}"
                )
    pose = np.array([[finite_number(entry) for entry in entries] for entries in rows], dtype=np.float64)
    return check_pose(pose, source=source, json_path=json_path)


def _load_npy(file: Path, source: str, what: str) -> np.ndarray:
    """A ``.npy`` array, never unpickled: a file that is not one (or holds objects) is refused in
    our words (numpy's would suggest allowing pickle, which runs code)."""
    try:
        array: np.ndarray = np.load(file, allow_pickle=False)
    except ValueError:
        raise InvalidFile(
            source, "$", f"expected a {what} as a .npy array of numbers, {file.name!r} is not one"
        ) from None
    return array


def _read_png(file: Path, what: str) -> np.ndarray:
    """A PNG file's pixels; any other image format, whatever its name, is refused (a JPEG's
    compression moves the edges of a mask and the values of a depth image)."""
    from PIL import Image

    with Image.open(file) as image:
        if image.format != "PNG":
            lossy = " (its compression blurs edges and values)" if image.format in ("JPEG", "WEBP", "JPEG2000") else ""
            raise InvalidFile(str(file), "$", f"expected a PNG or .npy {what}, got a {image.format} image{lossy}")
        return np.array(image)


def depth_scale(units: str | float) -> float:
    """Metres per unit of a depth image: ``"mm"``, ``"m"``, or the metres of one unit (a
    camera's depth scale: RealSense's 0.0001 for 0.1 mm), as a number or its text.

    Raises
    ------
    InvalidArgument
        Anything else, or a scale outside 1 micrometre to 1 metre.

    Examples
    --------
    >>> depth_scale("mm"), depth_scale("0.0001"), depth_scale(0.00025)
    (0.001, 0.0001, 0.00025)
    """
    from unstack.errors import InvalidArgument

    if isinstance(units, str) and units in DEPTH_UNITS:
        return DEPTH_UNITS[units]
    try:
        scale = float(units) if not isinstance(units, bool | np.bool_ | bytes) else math.nan
    except (TypeError, ValueError):
        scale = math.nan
    if not MIN_DEPTH_SCALE <= scale <= 1.0:
        raise InvalidArgument(
            f"depth units: expected mm, m or the metres of one unit ({MIN_DEPTH_SCALE:g} to 1; a camera's depth scale, "
            f"0.0001 for 0.1 mm), got {units!r}"
        )
    return scale


def load_depth(path: str | os.PathLike[str], *, units: str | float | None = None) -> np.ndarray:
    """Read a depth image as float64 metres along the optical axis; 0 where there is no reading.

    Parameters
    ----------
    path : path-like
        A 16-bit PNG (default units ``mm``) or a ``.npy`` array of floats (default units ``m``).
    units : {"mm", "m"} or float, optional
        What the values are (a number: the metres of one unit, :func:`depth_scale`); checked
        against the readings.
    """
    file = _file_path(path)
    source = str(file)
    refuse_special_file(file)
    if not file.is_file():
        raise InvalidFile(source, "$", "the depth image does not exist")
    suffix = file.suffix.lower()
    try:
        if suffix == ".npy":
            raw = _load_npy(file, source, "depth image")
        elif suffix == ".png":
            raw = _read_png(file, "depth image")
        else:
            raise InvalidFile(source, "$", f"expected a depth image .png (16-bit) or .npy, got {file.name!r}")
    except InvalidFile:
        raise
    except Exception as error:  # noqa: BLE001 - any reader failure is the file's fault
        raise InvalidFile(source, "$", f"cannot read the depth image: {error}") from None
    if raw.ndim != 2 or not (np.issubdtype(raw.dtype, np.integer) or np.issubdtype(raw.dtype, np.floating)):
        raise InvalidFile(source, "$", f"expected a single-channel depth image, got shape {raw.shape} of {raw.dtype}")
    if suffix == ".png" and raw.dtype.itemsize < 2:
        raise InvalidFile(
            source, "$", "expected a 16-bit PNG of depths, got an 8-bit image (at most 255 mm: a picture, not depth)"
        )
    given = ("m" if np.issubdtype(raw.dtype, np.floating) else "mm") if units is None else units
    scale = depth_scale(given)
    declared = given if isinstance(given, str) and given in DEPTH_UNITS else f"units of {scale:g} m"
    values = raw.astype(np.float64)
    valid = np.isfinite(values) & (values > 0)
    if not valid.any():
        negative = bool((np.isfinite(values) & (values < 0)).any())
        what = "every pixel is 0, negative or not a number" if negative else "every pixel is 0 or not a number"
        raise InvalidFile(source, "$", f"the depth image holds no reading ({what})")
    metres = np.where(valid, values, 0.0) * scale
    median = float(np.median(metres[valid]))
    if median > MAX_DEPTH_M:
        readings = values[valid]
        if np.issubdtype(raw.dtype, np.integer) and readings.min() == np.iinfo(raw.dtype).max:
            question = f"every reading is {readings[0]:g}, the largest the image holds: a code for no reading?"
        elif declared == "mm":
            question = (
                "are the values in a finer unit than millimetres (a depth scale of 0.1 mm, say: --depth-units 0.0001)?"
            )
        else:
            question = "are the values millimetres?"
        raise InvalidFile(source, "$", f"declared in {declared} but the median reading is {median:g} m: {question}")
    if declared == "mm" and float(values[valid].max()) <= MAX_DEPTH_M:
        raise InvalidFile(
            source, "$", f"declared in mm but every reading is at most {MAX_DEPTH_M:g} mm: are the values metres?"
        )
    far = metres > MAX_DEPTH_M
    if far.any():  # a few outliers (multipath, a reflection) in an image of plausible depths: no reading there
        rows, columns = np.nonzero(far)
        warnings.warn(
            f"{source}: {int(far.sum()):,} readings beyond {MAX_DEPTH_M:g} m (no depth camera reads so far; the "
            f"first at row {rows[0]}, column {columns[0]}: {float(metres[rows[0], columns[0]]):g} m) are taken as "
            "no reading",
            stacklevel=2,
        )
        metres[far] = 0.0
    return metres


def _mask_pixels(path: str | os.PathLike[str], what: str) -> tuple[np.ndarray, str]:
    """A mask file's pixels (a PNG, or a ``.npy`` array of numbers) and the file's name."""
    file = _file_path(path)
    source = str(file)
    refuse_special_file(file)
    if not file.is_file():
        raise InvalidFile(source, "$", f"the {what} does not exist")
    try:
        suffix = file.suffix.lower()
        if suffix not in (".png", ".npy"):
            raise InvalidFile(source, "$", f"expected a {what} .png or .npy, got {file.name!r}")
        raw = _load_npy(file, source, what) if suffix == ".npy" else _read_png(file, what)
    except InvalidFile:
        raise
    except Exception as error:  # noqa: BLE001 - any reader failure is the file's fault
        raise InvalidFile(source, "$", f"cannot read the {what}: {error}") from None
    if not (np.issubdtype(raw.dtype, np.integer) or np.issubdtype(raw.dtype, np.floating) or raw.dtype == bool):
        outside = "the box" if what == "mask" else "the boxes"
        raise InvalidFile(source, "$", f"expected a {what} of numbers (0 outside {outside}), got values of {raw.dtype}")
    return raw, source


def _image_shape(shape: Any) -> tuple[int, int]:
    """``shape`` as a (rows, columns) tuple of whole numbers (a list or an array of two serves)."""
    from unstack.errors import InvalidArgument

    values = np.asarray(shape)
    if values.shape != (2,) or not np.issubdtype(values.dtype, np.integer) or np.any(values < 1):
        raise InvalidArgument(f"shape: expected (rows, columns) of an image in pixels, got {shape!r}")
    return int(values[0]), int(values[1])


def _check_mask_shape(raw: np.ndarray, shape: Any, source: str, what: str) -> None:
    if raw.ndim != 2:
        image = what if what.endswith("image") else f"{what} image"
        raise InvalidFile(source, "$", f"expected a single-channel {image}, got shape {raw.shape}")
    if shape is not None:
        shape = _image_shape(shape)
    if shape is not None and raw.shape != shape:
        raise InvalidFile(source, "$", f"expected a {what} of {shape[1]} x {shape[0]} pixels like the depth image, "
                          f"got {raw.shape[1]} x {raw.shape[0]}")  # fmt: skip


def load_label_masks(
    path: str | os.PathLike[str], shape: tuple[int, int] | None = None, *, lines: bool = False
) -> dict[int, np.ndarray]:
    """Read a label image (a single-channel PNG, or a ``.npy`` array, of whole numbers) as one
    mask per box: 0 where no box is, each other value one box, as instance-segmentation
    detectors write them; the masks by value, ascending, of ``shape`` if given.

    A label that is a line a pixel or two thick (:func:`line_labels`: the edge between two
    others, as a label image resized or drawn with smoothing leaves them) is left out with a
    warning, or kept with ``lines`` (for a caller that names the labels first).

    Raises
    ------
    InvalidFile
        Not a label image: colour, fractions or negative values, no label, or more labels
        than :data:`MAX_LABELS` (a depth image, say).

    Examples
    --------
    >>> import tempfile
    >>> labels = np.zeros((5, 8), dtype=np.uint16); labels[:3, :3] = 3; labels[1:4, 4:8] = 7
    >>> path = Path(tempfile.mkdtemp()) / "labels.npy"; np.save(path, labels)
    >>> {value: int(mask.sum()) for value, mask in load_label_masks(path).items()}
    {3: 9, 7: 12}
    """
    raw, source = _mask_pixels(path, "label image")
    _check_mask_shape(raw, shape, source, "label image")
    values = np.asarray(raw)
    if np.issubdtype(values.dtype, np.floating):
        infinite = np.isinf(values)
        if infinite.any():
            rows, columns = np.nonzero(infinite)
            first = f"the first at row {rows[0]}, column {columns[0]}"
            raise InvalidFile(source, "$", "expected whole numbers in a label image (one per box, 0 or NaN where no "
                              f"box is), got {int(infinite.sum()):,} infinite ones ({first})")  # fmt: skip
        finite = np.isfinite(values)
        if np.any(finite & (values != np.round(values))):
            raise InvalidFile(source, "$", "expected whole numbers in a label image (one per box), got fractions")
        if np.any(finite & (np.abs(values) > MAX_LABEL_VALUE)):
            largest = float(np.max(np.abs(values[finite])))
            raise InvalidFile(source, "$", f"expected labels up to {MAX_LABEL_VALUE:,}, got {largest:g}")
        values = np.where(finite, values, 0).astype(np.int64)
    if values.dtype == bool or np.any(values < 0):
        got = "true/false values: a single mask" if values.dtype == bool else "negative values"
        raise InvalidFile(source, "$", f"expected a label image of whole numbers from 0 (one per box), got {got}")
    labels = np.unique(values[values != 0])
    if len(labels) == 0:
        raise InvalidFile(source, "$", "the label image is empty (every pixel is 0)")
    if len(labels) > MAX_LABELS:
        raise InvalidFile(
            source, "$", f"expected at most {MAX_LABELS:,} labels (one per box), got {len(labels):,}: a depth image?"
        )
    masks = {int(label): values == label for label in labels}
    for label, mask in masks.items():
        edges = (mask[0], mask[-1], mask[:, 0], mask[:, -1])
        if mask.mean() > BACKGROUND_SHARE and all(edge.any() for edge in edges):
            share = f"{100 * mask.mean():.0f} %"
            raise InvalidFile(source, "$", f"label {label} covers {share} of the image and reaches all four of its "
                              "edges: the background? (--labels reads 0, or NaN, as no box)")  # fmt: skip
    return masks if lines else without_line_labels(masks, source)


def line_labels(masks: Mapping[Any, np.ndarray]) -> list[Any]:
    """The keys of ``masks`` whose mask is a line a pixel or two thick: no pixel of it has all
    four neighbours in it.

    Examples
    --------
    >>> area, line = np.zeros((6, 6), dtype=bool), np.zeros((6, 6), dtype=bool)
    >>> area[1:5, 1:4] = True; line[:, 5] = True
    >>> line_labels({"area": area, "line": line})
    ['line']
    """
    from scipy.ndimage import binary_erosion

    def is_line(mask: np.ndarray) -> bool:  # eroded within its bounding box: outside it is no label anyway
        rows, columns = np.flatnonzero(mask.any(axis=1)), np.flatnonzero(mask.any(axis=0))
        return not binary_erosion(mask[rows[0] : rows[-1] + 1, columns[0] : columns[-1] + 1]).any()

    return [key for key, mask in masks.items() if is_line(mask)]


def without_line_labels(
    masks: Mapping[Any, np.ndarray], source: str, names: Mapping[Any, str] | None = None
) -> dict[Any, np.ndarray]:
    """The labels of ``masks`` that are areas; the lines (:func:`line_labels`: the edges between
    others, as a label image resized or drawn with smoothing leaves them) are left out with a
    warning that names them (by ``names`` where given: the box ids)."""
    slivers = line_labels(masks)
    if slivers and len(slivers) == len(masks):
        raise InvalidFile(source, "$", "every label is a line a pixel or two thick, no area a box could show")
    if slivers:
        shown = [str(label) if names is None else f"{label} ({names[label]})" for label in slivers]
        named = ", ".join(shown[:NAMED_SLIVERS])
        more = f" and {len(slivers) - NAMED_SLIVERS} more" if len(slivers) > NAMED_SLIVERS else ""
        warnings.warn(
            f"{source}: {len(slivers)} labels are lines a pixel or two thick ({named}{more}), too thin to show a box: "
            "left out (a label image resized or drawn with smoothing leaves such lines between the others: save "
            "label images with nearest-neighbour sampling)",
            stacklevel=3,
        )
    return {label: mask for label, mask in masks.items() if label not in slivers}


def load_mask(path: str | os.PathLike[str], shape: tuple[int, int] | None = None) -> np.ndarray:
    """Read an instance mask (a PNG, or a ``.npy`` array): True where the box is, of ``shape`` if given."""
    raw, source = _mask_pixels(path, "mask")
    if raw.ndim == 3 and raw.shape[-1] >= 1:
        raw = raw[..., :3].max(axis=-1)  # a colour mask: any non-black pixel
    _check_mask_shape(raw, shape, source, "mask")
    values = np.asarray(raw)
    mask: np.ndarray = np.asarray(values != 0)
    if np.issubdtype(values.dtype, np.floating):
        mask &= np.isfinite(values)
    if not mask.any():
        raise InvalidFile(source, "$", "the mask is empty (every pixel is 0 or not a number)")
    if np.issubdtype(values.dtype, np.integer) and raw.ndim == 2:
        labels, counts = np.unique(values[mask], return_counts=True)
        large = counts >= LABEL_SHARE * mask.sum()
        if large.sum() >= 2:
            shares = ", ".join(
                f"{label}: {100 * count / mask.sum():.0f} %"
                for label, count in zip(labels[large], counts[large], strict=True)
            )
            warnings.warn(
                f"{source}: the mask holds {int(large.sum())} values that each cover a large part of it ({shares}): "
                "a label image, a value per box? (unstack scene --labels, unstack.camera.load_label_masks, read one "
                "box per value; as a mask it is one box)",
                stacklevel=2,
            )
    return mask
