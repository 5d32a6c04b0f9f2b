"""Points from depth pixels, robust planes, and the world's gravity frame from them.

A camera's world frame (the robot's root, a calibration target) need not have its z along
gravity: in the NEURA palletizer capture the box tops and the pallet deck are tilted about 9
degrees in the root frame. Box tops and floors are horizontal, so the dominant planes of a
pile's cloud whose normals lie within :data:`HORIZONTAL_TOLERANCE_DEG` of the frame's z tell
where up is: their normals, averaged with their inlier counts as weights, are the gravity
frame's z. The floor is the lowest such plane, put at z = 0.

Examples
--------
>>> rng = np.random.default_rng(0)
>>> floor = np.column_stack([rng.uniform(-1, 1, 500), rng.uniform(-1, 1, 500), 0.002 * rng.normal(size=500)])
>>> normal, offset, inliers = fit_plane(floor, rng=np.random.default_rng(1))
>>> bool(abs(normal[2]) > 0.999), int(inliers.sum()) > 480
(True, True)
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from unstack.camera.files import Intrinsics
from unstack.errors import UnstackError

__all__ = [
    "GravityFrame",
    "check_gravity",
    "depth_points",
    "fit_plane",
    "gravity_frame",
    "plane_by_heights",
    "plane_within_noise",
]

#: Distance (metres) within which a point belongs to a plane.
PLANE_THRESHOLD = 0.01
#: Random three-point samples of a RANSAC fit.
RANSAC_ITERATIONS = 300
#: A plane whose normal is within this of the frame's z is a horizontal plane candidate.
HORIZONTAL_TOLERANCE_DEG = 25.0
#: Horizontal planes within this of the largest one's direction give gravity together (degrees).
PARALLEL_DEG = 2.0
#: Planes found in turn (each plane's inliers removed before the next).
MAX_PLANES = 8
#: A door direction rising or falling more than this (degrees from the horizontal) is refused
#: (a default towards a camera above the pile rises at most 72.5: see ``scene_from_depth``).
MAX_DOOR_RISE_DEG = 75.0
#: A plane holding fewer than this share of the points ends the search.
MIN_PLANE_SHARE = 0.02
#: A proposal takes its second and third points among an anchor's this many nearest neighbours.
NEIGHBOURS = 24
#: A plane's band is widened while its points lie a mean distance over this share of the band
#: from the plane (the noise fills the band) ...
NOISE_FILL = 0.35
#: ... up to this width (metres), and while the refitted plane turns less than this (degrees):
#: a wider band that takes in another surface turns the fit towards it.
NOISE_BAND = 0.05
NOISE_TURN_DEG = 15.0
#: ... or, for gravity's level planes, this: a wall's foot in the wider band turned the floor of a
#: wall of box fronts seen from the door by 12-26 degrees.
LEVEL_TURN_DEG = 2.0
#: The lowest plane is the floor unless more than this share of the points lies more than
#: :data:`NOISE_BAND` under it, on surfaces (:func:`_surfaces`: a floor seen as a sliver, the
#: sides of boxes standing on a floor not seen; not a sensor's stray readings scattered under
#: the floor); the floor is then the lowest readings' level (:func:`_lowest_level`).
FLOOR_BELOW_SHARE = 0.01
#: Points lie on surfaces when their distance to their this-many-th nearest point is under
#: :data:`SURFACE_SPREAD` times the cloud's (medians over at most :data:`SURFACE_SAMPLE` points).
SURFACE_NEIGHBOURS = 8
SURFACE_SPREAD = 3.0
SURFACE_SAMPLE = 5_000
#: A plane leans from the direction it is given only when its points' heights spread this many
#: times as far along that direction as along the plane's normal (:func:`_spread`).
LEAN_EVIDENCE = 1.2
#: A level plane's band holds at least this many times the points of the bands beside it.
LEVEL_PEAK = 2.0
#: Points used for the plane search (a random subset of larger clouds; the fit is refined on all).
PLANE_SAMPLE = 60_000
#: Where gravity comes from: the cloud's level planes (correcting a pose frame tilted against
#: gravity), or the pose frame's z taken as up (a robot cell's calibrated frame).
GRAVITY_SOURCES = ("planes", "pose")


def depth_points(
    depth_m: np.ndarray, intrinsics: Intrinsics, camera_to_world: np.ndarray, mask: np.ndarray | None = None
) -> np.ndarray:
    """World points (N, 3) of the pixels with a reading (and in ``mask``), row by row.

    Examples
    --------
    >>> camera = Intrinsics(fx=100.0, fy=100.0, cx=1.0, cy=1.0, width=3, height=3)
    >>> depth_points(np.full((3, 3), 2.0), camera, np.eye(4))[0].tolist()   # the top-left pixel
    [-0.02, -0.02, 2.0]
    """
    depth = np.asarray(depth_m, dtype=np.float64)
    if depth.shape != (intrinsics.height, intrinsics.width):
        raise UnstackError(
            f"the depth image is {depth.shape[1]} x {depth.shape[0]} pixels, the intrinsics say "
            f"{intrinsics.width} x {intrinsics.height}"
        )
    selected = depth > 0
    if mask is not None:
        selected &= mask
    rows, columns = np.nonzero(selected)
    z = depth[rows, columns]
    camera = np.column_stack(
        [(columns - intrinsics.cx) * z / intrinsics.fx, (rows - intrinsics.cy) * z / intrinsics.fy, z]
    )
    pose = np.asarray(camera_to_world, dtype=np.float64)
    points: np.ndarray = camera @ pose[:3, :3].T + pose[:3, 3]
    return points


def fit_plane(
    points: np.ndarray,
    *,
    threshold: float = PLANE_THRESHOLD,
    iterations: int = RANSAC_ITERATIONS,
    rng: np.random.Generator,
    near_normal: np.ndarray | None = None,
    tolerance_deg: float = HORIZONTAL_TOLERANCE_DEG,
    in_cone: bool = False,
) -> tuple[np.ndarray, float, np.ndarray]:
    """The plane ``normal . p = offset`` holding the most points within ``threshold`` (RANSAC).

    Three nearby points (an anchor and two of its nearest neighbours) propose a plane; the one
    with most inliers is refined by a least-squares fit (the smallest principal axis of its
    inliers). With ``near_normal``, only planes whose normal is within ``tolerance_deg`` of it
    are proposed (the normal is returned pointing its way); with ``in_cone`` too, a refinement
    that leaves that cone is not taken (the inliers were mostly another surface the proposal
    crossed, as a wall of box fronts).

    Returns
    -------
    normal : numpy.ndarray, shape (3,)
    offset : float
    inliers : numpy.ndarray of bool, shape (N,)
    """
    points = np.asarray(points, dtype=np.float64)
    if len(points) < 3:
        raise UnstackError(f"a plane needs at least 3 points, got {len(points)}")
    from scipy.spatial import cKDTree

    check = points if len(points) <= PLANE_SAMPLE else points[rng.choice(len(points), PLANE_SAMPLE, replace=False)]
    # three points of one surface: an anchor and two of its nearest neighbours (random triples
    # across a cloud of mostly vertical faces almost never propose a floor)
    neighbours = min(NEIGHBOURS, len(check))
    anchors_index = rng.integers(0, len(check), size=iterations)
    _, near = cKDTree(check).query(check[anchors_index], k=neighbours)
    near = np.asarray(near).reshape(iterations, -1)
    picks = near[np.arange(iterations)[:, None], rng.integers(1, max(2, near.shape[1]), size=(iterations, 2))]
    samples = np.stack([check[anchors_index], check[picks[:, 0]], check[picks[:, 1]]], axis=1)
    normals = np.cross(samples[:, 1] - samples[:, 0], samples[:, 2] - samples[:, 0])
    lengths = np.linalg.norm(normals, axis=1)
    usable = lengths > 1e-12
    normals = normals[usable] / lengths[usable, None]
    anchors = samples[usable, 0]
    if near_normal is not None:
        reference = np.asarray(near_normal, dtype=np.float64) / np.linalg.norm(near_normal)
        normals *= np.sign(normals @ reference)[:, None]
        keep = normals @ reference >= np.cos(np.radians(tolerance_deg))
        normals, anchors = normals[keep], anchors[keep]
    if len(normals) == 0:
        return np.array([0.0, 0.0, 1.0]), 0.0, np.zeros(len(points), dtype=bool)
    offsets = np.einsum("ij,ij->i", normals, anchors)
    counts = [
        (np.abs(check @ normal - offset) < threshold).sum() for normal, offset in zip(normals, offsets, strict=True)
    ]
    best = int(np.argmax(counts))
    inliers = np.abs(points @ normals[best] - offsets[best]) < threshold
    normal, offset = normals[best], float(offsets[best])
    if inliers.sum() >= 3:
        centre = points[inliers].mean(axis=0)
        refined = np.linalg.svd(points[inliers] - centre, full_matrices=False)[2][-1]
        refined *= np.sign(refined @ normal) or 1.0
        if not in_cone or near_normal is None or refined @ reference >= np.cos(np.radians(tolerance_deg)):
            normal, offset = refined, float(refined @ centre)
            inliers = np.abs(points @ normal - offset) < threshold
    return normal, offset, inliers


def plane_within_noise(
    points: np.ndarray,
    normal: np.ndarray,
    offset: float,
    inliers: np.ndarray,
    *,
    max_turn_deg: float = NOISE_TURN_DEG,
    level: bool = False,
) -> tuple[np.ndarray, float, np.ndarray]:
    """The plane refitted in a wider band when the depth noise fills the band it was fitted in
    (else the plane as given).

    The points within a band of :data:`PLANE_THRESHOLD` lie a mean distance under
    :data:`NOISE_FILL` of it from the plane when the noise is narrower than the band (0 for exact
    depth; 0.36 for noise of half the band, 0.5 for noise far wider); while they lie further, the
    band is doubled (up to :data:`NOISE_BAND`) and the plane refitted to the points in it. Depth
    noise of a centimetre or more puts most of a face outside a 1 cm band, and the band's points
    lean the fit towards the three that proposed it: a floor 4 m away, its depth 2.5 cm off,
    tilts gravity by degrees. A refit turning more than ``max_turn_deg`` took in another surface:
    the plane stays as it was, or, ``level``, keeps its direction and has only its height
    refitted in the widening band (gravity's level planes).

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> floor = np.column_stack([rng.uniform(-1, 1, 5000), rng.uniform(-1, 1, 5000), rng.normal(0, 0.01, 5000)])
    >>> leaning = np.array([0.05, 0.0, 1.0]) / np.hypot(0.05, 1.0)
    >>> normal, offset, inliers = plane_within_noise(floor, leaning, 0.0, np.abs(floor @ leaning) < 0.01)
    >>> bool(normal[2] > 0.9999), bool(inliers.mean() > 0.9)
    (True, True)
    """
    band = PLANE_THRESHOLD
    while _fills_band(points, normal, offset, band) and 2.0 * band <= NOISE_BAND:
        band *= 2.0
        wide = np.abs(points @ normal - offset) < band
        centre = points[wide].mean(axis=0)
        refined = np.linalg.svd(points[wide] - centre, full_matrices=False)[2][-1]
        refined *= np.sign(refined @ normal) or 1.0
        if refined @ normal < np.cos(np.radians(max_turn_deg)):  # the wider band holds another surface
            if level:  # a wall's foot beside a floor: the floor keeps its direction
                return (normal, *_widened(points @ normal, offset, band / 2.0))
            break
        normal, offset = refined, float(refined @ centre)
        inliers = np.abs(points @ normal - offset) < band
    return normal, offset, inliers


def _level_within_noise(points: np.ndarray, normal: np.ndarray) -> tuple[float, np.ndarray]:
    """The height along ``normal`` of the fullest 4 cm slab of the points (:func:`_fullest_slab`,
    as :func:`plane_by_heights` counts in one direction), refitted in a band doubled while the
    noise fills it (up to :data:`NOISE_BAND`), and the points within that band."""
    heights = points @ normal
    return _widened(heights, _fullest_slab(heights, 4 * PLANE_THRESHOLD)[0], PLANE_THRESHOLD)


def _level_along(points: np.ndarray, up: np.ndarray) -> tuple[float, np.ndarray]:
    """The fullest level of the points along ``up``: the median height of the fullest 4 cm slab
    (:func:`_fullest_slab`; exact depth puts a plane at the slab's lower edge, not its middle),
    refitted in a band doubled while the noise fills it (up to :data:`NOISE_BAND`), and the
    points within that band.

    Examples
    --------
    >>> heights = np.r_[np.zeros(500), np.full(200, 0.3)]
    >>> offset, inside = _level_along(np.column_stack([np.zeros(700), np.zeros(700), heights]), np.array([0, 0, 1.0]))
    >>> offset, int(inside.sum())
    (0.0, 500)
    """
    heights = points @ up
    centre = _fullest_slab(heights, 4 * PLANE_THRESHOLD)[0]
    slab = heights[np.abs(heights - centre) <= 2 * PLANE_THRESHOLD + 1e-9]  # its lower edge, past rounding
    return _widened(heights, float(np.median(slab)), PLANE_THRESHOLD)


def _widened(heights: np.ndarray, offset: float, band: float) -> tuple[float, np.ndarray]:
    """A level at ``offset`` among ``heights``, refitted (the mean within ``band``) in a band
    doubled while the noise fills it (up to :data:`NOISE_BAND`), and the heights within it."""
    inside = np.abs(heights - offset) < band
    if inside.any():
        offset = float(np.mean(heights[inside]))
    while _fills_level(heights, offset, band) and 2.0 * band <= NOISE_BAND:
        band *= 2.0
        inside = np.abs(heights - offset) < band
        offset = float(np.mean(heights[inside]))
    return offset, np.abs(heights - offset) < band


def _level_unless_leaning(
    points: np.ndarray, normal: np.ndarray, offset: float, inliers: np.ndarray, reference: np.ndarray
) -> tuple[np.ndarray, float, np.ndarray]:
    """The plane (``normal``, ``offset``) with its ``inliers``, or the plane level along
    ``reference`` through the same points when their heights along it spread less than
    :data:`LEAN_EVIDENCE` times as far as along ``normal`` (:func:`_spread`): a strip of floor
    before a wall of box fronts fits any lean about its length, and the wall's foot in its band
    leans the least-squares fit by degrees; a plane truly leaning spreads along the level.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> strip = np.column_stack([rng.uniform(1.6, 1.7, 3000), rng.uniform(-1, 1, 3000), np.zeros(3000)])
    >>> foot = np.column_stack([np.full(300, 1.7), rng.uniform(-1, 1, 300), rng.uniform(0.0, 0.01, 300)])
    >>> points = np.r_[strip, foot]
    >>> leaning = np.array([-np.sin(0.05), 0.0, np.cos(0.05)])
    >>> inliers = np.abs(points @ leaning - (points @ leaning).mean()) < 0.01
    >>> normal, offset, _ = _level_unless_leaning(points, leaning, 0.0, inliers, np.array([0.0, 0.0, 1.0]))
    >>> normal.tolist(), round(offset, 3)
    ([0.0, 0.0, 1.0], 0.0)
    """
    heights = points @ reference
    if _spread(heights[inliers]) < LEAN_EVIDENCE * _spread(points[inliers] @ normal):  # no lean shows
        level_offset = float(np.mean(heights[inliers]))
        return reference, level_offset, np.abs(heights - level_offset) < PLANE_THRESHOLD
    return normal, offset, inliers


def _stands_out(heights: np.ndarray, offset: float, band: float, *, per_side: bool = False) -> bool:
    """Whether a level plane's points stand out of the cloud's heights around it: the band
    (``offset`` +- ``band``) holds :data:`LEVEL_PEAK` times the points of the two bands as wide
    beside it. A plane does; a slab of the heights of a wall (box fronts seen from the door, with
    no floor or top in it) holds as many as the slabs above and below it. ``per_side``: each of
    the two bands counts as both (the fuller one, doubled): the lowest or highest slab of a
    surface leaning against the direction has nothing beyond it, and only its one side to
    compare with (gravity from the pose, where every slab is a level along the pose's z).

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> wall = rng.uniform(0.0, 1.5, 20000)
    >>> floor = np.r_[wall, rng.normal(0.0, 0.005, 3000)]
    >>> _stands_out(floor, 0.0, 0.02), _stands_out(wall, 0.7, 0.02)
    (True, False)
    >>> _stands_out(wall, 0.02, 0.02), _stands_out(wall, 0.02, 0.02, per_side=True)
    (True, False)
    """
    distances = np.abs(heights - offset)
    inside = int(np.sum(distances < band))
    beside = (distances >= band) & (distances < 2.0 * band)
    if per_side:
        above = int(np.sum(beside & (heights > offset)))
        return inside >= LEVEL_PEAK * 2 * max(above, int(np.sum(beside)) - above)
    return inside >= LEVEL_PEAK * int(np.sum(beside))


def _surfaces(points: np.ndarray, under: np.ndarray, rng: np.random.Generator) -> bool:
    """Whether the points ``under`` selects lie on surfaces as the rest do: the median distance
    to their :data:`SURFACE_NEIGHBOURS`-th nearest point is under :data:`SURFACE_SPREAD` times
    the cloud's, as a depth image samples a surface, and they are not readings scattered apart
    (multipath, a few pixels read far too long).

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> floor = np.column_stack([rng.uniform(0, 2, 8000), rng.uniform(0, 2, 8000), np.zeros(8000)])
    >>> sliver = np.column_stack([rng.uniform(0, 2, 400), rng.uniform(2, 2.1, 400), np.full(400, -0.3)])
    >>> stray = np.column_stack([rng.uniform(0, 2, 400), rng.uniform(0, 2, 400), rng.uniform(-1, -0.1, 400)])
    >>> below = np.r_[np.zeros(8000, bool), np.ones(400, bool)]
    >>> _surfaces(np.r_[floor, sliver], below, rng), _surfaces(np.r_[floor, stray], below, rng)
    (True, False)
    """
    from scipy.spatial import cKDTree

    def spacing(chosen: np.ndarray) -> float:
        if len(chosen) > SURFACE_SAMPLE:
            chosen = chosen[rng.choice(len(chosen), SURFACE_SAMPLE, replace=False)]
        return float(np.median(tree.query(chosen, k=SURFACE_NEIGHBOURS + 1)[0][:, -1]))

    tree = cKDTree(points)
    return spacing(points[under]) < SURFACE_SPREAD * spacing(points)


def _lowest_level(heights: np.ndarray) -> float:
    """The floor's height where no plane holds it: the median of the heights within
    2 :data:`PLANE_THRESHOLD` of their 0.5th percentile (a floor seen as a sliver, under 1 % of
    the points, or the lowest edges seen)."""
    lowest = float(np.percentile(heights, 0.5))
    return float(np.median(heights[np.abs(heights - lowest) <= 2 * PLANE_THRESHOLD]))


def _fills_band(points: np.ndarray, normal: np.ndarray, offset: float, band: float = PLANE_THRESHOLD) -> bool:
    """Whether the points within ``band`` of the plane lie a mean :data:`NOISE_FILL` of it or more
    from it: depth noise as wide as the band, or wider."""
    return _fills_level(points @ normal, offset, band)


def _fills_level(heights: np.ndarray, offset: float, band: float) -> bool:
    """:func:`_fills_band` for heights along the plane's normal."""
    distances = np.abs(heights - offset)
    inside = distances[distances < band]
    return bool(len(inside) >= 3 and np.mean(inside) >= NOISE_FILL * band)


def _directions_around(centre: np.ndarray, radius_deg: float, step_deg: float) -> np.ndarray:
    """Unit vectors within ``radius_deg`` of ``centre``, about ``step_deg`` apart."""
    helper = np.array([1.0, 0.0, 0.0]) if abs(centre[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    first = np.cross(centre, helper)
    first /= np.linalg.norm(first)
    second = np.cross(centre, first)
    steps = np.arange(-radius_deg, radius_deg + step_deg / 2, step_deg)
    a, b = (np.radians(grid).ravel() for grid in np.meshgrid(steps, steps))
    keep = np.hypot(a, b) <= np.radians(radius_deg) + 1e-12
    directions = centre + np.tan(a[keep, None]) * first + np.tan(b[keep, None]) * second
    unit: np.ndarray = directions / np.linalg.norm(directions, axis=1, keepdims=True)
    return unit


def plane_by_heights(
    points: np.ndarray, near_normal: np.ndarray, *, tolerance_deg: float = HORIZONTAL_TOLERANCE_DEG,
    bin_m: float = 4 * PLANE_THRESHOLD, rng: np.random.Generator,
) -> tuple[np.ndarray, float]:  # fmt: skip
    """The plane within ``tolerance_deg`` of ``near_normal`` that the most points lie in a slab of
    ``bin_m`` of: for each direction tried, the points' heights along it, the fullest slab of
    ``bin_m`` counted (:func:`_fullest_slab`) and weighed by the cosine of the direction's lean
    from ``near_normal`` (a leaning slab cuts a vertical face in a band as much wider: a wall of
    box fronts seen from the door otherwise leans gravity 20-30 degrees); directions 2.5 degrees
    apart over the whole cone, then 0.5 and 0.1 degrees apart around the best. The best leans
    from ``near_normal`` only when its slab's heights spread :data:`LEAN_EVIDENCE` times as far
    along ``near_normal`` as along it; else ``near_normal`` and its fullest slab are returned.

    What a noisy cloud needs: three neighbouring points a centimetre apart with depth noise of
    centimetres propose planes in every direction, while a floor 3 m across, its heights binned
    along a direction 1 degree off, spreads over 9 cm of heights.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> floor = np.column_stack([rng.uniform(-2, 2, 4000), rng.uniform(-2, 2, 4000), rng.normal(0, 0.03, 4000)])
    >>> normal, offset = plane_by_heights(floor, np.array([0.0, 0.0, 1.0]), rng=rng)
    >>> bool(normal[2] > np.cos(np.radians(0.5))), abs(offset) < 0.03
    (True, True)
    """
    points = np.asarray(points, dtype=np.float64)
    if len(points) > PLANE_SAMPLE // 2:
        points = points[rng.choice(len(points), PLANE_SAMPLE // 2, replace=False)]
    reference = np.asarray(near_normal, dtype=np.float64) / np.linalg.norm(near_normal)
    best = (reference, 0.0, -1.0)
    inside_cone = np.cos(np.radians(tolerance_deg)) - 1e-12
    for centre, radius, step in ((reference, tolerance_deg, 2.5), (None, 2.5, 0.5), (None, 0.5, 0.1)):
        directions = _directions_around(best[0] if centre is None else centre, radius, step)
        for direction in directions[directions @ reference >= inside_cone]:  # the finer grids stay in the cone
            offset, count = _fullest_slab(points @ direction, bin_m)
            # a slab leaning by t cuts a vertical face in a band 1 / cos(t) as wide: that much more
            # of a wall of box fronts is no evidence of a lean
            score = count * float(direction @ reference)
            if score > best[2]:
                best = (direction, offset, score)
    direction, offset = best[0], best[1]
    slab = points[np.abs(points @ direction - offset) < bin_m / 2]
    if _spread(slab @ reference) < LEAN_EVIDENCE * _spread(slab @ direction):  # no lean shows in the slab
        return reference, _fullest_slab(points @ reference, bin_m)[0]
    return direction, offset


def _spread(heights: np.ndarray) -> float:
    """The median absolute deviation of ``heights`` (0 for none)."""
    return float(np.median(np.abs(heights - np.median(heights)))) if len(heights) else 0.0


def _fullest_slab(heights: np.ndarray, bin_m: float) -> tuple[float, int]:
    """The centre of the slab ``bin_m`` thick that holds the most ``heights`` (a window sliding
    over them; the lowest on a tie), and how many it holds.

    Examples
    --------
    >>> _fullest_slab(np.array([0.0, 0.01, 0.5, 0.51, 0.52, 0.9]), 0.04)
    (0.52, 3)
    """
    ordered = np.sort(np.asarray(heights, dtype=np.float64))
    counts = np.searchsorted(ordered, ordered + bin_m, side="right") - np.arange(len(ordered))
    k = int(np.argmax(counts))
    return float(ordered[k] + bin_m / 2), int(counts[k])


@dataclass(frozen=True)
class GravityFrame:
    """A rigid transform from the camera's world frame to one with z up and the floor at z = 0.

    Attributes
    ----------
    rotation : numpy.ndarray, shape (3, 3)
        Applied as ``p' = rotation @ p + translation``.
    translation : numpy.ndarray, shape (3,)
    tilt_deg : float
        Angle between the input frame's z and gravity.
    planes : int
        Horizontal planes that gave the direction.
    floor_inliers : int
        Points on the floor plane (0 when the floor was taken as the lowest points).
    plane_heights : tuple of (float, int)
        Each of those horizontal planes' height in the gravity frame (metres) and its points.
    noisy : bool
        The depth's noise filled the lead plane's band (:data:`PLANE_THRESHOLD`; the plane with
        the most points): it was found by the points' heights and refitted in a band as
        wide as the noise (:func:`plane_by_heights`, :func:`plane_within_noise`).
    gravity : {"planes", "pose"}
        Where up came from: the level planes, or the input frame's z.
    planes_tilt_deg : float or None
        With ``gravity="pose"``: how far the level planes would have turned up from the frame's z
        (``None`` where they find no plane); ``None`` with ``"planes"``.
    """

    rotation: np.ndarray
    translation: np.ndarray
    tilt_deg: float
    planes: int
    floor_inliers: int
    plane_heights: tuple[tuple[float, int], ...] = ()
    noisy: bool = False
    gravity: str = "planes"
    planes_tilt_deg: float | None = None

    def apply(self, points: np.ndarray) -> np.ndarray:
        """The points in the gravity frame."""
        moved: np.ndarray = np.asarray(points, dtype=np.float64) @ self.rotation.T + self.translation
        return moved


def _rotation_onto_z(up: np.ndarray, heading: np.ndarray) -> np.ndarray:
    """The rotation taking ``up`` to +z and the horizontal part of ``heading`` to -x."""
    z = up / np.linalg.norm(up)
    toward = heading - (heading @ z) * z
    if np.linalg.norm(toward) < 1e-9:
        toward = np.array([1.0, 0.0, 0.0]) - z[0] * z
    x = -toward / np.linalg.norm(toward)
    y = np.cross(z, x)
    return np.vstack([x, y, z])


def gravity_frame(
    points: np.ndarray,
    *,
    door: np.ndarray | None = None,
    seed: int = 0,
    gravity: str = "planes",
    default_door: np.ndarray | None = None,
) -> GravityFrame:
    """Gravity and floor from a cloud's horizontal planes; the door towards -x.

    Parameters
    ----------
    points : numpy.ndarray, shape (N, 3)
        The cloud in the camera's world frame, whose z is roughly up (within
        :data:`HORIZONTAL_TOLERANCE_DEG`).
    door : numpy.ndarray, shape (3,), optional
        A direction in the input frame pointing out of the container through the door
        (towards where the robot stands); it becomes -x. Default: the input frame's -x.
    seed : int
        Seeds RANSAC.
    gravity : {"planes", "pose"}
        ``"planes"``: up is the level planes' normal (the input frame's z corrected by up to
        :data:`HORIZONTAL_TOLERANCE_DEG`). ``"pose"``: up is the input frame's z, as a calibrated
        robot frame gives it; the planes give only the levels, the floor among them (a ramp or
        a leaning layer of tops that would turn the planes' up is not followed), and
        ``planes_tilt_deg`` says how far the planes would have turned it.
    default_door : numpy.ndarray, shape (3,), optional
        Without ``door``: a direction out through the door guessed by the caller (towards the
        camera), taken unless the gravity found makes it as steep as a refused door (within
        :data:`MAX_DOOR_RISE_DEG` of the horizontal, or more): then the input frame's -x, never
        an error -- the caller gave no door.

    Raises
    ------
    InvalidArgument
        ``gravity`` is neither ``"planes"`` nor ``"pose"``.
    InvalidScene
        ``points`` is no N x 3 array of finite numbers.
    UnstackError
        No level plane, or a door given within 15 degrees of the vertical.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> tilt = np.radians(9.0)
    >>> flat = np.column_stack([rng.uniform(-1, 1, 2000), rng.uniform(-1, 1, 2000), np.zeros(2000)])
    >>> turn = np.array([[1, 0, 0], [0, np.cos(tilt), -np.sin(tilt)], [0, np.sin(tilt), np.cos(tilt)]])
    >>> frame = gravity_frame(flat @ turn.T + [0, 0, 0.7])
    >>> round(frame.tilt_deg, 1), round(float(np.abs(frame.apply(flat @ turn.T + [0, 0, 0.7])[:, 2]).max()), 3)
    (9.0, 0.0)

    A floor 1 degree off the frame's z, with that z taken as up: not corrected (the floor's
    level is its height along z), and how far the planes would have turned up is said:

    >>> tilt = np.radians(1.0)
    >>> turn = np.array([[1, 0, 0], [0, np.cos(tilt), -np.sin(tilt)], [0, np.sin(tilt), np.cos(tilt)]])
    >>> frame = gravity_frame(flat @ turn.T + [0, 0, 0.7], gravity="pose")
    >>> frame.tilt_deg, round(frame.planes_tilt_deg, 1), round(float(frame.translation[2]), 2)
    (0.0, 1.0, -0.7)
    """
    from unstack.checks import check_points

    gravity = check_gravity(gravity)
    points = check_points(points, source="<points>", path="$")
    rng = np.random.default_rng(seed)
    up_guess = np.array([0.0, 0.0, 1.0])
    from_pose = gravity == "pose"
    remaining = points
    found: list[tuple[np.ndarray, float, int]] = []
    noisy_planes: list[bool] = []
    first_up: np.ndarray | None = None  # the first plane's normal
    for _ in range(MAX_PLANES):
        if len(remaining) < max(3, MIN_PLANE_SHARE * len(points)):
            break
        if from_pose:  # up is the frame's z: each plane is the fullest level along it
            normal = up_guess
            offset, inliers = _level_along(remaining, up_guess)
            noisy = bool(inliers.sum() >= 3 and _fills_band(remaining, normal, offset))
        else:
            normal, offset, inliers, noisy = _plane_in_cone(remaining, rng, up_guess, first_up)
        if inliers.sum() < MIN_PLANE_SHARE * len(points):
            break
        band = max(float(np.max(np.abs(remaining[inliers] @ normal - offset))), PLANE_THRESHOLD)
        if not _stands_out(points @ normal, offset, band, per_side=from_pose):  # a slice of a wall, not a plane
            remaining = remaining[~inliers]
            continue
        found.append((normal, offset, int(inliers.sum())))
        noisy_planes.append(noisy)
        if first_up is None:
            first_up = normal
        remaining = remaining[~inliers]
    if not found and from_pose:
        planes_tilt = _planes_tilt_deg(points, seed)
        lean = (
            f"; the cloud's planes lean {planes_tilt:.1f} degrees from it: is the pose's z up? (gravity from the "
            "planes would follow them: check the tilt it prints)"
            if planes_tilt is not None
            else f", nor does a plane within {HORIZONTAL_TOLERANCE_DEG:g} degrees of it: is the pose's z up?"
        )
        raise UnstackError(f"no level plane along the frame's z (gravity from the pose) holds 2 % of the points{lean}")
    if not found:
        raise UnstackError(
            f"no horizontal plane in the cloud (none within {HORIZONTAL_TOLERANCE_DEG:g} degrees of the frame's z "
            "holds 2 % of the points): is the camera pose right?"
        )
    # the largest plane (a floor, a deck, a layer of tops) leads; planes parallel to it within
    # PARALLEL_DEG join it, weighted by their points; a box resting tilted does not
    lead = max(found, key=lambda plane: plane[2])[0]
    noisy = noisy_planes[max(range(len(found)), key=lambda k: found[k][2])]  # the lead plane's
    parallel = [plane for plane in found if plane[0] @ lead >= np.cos(np.radians(PARALLEL_DEG))]
    up = np.sum([normal * count for normal, _, count in parallel], axis=0)
    up /= np.linalg.norm(up)
    found = parallel
    heading = np.array([-1.0, 0.0, 0.0]) if door is None else np.asarray(door, dtype=np.float64)
    if door is None and default_door is not None and not _steep(np.asarray(default_door, dtype=np.float64), up):
        heading = np.asarray(default_door, dtype=np.float64)
    if door is not None and _steep(heading, up):
        raise UnstackError(
            f"the door's direction {heading.tolist()} is within {90 - MAX_DOOR_RISE_DEG:g} degrees of the vertical "
            "the cloud shows: expected a roughly horizontal direction out through the door"
        )
    rotation = _rotation_onto_z(up, heading)
    heights = points @ up
    floor_heights = [offset / (normal @ up) for normal, offset, _ in found]
    # the lowest plane, passing over the tail of a noisy one: a plane with a quarter of its points or
    # fewer, less than NOISE_BAND under it (a far floor's noise reaches past its widest band)
    lowest = min(
        (
            k
            for k in range(len(found))
            if not any(
                0.0 < floor_heights[j] - floor_heights[k] < NOISE_BAND and found[j][2] >= 4 * found[k][2]
                for j in range(len(found))
            )
        ),
        key=lambda k: floor_heights[k],
    )
    floor_level = float(floor_heights[lowest])
    floor_inliers = found[lowest][2]
    under = heights < floor_level - NOISE_BAND
    if under.mean() > FLOOR_BELOW_SHARE and _surfaces(points, under, rng):  # a hidden floor: not under the cloud
        floor_level, floor_inliers = _lowest_level(heights), 0
    tilt = float(np.degrees(np.arccos(np.clip(up @ up_guess, -1.0, 1.0))))
    plane_heights = tuple(
        (float(height - floor_level), count) for height, (*_, count) in zip(floor_heights, found, strict=True)
    )
    planes_tilt = _planes_tilt_deg(points, seed) if from_pose else None
    return GravityFrame(
        rotation,
        np.array([0.0, 0.0, -floor_level]),
        tilt,
        len(found),
        floor_inliers,
        plane_heights,
        bool(noisy),
        gravity,
        planes_tilt,
    )


def check_gravity(gravity: Any) -> str:
    """Check where gravity is to come from: one of :data:`GRAVITY_SOURCES`, as a plain ``str``.

    Examples
    --------
    >>> check_gravity("pose")
    'pose'
    """
    if not isinstance(gravity, str) or str(gravity) not in GRAVITY_SOURCES:
        from unstack.errors import InvalidArgument

        raise InvalidArgument(f"gravity: expected one of {', '.join(map(repr, GRAVITY_SOURCES))}, got {gravity!r}")
    return str(gravity)


def _plane_in_cone(
    points: np.ndarray, rng: np.random.Generator, up_guess: np.ndarray, first_up: np.ndarray | None
) -> tuple[np.ndarray, float, np.ndarray, bool]:
    """The next level plane of ``points`` within :data:`HORIZONTAL_TOLERANCE_DEG` of ``up_guess``
    (the first plane's normal ``first_up`` once there is one): its normal, offset, inliers and
    whether the depth's noise filled its band."""
    normal, offset, inliers = fit_plane(points, rng=rng, near_normal=up_guess, in_cone=True)
    # depth noise grows with distance: each plane tells whether noise fills its band
    noisy = bool(inliers.sum() >= 3 and _fills_band(points, normal, offset))
    if noisy and first_up is not None:
        # a noisy plane after the first -- a far floor, noisier with distance, tops among noisy
        # sides, or in exact depth a few tops among the sides crossing them -- keeps the first's
        # direction and gives only its height, in a band as wide as its noise (searched over the
        # cone, such a plane turned gravity 25 degrees; searched within 2 degrees of a noisy
        # ceiling, slabs cutting through a dropped pile's faces turned it 2-3 degrees)
        normal = first_up
        offset, inliers = _level_within_noise(points, first_up)
    else:
        if noisy:  # the first plane, over the whole cone, by its heights
            normal, offset = plane_by_heights(points, up_guess, rng=rng)
            inliers = np.abs(points @ normal - offset) < PLANE_THRESHOLD
        if inliers.sum() >= 3:
            normal, offset, inliers = plane_within_noise(
                points, normal, offset, inliers, max_turn_deg=LEVEL_TURN_DEG, level=True
            )
        if not noisy and inliers.sum() >= 3:  # RANSAC's plane leans only on evidence
            normal, offset, inliers = _level_unless_leaning(
                points, normal, offset, inliers, up_guess if first_up is None else first_up
            )
    return normal, offset, inliers, noisy


def _steep(direction: np.ndarray, up: np.ndarray) -> bool:
    """Whether a door's ``direction`` rises or falls more than :data:`MAX_DOOR_RISE_DEG` against ``up``
    (a zero vector is steep: it points nowhere)."""
    length = float(np.linalg.norm(direction))
    return not length > 0 or bool(abs(direction @ up) > np.sin(np.radians(MAX_DOOR_RISE_DEG)) * length)


def _planes_tilt_deg(points: np.ndarray, seed: int) -> float | None:
    """How far the level planes turn up from the frame's z (``None`` where they find no plane;
    the door is left out: it turns the frame about up, not up)."""
    try:
        return gravity_frame(points, seed=seed).tilt_deg
    except UnstackError:
        return None
