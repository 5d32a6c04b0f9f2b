"""Simulation settings: defaults from the issue, JSON round trip, clear errors."""

from __future__ import annotations

import json

import pytest

from unstack.sim.settings import SIZE_SETS, Container, InvalidSettings, SimulationSettings


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
        ({"boxes": (40, 30)}, r"box range 40-30 is reversed"),
        ({"boxes": (-1, 5)}, r"box counts must be positive, got -1-5"),
        ({"boxes": (0, 0)}, r"box counts must be positive"),
        ({"boxes": (300, 400)}, r"400 boxes of size set 'paper2' do not fit a 2.0 x 2.35 x 2.39 m container"),
        ({"container": Container(depth=0.2)}, r"do not fit a 0.2 m container"),
        ({"container": Container(depth=-1.0)}, r"container extents must be positive"),
    ],
)
def test_bad_settings_are_one_line_errors(arguments: dict[str, object], message: str) -> None:
    with pytest.raises(InvalidSettings, match=message) as caught:
        SimulationSettings(**arguments)  # type: ignore[arg-type]
    assert "\n" not in str(caught.value)
