"""Implausible scenes are refused with the JSON path; doubtful ones are warned about."""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from unstack.errors import InvalidScene
from unstack.scene import Box, Scene
from unstack.understanding.plausibility import scene_warnings


@pytest.mark.parametrize(
    ("size", "position", "message"),
    [
        ([600.0, 400.0, 400.0], [1000.0, 0.0, 200.0], r"\$\.size\[0\]: expected a box edge between 0\.02 and 5 m"),
        ([0.01, 0.4, 0.4], [1.0, 0.0, 0.2], r"\$\.size\[0\]: expected a box edge between 0\.02 and 5 m"),
        ([0.6, 0.4, 0.4], [1e300, 0.0, 0.2], r"\$\.position\[0\]: expected a coordinate within 100 m"),
    ],
)
def test_a_box_no_carton_can_be_is_refused(size: list[float], position: list[float], message: str) -> None:
    with pytest.raises(InvalidScene, match=message):
        Box("a", size, position)


def test_two_boxes_in_one_place_are_refused() -> None:
    boxes = [Box("a", [0.4, 0.4, 0.4], [1.0, 0.0, 0.2]), Box("b", [0.4, 0.4, 0.4], [1.05, 0.0, 0.2])]
    with pytest.raises(InvalidScene, match=r"\$\.boxes\[1\]: box 'b' shares 88 % of the smaller one's volume"):
        Scene(boxes, np.zeros((0, 3)), ["a"])


def test_a_small_overlap_a_floating_box_and_an_empty_cloud_are_warned_about() -> None:
    boxes = [
        Box("a", [0.4, 0.4, 0.4], [1.0, 0.0, 0.2]),
        Box("b", [0.4, 0.4, 0.4], [1.0, 0.36, 0.2]),
        Box("high", [0.3, 0.3, 0.3], [1.0, 1.0, 1.2]),
    ]
    warnings = scene_warnings(Scene(boxes, np.zeros((0, 3)), ["a", "b", "high"], source="s.json"))
    assert any(re.search(r"boxes 'a' and 'b' overlap by 1\d % of the smaller one's volume", line) for line in warnings)
    assert any("box 'high' floats" in line for line in warnings)
    assert any("the point cloud is empty" in line for line in warnings)


@pytest.mark.parametrize(
    ("centre_z", "message"),
    [
        (0.05, "box 'a' reaches 0.15 m into the floor (z = 0); check its pose and the frame"),
        (-1.0, "box 'a' lies wholly below the floor (z = 0); check its pose and the frame"),
    ],
)
def test_a_box_in_or_under_the_floor_is_warned_about(centre_z: float, message: str) -> None:
    boxes = [Box("a", [0.4, 0.4, 0.4], [1.0, 0.0, centre_z])]
    assert f"s.json: {message}" in scene_warnings(Scene(boxes, [[1.0, 0.0, 0.25]], ["a"], source="s.json"))


def test_a_box_a_centimetre_into_the_floor_is_not_warned_about() -> None:
    boxes = [Box("a", [0.4, 0.4, 0.4], [1.0, 0.0, 0.19])]  # simulated and measured poses sink a little
    assert not [line for line in scene_warnings(Scene(boxes, [[1.0, 0.0, 0.4]], ["a"])) if "floor (z = 0)" in line]


def test_a_box_resting_on_another_does_not_float() -> None:
    boxes = [Box("a", [0.4, 0.4, 0.4], [1.0, 0.0, 0.2]), Box("b", [0.3, 0.3, 0.3], [1.0, 0.0, 0.551])]
    assert scene_warnings(Scene(boxes, [[0.8, 0.0, 0.3]], ["a", "b"])) == []


def test_a_scene_in_millimetres_is_one_line_and_exit_code_2(tmp_path: Path) -> None:
    scene = {
        "format": "unstack.scene/1",
        "boxes": [{"id": "a", "size": [600, 400, 400], "position": [1000, 0, 200], "orientation_xyzw": [0, 0, 0, 1]}],
        "points": [],
        "detected": ["a"],
    }
    file = tmp_path / "mm.json"
    file.write_text(json.dumps(scene))
    result = subprocess.run([sys.executable, "-m", "unstack", "decide", str(file)], capture_output=True, text=True)
    assert result.returncode == 2
    assert result.stderr.strip().splitlines() == [
        f"unstack: error: {file}: $.boxes[0].size[0]: expected a box edge between 0.02 and 5 m "
        "(unstack works in metres), got 600"
    ]


@pytest.mark.parametrize(("shift", "share"), [(0.18, 0.55), (0.22, 0.45), (0.2, 0.5), (0.4, 0.0)])
def test_the_overlap_of_parallel_boxes_is_exact(shift: float, share: float) -> None:
    from unstack.understanding.plausibility import overlap_share

    turned = [0.0, 0.0, np.sin(np.pi / 4), np.cos(np.pi / 4)]  # a quarter turn about z: axes still parallel
    first = Box("a", [0.4, 0.4, 0.4], [1.0, 0.0, 0.2])
    second = Box("b", [0.4, 0.4, 0.4], [1.0 + shift, 0.0, 0.2], turned)
    assert overlap_share(first, second) == pytest.approx(share, abs=1e-9)


def test_boxes_sharing_55_percent_are_refused_and_45_percent_warned_about() -> None:
    boxes = [Box("a", [0.4, 0.4, 0.4], [1.0, 0.0, 0.2]), Box("b", [0.4, 0.4, 0.4], [1.18, 0.0, 0.2])]
    with pytest.raises(InvalidScene, match=r"box 'b' shares 55 % of the smaller one's volume"):
        Scene(boxes, np.zeros((0, 3)), ["a"])
    boxes[1] = Box("b", [0.4, 0.4, 0.4], [1.22, 0.0, 0.2])
    assert any("overlap by 45 %" in line for line in scene_warnings(Scene(boxes, [[1.0, 0.0, 0.5]], ["a"])))


def test_the_overlap_of_a_turned_box_is_estimated_on_a_grid() -> None:
    from unstack.understanding.plausibility import overlap_share

    eighth = [0.0, 0.0, np.sin(np.pi / 8), np.cos(np.pi / 8)]  # 45 degrees about z, same centre
    share = overlap_share(
        Box("a", [0.4, 0.4, 0.4], [1.0, 0.0, 0.2]), Box("b", [0.4, 0.4, 0.4], [1.0, 0.0, 0.2], eighth)
    )
    assert share == pytest.approx(2 * (np.sqrt(2) - 1), abs=0.03)  # the regular octagon inside the square


def test_a_box_smaller_than_a_carton_is_warned_about_and_a_small_carton_is_not() -> None:
    parcel = Box("parcel", [0.047, 0.027, 0.035], [1.0, 0.0, 0.0175])
    carton = Box("carton", [0.09, 0.06, 0.05], [1.5, 0.0, 0.025])
    warnings = scene_warnings(Scene([parcel, carton], [[1.0, 0.0, 0.035], [1.5, 0.0, 0.05]], ["parcel", "carton"]))
    assert warnings == [
        "<array>: box 'parcel' is 4.7 x 2.7 x 3.5 cm, smaller than a carton; are its size and the cloud in metres?"
    ]


def test_a_box_lighter_than_a_carton_is_warned_about_and_a_light_carton_is_not() -> None:
    feather = Box("feather", [0.4, 0.3, 0.3], [1.0, 0.0, 0.15], mass=1e-9)
    light = Box("light", [0.4, 0.3, 0.3], [1.0, 0.5, 0.15], mass=0.2)
    warnings = scene_warnings(Scene([feather, light], [[1.0, 0.0, 0.3], [1.0, 0.5, 0.3]], ["feather", "light"]))
    assert warnings == [
        "<array>: box 'feather' (1e-09 kg) weighs less than 0.01 kg, lighter than a carton; masses in kg?"
    ]


@pytest.mark.parametrize(("mass", "shown"), [(-1, "-1"), (10**400, "an integer of about 401 digits"), (0.0, "0.0")])
def test_a_mass_no_box_has_is_refused_at_its_path(mass: object, shown: str) -> None:
    with pytest.raises(InvalidScene, match=rf"\$\.mass: expected a positive, finite number of kg, got {shown}"):
        Box("a", [0.4, 0.3, 0.3], [1.0, 0.0, 0.15], mass=mass)  # type: ignore[arg-type]


def _container_cloud(rng: np.random.Generator, count: int) -> np.ndarray:
    """Points on a 2.35 m wide, 2.4 m high container's floor, walls and ceiling, 0-6 m deep."""
    x = rng.uniform(0.0, 6.0, count)
    side = rng.integers(0, 4, count)
    y = np.where(side == 0, -1.175, np.where(side == 1, 1.175, rng.uniform(-1.175, 1.175, count)))
    z = np.where(side == 2, 0.0, np.where(side == 3, 2.4, rng.uniform(0.0, 2.4, count)))
    return np.column_stack([x, y, z])


def test_one_box_whose_faces_the_cloud_shows_in_a_large_view_is_not_said_to_be_in_another_frame() -> None:
    # one detected box in a container's whole view: under 5 % of the points lie within 0.5 m of it,
    # but its faces are in the cloud (a box fitted to a camera's mask): no frame to doubt
    rng = np.random.default_rng(0)
    box = Box("a", [0.4, 0.3, 0.3], [3.0, 0.0, 0.15])
    top = np.column_stack([rng.uniform(2.8, 3.2, 300), rng.uniform(-0.15, 0.15, 300), np.full(300, 0.3)])
    warnings = scene_warnings(Scene([box], np.r_[_container_cloud(rng, 40_000), top], ["a"]))
    assert not [warning for warning in warnings if "same frame" in warning]


@pytest.mark.parametrize("shift", [[10.0, 0.0, 0.0], [0.0, 0.0, -3.0]])
def test_boxes_the_cloud_does_not_show_are_said_to_be_in_another_frame(shift: list[float]) -> None:
    rng = np.random.default_rng(0)
    boxes = [Box("a", [0.4, 0.3, 0.3], [3.0, 0.0, 0.15]), Box("b", [0.4, 0.3, 0.3], [3.0, 0.5, 0.15])]
    cloud = _container_cloud(rng, 40_000) + shift
    warnings = scene_warnings(Scene(boxes, cloud, ["a", "b"]))
    assert any(
        re.search(r"of the cloud's points lie within 0\.5 m of the boxes; is the cloud in the same frame", w)
        for w in warnings
    )


def test_a_box_the_cloud_shows_only_the_floor_under_is_said_to_be_in_another_frame() -> None:
    # the floor under a box's footprint is no face of it: a detection where nothing stands is doubted
    rng = np.random.default_rng(0)
    warnings = scene_warnings(
        Scene([Box("a", [0.4, 0.3, 0.3], [3.0, 0.0, 0.15])], _container_cloud(rng, 40_000), ["a"])
    )
    assert any("is the cloud in the same frame" in warning for warning in warnings)
