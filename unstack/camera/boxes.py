"""One box per instance mask: top plane, yaw from the top face, size from the known cartons.

For each mask (points already in the gravity frame, z up, floor at 0):

* the **top face** is the highest horizontal plane among the mask's points (RANSAC with the
  normal within :data:`~unstack.camera.planes.HORIZONTAL_TOLERANCE_DEG` of z); its height is
  the box's top;
* the **yaw** and the top's extents come from the minimum-area rectangle around the top
  face's points (the convex hull's edges, rotating calipers), the long edge on the long
  extent, leaving out points that stand apart (:data:`STRAY_SPREAD`: a time-of-flight sensor's
  flying pixels along the edges);
* the **size** is matched to the known carton sizes (any edge may stand vertical): the known
  size whose top edges are closest to the rectangle, ties to the one whose bottom lands nearest
  a surface (the floor or another box's top), never one whose bottom would sink under the floor
  while another does not; without known sizes, the rectangle and the height down to the
  surface below;
* the **residual** is the RMS distance of the top points to the fitted top plane, and the
  **fill** the share of the rectangle the top points cover;
* a mask whose pixels are mostly (:data:`DUPLICATE_SHARE`) inside another, larger mask is a
  **duplicate** detection: reported and left out.

A mask that shows no top face (a box above the camera, seen from the front) is fitted from
its front face instead: the vertical plane's normal gives the yaw, the face its width and
height, the known size its depth.

A box lying **tilted** (its faces :data:`TILT_MIN_DEG` or more from level and plumb, as boxes
dropped on others rest) is fitted in full 3-D: up to three planes of the mask's points are its
visible faces, the largest face's normal and a second face square to it (or the smallest
rectangle around the largest face) give its axes, the known size nearest the faces' edges its
size, and each seen face fixes where the box ends on that axis (the box lies behind it, away
from the camera).

Examples
--------
>>> rng = np.random.default_rng(0)
>>> top = np.column_stack([rng.uniform(-0.2, 0.2, 400), rng.uniform(-0.15, 0.15, 400), np.full(400, 0.3)])
>>> fitted = fit_box("b00", top, known_sizes=[(0.4, 0.3, 0.3)], surfaces=[0.0], rng=rng)
>>> [round(float(value), 2) for value in fitted.box.size], round(float(fitted.box.position[2]), 2)
([0.4, 0.3, 0.3], 0.15)
"""

from __future__ import annotations

import dataclasses
import zlib
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from unstack.camera.planes import PLANE_THRESHOLD, fit_plane, plane_within_noise
from unstack.errors import InvalidFile, UnstackError
from unstack.scene import Box

__all__ = [
    "DUPLICATE_SHARE",
    "FittedBox",
    "boxes_from_masks",
    "content_rng",
    "duplicate_masks",
    "fit_box",
    "merged_masks",
    "min_area_rectangle",
]

#: A mask with at least this share of its pixels inside a larger mask is a duplicate; a mask
#: holding two or more masks this way that are not duplicates of each other is a detection of
#: several boxes (or of none: a whole-image mask).
DUPLICATE_SHARE = 0.5
#: Fewer points than this on a mask's top face (or front face) cannot be fitted.
MIN_FACE_POINTS = 30
#: A mask is fitted from its top face when the top plane holds at least this share of its points.
TOP_SHARE = 0.15
#: A face covering less than this share of its rectangle was seen in part ...
PARTIAL_FILL = 0.8
#: ... as was one whose matched size reaches more than this beyond its measured edges (metres).
PARTIAL_EDGE = 0.03
#: An edge measured longer than a known size's costs this many times one measured shorter.
OVERSIZE_WEIGHT = 4.0
#: Known sizes whose top edges differ from the rectangle's by less than this (metres, summed)
#: are ties, decided by where the bottom lands.
SIZE_TIE = 0.02
#: A box whose axes are tilted at least this far from upright (degrees) is fitted in full 3-D
#: from its faces (:func:`fit_box`); below it, upright from its top or front face.
TILT_MIN_DEG = 5.0
#: Faces of a tilted box: planes holding at least this share of the mask's points ...
TILTED_FACE_SHARE = 0.1
#: ... whose normal is within this many degrees of square to the first face's (a second face).
SQUARE_TOLERANCE_DEG = 20.0
#: A level plane under the rest of a mask's points, holding less than this share of them, is a
#: surface the mask bled onto (left out).
BLEED_SHARE = 0.35
#: Depth noise moves a top's points along the camera's rays, and a door camera sees tops at a
#: grazing angle: the points stay in the face's band but spread centimetres past its edges. An
#: edge whose outer points lie this many times sparser than the face's (third-neighbour distances)
#: is put where the points' density falls to half of that just inside it; a sharp edge (exact
#: depth, or a top cut off by a box in front) is kept.
BLURRED_EDGE_SPARSITY = 1.2
#: The density profile along a top's edges is counted in bins this wide at least (metres), or the
#: points' spacing.
EDGE_BIN_M = 0.005
#: A point whose third nearest neighbour is this many times further than the median is a stray
#: (a flying pixel), left out of a top's rectangle and of a tilted box's extents.
STRAY_SPREAD = 3.0
#: A box seen in part whose centre moves more than this (metres) between two random draws of its
#: points' planes is not settled by them (:attr:`FittedBox.unsure_m`).
UNSURE_FIT_M = 0.05
#: Where no viewpoint is given, faces are taken to look this way (out through the door and up).
DEFAULT_VIEW = (-1.0, 0.0, 1.0)


@dataclass(frozen=True)
class FittedBox:
    """A box fitted to one mask, with how well it fits.

    Returned by :func:`fit_box`; :func:`boxes_from_masks` keeps one per mask it does not drop
    as a duplicate, and the fit measures below are what the camera input reports per box.

    Attributes
    ----------
    box : Box
    face : {"top", "front", "tilted"}
        The face it was fitted from ("tilted": in full 3-D from the faces of a box lying tilted).
    residual_m : float
        RMS distance of the face's points to the fitted face plane.
    fill : float
        Share of the fitted face rectangle its points cover (0-1; low for a partly hidden face).
    size_error_m : float
        Summed difference between the face's measured edges and the matched known size's.
    points : int
        Points of the mask.
    partial : bool
        The face was seen in part (it covers less than :data:`PARTIAL_FILL` of its rectangle,
        or the matched size reaches more than :data:`PARTIAL_EDGE` beyond what was seen): the
        centre is placed from the part seen and may be off by up to the missing length.
    unsure_m : float
        For a box seen in part: how far its centre moves when its points are fitted again with
        other random draws (RANSAC's planes; :func:`boxes_from_masks`), or its longest edge when
        the second fit finds no box; 0 for a box seen whole. Over :data:`UNSURE_FIT_M` the points
        do not settle the box's pose.
    """

    box: Box
    face: str
    residual_m: float
    fill: float
    size_error_m: float
    points: int
    partial: bool = False
    unsure_m: float = 0.0

    def to_dict(self) -> dict[str, Any]:
        return {
            "id": self.box.id,
            "face": self.face,
            "residual_m": self.residual_m,
            "fill": self.fill,
            "size_error_m": self.size_error_m,
            "points": self.points,
            "partial": self.partial,
            "unsure_m": self.unsure_m,
        }


def min_area_rectangle(xy: np.ndarray) -> tuple[np.ndarray, float, np.ndarray]:
    """The smallest-area rectangle around 2-D points: centre, angle of its long edge, (long, short).

    Examples
    --------
    >>> corners = np.array([[0.0, 0.0], [0.4, 0.0], [0.4, 0.2], [0.0, 0.2]])
    >>> centre, angle, extents = min_area_rectangle(corners)
    >>> centre.round(2).tolist(), round(angle, 3), extents.round(2).tolist()
    ([0.2, 0.1], 0.0, [0.4, 0.2])
    """
    from scipy.spatial import ConvexHull, QhullError

    xy = np.asarray(xy, dtype=np.float64)
    try:
        hull = xy[ConvexHull(xy).vertices]
    except (QhullError, ValueError):
        hull = xy
    edges = np.diff(np.vstack([hull, hull[:1]]), axis=0)
    angles = np.unique(np.mod(np.arctan2(edges[:, 1], edges[:, 0]), np.pi / 2))
    best: tuple[float, np.ndarray, float, np.ndarray] | None = None
    for angle in angles:
        axes = np.array([[np.cos(angle), np.sin(angle)], [-np.sin(angle), np.cos(angle)]])
        local = hull @ axes.T
        low, high = local.min(axis=0), local.max(axis=0)
        area = float(np.prod(high - low))
        if best is None or area < best[0]:
            best = (area, (low + high) / 2 @ axes, float(angle), high - low)
    assert best is not None
    _, centre, angle, extents = best
    if extents[1] > extents[0]:
        angle += np.pi / 2
        extents = extents[::-1]
    angle = float(np.mod(angle + np.pi / 2, np.pi) - np.pi / 2)  # the long edge's direction, in (-90, 90] degrees
    return np.asarray(centre), angle, np.asarray(extents)


def _yaw_quaternion(yaw: float) -> np.ndarray:
    return np.array([0.0, 0.0, np.sin(yaw / 2), np.cos(yaw / 2)])


def _match_size(
    top_edges: np.ndarray,
    top: float,
    known_sizes: Sequence[Sequence[float]],
    surfaces: Sequence[float],
    seen_height: float = 0.0,
) -> tuple[np.ndarray, float, bool]:
    """The known size nearest the measured top edges; ties to a size at least as tall as the
    front face shows (``seen_height``, less :data:`PARTIAL_EDGE`), then by where the bottom lands
    (to the centimetre), then by the edges, then by the size: not by the order of ``known_sizes``.

    A face seen in part is smaller than the box, never larger: an edge measured longer than a
    size's costs :data:`OVERSIZE_WEIGHT` times as much as one measured shorter. Returns the size
    as (along the measured long edge, across it, height), the error, and whether the size's long
    edge lies across the measured long edge (a face seen in part can show a box's short edge as
    its longer extent).
    """
    options: list[tuple[float, float, np.ndarray, bool]] = []
    for size in known_sizes:
        edges = np.asarray(size, dtype=np.float64)
        for vertical in range(3):
            height = edges[vertical]
            across = np.sort(np.delete(edges, vertical))[::-1]
            landing = min(abs(top - height - surface) for surface in surfaces) if surfaces else 0.0
            if top - height < -PLANE_THRESHOLD * 3:
                landing += 10.0  # the bottom would lie under the floor
            for turned in (False, True):
                placed = across[::-1] if turned else across
                difference = top_edges - placed
                error = float(np.sum(np.where(difference > 0, OVERSIZE_WEIGHT * difference, -difference)))
                options.append((error, landing, np.array([*placed, height]), turned))
    # a size that puts the bottom under the floor is taken only when every size does: edges
    # measured long (flying pixels, depth noise) otherwise pick a taller box sunk into the floor
    options = [option for option in options if option[1] < 10.0] or options
    best_error = min(option[0] for option in options)
    tied = [option for option in options if option[0] <= best_error + SIZE_TIE]
    # as tall as the front shows, where the bottom lands, the nearer top edges, the size itself:
    # never the order given
    chosen = min(
        tied,
        key=lambda option: (
            bool(option[2][2] < seen_height - PARTIAL_EDGE),
            round(option[1], 2),
            option[0],
            tuple(option[2]),
            option[3],
        ),
    )
    return np.asarray(chosen[2], dtype=np.float64), float(chosen[0]), chosen[3]


def _front_face(
    points: np.ndarray, rng: np.random.Generator, min_share: float = 0.0
) -> tuple[np.ndarray, float, np.ndarray] | None:
    """The vertical face turned towards the door (-x) among ``points``: normal, offset, inliers
    (None unless it holds :data:`MIN_FACE_POINTS` and ``min_share`` of the points)."""
    if len(points) < MIN_FACE_POINTS:
        return None
    normal, offset, inliers = fit_plane(points, rng=rng, near_normal=np.array([-1.0, 0.0, 0.0]), tolerance_deg=75.0)
    if inliers.sum() < max(MIN_FACE_POINTS, min_share * len(points)) or abs(normal[2]) > np.sin(np.radians(25.0)):
        return None
    return normal, offset, inliers


def fit_box(
    box_id: str,
    points: np.ndarray,
    *,
    known_sizes: Sequence[Sequence[float]] | None,
    surfaces: Sequence[float],
    rng: np.random.Generator,
    viewpoint: Sequence[float] | None = None,
) -> FittedBox:
    """Fit one box to a mask's points (gravity frame); see the module docstring.

    ``viewpoint``: where the camera stands (gravity frame), the side a tilted box's seen faces
    look to; default: out through the door and up (:data:`DEFAULT_VIEW`).
    """
    points = np.asarray(points, dtype=np.float64)
    if len(points) < MIN_FACE_POINTS:
        raise UnstackError(
            f"{box_id}: the mask holds {len(points)} points with depth; at least {MIN_FACE_POINTS} needed"
        )
    up = np.array([0.0, 0.0, 1.0])
    points = _without_surface_below(points, rng.spawn(1)[0])
    normal, offset, inliers = fit_plane(points, rng=rng, near_normal=up)
    top_seen = bool(inliers.sum() >= max(MIN_FACE_POINTS, TOP_SHARE * len(points)))
    if top_seen and normal @ up >= np.cos(np.radians(TILT_MIN_DEG)):
        return _fit_from_top(box_id, points, normal, offset, inliers, known_sizes, surfaces, rng)
    # the tilted fit draws from a child generator: the upright fits below draw as they would without it
    tilted = _fit_tilted(box_id, points, known_sizes, rng.spawn(1)[0], viewpoint, surfaces)
    if tilted is not None:
        return tilted
    if top_seen:
        return _fit_from_top(box_id, points, normal, offset, inliers, known_sizes, surfaces, rng)
    return _fit_from_front(box_id, points, known_sizes, rng, viewpoint)


def _without_surface_below(points: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """The mask's points without those on a level surface under the box (a mask that bleeds a
    pixel or two onto the floor or the box below): a level plane holding under
    :data:`BLEED_SHARE` of the points with half of them or more above it and almost none below."""
    normal, offset, inliers = fit_plane(points, rng=rng, near_normal=np.array([0.0, 0.0, 1.0]))
    if not inliers.any() or inliers.mean() > BLEED_SHARE or normal[2] < np.cos(np.radians(TILT_MIN_DEG)):
        return points
    heights = points @ normal - offset
    under_the_rest = np.mean(heights > 0.03) >= 0.5 and np.mean(heights < -0.03) <= 0.02
    if not under_the_rest or len(points) - inliers.sum() < MIN_FACE_POINTS:
        return points
    kept: np.ndarray = points[~inliers]
    return kept


def _tilted_axes(
    points: np.ndarray, rng: np.random.Generator, toward: np.ndarray
) -> tuple[np.ndarray, list[tuple[int, float, float, np.ndarray]]] | None:
    """A tilted box's axes (rows, right-handed) from the planes of its points, and its seen faces
    as ``(axis, side, place, inliers)``: the box lies from ``place`` along the axis towards
    ``side`` (+1 or -1), away from ``toward`` (a point: the camera); None when no face holds
    :data:`TILTED_FACE_SHARE` of the points."""
    remaining = np.ones(len(points), dtype=bool)
    planes: list[tuple[np.ndarray, float, np.ndarray]] = []
    while len(planes) < 3 and remaining.sum() >= MIN_FACE_POINTS:
        normal, offset, inliers = fit_plane(points[remaining], rng=rng)
        if inliers.sum() >= 3:
            normal, offset, inliers = plane_within_noise(points[remaining], normal, offset, inliers)
        if inliers.sum() < max(MIN_FACE_POINTS, TILTED_FACE_SHARE * len(points)):
            break
        where = np.flatnonzero(remaining)[inliers]
        face = np.zeros(len(points), dtype=bool)
        face[where] = True
        if normal @ (toward - points[face].mean(axis=0)) < 0:
            normal, offset = -normal, -offset
        planes.append((normal, offset, face))
        remaining &= ~face
    if not planes:
        return None
    first = planes[0][0]
    square = [plane for plane in planes[1:] if abs(plane[0] @ first) < np.sin(np.radians(SQUARE_TOLERANCE_DEG))]
    if square:
        second = square[0][0] - (square[0][0] @ first) * first
    else:  # one face: its smallest rectangle gives the other two axes
        helper = np.array([0.0, 0.0, 1.0]) if abs(first[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
        u = np.cross(first, helper)
        u /= np.linalg.norm(u)
        v = np.cross(first, u)
        face_points = points[planes[0][2]]
        _, angle, _ = min_area_rectangle(np.column_stack([face_points @ u, face_points @ v]))
        second = np.cos(angle) * u + np.sin(angle) * v
    second /= np.linalg.norm(second)
    axes = np.vstack([first, second, np.cross(first, second)])
    seen: list[tuple[int, np.ndarray, np.ndarray]] = [(0, first, planes[0][2])]
    for normal, _, face in planes[1:]:
        axis = int(np.argmax(np.abs(axes @ normal)))
        if axis != 0 and abs(axes[axis] @ normal) >= np.cos(np.radians(SQUARE_TOLERANCE_DEG)):
            seen.append((axis, normal, face))
    # each seen face: its axis, which way the box lies from it along that axis (against the face's
    # normal, which looks at the camera), and where the face is along it
    faces = [
        (axis, -float(np.sign(axes[axis] @ normal)), float(np.median(points[face] @ axes[axis])), face)
        for axis, normal, face in seen
    ]
    return axes, faces


def _match_tilted_sizes(
    extents: np.ndarray, observed: np.ndarray, known_sizes: Sequence[Sequence[float]] | None
) -> list[np.ndarray]:
    """The box's possible sizes along its three axes: the known sizes (in any of their six turns)
    nearest the extents measured along the ``observed`` axes (a longer measure costs
    :data:`OVERSIZE_WEIGHT` times a shorter), several when they differ only along an axis no face
    shows (in the order of their edges, not of ``known_sizes``); without known sizes, the
    measured extents, and an axis no face shows as deep as the shorter seen one."""
    if not known_sizes:
        seen = extents[observed]
        depth = float(seen.min()) if len(seen) else float(extents.max())
        return [np.where(observed, extents, depth)]
    options: list[tuple[float, tuple[float, ...]]] = []
    for size in known_sizes:
        for turn in ((0, 1, 2), (0, 2, 1), (1, 0, 2), (1, 2, 0), (2, 0, 1), (2, 1, 0)):
            placed = np.asarray(size, dtype=np.float64)[list(turn)]
            difference = (extents - placed)[observed]
            error = float(np.sum(np.where(difference > 0, OVERSIZE_WEIGHT * difference, -difference)))
            options.append((error, tuple(float(edge) for edge in placed)))
    best = min(error for error, _ in options)
    return [np.array(placed) for placed in sorted({placed for error, placed in options if error <= best + 1e-12})]


def _lowest_landing(size: np.ndarray, position: np.ndarray, axes: np.ndarray, surfaces: Sequence[float]) -> float:
    """How far a tilted box's lowest corner lies from the nearest surface (the floor or another
    box's top); under the floor costs 10 more, as for the upright fits (:func:`_match_size`)."""
    lowest = float(position[2] - 0.5 * np.abs(axes[:, 2]) @ size)
    landing = min((abs(lowest - surface) for surface in surfaces), default=0.0)
    return landing + (10.0 if lowest < -PLANE_THRESHOLD * 3 else 0.0)


def _fit_tilted(
    box_id: str,
    points: np.ndarray,
    known_sizes: Sequence[Sequence[float]] | None,
    rng: np.random.Generator,
    viewpoint: Sequence[float] | None,
    surfaces: Sequence[float] = (0.0,),
) -> FittedBox | None:
    """A box fitted in full 3-D from its seen faces; None when it stands within
    :data:`TILT_MIN_DEG` of upright (the upright fits are better there) or shows no face.

    Known sizes that fit the seen faces alike but differ in a depth no face shows are told
    apart by where the box's lowest corner lands (the floor or another box's top), then by the
    smaller; such a box is seen in part."""
    from scipy.spatial.transform import Rotation

    centroid = points.mean(axis=0)
    toward = np.asarray(viewpoint, dtype=np.float64) if viewpoint is not None else centroid + np.asarray(DEFAULT_VIEW)
    found = _tilted_axes(points, rng, toward)
    if found is None:
        return None
    axes, faces = found
    if np.max(np.abs(axes[:, 2])) >= np.cos(np.radians(TILT_MIN_DEG)):
        return None
    local = points @ axes.T
    # the extents from the points on the seen faces or among others: not from flying pixels, which
    # stand apart behind the box's edges
    kept = np.any([face for *_, face in faces], axis=0) | ~_strays(points)
    low, high = np.percentile(local[kept], 1, axis=0), np.percentile(local[kept], 99, axis=0)
    first = local[faces[0][3]]
    spacing = _spacing(first[:, 1:])
    extents = high - low + spacing
    observed = np.ones(3, dtype=bool)
    observed[0] = len(faces) > 1  # the depth behind the first face shows only on another face
    seen_faces = {axis: (side, place) for axis, side, place, _ in faces}
    view = (toward - centroid) / max(float(np.linalg.norm(toward - centroid)), 1e-9)

    def centre_of(size: np.ndarray) -> np.ndarray:
        centre = np.empty(3)
        for axis in range(3):
            if axis in seen_faces:  # the box lies behind its seen face
                side, place = seen_faces[axis]
                centre[axis] = place + side * size[axis] / 2
            elif axes[axis] @ view > 0.2:  # the end nearer the camera is the one seen
                centre[axis] = high[axis] + spacing / 2 - size[axis] / 2
            elif axes[axis] @ view < -0.2:
                centre[axis] = low[axis] - spacing / 2 + size[axis] / 2
            else:
                centre[axis] = (low[axis] + high[axis]) / 2
        return centre

    sizes = _match_tilted_sizes(extents, observed, known_sizes)
    size = min(
        sizes, key=lambda size: (_lowest_landing(size, centre_of(size) @ axes, axes, surfaces), float(np.prod(size)))
    )
    centre = centre_of(size)
    across = size[1:] - extents[1:]  # the largest face's two edges, as the upright fits report
    size_error = float(np.sum(np.where(across < 0, -OVERSIZE_WEIGHT * across, across))) if known_sizes else 0.0
    residual = float(np.sqrt(np.mean((first[:, 0] - faces[0][2]) ** 2)))
    face_extents = np.array([extents[1], extents[2]])
    fill = _fill(first[:, 1:], (low[1:] + high[1:]) / 2, 0.0, face_extents)
    partial = fill < PARTIAL_FILL or bool(np.any((size - extents)[observed] > PARTIAL_EDGE)) or len(sizes) > 1
    quaternion = Rotation.from_matrix(axes.T).as_quat()
    box = Box(box_id, size, centre @ axes, quaternion)
    return FittedBox(box, "tilted", residual, fill, size_error, len(points), partial)


def _fit_from_top(
    box_id: str,
    points: np.ndarray,
    normal: np.ndarray,
    offset: float,
    inliers: np.ndarray,
    known_sizes: Sequence[Sequence[float]] | None,
    surfaces: Sequence[float],
    rng: np.random.Generator,
) -> FittedBox:
    face = points[inliers]
    face = face[~_strays(face[:, :2])]
    top = float(np.median(face[:, 2]))
    residual = float(np.sqrt(np.mean((face @ normal - offset) ** 2)))
    centre, yaw, extents = min_area_rectangle(face[:, :2])
    extents = extents + _spacing(face[:, :2])  # pixel samples stop half a spacing short of each edge
    centre, extents = _unblurred(face[:, :2], centre, yaw, extents)
    front = _front_face(points[~inliers], rng, TOP_SHARE)
    seen_height = 0.0
    if front is not None:
        front_heights = points[~inliers][front[2], 2]
        if np.max(front_heights) >= top - 0.03:  # a face up to the top: the box is at least this tall
            seen_height = top - float(np.percentile(front_heights, 5))
        if np.percentile(front_heights, 95) < top - 0.03:
            front = None  # points below the top that do not reach it: another surface seen past the edge
    below = [surface for surface in surfaces if surface < top - 0.02]
    turned = False
    if known_sizes:
        # the front face's height only breaks ties among near sizes: a mask that bleeds onto the box
        # below continues its side in the same plane, so it is no hard bound
        size, size_error, turned = _match_size(extents, top, known_sizes, below or [0.0], seen_height)
    else:
        support = max(below, default=0.0)
        size, size_error = np.array([*extents, max(top - support, seen_height, 0.02)]), 0.0
    fill = _fill(face[:, :2], centre, yaw, extents)
    axes = np.array([[np.cos(yaw), np.sin(yaw)], [-np.sin(yaw), np.cos(yaw)]])  # rows: the measured long, short
    if front is not None:  # the box's near face lies on the front face; the rest of it is hidden beyond
        toward = front[0][:2] / np.linalg.norm(front[0][:2])  # out of the box, towards the door
        along = int(np.argmax(np.abs(axes @ toward)))
        direction = axes[along] * np.sign(axes[along] @ toward)
        near_now = min(float(np.max((face[:, :2] - centre) @ direction)), extents[along] / 2)  # a blurred edge
        centre = centre + direction * (near_now - size[along] / 2)
    if turned:
        yaw += np.pi / 2
        size = np.array([size[1], size[0], size[2]])
    partial = fill < PARTIAL_FILL or bool(np.any(np.sort(size[:2])[::-1] - extents > PARTIAL_EDGE))
    box = Box(box_id, size, [centre[0], centre[1], top - size[2] / 2], _yaw_quaternion(yaw))
    return FittedBox(box, "top", residual, fill, size_error, len(points), partial)


def _unblurred(xy: np.ndarray, centre: np.ndarray, yaw: float, extents: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The rectangle ``(centre, extents)`` of a top's points ``xy`` with each edge that depth noise
    blurred moved in (see :data:`BLURRED_EDGE_SPARSITY`)."""
    from scipy.spatial import cKDTree

    axes = np.array([[np.cos(yaw), np.sin(yaw)], [-np.sin(yaw), np.cos(yaw)]])
    local = (xy - centre) @ axes.T
    crowding = cKDTree(xy).query(xy, k=4)[0][:, 3]
    sparse_from = BLURRED_EDGE_SPARSITY * float(np.median(crowding))
    width = max(EDGE_BIN_M, _spacing(xy))
    lows, highs = -extents / 2, extents / 2
    for k in range(2):
        counts, edges = np.histogram(
            local[:, k], bins=max(4, int(np.ceil(extents[k] / width))), range=(lows[k], highs[k])
        )
        n = len(counts)
        if n < 8:
            continue
        skip, band = max(1, n // 10), max(3, n // 4)
        inside = (float(np.median(counts[skip : skip + band])), float(np.median(counts[n - skip - band : n - skip])))
        low = 0
        while low < n // 2 and counts[low] < 0.5 * inside[0]:
            low += 1
        beyond = local[:, k] < edges[low]
        if low >= 2 and beyond.sum() >= 3 and np.median(crowding[beyond]) > sparse_from:
            lows[k] = edges[low]
        high = n - 1
        while high > n // 2 and counts[high] < 0.5 * inside[1]:
            high -= 1
        beyond = local[:, k] > edges[high + 1]
        if n - 1 - high >= 2 and beyond.sum() >= 3 and np.median(crowding[beyond]) > sparse_from:
            highs[k] = edges[high + 1]
    return centre + (lows + highs) / 2 @ axes, highs - lows


def _strays(flat: np.ndarray) -> np.ndarray:
    """Which points stand apart from the rest (a face's in its plane, or a mask's in 3-D): their
    third nearest neighbour lies more than :data:`STRAY_SPREAD` times the median third-neighbour
    distance away. Flying pixels -- a time-of-flight sensor's readings that mix a box's edge with
    what lies behind it -- stand apart along their rays, one pixel wide."""
    from scipy.spatial import cKDTree

    if len(flat) < 8:
        return np.zeros(len(flat), dtype=bool)
    distances, _ = cKDTree(flat).query(flat, k=4)
    third = distances[:, 3]
    strays: np.ndarray = third > STRAY_SPREAD * max(float(np.median(third)), 1e-9)
    return strays


def _spacing(xy: np.ndarray) -> float:
    """The median distance between neighbouring points (the pixels' footprint on the face)."""
    from scipy.spatial import cKDTree

    if len(xy) < 2:
        return 0.0
    distances, _ = cKDTree(xy).query(xy, k=2)
    return float(np.median(distances[:, 1]))


def _fill(xy: np.ndarray, centre: np.ndarray, yaw: float, extents: np.ndarray) -> float:
    """Share of the rectangle's cells holding a point (cells of 2 cm, or twice the points' spacing)."""
    cell = max(0.02, 2.0 * _spacing(xy))
    axes = np.array([[np.cos(yaw), np.sin(yaw)], [-np.sin(yaw), np.cos(yaw)]])
    local = (xy - centre) @ axes.T + extents / 2
    bins = np.maximum(1, np.ceil(extents / cell)).astype(int)
    index = np.clip((local / extents * bins).astype(int), 0, bins - 1)
    occupied = len(np.unique(index[:, 0] * bins[1] + index[:, 1]))
    return float(occupied / (bins[0] * bins[1]))


def _fit_from_front(
    box_id: str,
    points: np.ndarray,
    known_sizes: Sequence[Sequence[float]] | None,
    rng: np.random.Generator,
    viewpoint: Sequence[float] | None = None,
) -> FittedBox:
    """A box seen from the front only: its vertical face gives yaw, width and height; the box
    lies behind the face as seen from ``viewpoint`` (default: out through the door and up,
    :data:`DEFAULT_VIEW`)."""
    front = _front_face(points, rng)
    if front is None:
        raise UnstackError(f"{box_id}: neither a top face nor a front face could be fitted to the mask's points")
    normal, offset, inliers = front
    face = points[inliers]
    horizontal = np.array([normal[0], normal[1], 0.0])
    horizontal /= np.linalg.norm(horizontal)
    centre_face = face.mean(axis=0)
    toward = np.asarray(viewpoint, dtype=np.float64) if viewpoint is not None else centre_face + DEFAULT_VIEW
    if horizontal @ (toward - centre_face) < 0:  # the face looks towards the camera; the box lies behind it
        horizontal = -horizontal
    across = np.array([-horizontal[1], horizontal[0], 0.0])
    width = float(np.ptp(face @ across))
    low, high = float(face[:, 2].min()), float(face[:, 2].max())
    residual = float(np.sqrt(np.mean((face @ normal - offset) ** 2)))
    depths: set[float] = set()
    if known_sizes:
        seen = np.array([width, high - low])  # across and up: a face standing the other way up is another face
        options = []
        for known in known_sizes:
            for a, b, c in _faces(known):
                difference = seen - (a, b)
                error = float(np.sum(np.where(difference > 0, OVERSIZE_WEIGHT * difference, -difference)))
                options.append((error, a, b, c))
        best_error = min(option[0] for option in options)
        tied = [option for option in options if option[0] <= best_error + 1e-12]
        # sizes that share the seen face differ in the depth behind it, which nothing shows: the
        # deeper (it may hold up more behind), never the order of ``known_sizes``; seen in part
        size_error, face_width, face_height, depth = max(tied, key=lambda option: (option[3], option[1], option[2]))
        depths = {option[3] for option in tied}
    else:
        size_error, face_width, face_height, depth = 0.0, width, high - low, width
    face_centre = centre_face - (centre_face @ across - (face @ across).min() - width / 2) * across
    centre = face_centre - horizontal * depth / 2
    yaw = float(np.arctan2(horizontal[1], horizontal[0]))
    size = np.array([depth, face_width, face_height])
    box = Box(box_id, size, [centre[0], centre[1], low + face_height / 2], _yaw_quaternion(yaw))
    partial = bool(face_width - width > PARTIAL_EDGE or face_height - (high - low) > PARTIAL_EDGE or len(depths) > 1)
    return FittedBox(box, "front", residual, 1.0, float(size_error), len(points), partial)


def _faces(size: Sequence[float]) -> list[tuple[float, float, float]]:
    """(face width, face height, depth) for each way a carton can show its front."""
    a, b, c = (float(value) for value in size)
    return [(a, b, c), (b, a, c), (a, c, b), (c, a, b), (b, c, a), (c, b, a)]


def duplicate_masks(masks: Sequence[np.ndarray]) -> dict[int, int]:
    """Masks mostly inside a larger one: ``{duplicate index: the larger mask's index}``; a mask
    that holds several boxes (:func:`merged_masks`) is nobody's original and nobody's duplicate.

    Examples
    --------
    >>> big = np.zeros((4, 4), bool); big[:3, :3] = True
    >>> small = np.zeros((4, 4), bool); small[1:3, 1:3] = True
    >>> other = np.zeros((4, 4), bool); other[3, 3] = True
    >>> duplicate_masks([big, small, other])
    {1: 0}
    >>> duplicate_masks([np.ones((4, 4), bool), big, other])  # the whole image holds two boxes
    {}
    """
    inside = _Containment(masks)
    merged = merged_masks(masks)
    duplicates = {}
    for k in range(len(masks)):
        if k in merged:
            continue
        for j in range(len(masks)):
            if j == k or j in merged or j in duplicates or not inside.larger(j, k):
                continue
            if inside(k, j):
                duplicates[k] = j
                break
    return duplicates


def merged_masks(masks: Sequence[np.ndarray]) -> dict[int, list[int]]:
    """Masks holding most of two or more smaller masks that are not duplicates of each other (a
    detection of several boxes, or a whole-image mask): ``{index: the masks it holds}``.

    Examples
    --------
    >>> left = np.zeros((4, 4), bool); left[:, :2] = True
    >>> right = np.zeros((4, 4), bool); right[:, 2:] = True
    >>> merged_masks([np.ones((4, 4), bool), left, right])
    {0: [1, 2]}
    """
    inside = _Containment(masks)
    merged = {}
    for j in range(len(masks)):
        held = [k for k in range(len(masks)) if inside.areas[k] < inside.areas[j] and inside(k, j)]
        apart = [k for n, k in enumerate(held) if not any(inside(k, m) or inside(m, k) for m in held[:n])]
        if len(apart) >= 2:
            merged[j] = held
    return merged


class _Containment:
    """Whether most of one mask lies in another (at least :data:`DUPLICATE_SHARE` of its
    pixels), counted only where the two masks' bounding boxes meet."""

    def __init__(self, masks: Sequence[np.ndarray]) -> None:
        self.masks = masks
        self.areas = [int(mask.sum()) for mask in masks]
        self.bounds = []
        for mask in masks:
            rows, columns = np.flatnonzero(mask.any(axis=1)), np.flatnonzero(mask.any(axis=0))
            empty = len(rows) == 0
            self.bounds.append((0, 0, 0, 0) if empty else (rows[0], rows[-1] + 1, columns[0], columns[-1] + 1))

    def larger(self, j: int, k: int) -> bool:
        """Mask ``j`` comes before ``k`` by area (ties: the first given)."""
        return self.areas[j] > self.areas[k] or (self.areas[j] == self.areas[k] and j < k)

    def __call__(self, k: int, j: int) -> bool:
        """Most of mask ``k`` lies in mask ``j``."""
        top, bottom = max(self.bounds[k][0], self.bounds[j][0]), min(self.bounds[k][1], self.bounds[j][1])
        left, right = max(self.bounds[k][2], self.bounds[j][2]), min(self.bounds[k][3], self.bounds[j][3])
        if top >= bottom or left >= right:
            return False
        shared = (self.masks[k][top:bottom, left:right] & self.masks[j][top:bottom, left:right]).sum()
        return bool(shared >= DUPLICATE_SHARE * self.areas[k]) and self.areas[k] > 0


def content_rng(seed: int, values: np.ndarray, stream: int = 0) -> np.random.Generator:
    """A generator seeded by ``seed`` and the bytes of ``values``: the same values draw the same
    numbers wherever they stand among others (``stream`` > 0: another, independent generator of them).

    Examples
    --------
    >>> points = np.arange(6.0).reshape(2, 3)
    >>> content_rng(0, points).random() == content_rng(0, points.copy()).random()
    True
    >>> content_rng(0, points).random() == content_rng(0, points + 1.0).random()
    False
    """
    key = zlib.crc32(np.ascontiguousarray(values).tobytes())
    return np.random.default_rng([int(seed), key] if stream == 0 else [int(seed), key, int(stream)])


def _moved_by_redraw(
    fit: FittedBox,
    points: np.ndarray,
    known_sizes: Sequence[Sequence[float]] | None,
    surfaces: Sequence[float],
    rng: np.random.Generator,
    viewpoint: Sequence[float] | None,
) -> float:
    """How far ``fit``'s centre moves when ``points`` are fitted again from ``rng`` (its longest
    edge when that fit finds no box)."""
    try:
        again = fit_box(fit.box.id, points, known_sizes=known_sizes, surfaces=surfaces, rng=rng, viewpoint=viewpoint)
    except (UnstackError, InvalidFile):
        return float(np.max(fit.box.size))
    return float(np.linalg.norm(again.box.position - fit.box.position))


def boxes_from_masks(
    mask_points: Sequence[np.ndarray],
    ids: Sequence[str],
    *,
    known_sizes: Sequence[Sequence[float]] | None = None,
    seed: int = 0,
    viewpoint: Sequence[float] | None = None,
    levels: Sequence[float] = (),
) -> tuple[list[FittedBox], dict[str, str]]:
    """Fit a box to each mask's points (gravity frame); bottoms land on the floor or other tops.

    Returns the fitted boxes and, for each mask that could not be fitted, why. Each mask's
    RANSAC draws from its own generator, seeded by ``seed`` and the mask's points
    (:func:`content_rng`): a box's fit depends on its own points only, not on the masks given
    before it or their order. ``viewpoint``: the camera's place (gravity frame), see
    :func:`fit_box`. A bottom lands on the floor (z = 0), on another mask's top, or on one of
    ``levels``: the heights of level surfaces no mask holds (a pallet's deck, a shelf), as
    :attr:`~unstack.camera.planes.GravityFrame.plane_heights` gives them.
    """
    if len(mask_points) != len(ids):
        raise UnstackError(f"{len(mask_points)} masks but {len(ids)} ids")
    tops = [float(np.percentile(points[:, 2], 95)) if len(points) else 0.0 for points in mask_points]
    fitted: list[FittedBox] = []
    unfitted: dict[str, str] = {}
    for k, (box_id, points) in enumerate(zip(ids, mask_points, strict=True)):
        surfaces = [0.0, *(top for j, top in enumerate(tops) if j != k), *levels]
        try:
            rng = content_rng(seed, points)
            fit = fit_box(box_id, points, known_sizes=known_sizes, surfaces=surfaces, rng=rng, viewpoint=viewpoint)
            if fit.partial:  # a face seen in part: does another draw of its planes give the same box?
                again = content_rng(seed, points, stream=1)
                fit = dataclasses.replace(
                    fit, unsure_m=_moved_by_redraw(fit, points, known_sizes, surfaces, again, viewpoint)
                )
            fitted.append(fit)
        except InvalidFile as error:  # a box no carton is: say so of the fit, not of an array
            unfitted[box_id] = f"the fitted box's {error.json_path[2:]}: {error.message}"
        except UnstackError as error:
            unfitted[box_id] = str(error).removeprefix(f"{box_id}: ")  # the id is said where the reason is
    return fitted, unfitted
