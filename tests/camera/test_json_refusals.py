"""A camera's JSON files -- detections, pose, intrinsics -- that no camera or detector gives are
refused with the file and the JSON path of the value, in one table for every loader."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from unstack.camera import load_detections, load_intrinsics, load_pose
from unstack.errors import InvalidFile

LOADERS = {"detections": load_detections, "pose": load_pose, "intrinsics": load_intrinsics}


def intrinsics(**change: Any) -> dict[str, Any]:
    """A 640 x 480 depth camera's intrinsics with ``change`` made (a value of None: the key left out)."""
    given = {"fx": 600.0, "fy": 600.0, "cx": 320.0, "cy": 240.0, "width": 640, "height": 480, **change}
    return {key: value for key, value in given.items() if value is not None}


@pytest.mark.parametrize(
    ("loader", "content", "message"),
    [
        (
            "detections",
            [{"id": "a", "center": [0, 0], "size": [1, 1, 1]}],
            r"\$\[0\]\.center: expected 3 numbers, got shape \(2,\)",
        ),
        (
            "detections",
            [{"id": "a", "center": [0, 0, 0], "size": [1, -1, 1]}],
            r"\$\[0\]\.size\[1\]: expected a positive number, got -1",
        ),
        (
            "detections",
            [{"center": [0, 0, 0], "size": [1, 1, 1]}],
            r"\$\[0\]: expected an object with a non-empty string id",
        ),
        ("detections", {"boxes": []}, r"\$\.boxes: expected a non-empty list"),
        (
            "detections",
            [{"id": "a", "center": [10**400, 0, 0], "size": [1, 1, 1]}],
            r"\$\[0\]\.center\[0\]: expected a finite number, got an integer of about 401 digits",
        ),
        (
            "detections",
            [{"id": "a", "center": [0, 0, 0], "size": [1, 1, 1], "yaw_deg": "north"}],
            r"\$\[0\]\.yaw_deg: expected a finite number of degrees, got 'north'",
        ),
        (
            "detections",
            [{"id": "a", "center": [0, 0, 0], "size": [1, 1, 1], "yaw_deg": 1e308}],
            r"\$\[0\]\.yaw_deg: expected a yaw within 3600 degrees either way, got 1e\+308",
        ),
        (
            "detections",
            [{"id": "a", "center": [0, 0, 0], "size": [1, 1, 1], "yaw_deg": 0, "orientation_xyzw": [0, 0, 0, 1]}],
            r"\$\[0\]: expected yaw_deg or orientation_xyzw, not both",
        ),
        (
            "detections",
            [{"id": "a", "center": [0, 0, 0], "size": [1, 1, 1], "orientation_xyzw": [0, 0, 0, 3]}],
            r"\$\[0\]\.orientation_xyzw: expected a unit quaternion .* got norm 3",
        ),
        (
            "detections",
            {"boxes": [{"id": "a", "center": [0, 0, 0], "size": [50, 1, 1]}]},
            r"\$\.boxes\[0\]\.size\[0\]: expected a box edge between 0\.02 and 5 m",
        ),
        (
            "detections",
            [{"id": "a", "center": [0, 0, 1e4], "size": [1, 1, 1]}],
            r"\$\[0\]\.center\[2\]: expected a coordinate within 100 m",
        ),
        ("pose", np.eye(3).tolist(), "expected a 4 x 4 matrix"),
        ("pose", (2 * np.eye(4)).tolist(), "expected the last row 0 0 0 1"),
        ("pose", np.diag([2.0, 1.0, 1.0, 1.0]).tolist(), "expected a rotation"),
        ("pose", {"a": np.eye(4).tolist(), "b": np.eye(4).tolist()}, "exactly one matrix"),
        (
            "pose",
            [[1, 0, 0, float("nan")], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]],
            r"\$\[0\]\[3\]: expected a finite number",
        ),
        (
            "intrinsics",
            intrinsics(fx=1e9),
            r"\$\.fx: expected a focal length that sees 1 to 170 degrees across 640 px \(28 to",
        ),
        ("intrinsics", intrinsics(fy=2.0), r"\$\.fy: expected a focal length that sees 1 to 170 degrees across 480 px"),
        ("intrinsics", intrinsics(cx=1e308), r"\$\.cx: expected a principal point inside the image \(0 to 640 px\)"),
        (
            "intrinsics",
            intrinsics(fx=304.6, fy=30.0),
            r"\$\.fy: expected square-ish pixels \(fx / fy between 0\.5 and 2\), got fx 304\.6 and fy 30",
        ),
        (
            "intrinsics",
            intrinsics(cy=481),
            r"\$\.cy: expected a principal point inside the image \(0 to 480 px\), got 481",
        ),
        ("intrinsics", intrinsics(width=10**9), r"\$\.width: expected at most 16384 pixels, got 1e\+09"),
        ("intrinsics", intrinsics(fx=-1), r"\$\.fx: expected a positive number of pixels, got -1"),
        (
            "intrinsics",
            intrinsics(fx=10**400),
            r"\$\.fx: expected a positive number of pixels, got an integer of about",
        ),
        ("pose", [["1", "0", "0", "0"], *np.eye(4)[1:].tolist()], r"\$\[0\]\[0\]: expected a finite number, got '1'"),
        ("pose", [[True, 0, 0, 0], *np.eye(4)[1:].tolist()], r"\$\[0\]\[0\]: expected a finite number, got True"),
        (
            "pose",
            [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 1500], [0, 0, 0, 1]],
            r"\$\[2\]\[3\]: expected a translation within",
        ),
        ("intrinsics", intrinsics(cy=None), r"\$: missing required key 'cy'"),
        ("intrinsics", intrinsics(k1=0.01), r"\$\.k1: expected no lens distortion"),
        ("intrinsics", intrinsics(D=[0.1, 0.0, 0.0, 0.0, 0.0]), r"\$\.D: expected no lens distortion"),
        ("intrinsics", intrinsics(p2="x"), r"\$\.p2: expected no lens distortion"),
    ],
)
def test_a_bad_camera_json_file_is_refused_with_its_json_path(
    tmp_path: Path, loader: str, content: object, message: str
) -> None:
    (tmp_path / "given.json").write_text(json.dumps(content))
    with pytest.raises(InvalidFile, match=message) as refused:
        LOADERS[loader](tmp_path / "given.json")
    assert str(refused.value).startswith(f"{tmp_path / 'given.json'}: ")


def test_an_integer_of_thousands_of_digits_is_refused_in_one_line(tmp_path: Path) -> None:
    (tmp_path / "k.json").write_text('{"fx": ' + "9" * 5000 + ', "fy": 600, "cx": 320, "cy": 240}')
    with pytest.raises(
        InvalidFile,
        match=r"k.json: \$: invalid JSON: an integer of more than 4,300 digits, no number an unstack file holds",
    ):
        load_intrinsics(tmp_path / "k.json")
