"""Scenes from a point cloud and box detections: PCD files read, a tilted frame levelled."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from unstack.camera import load_cloud, load_detections, scene_from_cloud
from unstack.errors import InvalidFile
from unstack.geometry import rotation_matrix


def _floor_and_top(rng: np.random.Generator) -> np.ndarray:
    floor = np.column_stack([rng.uniform(-1, 1, 4000), rng.uniform(-1, 1, 4000), np.zeros(4000)])
    top = np.column_stack([rng.uniform(-0.2, 0.2, 800), rng.uniform(-0.15, 0.15, 800), np.full(800, 0.3)])
    return np.vstack([floor, top])


def _tilt(angle_deg: float) -> np.ndarray:
    angle = np.radians(angle_deg)
    return np.array([[1.0, 0.0, 0.0], [0.0, np.cos(angle), -np.sin(angle)], [0.0, np.sin(angle), np.cos(angle)]])


@pytest.mark.parametrize("tilt_deg", [0.0, 9.0])
def test_a_tilted_frame_is_levelled_and_the_box_stands_on_the_floor(tilt_deg: float) -> None:
    turn = _tilt(tilt_deg)
    cloud = _floor_and_top(np.random.default_rng(3)) @ turn.T + [0.0, 0.0, 0.5]
    centre = (turn @ [0.0, 0.0, 0.15]) + [0.0, 0.0, 0.5]
    built = scene_from_cloud(cloud, [{"id": "a", "center": centre.tolist(), "size": [0.4, 0.3, 0.3], "yaw_deg": 30}])
    box = built.scene.box("a")
    assert built.frame.tilt_deg == pytest.approx(tilt_deg, abs=0.2)
    assert box.position[2] == pytest.approx(0.15, abs=0.005)
    assert abs(rotation_matrix(box.orientation_xyzw)[2, 2]) == pytest.approx(1.0)  # level
    assert box.size.tolist() == [0.4, 0.3, 0.3]


def _quaternion(rotation: np.ndarray) -> list[float]:
    from scipy.spatial.transform import Rotation

    return [float(value) for value in Rotation.from_matrix(rotation).as_quat()]


@pytest.mark.parametrize(
    ("frame_tilt_deg", "box_tilt_deg", "kept"),
    [(0.0, 30.0, True), (9.0, 30.0, True), (9.0, 0.0, False), (0.0, 3.0, False), (9.0, -9.0, False)],
)  # the last: given upright in the detector's tilted frame
def test_a_detection_lying_tilted_in_both_frames_keeps_its_tilt(
    frame_tilt_deg: float, box_tilt_deg: float, kept: bool
) -> None:
    turn = _tilt(frame_tilt_deg)  # the detector's frame against gravity
    cloud = _floor_and_top(np.random.default_rng(3)) @ turn.T + [0.0, 0.0, 0.5]
    lying = _tilt(box_tilt_deg)  # the box against gravity
    given = turn @ lying  # as the detector sees it in its frame
    centre = (turn @ [0.0, 0.0, 0.3]) + [0.0, 0.0, 0.5]
    detection = {"id": "a", "center": centre.tolist(), "size": [0.4, 0.3, 0.3], "orientation_xyzw": _quaternion(given)}
    box = scene_from_cloud(cloud, [detection]).scene.box("a")
    rotation = rotation_matrix(box.orientation_xyzw)
    if kept:
        assert rotation == pytest.approx(lying, abs=0.01)  # the tilt against gravity, not the frame's
        assert box.size.tolist() == [0.4, 0.3, 0.3]
    else:
        assert abs(rotation[2, 2]) == pytest.approx(1.0)  # levelled
    assert box.position[2] == pytest.approx(0.3, abs=0.005)


def _write_pcd(path: Path, points: np.ndarray, data: str) -> None:
    header = (
        "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z intensity\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\n"
        f"WIDTH {len(points)}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {len(points)}\nDATA {data}\n"
    )
    values = np.column_stack([points, np.ones(len(points))]).astype("<f4")
    body = (
        values.tobytes()
        if data == "binary"
        else "\n".join(" ".join(f"{v:.6f}" for v in row) for row in values).encode()
    )
    path.write_bytes(header.encode() + body)


@pytest.mark.parametrize("data", ["ascii", "binary"])
def test_pcd_files_are_read_in_ascii_and_binary(tmp_path: Path, data: str) -> None:
    points = np.random.default_rng(0).uniform(-1, 1, (50, 3))
    _write_pcd(tmp_path / "cloud.pcd", points, data)
    assert load_cloud(tmp_path / "cloud.pcd") == pytest.approx(points.astype("<f4").astype(np.float64), abs=1e-6)


def _mangled(text: str, data: str) -> str:
    """The test cloud's PCD text (5 points) with ``text`` edited: ``KEY=VALUE`` sets a header line."""
    key, value = text.split("=", 1)
    lines = data.splitlines()
    lines = [f"{key} {value}" if line.split()[0] == key else line for line in lines]
    return "\n".join(lines) + "\n"


@pytest.mark.parametrize(
    ("change", "rows", "message"),
    [
        ("POINTS=7", None, r"the header gives 7 POINTS, the ascii data holds 5 rows"),
        ("POINTS=-5", None, r"expected a POINTS count of at least 0, got -5"),
        ("COUNT=1 1 1", None, r"expected one SIZE, TYPE and COUNT \(at least 1\) for each of the 4 FIELDS"),
        ("TYPE=F F F", None, r"expected one SIZE, TYPE and COUNT"),
        ("COUNT=1 1 1 0", None, r"expected one SIZE, TYPE and COUNT \(at least 1\)"),
        (None, ["1 2 3"] * 5, r"expected ascii rows of 4 numbers each, got 3"),
        (None, ["1 2 x 4"] * 5, r"expected ascii rows of 4 numbers each"),
    ],
)
def test_a_malformed_ascii_pcd_is_one_line(
    tmp_path: Path, change: str | None, rows: list[str] | None, message: str
) -> None:
    _write_pcd(tmp_path / "cloud.pcd", np.zeros((5, 3)), "ascii")
    text = (tmp_path / "cloud.pcd").read_text()
    header, body = text.split("DATA ascii\n")
    header = _mangled(change, header) if change else header
    body = "\n".join(rows) + "\n" if rows else body
    (tmp_path / "cloud.pcd").write_text(header + "DATA ascii\n" + body)
    with pytest.raises(InvalidFile, match=message):
        load_cloud(tmp_path / "cloud.pcd")


@pytest.mark.parametrize("points", [6, 10**12])
def test_a_binary_pcd_shorter_than_its_header_says_is_one_line(tmp_path: Path, points: int) -> None:
    _write_pcd(tmp_path / "cloud.pcd", np.zeros((5, 3)), "binary")
    raw = (tmp_path / "cloud.pcd").read_bytes().replace(b"POINTS 5", f"POINTS {points}".encode())
    (tmp_path / "cloud.pcd").write_bytes(raw)
    with pytest.raises(InvalidFile, match=rf"the header gives {points} POINTS, the binary data holds 5"):
        load_cloud(tmp_path / "cloud.pcd")


def test_compressed_pcd_is_refused_in_one_line(tmp_path: Path) -> None:
    _write_pcd(tmp_path / "cloud.pcd", np.zeros((5, 3)), "binary_compressed")
    with pytest.raises(InvalidFile, match="PCD data 'binary_compressed' is not read"):
        load_cloud(tmp_path / "cloud.pcd")


def test_keys_a_box_is_not_read_from_are_left_out_with_a_warning(tmp_path: Path) -> None:
    box = {"id": "a", "center": [0, 0, 0.15], "size": [0.4, 0.3, 0.3], "score": 0.9, "label": "carton"}
    (tmp_path / "boxes.json").write_text(json.dumps([box]))
    with pytest.warns(UserWarning, match=r"detection keys passed over .*: label, score"):
        [read] = load_detections(tmp_path / "boxes.json")
    assert sorted(read) == ["center", "id", "size"]


@pytest.mark.parametrize("suffix", [".npy", ".ply", ".pcd"])
def test_points_without_a_reading_are_left_out_with_a_warning_in_every_format(tmp_path: Path, suffix: str) -> None:
    cloud = np.random.default_rng(4).uniform(0.0, 1.0, (10, 3))
    cloud[[2, 7]] = np.nan  # an organised cloud's pixels without a reading
    path = tmp_path / f"cloud{suffix}"
    if suffix == ".npy":
        np.save(path, cloud)
    elif suffix == ".ply":
        from plyfile import PlyData, PlyElement

        vertices = np.array([tuple(point) for point in cloud], dtype=[("x", "f8"), ("y", "f8"), ("z", "f8")])
        PlyData([PlyElement.describe(vertices, "vertex")]).write(str(path))
    else:
        _write_pcd(path, cloud, "ascii")
    with pytest.warns(UserWarning, match=r"2 of 10 points without a finite reading \(NaN or infinite\) left out"):
        read = load_cloud(path)
    assert read.shape == (8, 3) and np.allclose(read, cloud[np.isfinite(cloud).all(axis=1)])


def test_a_binary_pcd_with_pcls_padding_fields_and_counts_is_read(tmp_path: Path) -> None:
    points = np.random.default_rng(5).uniform(-1, 1, (20, 3))
    header = (  # PCL's PointNormal: padding fields all named "_", and a field of two components
        "VERSION 0.7\nFIELDS x y z _ normal_x _ curvature\nSIZE 4 4 4 1 4 1 4\nTYPE F F F U F U F\n"
        f"COUNT 1 1 1 4 3 4 2\nWIDTH {len(points)}\nHEIGHT 1\nPOINTS {len(points)}\nDATA binary\n"
    )
    record = np.dtype([("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("p", "u1", (4,)), ("n", "<f4", (3,)),
                       ("q", "u1", (4,)), ("c", "<f4", (2,))])  # fmt: skip
    rows = np.zeros(len(points), dtype=record)
    rows["x"], rows["y"], rows["z"] = points.T
    (tmp_path / "normals.pcd").write_bytes(header.encode() + rows.tobytes())
    assert load_cloud(tmp_path / "normals.pcd") == pytest.approx(points.astype("<f4").astype(np.float64), abs=1e-6)


@pytest.mark.parametrize(
    "scale, hint",
    [(1000.0, r"a cloud in millimetres\? unstack works in metres"),
     (1e30, r"no coordinates in metres: the wrong byte order, or fields other than x, y and z\?")],  # bytes swapped
)  # fmt: skip
def test_a_cloud_not_in_metres_is_refused_saying_what_its_values_look_like(
    tmp_path: Path, scale: float, hint: str
) -> None:
    np.save(tmp_path / "cloud.npy", np.random.default_rng(6).uniform(0.5, 2.0, (200, 3)) * scale)
    with pytest.raises(
        InvalidFile, match=rf"cloud.npy: \$: [\d,]+ of [\d,]+ points lie beyond 100 m of the origin .*{hint}"
    ):
        load_cloud(tmp_path / "cloud.npy")


def test_a_cloud_file_of_another_kind_names_the_three_read(tmp_path: Path) -> None:
    (tmp_path / "cloud.xyz").write_text("0 0 0\n")
    with pytest.raises(InvalidFile, match=r"cloud.xyz: \$: expected a .npy, .ply or .pcd point cloud file, got"):
        load_cloud(tmp_path / "cloud.xyz")


def test_detections_with_a_key_twice_in_one_object_are_refused(tmp_path: Path) -> None:
    (tmp_path / "boxes.json").write_text('[{"id": "a", "id": "b", "center": [1, 0, 0.2], "size": [0.4, 0.4, 0.4]}]')
    with pytest.raises(InvalidFile, match=r"boxes.json: \$: the key 'id' appears twice in one JSON object"):
        load_detections(tmp_path / "boxes.json")


def test_detections_are_not_read_from_standard_input() -> None:
    with pytest.raises(
        InvalidFile, match=r"^-: \$: expected the name of the detections file: standard input is not read for it"
    ):
        load_detections("-")


def _ply(path: Path, header_count: int, rows: int, *, binary: bool, extra: bytes = b"") -> Path:
    cloud = np.random.default_rng(7).uniform(0.0, 1.0, (rows, 3)).astype("<f4")
    kind = "binary_little_endian" if binary else "ascii"
    header = f"ply\nformat {kind} 1.0\nelement vertex {header_count}\nproperty float x\nproperty float y\nproperty float z\nend_header\n"
    body = cloud.tobytes() if binary else "".join(f"{x} {y} {z}\n" for x, y, z in cloud).encode()
    path.write_bytes(header.encode() + body + extra)
    return path


@pytest.mark.parametrize(
    "header_count, rows, binary, extra, message",
    [(10, 12, False, b"", r"the header gives 10 vertices, the data 12"),
     (12, 12, True, b"\0" * 8, r"the binary data holds 8 bytes beyond the header's 12 vertices"),
     (10**12, 3, False, b"", r"expected a vertex count from 0 to 5,000,000, got 1,000,000,000,000"),
     (-5, 3, False, b"", r"expected a vertex count from 0 to 5,000,000, got -5")],
)  # fmt: skip
def test_a_ply_whose_header_and_data_disagree_is_refused_in_one_line(
    tmp_path: Path, header_count: int, rows: int, binary: bool, extra: bytes, message: str
) -> None:
    path = _ply(tmp_path / "cloud.ply", header_count, rows, binary=binary, extra=extra)
    with pytest.raises(InvalidFile, match=rf"cloud.ply: \$: {message}$"):
        load_cloud(path)


@pytest.mark.parametrize(
    ("faces", "message"),
    [("200000000", r"the header declares 200,000,000 rows of element 'face', more than the 24 bytes of data after it"),
     ("many", r"expected a row count of element 'face', got 'many'")],
)  # fmt: skip
def test_a_ply_declaring_more_rows_of_any_element_than_its_bytes_is_refused_before_reading(
    tmp_path: Path, faces: str, message: str
) -> None:
    """plyfile allocates what the header declares before it reads: 200 million faces took 1.6 GB."""
    header = (
        "ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
        f"property float z\nelement face {faces}\nproperty list uchar int vertex_indices\nend_header\n"
    )
    (tmp_path / "cloud.ply").write_bytes(header.encode() + b"\0" * 24)
    with pytest.raises(InvalidFile, match=rf"cloud.ply: \$: {message}$"):
        load_cloud(tmp_path / "cloud.ply")


@pytest.mark.parametrize("binary", [False, True])
def test_a_ply_whose_header_and_data_agree_is_read(tmp_path: Path, binary: bool) -> None:
    assert load_cloud(_ply(tmp_path / "cloud.ply", 12, 12, binary=binary)).shape == (12, 3)


def test_the_library_takes_numpy_detections_and_leaves_out_points_without_a_reading() -> None:
    cloud = np.vstack([_floor_and_top(np.random.default_rng(8)), [[np.nan, 0.0, 0.0]]])
    numpy_box = {
        "id": "a",
        "center": np.array([0.0, 0.0, 0.15]),
        "size": np.array([0.4, 0.3, 0.3]),
        "yaw_deg": np.float32(30),
    }
    with pytest.warns(
        UserWarning, match=r"<cloud>: 1 of 4,801 points without a finite reading \(NaN or infinite\) left out"
    ):
        built = scene_from_cloud(cloud, [numpy_box])
    plain = scene_from_cloud(
        cloud[:-1], [{"id": "a", "center": [0.0, 0.0, 0.15], "size": [0.4, 0.3, 0.3], "yaw_deg": 30}]
    )
    assert np.allclose(built.scene.box("a").position, plain.scene.box("a").position)


@pytest.mark.parametrize("door, doubted", [(None, False), ([-1.0, 0.0, 0.0], False), ([1.0, 0.0, 0.0], True)])
def test_a_door_given_the_wrong_way_for_a_cloud_is_doubted(door: list[float] | None, doubted: bool) -> None:
    cloud = _floor_and_top(np.random.default_rng(9)) + np.array([1.0, 0.0, 0.0])  # the pile 1 m in from the door
    box = {"id": "a", "center": [1.0, 0.0, 0.15], "size": [0.4, 0.3, 0.3], "yaw_deg": 0}
    doubts = scene_from_cloud(cloud, [box], door=door).doubts()
    assert any(doubt.startswith("the boxes stand in front of the door") for doubt in doubts) is doubted


def test_keys_beside_the_boxes_are_passed_over_with_a_warning(tmp_path: Path) -> None:
    boxes = [{"id": "a", "center": [1.0, 0.0, 0.2], "size": [0.4, 0.4, 0.4]}]
    (tmp_path / "boxes.json").write_text(json.dumps({"boxes": boxes, "frame": "camera", "stamp": 1}))
    with pytest.warns(UserWarning, match=r"keys passed over \(the boxes are read from 'boxes' alone\): frame, stamp"):
        assert [box["id"] for box in load_detections(tmp_path / "boxes.json")] == ["a"]


@pytest.mark.parametrize(
    "change, message",
    [(("WIDTH 5", "WIDTH 4"), r"the PCD header's WIDTH x HEIGHT \(4 x 1\) is not its 5 POINTS"),
     (("POINTS 5", "POINTS 5\nPOINTS 5"), r"the PCD header gives POINTS twice")],
)  # fmt: skip
def test_a_pcd_header_at_odds_with_itself_is_refused(tmp_path: Path, change: tuple[str, str], message: str) -> None:
    _write_pcd(tmp_path / "cloud.pcd", np.zeros((5, 3)), "binary")
    raw = (tmp_path / "cloud.pcd").read_bytes().replace(change[0].encode(), change[1].encode(), 1)
    (tmp_path / "cloud.pcd").write_bytes(raw)
    with pytest.raises(InvalidFile, match=message):
        load_cloud(tmp_path / "cloud.pcd")


def test_a_pcd_viewpoint_is_not_applied_and_says_so(tmp_path: Path) -> None:
    points = np.random.default_rng(10).uniform(-1, 1, (5, 3))
    _write_pcd(tmp_path / "cloud.pcd", points, "ascii")
    raw = (tmp_path / "cloud.pcd").read_bytes().replace(b"VIEWPOINT 0 0 0 1 0 0 0", b"VIEWPOINT 1 2 3 1 0 0 0")
    (tmp_path / "cloud.pcd").write_bytes(raw)
    with pytest.warns(UserWarning, match=r"VIEWPOINT 1 2 3 1 0 0 0 is not applied: the points are taken as they are"):
        assert load_cloud(tmp_path / "cloud.pcd") == pytest.approx(points, abs=1e-5)
