"""Point clouds made without the simulator: box faces sampled as a different sensor would.

The project's range sensor (:mod:`unstack.sim.sensor`) renders a pinhole depth image with
pybullet. :func:`surface_cloud` makes a cloud another way -- points spread over the faces
of the boxes (and the floor) at a chosen spacing with random jitter, kept only where the
viewpoint sees them (a point z-buffer over angular bins), optionally with depth noise along
the rays and whole faces missing (dark or shiny cartons that return nothing). A model that
leans on how the simulator samples its clouds shows it on these.

Examples
--------
>>> from unstack.scene import Box
>>> boxes = [Box("a", [0.6, 0.4, 0.4], [1.0, 0.0, 0.2]), Box("b", [0.4, 0.3, 0.3], [1.0, 0.0, 0.55])]
>>> cloud = surface_cloud(boxes, viewpoint=[-2.0, 0.0, 1.3], spacing=0.02, seed=0)
>>> cloud.shape[1], bool(cloud[:, 2].max() <= 0.7 + 1e-9)
(3, True)
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from unstack.errors import UnstackError
from unstack.geometry import rotation_matrix
from unstack.scene import Box

__all__ = ["NOMINAL_VIEWPOINT", "surface_cloud", "vary_cloud"]

#: Face normals of a cuboid in its own frame, and the two axes spanning each face.
_FACES = [(axis, sign, [k for k in range(3) if k != axis]) for axis in range(3) for sign in (-1.0, 1.0)]


def _face_points(box: Box, spacing: float, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Jittered grid points on each face: points (m, 3), outward normals (m, 3), face index (m,)."""
    rotation = rotation_matrix(box.orientation_xyzw)
    half = box.size / 2.0
    points, normals, faces = [], [], []
    for face, (axis, sign, span) in enumerate(_FACES):
        counts = [max(1, int(np.ceil(2 * half[k] / spacing))) for k in span]
        u = (np.arange(counts[0]) + 0.5) / counts[0]
        v = (np.arange(counts[1]) + 0.5) / counts[1]
        grid_u, grid_v = np.meshgrid(u, v, indexing="ij")
        jitter = rng.uniform(-0.5, 0.5, size=(2, *grid_u.shape))
        local = np.zeros((grid_u.size, 3))
        local[:, span[0]] = ((grid_u + jitter[0] / counts[0]).ravel() * 2 - 1) * half[span[0]]
        local[:, span[1]] = ((grid_v + jitter[1] / counts[1]).ravel() * 2 - 1) * half[span[1]]
        local[:, axis] = sign * half[axis]
        normal = np.zeros(3)
        normal[axis] = sign
        points.append(local @ rotation.T + box.position)
        normals.append(np.tile(rotation @ normal, (len(local), 1)))
        faces.append(np.full(len(local), face))
    return np.vstack(points), np.vstack(normals), np.concatenate(faces)


def surface_cloud(
    boxes: Sequence[Box],
    *,
    viewpoint: Sequence[float] | np.ndarray = (-2.8, 0.0, 1.3),
    spacing: float = 0.02,
    depth_noise: float = 0.0,
    missing_faces: float = 0.0,
    floor: bool = True,
    seed: int | np.random.SeedSequence | None = None,
) -> np.ndarray:
    """The points of the boxes' faces (and the floor) that a viewpoint sees.

    Parameters
    ----------
    boxes : sequence of Box
    viewpoint : sequence of 3 floats
        Where the sensor is (metres, world frame).
    spacing : float
        Distance between neighbouring samples on a face (metres).
    depth_noise : float
        Standard deviation of a normal error along each ray (metres).
    missing_faces : float
        Probability that a whole face returns no points.
    floor : bool
        Also sample the floor (z = 0) around the boxes.
    seed : int, optional

    Returns
    -------
    numpy.ndarray, shape (N, 3)
    """
    if not spacing > 0 or not depth_noise >= 0 or not 0 <= missing_faces < 1:
        raise UnstackError(
            f"surface_cloud needs spacing > 0, depth_noise >= 0 and 0 <= missing_faces < 1, got {spacing}, "
            f"{depth_noise} and {missing_faces}"
        )
    rng = np.random.default_rng(seed)
    eye = np.asarray(viewpoint, dtype=np.float64)
    parts = []
    for box in boxes:
        points, normals, faces = _face_points(box, spacing, rng)
        facing = np.einsum("ij,ij->i", normals, eye - points) > 0
        kept = rng.random(len(_FACES)) >= missing_faces
        keep = facing & kept[faces]
        parts.append(points[keep])
    if floor and boxes:
        low = np.min([box.position - box.size.max() for box in boxes], axis=0) - 0.5
        high = np.max([box.position + box.size.max() for box in boxes], axis=0) + 0.5
        xs = np.arange(low[0], high[0], spacing)
        ys = np.arange(low[1], high[1], spacing)
        grid_x, grid_y = np.meshgrid(xs, ys, indexing="ij")
        floor_points = np.column_stack([grid_x.ravel(), grid_y.ravel(), np.zeros(grid_x.size)])
        floor_points[:, :2] += rng.uniform(-spacing / 2, spacing / 2, size=(len(floor_points), 2))
        parts.append(floor_points)
    cloud = np.vstack(parts) if parts else np.zeros((0, 3))
    if len(cloud) == 0:
        return cloud
    rays = cloud - eye
    ranges = np.linalg.norm(rays, axis=1)
    directions = rays / ranges[:, None]
    # A point z-buffer: angular bins coarser than the samples at the nearest range, so that a
    # near surface leaves no empty bin to see through; in each bin only the points within
    # two spacings of the nearest survive.
    step = 1.5 * spacing / max(float(ranges.min()), spacing)
    azimuth = np.arctan2(directions[:, 1], directions[:, 0])
    elevation = np.arcsin(np.clip(directions[:, 2], -1.0, 1.0))
    bins = np.stack([np.floor(azimuth / step), np.floor(elevation / step)], axis=1).astype(np.int64)
    _, bin_index = np.unique(bins, axis=0, return_inverse=True)
    bin_index = bin_index.ravel()
    nearest = np.full(bin_index.max() + 1, np.inf)
    np.minimum.at(nearest, bin_index, ranges)
    visible = ranges <= nearest[bin_index] + 2 * spacing
    cloud, ranges, directions = cloud[visible], ranges[visible], directions[visible]
    if depth_noise > 0:
        cloud = eye + directions * (ranges + rng.normal(0.0, depth_noise, size=len(ranges)))[:, None]
    return np.ascontiguousarray(cloud, dtype=np.float64)


#: Where :func:`vary_cloud` assumes the sensor was when it adds depth noise (the project's
#: default sensor position).
NOMINAL_VIEWPOINT = (-2.8, 0.0, 1.3)


def vary_cloud(
    points: np.ndarray,
    rng: np.random.Generator,
    *,
    keep_range: tuple[float, float] = (0.05, 1.0),
    max_depth_noise: float = 0.01,
    max_holes: int = 4,
    viewpoint: Sequence[float] = NOMINAL_VIEWPOINT,
) -> np.ndarray:
    """The same scene as another sensor might see it: sparser, noisier, with holes.

    Keeps a share of the points drawn log-uniformly from ``keep_range``, adds a normal
    error of up to ``max_depth_noise`` metres along the rays from ``viewpoint``, and cuts up
    to ``max_holes`` balls (radius 0.05-0.25 m, around random points) out of the cloud --
    faces that returned nothing. Used to train models that do not lean on one sensor.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> cloud = rng.uniform(0, 1, size=(10_000, 3))
    >>> varied = vary_cloud(cloud, np.random.default_rng(1))
    >>> 0 < len(varied) <= len(cloud)
    True
    """
    if len(points) == 0:
        return points
    low, high = keep_range
    share = float(np.exp(rng.uniform(np.log(low), np.log(high))))
    kept = points[rng.random(len(points)) < share]
    for _ in range(int(rng.integers(0, max_holes + 1))):
        if len(kept) == 0:
            break
        centre = kept[rng.integers(len(kept))]
        kept = kept[np.linalg.norm(kept - centre, axis=1) > rng.uniform(0.05, 0.25)]
    sigma = float(rng.uniform(0.0, max_depth_noise))
    if sigma > 0 and len(kept):
        eye = np.asarray(viewpoint, dtype=np.float64)
        rays = kept - eye
        ranges = np.linalg.norm(rays, axis=1, keepdims=True)
        kept = eye + rays / ranges * (ranges + rng.normal(0.0, sigma, size=ranges.shape))
    return np.ascontiguousarray(kept, dtype=np.float64)
