"""Make ``examples/camera/``: the range sensor's view of ``examples/pile5.scene.json`` as a camera's files.

A 16-bit depth PNG in millimetres, the pinhole intrinsics, the camera-to-world pose and one
mask per box the sensor sees (at least ``min_pixels`` pixels), as a depth camera and a box
detector would hand them over. The tutorial "Your own camera" builds a scene from them.

Run from the repository root (needs the ``sim`` extra)::

    python examples/make_camera_files.py
"""

from __future__ import annotations

from pathlib import Path

from unstack.scene import load_scene
from unstack.sim.camera_view import camera_view, save_camera_files

HERE = Path(__file__).resolve().parent

if __name__ == "__main__":
    view = camera_view(load_scene(HERE / "pile5.scene.json"))
    for path in save_camera_files(view, HERE / "camera"):
        print(path.relative_to(HERE.parent))
