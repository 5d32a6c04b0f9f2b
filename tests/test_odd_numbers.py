"""Numbers no float holds, clouds of one number, point labels of no box: one error naming the
place (fuzz round 19), never a traceback; in-process through the loaders the CLI uses."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import unstack
from unstack.errors import UnstackError
from unstack.scene import Box, Scene

HUGE = 10**400  # JSON parses it as a Python int of 401 digits
BOX = Box("a", [0.4, 0.3, 0.3], [1.0, 0.0, 0.15])


def _scene_document(**changes: Any) -> dict[str, Any]:
    document = {
        "format": "unstack.scene/1",
        "boxes": [{"id": "a", "size": [0.4, 0.3, 0.3], "position": [1, 0, 0.15], "orientation_xyzw": [0, 0, 0, 1]}],
        "points": [[1.0, 0.0, 0.3]],
        "detected": ["a"],
    }
    return {**document, **changes}


@pytest.mark.parametrize(
    ("build", "message"),
    [
        (lambda: unstack.Supports(["a", "b"], [[0, HUGE], [0.5, 0]]), r"\$\.probabilities\[0\]\[1\]: .*401 digits"),
        (
            lambda: Scene([BOX], [[HUGE, 0, 0]], ["a"]),
            r"\$\.points\[0\]\[0\]: expected a finite number, got an integer",
        ),
        (lambda: Scene([BOX], [[0, 0, 0]], ["a"], ground_truth=[[HUGE]]), r"ground_truth.*\[0\]\[0\]: .*401 digits"),
        (lambda: Scene([BOX], [["1", "0", "0"]], ["a"]), r"\$\.points: expected real numbers, got text"),
        (lambda: Scene([BOX], [[True, False, True]], ["a"]), r"\$\.points: expected real numbers, got true or false"),
    ],
    ids=["probability", "point", "ground-truth", "text-point", "bool-point"],
)
def test_numbers_no_float_holds_and_points_that_are_no_numbers_are_refused_in_the_library(
    build: Any, message: str
) -> None:
    with pytest.raises(UnstackError, match=message):
        build()


@pytest.mark.parametrize(
    ("document", "message"),
    [
        (_scene_document(points=[[HUGE, 0, 0]]), r"\$\.points\[0\]\[0\]: expected a finite number, got an integer"),
        (
            _scene_document(metadata={"settings": {"container": {"depth": HUGE}}}),
            r"\$\.metadata\.settings\.container\.depth: expected a finite number, got an integer of about 401",
        ),
    ],
    ids=["point", "settings"],
)
def test_a_scene_file_with_an_integer_no_float_holds_is_refused_by_path(
    tmp_path: Path, document: dict[str, Any], message: str
) -> None:
    file = tmp_path / "scene.json"
    file.write_text(json.dumps(document))
    with pytest.raises(UnstackError, match=message):
        unstack.validate(file)  # loading checks the scene; validating its settings too


def test_a_decision_file_with_an_integer_no_float_holds_is_refused_by_path(tmp_path: Path, examples: Path) -> None:
    decision = unstack.decide(unstack.load(examples / "stack5.supports.json")).to_dict()
    decision["expected_costs"][0] = HUGE
    file = tmp_path / "decision.json"
    file.write_text(json.dumps(decision))
    with pytest.raises(UnstackError, match=r"\$\.expected_costs\[0\]: expected a finite number, got an integer"):
        unstack.validate(file)


def test_a_container_extent_no_float_holds_is_refused_before_the_veto(examples: Path) -> None:
    from unstack.physics_veto import world_settings

    scene = unstack.load(examples / "pile5.scene.json")
    odd = Scene(
        scene.boxes,
        scene.points,
        scene.detected,
        metadata={"container": {"depth": HUGE, "width": 2.35, "height": 2.39}},
    )
    with pytest.raises(UnstackError, match=r"\$\.metadata\.container.*got an integer of about 401 digits"):
        world_settings(odd)


def test_a_cloud_file_of_one_number_is_refused_as_no_array_of_points(tmp_path: Path) -> None:
    np.save(tmp_path / "one.npy", np.float64(3.0))
    file = tmp_path / "scene.json"
    document = _scene_document(points_file="one.npy")
    del document["points"]
    file.write_text(json.dumps(document))
    with pytest.raises(UnstackError, match=r"\$\.points_file: expected an N x 3 array of points, got shape \(\)"):
        unstack.load(file)


@pytest.mark.parametrize(
    "labels", [np.full(3, 99), np.full(3, 0.5), np.full(3, -2)], ids=["past-the-boxes", "not-whole", "below-minus-one"]
)
def test_point_labels_of_no_box_are_not_used(tmp_path: Path, labels: np.ndarray) -> None:
    from unstack.pictures.camera import point_box_labels

    np.save(tmp_path / "labels.npy", labels)
    scene = Scene([BOX], np.zeros((3, 3)), ["a"], metadata={"point_boxes_file": "labels.npy"})
    assert point_box_labels(scene, tmp_path) is None
    np.save(tmp_path / "labels.npy", np.array([-1, 0, 0]))
    assert point_box_labels(scene, tmp_path).tolist() == [-1, 0, 0]


def test_validate_checks_the_physics_vetos_container_as_the_veto_does(tmp_path: Path) -> None:
    file = tmp_path / "scene.json"
    file.write_text(json.dumps(_scene_document(metadata={"container": {"depth": -1, "width": 2.35, "height": 2.39}})))
    with pytest.raises(UnstackError, match=r"\$\.metadata\.container\.depth: expected a positive extent"):
        unstack.validate(file)
