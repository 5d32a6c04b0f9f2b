"""``unstack scene``: camera files in, a scene that ``unstack decide`` takes out."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from tests.conftest import unstack

pytestmark = pytest.mark.slow  # subprocesses


def test_the_scene_is_written_and_decided(camera_files: list[str], tmp_path: Path) -> None:
    out = tmp_path / "out" / "scene.json"
    out.parent.mkdir()
    run = unstack("scene", *camera_files, "--sizes", "0.6x0.4x0.4,0.4x0.3x0.3", "--out", str(out),
                  "--report", str(tmp_path / "report.json"))  # fmt: skip
    assert run.returncode == 0, run.stderr
    assert "gravity tilted 9.0 degrees" in run.stdout
    assert json.loads((tmp_path / "report.json").read_text())["tilt_deg"] == pytest.approx(9.0, abs=0.3)
    decided = unstack("decide", str(out), "--seed", "0", "--json")
    assert decided.returncode == 0, decided.stderr
    assert json.loads(decided.stdout)["choice"] in ("b00", "b01")


def test_a_cloud_and_detections_make_a_scene(cloud_and_detections: list[str], tmp_path: Path) -> None:
    out = tmp_path / "scene.json"
    run = unstack("scene", *cloud_and_detections, "--out", str(out))
    assert run.returncode == 0, run.stderr
    assert json.loads(out.read_text())["detected"] == ["low", "high"]


def test_two_scene_files_whose_names_differ_in_case_keep_a_cloud_each(
    cloud_and_detections: list[str], tmp_path: Path
) -> None:
    for name in ("x.json", "x.JSON"):
        run = unstack("scene", *cloud_and_detections, "--out", str(tmp_path / name))
        assert run.returncode == 0, run.stderr
    assert json.loads((tmp_path / "x.json").read_text())["points_file"] == "x.points.npy"
    assert json.loads((tmp_path / "x.JSON").read_text())["points_file"] == "x.JSON.points.npy"
    assert (tmp_path / "x.points.npy").exists() and (tmp_path / "x.JSON.points.npy").exists()


def test_a_cloud_without_detections_is_one_line(tmp_path: Path) -> None:
    np.save(tmp_path / "cloud.npy", np.zeros((200, 3)))
    run = unstack("scene", "--cloud", str(tmp_path / "cloud.npy"), "--out", str(tmp_path / "scene.json"))
    assert run.returncode == 2 and "--cloud needs --detections" in run.stderr


def test_a_depth_image_and_detections_make_a_scene(camera_files: list[str], tmp_path: Path) -> None:
    (tmp_path / "boxes.json").write_text(json.dumps([{"id": "a", "center": [0, 0, 0.15], "size": [0.4, 0.3, 0.3]}]))
    depth_only = [argument for argument in camera_files if "mask-" not in argument]
    run = unstack("scene", *depth_only, "--detections", str(tmp_path / "boxes.json"), "--out", str(tmp_path / "s.json"))
    assert run.returncode == 0, run.stderr
    assert json.loads((tmp_path / "s.json").read_text())["detected"] == ["a"]


def test_a_scene_with_a_box_in_the_floor_is_written_and_warned_about(tmp_path: Path) -> None:
    rng = np.random.default_rng(0)
    floor = np.column_stack([rng.uniform(-1, 1, 4000), rng.uniform(-1, 1, 4000), np.zeros(4000)])
    np.save(tmp_path / "cloud.npy", floor)
    sunk = [{"id": "sunk", "center": [0, 0, 0.0], "size": [0.4, 0.3, 0.3], "yaw_deg": 0}]
    (tmp_path / "boxes.json").write_text(json.dumps(sunk))
    out = tmp_path / "scene.json"
    run = unstack("scene", "--cloud", str(tmp_path / "cloud.npy"), "--detections", str(tmp_path / "boxes.json"),
                  "--out", str(out))  # fmt: skip
    assert run.returncode == 0 and out.exists()
    assert f"unstack: warning: {out}: box 'sunk' reaches 0.15 m into the floor" in run.stderr


def test_an_unwritable_report_stops_the_command_before_the_scene_is_written(
    camera_files: list[str], tmp_path: Path
) -> None:
    out = tmp_path / "scene.json"
    run = unstack("scene", *camera_files, "--out", str(out), "--report", str(tmp_path / "missing" / "report.json"))
    assert run.returncode == 2 and "cannot write there: the folder" in run.stderr
    assert not out.exists() and not (tmp_path / "scene.points.npy").exists()


@pytest.mark.parametrize("report", ["scene.json", "scene.points.npy", "pose.json"])
def test_a_report_on_the_scene_or_an_input_is_refused_before_any_work(
    camera_files: list[str], tmp_path: Path, report: str
) -> None:
    before = (tmp_path / "pose.json").read_text()
    run = unstack("scene", *camera_files, "--out", str(tmp_path / "scene.json"), "--report", str(tmp_path / report))
    assert run.returncode == 2 and len(run.stderr.strip().splitlines()) == 1
    assert not (tmp_path / "scene.json").exists() and (tmp_path / "pose.json").read_text() == before


def test_a_mask_given_twice_is_named(camera_files: list[str], tmp_path: Path) -> None:
    run = unstack("scene", *camera_files, camera_files[-1], "--out", str(tmp_path / "scene.json"))
    assert run.returncode == 2 and f"{camera_files[-1]}: the same mask file is given twice" in run.stderr


def test_a_mask_file_that_names_no_box_is_refused(camera_files: list[str], tmp_path: Path) -> None:
    unnamed = tmp_path / "mask-.png"
    unnamed.write_bytes(Path(camera_files[-1]).read_bytes())
    run = unstack("scene", *camera_files[:-1], str(unnamed), "--out", str(tmp_path / "scene.json"))
    assert run.returncode == 2 and f"{unnamed}: the file name gives an empty box id" in run.stderr
    assert not (tmp_path / "scene.json").exists()


def _as_label_image(camera_files: list[str], tmp_path: Path, labels: tuple[int, ...]) -> list[str]:
    """The fixture's masks written as one 16-bit label image (the k-th mask as ``labels[k]``)."""
    from PIL import Image

    masks = [path for path in camera_files if Path(path).name.startswith("mask-")]
    image = np.zeros(np.asarray(Image.open(masks[0])).shape, dtype=np.uint16)
    for label, path in zip(labels, masks, strict=True):
        image[np.asarray(Image.open(path)) != 0] = label
    Image.fromarray(image).save(tmp_path / "labels.png")
    return [*(argument for argument in camera_files if argument not in masks), str(tmp_path / "labels.png")]


def test_a_label_image_makes_the_same_boxes_as_one_mask_per_box(camera_files: list[str], tmp_path: Path) -> None:
    sizes = ("--sizes", "0.6x0.4x0.4,0.4x0.3x0.3")
    by_masks = unstack("scene", *camera_files, *sizes, "--out", str(tmp_path / "masks.json"))
    by_labels = unstack("scene", *_as_label_image(camera_files, tmp_path, (7, 300)), "--labels", *sizes,
                        "--out", str(tmp_path / "labels.json"))  # fmt: skip
    assert by_masks.returncode == 0 and by_labels.returncode == 0, by_labels.stderr
    boxes = {box["id"]: box for box in json.loads((tmp_path / "labels.json").read_text())["boxes"]}
    assert sorted(boxes) == ["label-300", "label-7"]
    for box in json.loads((tmp_path / "masks.json").read_text())["boxes"]:
        twin = boxes[{"b00": "label-7", "b01": "label-300"}[box["id"]]]
        assert twin["position"] == box["position"] and twin["size"] == box["size"]


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--ids", "a"], "--ids names 1 boxes but 2 labels in "),
        (
            ["--detections", "boxes.json"],
            "--labels reads one label image and a depth image; got 1 mask files and --detections",
        ),
    ],
    ids=["ids-count", "with-detections"],
)
def test_a_label_image_with_arguments_it_cannot_take_is_refused(
    camera_files: list[str], tmp_path: Path, extra: list[str], message: str
) -> None:
    arguments = _as_label_image(camera_files, tmp_path, (1, 2))
    extra = [str(tmp_path / part) if part.endswith(".json") else part for part in extra]
    run = unstack("scene", *arguments, "--labels", *extra, "--out", str(tmp_path / "scene.json"))
    assert run.returncode == 2 and message in run.stderr and run.stderr.count("\n") == 1, run.stderr
    assert not (tmp_path / "scene.json").exists()


def test_a_label_image_given_as_one_mask_is_warned_about(camera_files: list[str], tmp_path: Path) -> None:
    run = unstack("scene", *_as_label_image(camera_files, tmp_path, (1, 2)), "--out", str(tmp_path / "scene.json"))
    assert "labels.png: the mask holds 2 values that each cover a large part of it (1: " in run.stderr
    assert "a label image, a value per box? (unstack scene --labels" in run.stderr


def test_an_id_given_to_two_boxes_is_named_with_its_option(camera_files: list[str], tmp_path: Path) -> None:
    run = unstack("scene", *camera_files, "--ids", "a,a", "--out", str(tmp_path / "scene.json"))
    assert run.returncode == 2 and "--ids: the box id 'a' is given to two boxes; ids must differ" in run.stderr


def test_ids_name_every_value_of_a_label_image_and_a_line_left_out_is_named_by_its_id(
    camera_files: list[str], tmp_path: Path
) -> None:
    from PIL import Image

    arguments = _as_label_image(camera_files, tmp_path, (1, 2))
    image = np.asarray(Image.open(tmp_path / "labels.png")).copy()
    image[0, :] = 9  # a line a pixel thick along the top: a third value in the file
    Image.fromarray(image).save(tmp_path / "labels.png")
    run = unstack("scene", *arguments, "--labels", "--ids", "near,far,edge", "--out", str(tmp_path / "scene.json"))
    assert run.returncode == 0, run.stderr
    assert "1 labels are lines a pixel or two thick (9 (edge)), too thin to show a box: left out" in run.stderr
    boxes = [box["id"] for box in json.loads((tmp_path / "scene.json").read_text())["boxes"]]
    assert sorted(boxes) == ["far", "near"]


def test_a_label_image_of_another_size_than_the_depth_is_refused_before_the_ids_are_counted(
    camera_files: list[str], tmp_path: Path
) -> None:
    from PIL import Image

    arguments = _as_label_image(camera_files, tmp_path, (1, 2))
    image = np.asarray(Image.open(tmp_path / "labels.png"))
    Image.fromarray(image[::2, ::2]).save(tmp_path / "labels.png")  # nearest-neighbour, half the size
    run = unstack("scene", *arguments, "--labels", "--ids", "a,b,c", "--out", str(tmp_path / "scene.json"))
    assert run.returncode == 2 and run.stderr.count("\n") == 1, run.stderr
    assert "labels.png: $: expected a label image of " in run.stderr and "like the depth image, got " in run.stderr


def test_gravity_from_the_pose_is_said_in_the_table_the_warnings_and_the_report(
    camera_files: list[str], tmp_path: Path
) -> None:
    # the fixture's pose frame is tilted 9 degrees against gravity: taken as asked, and said
    run = unstack("scene", *camera_files, "--sizes", "0.6x0.4x0.4,0.4x0.3x0.3", "--gravity", "pose",
                  "--out", str(tmp_path / "scene.json"), "--report", str(tmp_path / "report.json"))  # fmt: skip
    assert run.returncode == 0, run.stderr
    assert "gravity along the pose's z" in run.stdout
    assert "level planes lean 9.0 degrees" in run.stderr
    report = json.loads((tmp_path / "report.json").read_text())
    assert report["gravity"] == "pose" and report["tilt_deg"] == 0.0
    assert report["planes_tilt_deg"] == pytest.approx(9.0, abs=0.3)


def test_an_unknown_gravity_source_is_one_line(camera_files: list[str], tmp_path: Path) -> None:
    run = unstack("scene", *camera_files, "--gravity", "imu", "--out", str(tmp_path / "scene.json"))
    assert run.returncode == 2 and run.stderr.count("\n") == 1
    assert "--gravity" in run.stderr and "'imu' is not one of 'planes', 'pose'" in run.stderr
    assert not (tmp_path / "scene.json").exists()
