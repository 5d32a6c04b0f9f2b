"""A synthetic top-down depth camera over cartons on a floor: exact depth images to fit back."""

from __future__ import annotations

import numpy as np
import pytest

from unstack.camera import Intrinsics

CAMERA_HEIGHT = 2.5
MAX_RANGE = 6.0
INTRINSICS = Intrinsics(fx=300.0, fy=300.0, cx=159.5, cy=119.5, width=320, height=240)


def looking_down(tilt_deg: float = 0.0) -> np.ndarray:
    """Camera-to-world pose of a camera at CAMERA_HEIGHT looking straight down, the world tilted about x."""
    pose = np.array([[1.0, 0.0, 0.0, 0.0], [0.0, -1.0, 0.0, 0.0], [0.0, 0.0, -1.0, CAMERA_HEIGHT], [0, 0, 0, 1.0]])
    angle = np.radians(tilt_deg)
    tilt = np.eye(4)
    tilt[1:3, 1:3] = [[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]]
    return tilt @ pose


def render_tops(boxes: list[tuple[float, float, float, float, float, float]], tilt_deg: float = 0.0):
    """Depth (metres) and one mask per box for boxes ``(x, y, yaw_deg, long, short, height)`` on the floor.

    Seen from straight above only the tops show; the world is then tilted by ``tilt_deg`` so
    the pose's z is not gravity (the pose is tilted with it: the images stay the same).
    """
    rows, columns = np.mgrid[0 : INTRINSICS.height, 0 : INTRINSICS.width]
    ray_x = (columns - INTRINSICS.cx) / INTRINSICS.fx  # camera frame, per unit depth
    ray_y = (rows - INTRINSICS.cy) / INTRINSICS.fy
    depth = np.full(rows.shape, CAMERA_HEIGHT)  # the floor
    owner = np.full(rows.shape, -1)
    for index, (x, y, yaw, long, short, height) in enumerate(boxes):
        z = CAMERA_HEIGHT - height
        world_x, world_y = ray_x * z, -ray_y * z  # looking down: camera x = world x, camera y = -world y
        angle = np.radians(yaw)
        local_x = (world_x - x) * np.cos(angle) + (world_y - y) * np.sin(angle)
        local_y = -(world_x - x) * np.sin(angle) + (world_y - y) * np.cos(angle)
        inside = (np.abs(local_x) <= long / 2) & (np.abs(local_y) <= short / 2) & (z < depth)
        depth[inside] = z
        owner[inside] = index
    return depth, [owner == index for index in range(len(boxes))], looking_down(tilt_deg)


@pytest.fixture
def three_cartons():
    """Three cartons of two sizes, turned 0, 20 and -35 degrees, one on another's level."""
    return [(0.0, 0.0, 0.0, 0.4, 0.3, 0.3), (0.65, 0.1, 20.0, 0.6, 0.4, 0.4), (-0.45, -0.3, -35.0, 0.4, 0.3, 0.3)]


def looking_in(height: float = 1.2, pitch_deg: float = 20.0) -> np.ndarray:
    """Camera-to-world pose of a camera at the door (x = 0) ``height`` up, looking along +x and
    ``pitch_deg`` down."""
    forward = np.array([np.cos(np.radians(pitch_deg)), 0.0, -np.sin(np.radians(pitch_deg))])
    right = np.array([0.0, -1.0, 0.0])
    down = np.cross(forward, right)
    pose = np.eye(4)
    pose[:3, :3] = np.column_stack([right, down, forward])
    pose[:3, 3] = [0.0, 0.0, height]
    return pose


FLOOR = (np.array([0.0, 0.0, 1.0]), 0.0)


def render_boxes(boxes, pose: np.ndarray, planes=(FLOOR,)):
    """Depth (metres along the optical axis) and one mask per box for :class:`~unstack.scene.Box`
    objects in any orientation, and planes ``(normal, offset)`` (default: the floor z = 0)
    seen from the side their normal points to."""
    from unstack.geometry import rotation_matrix

    rows, columns = np.mgrid[0 : INTRINSICS.height, 0 : INTRINSICS.width]
    rays = (
        np.stack(
            [(columns - INTRINSICS.cx) / INTRINSICS.fx, (rows - INTRINSICS.cy) / INTRINSICS.fy, np.ones(rows.shape)], -1
        )
        @ pose[:3, :3].T
    )  # world directions whose optical-axis part is 1: the distance along them is the depth
    origin = pose[:3, 3]
    depth = np.full(rows.shape, np.inf)
    owner = np.full(rows.shape, -1)
    for normal, offset in planes:
        facing = rays @ normal
        with np.errstate(divide="ignore", invalid="ignore"):
            distance = (offset - origin @ normal) / facing
        hit = (facing < 0) & (distance > 0) & (distance < depth)
        depth[hit] = distance[hit]
    for index, box in enumerate(boxes):
        rotation = rotation_matrix(box.orientation_xyzw)
        local_origin = (origin - box.position) @ rotation
        local_rays = rays @ rotation
        half = np.asarray(box.size) / 2
        with np.errstate(divide="ignore", invalid="ignore"):
            first = (-half - local_origin) / local_rays
            second = (half - local_origin) / local_rays
        near = np.nanmax(np.minimum(first, second), axis=-1)
        far = np.nanmin(np.maximum(first, second), axis=-1)
        hit = (near <= far) & (near > 0) & (near < depth)
        depth[hit] = near[hit]
        owner[hit] = index
    depth[~np.isfinite(depth) | (depth > MAX_RANGE)] = 0.0  # nothing within the sensor's range
    return depth, [owner == index for index in range(len(boxes))]
