"""Reading supports and scene files: every kind of bad input is one clear error."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import unstack
from unstack.errors import InvalidFile, InvalidScene, InvalidSupports, UnknownFormat
from unstack.scene import Box, Scene, load_scene
from unstack.supports import Supports, load_supports


def supports_document(**changes: Any) -> dict[str, Any]:
    document: dict[str, Any] = {
        "format": "unstack.supports/1",
        "objects": ["a", "b", "c"],
        "probabilities": [[0, 0.5, 0.2], [0.1, 0, 0.3], [0.4, 0.6, 0]],
    }
    document.update(changes)
    return document


def with_probability(row: int, column: int, value: Any) -> dict[str, Any]:
    """The valid supports document with one cell of its matrix replaced."""
    probabilities: list[list[Any]] = [list(values) for values in supports_document()["probabilities"]]
    probabilities[row][column] = value
    return supports_document(probabilities=probabilities)


def scene_document(**changes: Any) -> dict[str, Any]:
    document: dict[str, Any] = {
        "format": "unstack.scene/1",
        "boxes": [
            {"id": "a", "size": [0.6, 0.4, 0.4], "position": [1, 0, 0.2], "orientation_xyzw": [0, 0, 0, 1]},
            {"id": "b", "size": [0.4, 0.3, 0.3], "position": [1, 0, 0.55], "orientation_xyzw": [0, 0, 0, 1]},
        ],
        "points": [[0.7, 0.0, 0.2], [0.8, 0.0, 0.55]],
        "detected": ["b", "a"],
    }
    document.update(changes)
    return document


def write(tmp_path: Path, document: Any, name: str = "input.json") -> Path:
    path = tmp_path / name
    path.write_text(document if isinstance(document, str) else json.dumps(document))
    return path


BAD_SUPPORTS = [
    pytest.param("{not json", r"\$: invalid JSON at line 1 column 2", id="malformed"),
    pytest.param("[1, 2]", r"\$: expected a JSON object, got a list", id="not-object"),
    pytest.param("null", r"\$: expected a JSON object, got null", id="null"),
    pytest.param("  \n", r"\$: expected a JSON document, got an empty text", id="empty-text"),
    pytest.param(
        supports_document(format="unstack.supports/2"),
        r"\$\.format: unsupported version 'unstack.supports/2'",
        id="version",
    ),
    pytest.param(supports_document(format="other/1"), r"\$\.format: unknown format 'other/1'", id="unknown-format"),
    pytest.param({"objects": ["a"], "probabilities": [[0]]}, r"\$: missing required key 'format'", id="no-format"),
    pytest.param(
        {"format": "unstack.supports/1", "objects": ["a"]},
        r"\$: missing required key 'probabilities'",
        id="missing-key",
    ),
    pytest.param(
        supports_document(probabilities=[[0, 0.5], [0.1, 0]]), r"\$\.probabilities: expected 3 rows", id="not-square"
    ),
    pytest.param(
        supports_document(probabilities=[[0, 0.5, 0.2], [0.1, 0], [0.4, 0.6, 0]]),
        r"\$\.probabilities\[1\]: expected 3 numbers",
        id="ragged",
    ),
    pytest.param(
        with_probability(0, 1, "x"), r"\$\.probabilities\[0\]\[1\]: expected number, got 'x'", id="non-numeric"
    ),
    pytest.param(
        '{"format": "unstack.supports/1", "objects": ["a", "b"], "probabilities": [[0, NaN], [0.1, 0]]}',
        r"\$\.probabilities\[0\]\[1\]: expected a finite number, got nan",
        id="nan",
    ),
    pytest.param(
        '{"format": "unstack.supports/1", "objects": ["a", "b"], "probabilities": [[0, Infinity], [0.1, 0]]}',
        r"\$\.probabilities\[0\]\[1\]: expected a finite number, got inf",
        id="infinite",
    ),
    pytest.param(
        with_probability(0, 1, 1.5), r"\$\.probabilities\[0\]\[1\]: expected a number <= 1, got 1.5", id="above-one"
    ),
    pytest.param(
        with_probability(1, 0, -0.1), r"\$\.probabilities\[1\]\[0\]: expected a number >= 0, got -0.1", id="negative"
    ),
    pytest.param(
        with_probability(1, 1, 0.3), r"\$\.probabilities\[1\]\[1\]: expected 0 on the diagonal, got 0.3", id="diagonal"
    ),
    pytest.param(
        supports_document(objects=["a", "b", "a"]),
        r"\$\.objects: expected unique items, 'a' appears twice",
        id="duplicate-ids",
    ),
    pytest.param(
        supports_document(objects=["a", "b"]),
        r"\$\.probabilities: expected 2 rows \(one per object\), got 3",
        id="ids-vs-size",
    ),
    pytest.param(
        supports_document(objects=[], probabilities=[]), r"\$\.objects: expected at least 1 items, got 0", id="empty"
    ),
    pytest.param(
        supports_document(masses=[1, 2]), r"\$\.masses: expected 3 numbers, got shape \(2,\)", id="masses-length"
    ),
    pytest.param(supports_document(extra=1), r"\$: unexpected key 'extra'", id="unknown-key"),
    pytest.param(
        supports_document(masses=[1, 2, 1e308]), r"\$\.masses\[2\]: expected a number <= 10000, got 1e\+308", id="mass"
    ),
    pytest.param(
        supports_document(heights=[0, 0.4, -5]), r"\$\.heights\[2\]: expected a number >= -1, got -5", id="height"
    ),
    pytest.param(
        supports_document(hidden_load=[0, 1e6, 0]),
        r"\$\.hidden_load\[1\]: expected a number <= 1000, got 1000000",
        id="hidden-load",
    ),
]


@pytest.mark.parametrize(("document", "message"), BAD_SUPPORTS)
def test_bad_supports_files_name_file_path_and_expectation(tmp_path: Path, document: Any, message: str) -> None:
    path = write(tmp_path, document)
    with pytest.raises(InvalidFile, match=f"^{path}: {message}") as caught:
        load_supports(path)
    assert "\n" not in str(caught.value)


def test_a_byte_order_mark_before_the_document_is_passed_over(tmp_path: Path) -> None:
    path = tmp_path / "bom.json"
    path.write_bytes(b"\xef\xbb\xbf" + json.dumps(supports_document()).encode())
    assert load_supports(path).objects == ("a", "b", "c")


def test_unknown_version_is_its_own_error(tmp_path: Path) -> None:
    with pytest.raises(UnknownFormat):
        load_supports(write(tmp_path, supports_document(format="unstack.supports/9")))


def test_missing_file_and_directory(tmp_path: Path) -> None:
    with pytest.raises(InvalidFile, match=r"nope.json: \$: no such file"):
        load_supports(tmp_path / "nope.json")
    with pytest.raises(InvalidFile, match=r"\$: expected a JSON file, got a directory"):
        load_supports(tmp_path)


def test_supports_round_trip(tmp_path: Path) -> None:
    original = Supports(["x", "y"], [[0, 0.25], [0.75, 0]], masses=[3.0, 4.0], metadata={"by": "test"})
    original.save(tmp_path / "s.json")
    loaded = load_supports(tmp_path / "s.json")
    assert loaded.objects == ("x", "y")
    np.testing.assert_array_equal(loaded.probabilities, original.probabilities)
    np.testing.assert_array_equal(loaded.masses, [3.0, 4.0])
    assert loaded.metadata == {"by": "test"}


def test_in_memory_matrix_is_checked_too() -> None:
    with pytest.raises(
        InvalidSupports, match=r"<array>: \$\.probabilities: expected a 2 x 2 matrix, got shape \(2, 3\)"
    ):
        Supports(["a", "b"], np.zeros((2, 3)))


BAD_SCENES = [
    pytest.param(scene_document(boxes=[]), r"\$\.boxes: expected at least 1 items, got 0", id="no-boxes"),
    pytest.param(
        scene_document(
            boxes=[{"id": "a", "size": [0.6, -0.4, 0.4], "position": [1, 0, 0.2], "orientation_xyzw": [0, 0, 0, 1]}],
            detected=["a"],
        ),
        r"\$\.boxes\[0\]\.size\[1\]: expected a number > 0, got -0.4",
        id="negative-size",
    ),
    pytest.param(
        scene_document(
            boxes=[{"id": "a", "size": [0.6, 0.4, 0.4], "position": [1, 0, 0.2], "orientation_xyzw": [0, 0, 0, 2]}],
            detected=["a"],
        ),
        r"\$\.boxes\[0\]\.orientation_xyzw: expected a unit quaternion .* got norm 2",
        id="non-unit-quaternion",
    ),
    pytest.param(
        scene_document(detected=["a", "zz"]),
        r"\$\.detected\[1\]: expected the id of a box, got unknown id 'zz'",
        id="unknown-detected",
    ),
    pytest.param(
        scene_document(points=[[0, 0], [1, 1]]), r"\$\.points\[0\]: expected at least 3 items, got 2", id="points-shape"
    ),
    pytest.param(
        scene_document(points_file="cloud.npy"), r"\$: expected exactly one of points or points_file", id="both-clouds"
    ),
    pytest.param(
        {k: v for k, v in scene_document(points_file="missing.npy").items() if k != "points"},
        r"\$\.points_file: point cloud file .*missing.npy' does not exist",
        id="missing-points-file",
    ),
    pytest.param(
        scene_document(ground_truth={"support": [[0, 1], [1, 1]]}),
        r"\$\.ground_truth\.support\[1\]\[1\]: expected 0 on the diagonal, got 1.0",
        id="truth-diagonal",
    ),
    pytest.param(
        {k: v for k, v in scene_document(points_file="cloud.txt").items() if k != "points"},
        r"\$\.points_file: expected a \.npy or \.ply file name, got 'cloud.txt'",
        id="points-file-suffix",
    ),
]


@pytest.mark.parametrize(("document", "message"), BAD_SCENES)
def test_bad_scene_files(tmp_path: Path, document: Any, message: str) -> None:
    path = write(tmp_path, document)
    with pytest.raises(InvalidFile, match=f"^{path}: {message}"):
        load_scene(path)


def test_points_file_directory_and_bad_array(tmp_path: Path) -> None:
    (tmp_path / "cloud.npy").mkdir()
    document = {k: v for k, v in scene_document(points_file="cloud.npy").items() if k != "points"}
    with pytest.raises(InvalidScene, match=r"\$\.points_file: expected a point cloud file, got the directory"):
        load_scene(write(tmp_path, document))
    np.save(tmp_path / "flat.npy", np.zeros((4, 2)))
    document["points_file"] = "flat.npy"
    with pytest.raises(InvalidScene, match=r"\$\.points_file: expected an N x 3 array of points, got shape \(4, 2\)"):
        load_scene(write(tmp_path, document))
    np.save(tmp_path / "nan.npy", np.array([[0.0, np.nan, 1.0]]))
    document["points_file"] = "nan.npy"
    with pytest.raises(InvalidScene, match=r"\$\.points_file\[0\]\[1\]: expected a finite coordinate, got nan"):
        load_scene(write(tmp_path, document))


@pytest.mark.parametrize("suffix", [".npy", ".ply"])
def test_points_file_relative_to_the_json(tmp_path: Path, suffix: str, rng: np.random.Generator) -> None:
    points = rng.uniform(-1, 1, (50, 3))
    folder = tmp_path / "data"
    folder.mkdir()
    if suffix == ".npy":
        np.save(folder / "cloud.npy", points)
    else:
        from plyfile import PlyData, PlyElement

        vertices = np.array([tuple(p) for p in points], dtype=[("x", "f8"), ("y", "f8"), ("z", "f8")])
        PlyData([PlyElement.describe(vertices, "vertex")]).write(str(folder / "cloud.ply"))
    document = {k: v for k, v in scene_document(points_file=f"cloud{suffix}").items() if k != "points"}
    scene = load_scene(write(folder, document))
    np.testing.assert_allclose(scene.points, points)


def test_quaternion_close_to_unit_is_normalised() -> None:
    box = Box("a", [1, 1, 1], [0, 0, 0], [0, 0, 0, 1.0004])
    assert np.linalg.norm(box.orientation_xyzw) == pytest.approx(1.0, abs=1e-15)


def test_scene_round_trip_and_ground_truth(tmp_path: Path) -> None:
    scene = Scene(
        [Box("a", [1, 1, 1], [0, 0, 0.5], mass=5.0), Box("b", [1, 1, 1], [0, 0, 1.5])],
        points=np.zeros((0, 3)),
        detected=["b", "a"],
        ground_truth=[[0, 1], [0, 0]],
    )
    scene.save(tmp_path / "scene.json", points_file="scene.npy")
    loaded = unstack.load(tmp_path / "scene.json")
    assert isinstance(loaded, Scene)
    assert loaded.detected == ("b", "a")
    assert loaded.box("a").mass == 5.0
    assert loaded.detected_ground_truth().tolist() == [[0.0, 0.0], [1.0, 0.0]]
    assert loaded.points.shape == (0, 3)


def test_bundled_examples_load(examples: Path) -> None:
    for path in sorted(examples.glob("*.json")):
        assert unstack.load(path) is not None


def test_a_key_given_twice_is_refused_not_overwritten(tmp_path: Path) -> None:
    path = tmp_path / "twice.json"
    text = json.dumps(supports_document())
    path.write_text(text[:-1] + ', "objects": ["x", "y", "z"]}')
    with pytest.raises(InvalidFile, match=rf"^{path}: \$: the key 'objects' appears twice in one JSON object$"):
        load_supports(path)


def test_a_complex_point_cloud_is_refused(tmp_path: Path) -> None:
    np.save(tmp_path / "cloud.npy", np.ones((4, 3), dtype=complex))
    document = {k: v for k, v in scene_document(points_file="cloud.npy").items() if k != "points"}
    path = write(tmp_path, document)
    with pytest.raises(InvalidFile, match=r"\$\.points_file: expected real numbers, got dtype complex128"):
        load_scene(path)


@pytest.mark.parametrize(
    ("content", "message"),
    [
        (b'{"tilt_deg": 9.0, "boxes": []}', r"missing required key 'format' .*: not an unstack document"),
        (b"PK\x03\x04\xbd\xff binary", r"expected a JSON document \(UTF-8 text\), got a binary file"),
    ],
    ids=["no-format-tag", "binary"],
)
def test_a_file_that_is_no_unstack_document_says_so(tmp_path: Path, content: bytes, message: str) -> None:
    (tmp_path / "other.json").write_bytes(content)
    with pytest.raises(InvalidFile, match=message):
        unstack.validate(tmp_path / "other.json")


@pytest.mark.parametrize("points_file", ["pts.txt", "scene.json", "cloud.ply"])
def test_a_scene_is_not_saved_with_a_points_file_it_cannot_write(tmp_path: Path, points_file: str) -> None:
    scene = Scene([Box("a", [0.4, 0.3, 0.3], [1.0, 0.0, 0.15])], [[1.0, 0.0, 0.3]], ["a"])
    with pytest.raises(unstack.errors.InvalidArgument, match=r"points_file must name a .npy file beside the scene"):
        scene.save(tmp_path / "scene.json", points_file=points_file)
    assert list(tmp_path.iterdir()) == []


def test_an_id_longer_than_a_label_can_be_is_refused_at_its_path() -> None:
    with pytest.raises(InvalidScene, match=r"\$\.id: expected an id of at most 200 characters, got one of 300"):
        Box("a" * 300, [0.4, 0.3, 0.3], [1.0, 0.0, 0.15])
    with pytest.raises(InvalidSupports, match=r"\$\.objects\[0\]: expected an id of at most 200 characters"):
        unstack.Supports(["b" * 201, "c"], [[0, 0.5], [0.5, 0]])
    assert Box("a" * 200, [0.4, 0.3, 0.3], [1.0, 0.0, 0.15]).id == "a" * 200
