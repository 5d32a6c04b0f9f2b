"""Simulated piles as camera files, built back and compared with the truth."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from tests.conftest import unstack
from unstack.experiments.camera_roundtrip import yaw_error_deg
from unstack.geometry import axis_error_deg

pytestmark = pytest.mark.slow  # renders piles and decides


@pytest.mark.parametrize(
    ("turn_deg", "square", "error"), [(0.0, False, 0.0), (179.0, False, 1.0), (91.0, True, 1.0), (91.0, False, 89.0)]
)
def test_yaw_errors_are_taken_modulo_the_top_face_symmetry(turn_deg: float, square: bool, error: float) -> None:
    half = np.radians(turn_deg) / 2
    turned = np.array([0.0, 0.0, np.sin(half), np.cos(half)])
    assert yaw_error_deg(np.array([0.0, 0.0, 0.0, 1.0]), turned, square) == pytest.approx(error, abs=1e-6)


@pytest.mark.parametrize(
    ("axis", "turn_deg", "error"), [([0, 0, 1], 90.0, 0.0), ([0, 1, 0], 180.0, 0.0), ([0, 1, 0], 30.0, 30.0)]
)
def test_axis_errors_pair_each_axis_with_the_nearest_true_one(axis: list[float], turn_deg: float, error: float) -> None:
    half = np.radians(turn_deg) / 2
    turned = np.array([*(np.sin(half) * np.asarray(axis, dtype=float)), np.cos(half)])
    assert axis_error_deg(np.array([0.0, 0.0, 0.0, 1.0]), turned) == pytest.approx(error, abs=1e-6)


def test_the_cli_reports_errors_and_decisions(small_dataset: Path, tmp_path: Path) -> None:
    run = unstack("experiment", "camera-roundtrip", str(small_dataset), "--out", str(tmp_path), "--piles", "2")
    assert run.returncode == 0, run.stderr
    assert "position error (mm)" in run.stdout and "axis error (degrees)" in run.stdout
    result = json.loads((tmp_path / "camera-roundtrip.json").read_text())
    summary, piles = result["summary"], result["piles"]
    assert summary["piles"] == 2 and summary["boxes"] <= summary["masks"]
    assert summary["position_error_m_median"] < 0.02
    assert summary["axis_error_deg_median"] < 2.0
    assert summary["tilted_boxes"] == sum(box["true_tilt_deg"] >= 5.0 for pile in piles for box in pile["boxes"])
    for name in ("camera", "truth"):  # each pick was taken out of the true pile in the physics engine
        assert all(pile["choices"][name] not in pile["moved"][name] for pile in piles)
        moved = [len(pile["moved"][name]) for pile in piles]
        assert summary[f"{name}_pick_boxes_moved_mean"] == pytest.approx(np.mean(moved))
        assert summary[f"{name}_pick_moved_nothing_share"] == pytest.approx(np.mean([count == 0 for count in moved]))
    assert "the pick moves nothing in the true pile" in run.stdout


def test_a_doubt_of_the_built_scene_names_its_pile(small_dataset: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The camera's doubts were said of a scene the user never saw, naming no pile."""
    import warnings

    import unstack.camera
    from unstack.experiments.camera_roundtrip import _roundtrip_pile
    from unstack.learning.model_file import default_model_path, load_model

    real = unstack.camera.scene_from_depth

    def doubting(*args: object, **kwargs: object) -> object:
        warnings.warn("cannot tell whether the pose's z is up", stacklevel=2)  # as scene_from_depth says it
        return real(*args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(unstack.camera, "scene_from_depth", doubting)
    path = sorted(small_dataset.glob("config-*.json"))[0]
    with pytest.warns(UserWarning, match=rf"^{path.name}, built from its camera view: cannot tell whether the pose"):
        _, result = _roundtrip_pile(path, 0, load_model(default_model_path()), 64)
    assert result["warnings"] == ["cannot tell whether the pose's z is up"]
