"""Fixtures of the command-line tests: a camera's files as a user hands them to ``unstack scene``."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from tests.camera.conftest import INTRINSICS, render_tops


@pytest.fixture
def camera_files(tmp_path: Path) -> list[str]:
    cartons = [(0.0, 0.0, 0.0, 0.4, 0.3, 0.3), (0.65, 0.1, 20.0, 0.6, 0.4, 0.4)]
    depth, masks, pose = render_tops(cartons, tilt_deg=9.0)
    Image.fromarray(np.round(depth * 1000).astype(np.uint16)).save(tmp_path / "depth.png")
    (tmp_path / "k.json").write_text(json.dumps(INTRINSICS.__dict__))
    (tmp_path / "pose.json").write_text(json.dumps({"cam2root": pose.tolist()}))
    arguments = ["--depth", str(tmp_path / "depth.png"), "--intrinsics", str(tmp_path / "k.json"),
                 "--pose", str(tmp_path / "pose.json")]  # fmt: skip
    for k, mask in enumerate(masks):
        Image.fromarray(mask.astype(np.uint8) * 255).save(tmp_path / f"mask-b{k:02d}.png")
        arguments.append(str(tmp_path / f"mask-b{k:02d}.png"))
    return arguments


@pytest.fixture
def cloud_and_detections(tmp_path: Path) -> list[str]:
    """A floor's cloud (``.npy``) and two detected boxes on it: ``--cloud FILE --detections FILE``."""
    rng = np.random.default_rng(0)
    floor = np.column_stack([rng.uniform(-1, 1, 4000), rng.uniform(-1, 1, 4000), np.zeros(4000)])
    np.save(tmp_path / "cloud.npy", floor)
    (tmp_path / "boxes.json").write_text(json.dumps({"boxes": [
        {"id": "low", "center": [0, 0, 0.15], "size": [0.4, 0.3, 0.3], "yaw_deg": 10},
        {"id": "high", "center": [0, 0, 0.45], "size": [0.4, 0.3, 0.3], "yaw_deg": 10},
    ]}))  # fmt: skip
    return ["--cloud", str(tmp_path / "cloud.npy"), "--detections", str(tmp_path / "boxes.json")]
