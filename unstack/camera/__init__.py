"""From a real camera to a scene: depth image, intrinsics, camera pose and box masks (issue 36).

A robot cell has a depth camera and a box detector. This package turns their files into an
``unstack.scene/1`` scene that :func:`unstack.api.decide` can take:

* :mod:`unstack.camera.files` reads a depth image (16-bit PNG in millimetres, or ``.npy`` in
  metres, units checked), pinhole intrinsics, a camera-to-world pose and instance masks;
* :mod:`unstack.camera.planes` back-projects depth pixels to points and finds gravity and the
  floor from the dominant horizontal planes (a robust RANSAC plane fit);
* :mod:`unstack.camera.boxes` fits one box per mask: its top plane, its yaw from the top face,
  its size matched to the known carton sizes, each box with its residual; a mask mostly
  covered by another is reported as a duplicate and left out;
* :mod:`unstack.camera.build` assembles the scene and the report;
* :mod:`unstack.camera.clouds` does the same from a point cloud (``.npy``, ``.ply``, ``.pcd``)
  and box detections (centre, size, yaw).

Point-cloud handling is numpy and scipy (``scipy.spatial.ConvexHull`` for the top face's
rectangle): every step is a few array operations on at most a few hundred thousand points,
and Open3D would add a 100 MB dependency for RANSAC and a normal estimate.

Examples
--------
>>> from unstack.camera import Intrinsics
>>> Intrinsics(fx=600.0, fy=600.0, cx=320.0, cy=240.0, width=640, height=480).fx
600.0
"""

from unstack.camera.boxes import FittedBox, boxes_from_masks
from unstack.camera.build import CameraScene, scene_from_depth
from unstack.camera.clouds import load_cloud, load_detections, scene_from_cloud
from unstack.camera.files import (
    Intrinsics,
    check_pose,
    load_depth,
    load_intrinsics,
    load_label_masks,
    load_mask,
    load_pose,
)
from unstack.camera.planes import GravityFrame, depth_points, fit_plane, gravity_frame

__all__ = [
    "CameraScene",
    "FittedBox",
    "GravityFrame",
    "Intrinsics",
    "boxes_from_masks",
    "check_pose",
    "depth_points",
    "fit_plane",
    "gravity_frame",
    "load_cloud",
    "load_depth",
    "load_detections",
    "load_intrinsics",
    "load_label_masks",
    "load_mask",
    "load_pose",
    "scene_from_cloud",
    "scene_from_depth",
]
