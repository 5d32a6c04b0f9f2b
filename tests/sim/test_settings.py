"""Simulation settings: defaults from the issue, JSON round trip, clear errors."""

from __future__ import annotations

import json

import pytest

from unstack.errors import InvalidFile, InvalidScene
from unstack.sim.settings import (
    SIZE_SETS,
    Container,
    GroundTruthSettings,
    InvalidSettings,
    PileSettings,
    SimulationSettings,
    settings_from_json,
)


def test_defaults_are_the_papers_setting() -> None:
    settings = SimulationSettings()
    assert settings.boxes == (30, 40)
    assert SIZE_SETS[settings.sizes] == ((0.6, 0.4, 0.4), (0.4, 0.3, 0.3))
    assert (settings.container.depth, settings.container.width, settings.container.height) == (2.0, 2.35, 2.39)
    assert settings.pile.mass_range == (5.0, 15.0) and settings.pile.friction == 0.5
    assert settings.ground_truth.displacement_threshold == 0.02
    assert settings.ground_truth.rotation_threshold_deg == 5.0
    assert settings.sensor.position == (-2.8, 0.0, 1.3) and settings.sensor.vertical_fov_deg == 43.0


@pytest.mark.parametrize("sizes", list(SIZE_SETS))
def test_round_trip_through_json(sizes: str) -> None:
    settings = SimulationSettings(boxes=(10, 20), sizes=sizes, container=Container(depth=1.0))
    assert SimulationSettings.from_dict(json.loads(json.dumps(settings.to_dict()))) == settings


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        ({"sizes": "paper3"}, r"unknown size set 'paper3'; expected one of paper2, four"),
        ({"boxes": (40, 30)}, r"settings\.boxes: the range 40-30 is reversed"),
        ({"boxes": (-1, 5)}, r"settings\.boxes\[0\]: expected a number at least 1, got -1"),
        ({"boxes": (0, 0)}, r"settings\.boxes\[0\]: expected a number at least 1, got 0"),
        ({"boxes": (300, 400)}, r"400 boxes of size set 'paper2' do not fit a 2.0 x 2.35 x 2.39 m container"),
        (
            {"container": Container(depth=0.2)},
            r"do not all fit a 0\.2 x 2\.35 x 2\.39 m container \(depth x width x height\): one's smallest edge is 0\.4 m",
        ),
        ({"container": Container(depth=-1.0)}, r"settings\.container\.depth: expected a positive extent"),
        (
            {"container": Container(width=float("nan"))},
            r"settings\.container\.width: expected a finite number, got nan",
        ),
        (
            {"ground_truth": GroundTruthSettings(horizon=1e6)},
            r"settings\.ground_truth\.horizon: expected a number from",
        ),
        (
            {"pile": PileSettings(mass_range=(15.0, 5.0))},
            r"settings\.pile\.mass_range: expected \[low, high\] with low <= high, got \[15\.0, 5\.0\]",
        ),
    ],
)
def test_bad_settings_are_one_line_errors(arguments: dict[str, object], message: str) -> None:
    with pytest.raises(InvalidSettings, match=message) as caught:
        SimulationSettings(**arguments)  # type: ignore[arg-type]
    assert "\n" not in str(caught.value)


@pytest.mark.parametrize(
    ("section", "key", "value", "message"),
    [
        (
            "pile",
            "time_step",
            -0.5,
            r"\$\.pile\.time_step: expected a physics step from 0\.0005 to 0\.02 s, got -0\.5",
        ),
        ("pile", "time_step", 0.1, r"\$\.pile\.time_step: expected a physics step"),
        ("pile", "mass_range", [5.0], r"\$\.pile\.mass_range: expected a list of 2 numbers"),
        ("pile", "mass_range", [15.0, 5.0], r"\$\.pile\.mass_range: expected \[low, high\] with low <= high"),
        ("pile", "mass_range", [float("nan"), 5.0], r"\$\.pile\.mass_range\[0\]: expected a finite number, got nan"),
        ("pile", "friction", "high", r"\$\.pile\.friction: expected a finite number, got 'high'"),
        ("pile", "settle_windows", 2.5, r"\$\.pile\.settle_windows: expected a whole number, got 2\.5"),
        ("ground_truth", "horizon", 1e6, r"\$\.ground_truth\.horizon: expected a number from 0\.001 to 10"),
        ("ground_truth", "displacement_threshold", True, r"displacement_threshold: expected a finite number, got True"),
        ("ground_truth", "rotation_threshold_deg", 0.0, r"rotation_threshold_deg: expected a number from 0\.01 to 90"),
        ("sensor", "width", 10**9, r"\$\.sensor\.width: expected a number from 1 to 8192"),
        ("sensor", "position", [0.0, 0.0], r"\$\.sensor\.position: expected a list of 3 numbers"),
        ("sensor", "target", [1e308, 0.0, 0.0], r"\$\.sensor\.target\[0\]: expected a coordinate within 100 m"),
        ("sensor", "far", 0.05, r"\$\.sensor\.far: expected beyond near \(0\.1\), got 0\.05"),
        ("sensor", "noise", 1, r"\$\.sensor\.noise: expected true or false, got 1"),
        ("sensor", "lens", 1, r"\$\.sensor: unknown key 'lens'; expected keys among position, target"),
        ("container", "depth", 1e308, r"\$\.container\.depth: expected a positive extent of at most 100 m"),
    ],
)
def test_settings_from_json_names_the_field_and_what_was_expected(
    section: str, key: str, value: object, message: str
) -> None:
    data = SimulationSettings().to_dict()
    data[section][key] = value
    with pytest.raises(InvalidFile, match=message) as caught:
        settings_from_json(data)
    assert "\n" not in str(caught.value)


@pytest.mark.parametrize("part", ["container", "pile", "ground_truth", "sensor"])
def test_settings_from_json_refuses_a_part_that_is_not_an_object(part: str) -> None:
    data = SimulationSettings().to_dict()
    data[part] = [1, 2]
    with pytest.raises(InvalidFile, match=rf"<settings>: \$\.{part}: expected an object, got \[1, 2\]"):
        settings_from_json(data)


def test_settings_from_json_gives_left_out_keys_their_defaults() -> None:
    settings = settings_from_json({"boxes": [3, 5], "pile": {"friction": 0.8}})
    assert settings.boxes == (3, 5) and settings.pile.friction == 0.8
    defaults = SimulationSettings()
    assert settings.pile.time_step == defaults.pile.time_step and settings.sensor == defaults.sensor


def test_settings_from_json_turns_a_refused_combination_into_a_path_error() -> None:
    data = {"sizes": "four", "container": {"depth": 0.2}}
    with pytest.raises(InvalidScene, match=r"a\.json: \$\.metadata\.settings: boxes of size set 'four' do not all fit"):
        settings_from_json(data, source="a.json", path="$.metadata.settings", error=InvalidScene)


@pytest.mark.parametrize(("key", "value"), [("time_step", 1e-9), ("settle_max_time", 1e6)])
def test_settings_that_would_run_for_ever_are_refused(key: str, value: float) -> None:
    data = SimulationSettings().to_dict()
    data["pile"][key] = value
    with pytest.raises(InvalidFile, match=rf"\$\.pile\.{key}: expected a"):
        settings_from_json(data)
