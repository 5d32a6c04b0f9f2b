"""Small, fast simulation settings for the tests: few boxes, a short section, a tiny image."""

from __future__ import annotations

import pytest

from unstack.sim.settings import Container, GroundTruthSettings, SensorSettings, SimulationSettings


def small_settings(boxes: tuple[int, int] = (3, 5), **sensor: object) -> SimulationSettings:
    return SimulationSettings(
        boxes=boxes,
        sizes="four",
        container=Container(depth=1.0),
        ground_truth=GroundTruthSettings(horizon=0.5),
        sensor=SensorSettings(width=96, height=72, min_pixels=5, **sensor),  # type: ignore[arg-type]
    )


@pytest.fixture
def settings() -> SimulationSettings:
    return small_settings()
