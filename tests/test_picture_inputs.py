"""What a picture needs from the library: the decision's numbers and the sensor's camera."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import unstack
from unstack.errors import UnstackError
from unstack.picture_inputs import decision_values, scene_camera
from unstack.pictures.camera import Camera


def test_a_plan_does_not_combine_with_a_stored_decision(tmp_path: Path) -> None:
    supports = unstack.Supports(["top", "bottom"], [[0, 0.1], [0.9, 0]])
    with pytest.raises(UnstackError, match="does not combine with --decision"):
        decision_values(supports, str(tmp_path / "decision.json"), with_plan=True)


def test_a_stored_decision_is_shown_as_it_was_decided(tmp_path: Path) -> None:
    supports = unstack.Supports(["top", "bottom"], [[0, 0.1], [0.9, 0]])
    stored = tmp_path / "decision.json"
    stored.write_text(json.dumps(unstack.decide(supports).to_dict()))
    values = decision_values(supports, str(stored))
    fresh = decision_values(supports)
    assert values.choice == fresh.choice == "top"
    np.testing.assert_allclose(values.expected_costs, fresh.expected_costs)


def test_a_plan_gives_the_order(examples: Path) -> None:
    values = decision_values(unstack.load(examples / "stack5.supports.json"), with_plan=True)
    assert values.order and values.order[0] == values.choice


def test_a_scene_without_simulation_settings_gets_the_default_camera() -> None:
    scene = unstack.Scene([unstack.Box("a", [0.4, 0.4, 0.4], [1.0, 0.0, 0.2])], np.zeros((0, 3)), ["a"])
    assert scene_camera(scene) == Camera()
