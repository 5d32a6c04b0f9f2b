"""Reading a camera's files: units checked, poses validated, one-line errors."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from unstack.camera import load_depth, load_intrinsics, load_label_masks, load_mask, load_pose
from unstack.camera.files import line_labels
from unstack.errors import InvalidArgument, InvalidFile


def _png(path: Path, array: np.ndarray) -> Path:
    Image.fromarray(array).save(path)
    return path


def test_a_16_bit_png_in_millimetres_reads_as_metres(tmp_path: Path) -> None:
    depth = load_depth(_png(tmp_path / "d.png", np.full((4, 5), 1250, dtype=np.uint16)))
    assert depth.dtype == np.float64 and depth[0, 0] == pytest.approx(1.25)


def test_an_8_bit_png_is_refused_as_a_depth_image(tmp_path: Path) -> None:
    with pytest.raises(InvalidFile, match="expected a 16-bit PNG of depths, got an 8-bit image"):
        load_depth(_png(tmp_path / "d.png", np.full((4, 5), 200, dtype=np.uint8)))


def test_metres_declared_as_millimetres_are_refused(tmp_path: Path) -> None:
    with pytest.raises(InvalidFile, match="declared in mm but every reading is at most 20 mm: are the values metres"):
        load_depth(_png(tmp_path / "d.png", np.full((4, 5), 2, dtype=np.uint16)))


def test_millimetres_declared_as_metres_are_refused(tmp_path: Path) -> None:
    np.save(tmp_path / "d.npy", np.full((4, 5), 1250.0))
    with pytest.raises(InvalidFile, match="declared in m but the median reading is 1250 m: are the values millimetres"):
        load_depth(tmp_path / "d.npy")


def test_a_depth_image_without_readings_is_refused(tmp_path: Path) -> None:
    with pytest.raises(InvalidFile, match=r"holds no reading \(every pixel is 0 or not a number\)"):
        load_depth(_png(tmp_path / "d.png", np.zeros((4, 5), dtype=np.uint16)))
    np.save(tmp_path / "d.npy", np.full((4, 5), -1.5))
    with pytest.raises(InvalidFile, match=r"holds no reading \(every pixel is 0, negative or not a number\)"):
        load_depth(tmp_path / "d.npy")


@pytest.mark.parametrize(
    "value, question",
    [(65535, r"every reading is 65535, the largest the image holds: a code for no reading\?"),
     (52000, r"are the values in a finer unit than millimetres \(a depth scale of 0.1 mm, say: --depth-units 0.0001\)\?")],
)  # fmt: skip
def test_a_png_of_readings_beyond_any_camera_asks_the_right_question(tmp_path: Path, value: int, question: str) -> None:
    with pytest.raises(InvalidFile, match=f"declared in mm but the median reading is [0-9.]+ m: {question}"):
        load_depth(_png(tmp_path / "d.png", np.full((4, 5), value, dtype=np.uint16)))


@pytest.mark.parametrize("units", ["0.0001", 0.0001])
def test_a_depth_scale_in_metres_per_unit_reads_a_finer_unit(tmp_path: Path, units: str | float) -> None:
    depth = load_depth(_png(tmp_path / "d.png", np.full((4, 5), 12500, dtype=np.uint16)), units=units)
    assert depth[0, 0] == pytest.approx(1.25)


@pytest.mark.parametrize("units", ["0.1mm", "cm", "0", "-0.001", "2", "nan", True, np.bool_(True), b"0.001"])
def test_depth_units_that_are_no_unit_nor_a_scale_are_refused(tmp_path: Path, units: object) -> None:
    with pytest.raises(InvalidArgument, match=r"depth units: expected mm, m or the metres of one unit .* got "):
        load_depth(_png(tmp_path / "d.png", np.full((4, 5), 1250, dtype=np.uint16)), units=units)  # type: ignore[arg-type]


def test_a_pose_inside_an_object_is_read(tmp_path: Path) -> None:
    (tmp_path / "pose.json").write_text(json.dumps({"cam2root": np.eye(4).tolist()}))
    assert load_pose(tmp_path / "pose.json").shape == (4, 4)


def test_camera_json_written_with_a_byte_order_mark_is_read(tmp_path: Path) -> None:
    intrinsics = {"fx": 600, "fy": 600, "cx": 320, "cy": 240, "width": 640, "height": 480}
    (tmp_path / "k.json").write_bytes(b"\xef\xbb\xbf" + json.dumps(intrinsics).encode())
    assert load_intrinsics(tmp_path / "k.json").fx == 600


def test_a_mask_of_another_size_than_the_depth_image_is_refused(tmp_path: Path) -> None:
    mask = _png(tmp_path / "m.png", np.full((3, 3), 255, dtype=np.uint8))
    with pytest.raises(InvalidFile, match="expected a mask of 5 x 4 pixels like the depth image, got 3 x 3"):
        load_mask(mask, (4, 5))


def test_a_mask_holding_depth_values_is_a_mask_where_they_are_not_zero(tmp_path: Path) -> None:
    values = np.zeros((4, 5), dtype=np.uint16)
    values[1:3, 1:4] = 1684  # the NEURA capture's masks hold the depth inside the box
    assert load_mask(_png(tmp_path / "m.png", values)).sum() == 6


@pytest.mark.parametrize(
    "name, image_format, message",
    [
        ("m.jpg", "JPEG", r"m.jpg: \$: expected a mask .png or .npy, got 'm.jpg'"),
        ("m.bmp", "BMP", r"m.bmp: \$: expected a mask .png or .npy, got 'm.bmp'"),
        ("m.png", "JPEG", r"m.png: \$: expected a PNG or .npy mask, got a JPEG image \(its compression blurs edges"),
        ("m.png", "BMP", r"m.png: \$: expected a PNG or .npy mask, got a BMP image$"),
    ],
)
def test_a_mask_in_another_image_format_is_refused_whatever_its_name(
    tmp_path: Path, name: str, image_format: str, message: str
) -> None:
    values = np.zeros((4, 5), dtype=np.uint8)
    values[1:3, 1:4] = 255
    Image.fromarray(values).save(tmp_path / name, format=image_format)
    with pytest.raises(InvalidFile, match=message):
        load_mask(tmp_path / name)


def test_a_depth_png_that_is_another_format_inside_is_refused(tmp_path: Path) -> None:
    Image.fromarray(np.full((4, 5), 200, dtype=np.uint8)).save(tmp_path / "d.png", format="JPEG")
    with pytest.raises(InvalidFile, match=r"d.png: \$: expected a PNG or .npy depth image, got a JPEG image"):
        load_depth(tmp_path / "d.png")


def test_a_mask_is_where_it_is_not_zero_negative_values_too(tmp_path: Path) -> None:
    values = np.zeros((4, 5), dtype=np.int8)
    values[1:3, 1:4] = -1  # int8 255
    np.save(tmp_path / "m.npy", values)
    assert load_mask(tmp_path / "m.npy").sum() == 6
    np.save(tmp_path / "n.npy", np.full((4, 5), np.nan))
    with pytest.raises(InvalidFile, match=r"the mask is empty \(every pixel is 0 or not a number\)"):
        load_mask(tmp_path / "n.npy")


def test_an_empty_mask_is_refused(tmp_path: Path) -> None:
    with pytest.raises(InvalidFile, match="the mask is empty"):
        load_mask(_png(tmp_path / "m.png", np.zeros((4, 5), dtype=np.uint8)))


def _intrinsics(tmp_path: Path, **change: object) -> Path:
    intrinsics = {"fx": 600.0, "fy": 600.0, "cx": 320.0, "cy": 240.0, "width": 640, "height": 480, **change}
    (tmp_path / "k.json").write_text(json.dumps({key: value for key, value in intrinsics.items() if value is not None}))
    return tmp_path / "k.json"


def test_intrinsics_with_zero_distortion_and_other_keys_are_read_with_a_warning(tmp_path: Path) -> None:
    with pytest.warns(UserWarning, match="keys passed over .*: camera_name, distortion_model"):
        intrinsics = load_intrinsics(
            _intrinsics(tmp_path, D=[0, 0, 0, 0, 0], distortion_model="plumb_bob", camera_name="front")
        )
    assert intrinsics.fx == 600.0


@pytest.mark.parametrize(
    "given",
    [
        {"cx": None, "cy": None, "ppx": 320.0, "ppy": 240.0},
        {"fx": None, "fy": None, "cx": None, "cy": None, "K": [600.0, 0, 320.0, 0, 600.0, 240.0, 0, 0, 1]},
        {"fx": None, "fy": None, "cx": None, "cy": None, "k": [600.0, 0, 320.0, 0, 600.0, 240.0, 0, 0, 1]},
    ],
    ids=["realsense-ppx-ppy", "ros-K", "ros2-k"],
)
def test_realsense_and_ros_intrinsics_are_read_as_a_pinholes(tmp_path: Path, given: dict[str, object]) -> None:
    intrinsics = load_intrinsics(_intrinsics(tmp_path, **given))
    assert (intrinsics.fx, intrinsics.fy, intrinsics.cx, intrinsics.cy) == (600.0, 600.0, 320.0, 240.0)


@pytest.mark.parametrize(
    ("given", "message"),
    [
        ({"ppx": 320.0}, r"\$\.ppx: expected cx or ppx \(RealSense's name for it\), not both"),
        (
            {"K": [600.0, 0, 320.0, 0, 600.0, 240.0, 0, 0, 1]},
            r"\$\.K: expected the camera matrix K or fx, fy, cx, cy, not both",
        ),
        ({"fx": None, "fy": None, "cx": None, "cy": None, "K": [600.0, 0, 320.0]}, r"\$\.K: expected 9 numbers"),
        (
            {"fx": None, "fy": None, "cx": None, "cy": None, "K": [600.0, 3.0, 320.0, 0, 600.0, 240.0, 0, 0, 1]},
            r"\$\.K: expected a pinhole camera matrix \[fx, 0, cx, 0, fy, cy, 0, 0, 1\]",
        ),
    ],
    ids=["cx-and-ppx", "K-and-fx", "K-short", "K-skewed"],
)
def test_intrinsics_under_two_names_or_a_matrix_no_pinhole_has_are_refused(
    tmp_path: Path, given: dict[str, object], message: str
) -> None:
    with pytest.raises(InvalidFile, match=message):
        load_intrinsics(_intrinsics(tmp_path, **given))


def test_a_bare_camera_matrix_is_refused_for_want_of_the_image_size(tmp_path: Path) -> None:
    (tmp_path / "k.json").write_text(json.dumps([[600, 0, 320], [0, 600, 240], [0, 0, 1]]))
    with pytest.raises(InvalidFile, match="a bare 3 x 3 matrix gives no image size"):
        load_intrinsics(tmp_path / "k.json")


def test_depth_readings_no_camera_gives_are_no_readings_with_a_warning(tmp_path: Path) -> None:
    depth = np.full((4, 5), 1.5)
    depth[2, 3] = 1e300  # one outlier, as multipath or a reflection gives
    np.save(tmp_path / "d.npy", depth)
    with pytest.warns(
        UserWarning, match=r"d.npy: 1 readings beyond 20 m .* row 2, column 3: 1e\+300 m\) are taken as no"
    ):
        read = load_depth(tmp_path / "d.npy")
    assert read[2, 3] == 0.0 and np.count_nonzero(read) == 19


@pytest.mark.parametrize(
    ("mask", "message"),
    [
        (np.zeros((4, 5, 0), dtype=np.uint8), r"expected a single-channel mask image, got shape \(4, 5, 0\)"),
        (np.full((4, 5), "x"), r"expected a mask of numbers \(0 outside the box\), got values of <U1"),
        (np.ones((4, 5), dtype=complex), r"expected a mask of numbers .* got values of complex128"),
    ],
)
def test_a_mask_array_of_no_channel_or_no_numbers_is_refused(tmp_path: Path, mask: np.ndarray, message: str) -> None:
    np.save(tmp_path / "m.npy", mask)
    with pytest.raises(InvalidFile, match=message):
        load_mask(tmp_path / "m.npy")


def test_a_depth_file_that_is_no_npy_array_is_refused_without_numpys_pickle_advice(tmp_path: Path) -> None:
    (tmp_path / "d.npy").write_bytes(b"\x89PNG\r\n\x1a\n" + bytes(64))
    with pytest.raises(InvalidFile, match=r"d.npy: \$: expected a depth image as a .npy array of numbers") as refused:
        load_depth(tmp_path / "d.npy")
    assert "pickle" not in str(refused.value)


@pytest.mark.parametrize(
    ("labels", "message"),
    [
        (np.zeros((4, 5), dtype=np.uint16), r"the label image is empty \(every pixel is 0\)"),
        (np.full((4, 5), 1.5), "expected whole numbers in a label image"),
        (np.full((4, 5), -1, dtype=np.int32), "got negative values"),
        (np.ones((4, 5), dtype=bool), "got true/false values: a single mask"),
        (
            np.arange(2000, dtype=np.uint16).reshape(40, 50) + 1,
            r"expected at most 1,000 labels .* got 2,000: a depth image\?",
        ),
        (np.ones((4, 5, 3), dtype=np.uint8), r"expected a single-channel label image, got shape \(4, 5, 3\)"),
    ],
    ids=["empty", "fractions", "negative", "boolean", "depth-image", "colour"],
)
def test_what_is_no_label_image_is_refused(tmp_path: Path, labels: np.ndarray, message: str) -> None:
    np.save(tmp_path / "labels.npy", labels)
    with pytest.raises(InvalidFile, match=message):
        load_label_masks(tmp_path / "labels.npy")


def test_a_label_image_of_another_size_than_the_depth_image_is_refused(tmp_path: Path) -> None:
    np.save(tmp_path / "labels.npy", np.ones((4, 5), dtype=np.uint8))
    with pytest.raises(InvalidFile, match="expected a label image of 6 x 4 pixels like the depth image, got 5 x 4"):
        load_label_masks(tmp_path / "labels.npy", (4, 6))


@pytest.mark.parametrize(
    ("labels", "message"),
    [
        (np.array([[1.0, np.inf], [2.0, 0.0]]), r"got 1 infinite ones \(the first at row 0, column 1\)"),
        (np.array([[1.0, 1e20], [2.0, 0.0]]), r"expected labels up to 9,007,199,254,740,992, got 1e\+20"),
        (
            np.pad(np.full((4, 4), 3, dtype=np.uint8), 8, constant_values=255),
            r"label 255 covers 96 % of the image and reaches all four of its edges: the background\?",
        ),
    ],
    ids=["infinite", "huge", "background-255"],
)
def test_label_values_no_box_has_are_refused(tmp_path: Path, labels: np.ndarray, message: str) -> None:
    np.save(tmp_path / "labels.npy", labels)
    with pytest.raises(InvalidFile, match=message):
        load_label_masks(tmp_path / "labels.npy")


def test_labels_a_pixel_thick_between_others_are_left_out_with_a_warning(tmp_path: Path) -> None:
    labels = np.zeros((12, 12), dtype=np.uint8)
    labels[1:6, 1:11], labels[7:11, 1:11] = 10, 20
    labels[6, 1:11] = 15  # the edge between the two, as smoothing leaves it
    np.save(tmp_path / "labels.npy", labels)
    with pytest.warns(UserWarning, match=r"1 labels are lines a pixel or two thick \(15\), too thin .*: left out"):
        assert sorted(load_label_masks(tmp_path / "labels.npy")) == [10, 20]
    np.save(tmp_path / "lines.npy", np.eye(12, dtype=np.uint8))
    with pytest.raises(InvalidFile, match="every label is a line a pixel or two thick"):
        load_label_masks(tmp_path / "lines.npy")


def _one_block(tmp_path: Path) -> Path:
    """A 5 x 6 label image of one label over 3 x 4 pixels."""
    labels = np.zeros((5, 6), dtype=np.uint8)
    labels[1:4, 1:5] = 1
    np.save(tmp_path / "labels.npy", labels)
    return tmp_path / "labels.npy"


@pytest.mark.parametrize(
    "shape", [[5, 6], np.array([5, 6]), (np.int64(5), np.int64(6))], ids=["list", "array", "numpy-ints"]
)
def test_a_label_images_shape_may_be_any_pair_of_whole_numbers(tmp_path: Path, shape: object) -> None:
    assert list(load_label_masks(_one_block(tmp_path), shape)) == [1]  # type: ignore[arg-type]


@pytest.mark.parametrize("shape", [[5], [5.0, 6.0], [0, 6]], ids=["one-number", "floats", "zero"])
def test_a_shape_that_is_no_image_size_is_refused(tmp_path: Path, shape: object) -> None:
    with pytest.raises(InvalidArgument, match=r"shape: expected \(rows, columns\) of an image in pixels"):
        load_label_masks(_one_block(tmp_path), shape)  # type: ignore[arg-type]


@pytest.mark.parametrize("reader", [load_depth, load_intrinsics, load_label_masks, load_mask, load_pose])
@pytest.mark.parametrize("path", [b"/tmp/x.png", None, 3], ids=["bytes", "none", "number"])
def test_a_file_name_that_is_no_text_nor_path_is_refused(reader: object, path: object) -> None:
    with pytest.raises(InvalidArgument, match=r"expected a file name \(text or a path\), got "):
        reader(path)  # type: ignore[operator]


def test_a_camera_matrix_given_as_three_rows_is_read(tmp_path: Path) -> None:
    matrix = [[600.0, 0, 320.0], [0, 600.0, 240.0], [0, 0, 1]]
    intrinsics = load_intrinsics(_intrinsics(tmp_path, fx=None, fy=None, cx=None, cy=None, K=matrix))
    assert (intrinsics.fx, intrinsics.cy) == (600.0, 240.0)


def test_a_camera_matrix_given_as_both_K_and_k_is_refused(tmp_path: Path) -> None:
    flat = [600.0, 0, 320.0, 0, 600.0, 240.0, 0, 0, 1]
    with pytest.raises(InvalidFile, match=r"\$\.k: expected the camera matrix once, as K \(ROS\) or k \(ROS 2\)"):
        load_intrinsics(_intrinsics(tmp_path, fx=None, fy=None, cx=None, cy=None, K=flat, k=flat))


def test_lines_kept_on_request_are_found_by_line_labels(tmp_path: Path) -> None:
    labels = np.zeros((12, 12), dtype=np.uint8)
    labels[1:6, 1:11], labels[7:11, 1:11] = 10, 20
    labels[6, 1:11] = 15
    np.save(tmp_path / "labels.npy", labels)
    masks = load_label_masks(tmp_path / "labels.npy", lines=True)
    assert sorted(masks) == [10, 15, 20]
    assert line_labels(masks) == [15]


@pytest.mark.parametrize(
    ("matrix", "message"),
    [
        (np.eye(4).astype(str), r"\$: expected a 4 x 4 matrix of finite numbers, got text"),
        (np.eye(4, dtype=bool), r"\$: expected a 4 x 4 matrix of finite numbers, got true or false"),
        (np.eye(4, dtype=complex), r"\$: expected a 4 x 4 matrix of finite numbers, got complex numbers"),
        (np.ma.masked_array(np.eye(4), mask=np.eye(4, dtype=bool)), r"\$: expected a plain array, got a masked array"),
        ([[10**400, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]], r"\$\[0\]\[0\]: expected a finite number"),
        ("pose", r"\$: expected a 4 x 4 matrix of finite numbers, got text"),
    ],
    ids=["text", "bool", "complex", "masked", "huge-integer", "a-string"],
)
def test_a_library_pose_of_no_numbers_is_refused_by_its_path(matrix: object, message: str) -> None:
    from unstack.camera import check_pose
    from unstack.errors import InvalidFile

    with pytest.raises(InvalidFile, match=rf"^<camera_to_world>: {message}"):
        check_pose(matrix)


def test_a_library_pose_of_whole_numbers_or_nested_lists_is_taken_as_float64() -> None:
    from unstack.camera import check_pose

    assert check_pose(np.eye(4, dtype=int)).dtype == np.float64
    np.testing.assert_array_equal(check_pose(np.eye(4).tolist()), np.eye(4))
