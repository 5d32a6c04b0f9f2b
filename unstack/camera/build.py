"""A scene from a depth image, intrinsics, a camera pose and one mask per box.

Examples
--------
>>> from unstack.camera.files import Intrinsics
>>> camera = Intrinsics(fx=100.0, fy=100.0, cx=80.0, cy=60.0, width=160, height=120)
>>> depth = np.full((120, 160), 1.0); depth[39:82, 51:108] = 0.7      # a carton 0.3 m tall, seen from above
>>> looking_down = np.array([[1.0, 0, 0, 0], [0, -1.0, 0, 0], [0, 0, -1.0, 1.0], [0, 0, 0, 1.0]])
>>> mask = np.zeros((120, 160), bool); mask[39:82, 51:108] = True
>>> built = scene_from_depth(depth, camera, looking_down, [mask], known_sizes=[(0.4, 0.3, 0.3)])
>>> built.scene.detected, [round(float(v), 2) for v in built.scene.box("b00").size]
(('b00',), [0.4, 0.3, 0.3])
"""

from __future__ import annotations

import dataclasses
import warnings
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from unstack.camera.boxes import (
    UNSURE_FIT_M,
    FittedBox,
    boxes_from_masks,
    content_rng,
    duplicate_masks,
    merged_masks,
)
from unstack.camera.files import Intrinsics, check_pose
from unstack.camera.planes import (
    HORIZONTAL_TOLERANCE_DEG,
    PLANE_THRESHOLD,
    GravityFrame,
    check_gravity,
    depth_points,
    gravity_frame,
)
from unstack.checks import counted
from unstack.errors import UnstackError
from unstack.geometry import points_in_box
from unstack.scene import Box, Scene

__all__ = ["CameraScene", "scene_from_depth"]

#: Points per mask kept for fitting (a random subset of larger masks).
MAX_MASK_POINTS = 20_000
#: Cloud points kept in the scene (a random subset of larger clouds).
MAX_SCENE_POINTS = 200_000


#: Heights of a mask's points are binned this fine (metres) to find the slab of its top face.
TOP_SLAB_M = 0.03
#: A box shows its top when the fullest slab holds this share of its points or more, and this
#: many times the points of a typical slab (a strip of a front cut by the image's edge fills its
#: few slabs alike) ...
TOP_SLAB_SHARE = 0.15
SLAB_PROMINENCE = 3.0
#: ... and its points spread this far (metres, standard deviation) across their narrower
#: direction: a top, not the strip a slab cuts from a face lying tilted ...
TOP_SPREAD_M = 0.03
#: ... and says which way is up when this many times more of its other points lie on one side of
#: the slab (below: seen from above, as a camera sees tops) than on the other.
SIDE_MARGIN = 2.0


def _side_of_tops(box_points: Sequence[np.ndarray]) -> tuple[int, int]:
    """Boxes whose top slab has most of their other points below it (a top seen from above) and
    boxes whose slab has most above it (a top seen from below: the pose upside down)."""
    below_votes = above_votes = 0
    for points in box_points:
        if len(points) < 30:
            continue
        heights = points[:, 2]
        bins = np.floor(heights / TOP_SLAB_M).astype(np.int64)
        counts = np.bincount(bins - bins.min())
        fullest = int(np.argmax(counts))
        if counts[fullest] < max(TOP_SLAB_SHARE * len(points), SLAB_PROMINENCE * np.median(counts[counts > 0])):
            continue  # no level face: a front (whole, or a strip of it), or a box lying tilted
        slab = (fullest + bins.min() + 0.5) * TOP_SLAB_M
        level = points[bins - bins.min() == fullest, :2]  # the slab's own bin (a top on a bin edge)
        if np.linalg.svd(level - level.mean(axis=0), compute_uv=False)[-1] / np.sqrt(len(level)) < TOP_SPREAD_M:
            continue  # a strip, not a face: a slice through a face lying tilted
        below = int(np.sum(heights < slab - TOP_SLAB_M))
        above = int(np.sum(heights > slab + TOP_SLAB_M))
        if below >= 10 and below >= SIDE_MARGIN * above:
            below_votes += 1
        elif above >= 10 and above >= SIDE_MARGIN * below:
            above_votes += 1
    return below_votes, above_votes


#: The level planes lie all on one side of the camera when the other holds no more than this
#: share of their points.
ONE_SIDE_SHARE = 0.05
#: Box points within this of a level plane (metres) rest on it or hang from it.
RESTING_M = 0.05


def _resting_planes(frame: GravityFrame, box_points: Sequence[np.ndarray]) -> list[float]:
    """The heights of the level planes that box points rest on: at least 30 of them within
    :data:`RESTING_M` above the plane and :data:`SIDE_MARGIN` times as many as within it below."""
    heights = np.concatenate([points[:, 2] for points in box_points] + [np.empty(0)])
    resting = []
    for height, _ in frame.plane_heights:
        above = int(np.sum((heights > height) & (heights < height + RESTING_M)))
        below = int(np.sum((heights < height) & (heights > height - RESTING_M)))
        if above >= 30 and above >= SIDE_MARGIN * below:
            resting.append(height)
    return resting


#: The up check reads each mask without this many pixels at its edge (a mask that bleeds onto the
#: floor under a box shows a level ring below it, as a top would in a pose upside down).
CORE_ERODE_PX = 3


def _core_points(
    depth_m: np.ndarray, intrinsics: Intrinsics, pose: np.ndarray, frame: GravityFrame, mask: np.ndarray
) -> np.ndarray:
    """The gravity-frame points of ``mask`` without its edge (:data:`CORE_ERODE_PX`), every n-th
    of more than :data:`MAX_MASK_POINTS`."""
    from scipy.ndimage import binary_erosion

    core = binary_erosion(mask, iterations=CORE_ERODE_PX)
    points = frame.apply(depth_points(depth_m, intrinsics, pose, core))
    return points[:: max(1, -(-len(points) // MAX_MASK_POINTS))]


def _check_upright(frame: GravityFrame, pose: np.ndarray, box_points: Sequence[np.ndarray]) -> None:
    """Raise when the pose's z points down; warn when nothing tells.

    A box seen with its top shows it as the highest level slab of its points, its front below:
    upside down, the slab is the lowest and the front above it. The boxes decide when they agree
    (one side at least :data:`SIDE_MARGIN` times the other; two boxes at least to refuse: a front
    cut by what stands before it can show a slab at its foot). Else the cloud's level planes do
    when they all lie on one side of the camera (a camera looking down sees tops and floor alone;
    one that sees nothing level but a ceiling is taken upside down: the mirror image of a floor);
    else the floor, the level plane the boxes rest on, seen from above. (Level planes on both
    sides cannot tell by their points: a camera at a container's door sees the ceiling from
    below.) When none tells, a warning says so.
    """
    seen_from_above, seen_from_below = _side_of_tops(box_points)
    if seen_from_below >= 2 and seen_from_below >= SIDE_MARGIN * seen_from_above:
        raise UnstackError(
            f"{seen_from_below} of the {seen_from_above + seen_from_below} boxes that show a level top show it as "
            "their lowest face with the rest of the box above (a camera sees tops from above): the pose's z points "
            "down, or the masks reach past their boxes onto the floor under them; expected a camera-to-world pose "
            "whose z is up, and masks on their boxes"
        )
    if seen_from_above >= 1 and seen_from_above >= SIDE_MARGIN * seen_from_below:
        return
    camera_height = float(frame.apply(pose[None, :3, 3])[0, 2])
    below = sum(count for height, count in frame.plane_heights if height < camera_height)
    above = sum(count for height, count in frame.plane_heights if height > camera_height)
    if above <= ONE_SIDE_SHARE * (above + below):  # every level plane below: a camera looking down
        return
    if below <= ONE_SIDE_SHARE * (above + below):
        raise UnstackError(
            f"the camera sees all {above} points of the cloud's level planes from below and no box shows its top (a "
            "camera sees the floor and the tops of boxes from above): the pose's z points down; expected a "
            "camera-to-world pose whose z is up"
        )
    resting = _resting_planes(frame, box_points)
    if resting and all(height > camera_height for height in resting):
        raise UnstackError(
            f"the level plane the boxes rest on lies {min(resting) - camera_height:.2f} m above the camera and no box "
            "shows its top (a camera sees the floor from above): the pose's z points down; expected a "
            "camera-to-world pose whose z is up"
        )
    if not resting or any(height > camera_height for height in resting):
        warnings.warn(
            "cannot tell whether the pose's z is up: no box shows a level top and no floor the boxes rest on is seen "
            "below the camera; check the boxes' heights in the scene",
            stacklevel=3,
        )


#: A median summed edge error of the fitted boxes above this (metres) says the depth's units or
#: the known sizes are wrong: the camera example's 29 boxes, many seen in part, err by a median
#: 0.08 m; depth in centimetres read as millimetres by 0.53 m, sizes of 1.5 and 2.4 m by 1.32 m.
SIZE_DOUBT_M = 0.25
#: Fitted boxes whose longest edges' median is above this (metres) are no cartons: the depth is
#: in a finer unit than declared (the camera example's 29 boxes: 0.40 m; read at 4 times the
#: depth, 1.59 m).
LARGE_FIT_M = 1.0
#: A camera further in than the boxes' median by more than this (metres) stands beyond the pile
#: from the door: the door's direction was given the wrong way (a camera looking down from above
#: the pile stands about level with it).
DOOR_DOUBT_M = 0.3
#: The direction towards the camera is the default door when its horizontal part (in the pose's
#: frame) is over this share of it: a camera above the pile says nothing of the door.
DEFAULT_DOOR_SHARE = 0.3
#: With gravity from the pose, level planes of the cloud leaning more than this (degrees) from
#: the pose's z are said: a pose not calibrated to gravity, or a ramp or leaning layer in view
#: (the planes find gravity within 0.5 degrees under Kinect-like noise: docs page "Your own camera").
POSE_DOUBT_DEG = 1.5
#: Without a floor plane, a level plane this far (metres) above the lowest readings, the largest
#: one, is named: it may be the floor, and the lowest readings a ramp or pit going down from it.
FLOOR_ABOVE_DOUBT_M = 0.05
#: ... whose points lie mostly this far (metres) beyond every box's footprint.
FOOTPRINT_MARGIN_M = 0.05
#: A tilt this close (degrees) to what the planes correct is said: the fit may have stopped there.
CONE_EDGE_DEG = 1.0


@dataclass(frozen=True)
class CameraScene:
    """The scene built from camera files, and how it was built.

    Attributes
    ----------
    scene : Scene
        The fitted boxes (all detected) and the cloud, in the gravity frame.
    frame : GravityFrame
        The transform from the camera's frame (z up, the floor at z = 0).
    fitted : tuple of FittedBox
        Every box kept, with how well it fits.
    duplicates : dict of str to str
        A mask left out as a duplicate -> the larger mask it lies in.
    unfitted : dict of str to str
        A mask no box was kept for -> why.
    camera : tuple of float, optional
        Where the camera stands in the scene's frame (x from the door inwards).
    door_given : bool
        The door's direction was given, not taken from the camera or the cloud's frame.
    """

    scene: Scene
    frame: GravityFrame
    fitted: tuple[FittedBox, ...]
    duplicates: dict[str, str] = field(default_factory=dict)
    unfitted: dict[str, str] = field(default_factory=dict)
    camera: tuple[float, float, float] | None = None
    door_given: bool = False

    def doubts(self) -> list[str]:
        """What the fits say of the inputs, as warnings: measured faces far from every known
        size (depth in other units than declared, or sizes not in metres), boxes larger than
        cartons, no floor seen (z = 0 at the lowest readings), a camera beyond the pile from the
        door (``door`` the wrong way)."""
        doubts = []
        errors = [item.size_error_m for item in self.fitted]
        if errors and float(np.median(errors)) > SIZE_DOUBT_M:
            doubts.append(
                f"the measured faces differ from the nearest known size by {float(np.median(errors)):.2f} m "
                f"(median over {len(errors)} boxes, two edges summed): are the depth image's units right "
                "(--depth-units) and the sizes in metres?"
            )
        longest = float(np.median([box.size.max() for box in self.scene.boxes]))
        if longest > LARGE_FIT_M:
            doubts.append(
                f"the fitted boxes are larger than cartons (their longest edges' median is {longest:.2f} m): are the "
                "depth image's units right (--depth-units)?"
            )
        if self.frame.gravity == "planes" and self.frame.tilt_deg >= HORIZONTAL_TOLERANCE_DEG - CONE_EDGE_DEG:
            doubts.append(
                f"gravity is tilted {self.frame.tilt_deg:.1f} degrees from the input frame's z, at or past the edge "
                f"of the {HORIZONTAL_TOLERANCE_DEG:g} degrees the planes search: a frame further off is fitted short "
                "of gravity, or to a wall; check the pose"
            )
        lean = self.frame.planes_tilt_deg
        if lean is not None and lean > POSE_DOUBT_DEG:
            doubts.append(
                f"gravity is the pose's z, as asked, but the cloud's level planes lean {lean:.1f} degrees from it: "
                "check the pose's calibration; where the pile's tops and the floor are level, let the planes "
                "correct it (gravity from the planes)"
            )
        unsure = sorted((item for item in self.fitted if item.unsure_m > UNSURE_FIT_M), key=lambda item: item.box.id)
        if unsure:
            named = ", ".join(f"{item.box.id} by {item.unsure_m:.2f} m" for item in unsure)
            doubts.append(
                f"{counted(len(unsure), 'box', 'boxes')} seen in part with a pose its points do not settle: fitted "
                f"again with other random draws of the planes, the centre moves ({named}); a view that shows more "
                "of it settles it"
            )
        if self.frame.floor_inliers == 0:
            floor = _floor_above(self.scene, self.frame.plane_heights)
            above = (
                f"; a level plane ({floor[1]:,} points, most of them beside the boxes) lies {floor[0]:.2f} m above "
                "it: if that is the floor (a ramp or a pit going down from it seen past it), every box stands that "
                "much too high"
                if floor is not None
                else ""
            )
            doubts.append(
                "no floor plane was seen (hidden by the boxes, or out of the view): z = 0 is put at the lowest "
                f"readings; if the floor lies lower, every box stands that much too low{above}"
            )
        pile_x = float(np.median([box.position[0] for box in self.scene.boxes]))
        if self.camera is None and self.door_given and pile_x < 0:
            doubts.append(
                f"the boxes stand in front of the door (their median x is {pile_x:.2f} m; x runs from the door "
                "inwards): does --door point out of the container?"
            )
        if self.camera is not None and self.camera[0] > pile_x + DOOR_DOUBT_M:
            doubts.append(
                f"the camera stands beyond the pile from the door (x {self.camera[0]:.2f} m, the boxes' median "
                f"{pile_x:.2f} m; x runs from the door inwards): does --door point out of the container?"
            )
        return doubts

    def report(self) -> dict[str, Any]:
        """JSON-ready: gravity (tilt, planes, floor, whether the depth's noise filled the planes' band),
        every fitted box with its residual, duplicates."""
        return {
            "gravity": self.frame.gravity,
            "tilt_deg": self.frame.tilt_deg,
            "planes_tilt_deg": self.frame.planes_tilt_deg,
            "horizontal_planes": self.frame.planes,
            "floor_points": self.frame.floor_inliers,
            "noisy_depth": self.frame.noisy,
            "boxes": [item.to_dict() for item in self.fitted],
            "duplicates": dict(self.duplicates),
            "unfitted": dict(self.unfitted),
        }


def _floor_above(scene: Scene, plane_heights: Sequence[tuple[float, int]]) -> tuple[float, int] | None:
    """The largest level plane over :data:`FLOOR_ABOVE_DOUBT_M` above z = 0 whose points lie mostly
    beside the boxes' footprints, as a floor's do (a layer of tops lies on them), or ``None``."""
    from unstack.geometry import bounding_boxes

    bounds = bounding_boxes(scene.boxes)
    for height, count in sorted(plane_heights, key=lambda plane: -plane[1]):
        if height <= FLOOR_ABOVE_DOUBT_M:
            continue
        level = scene.points[np.abs(scene.points[:, 2] - height) < PLANE_THRESHOLD, :2]
        over = np.zeros(len(level), dtype=bool)
        for low, high in zip(bounds[:, :2] - FOOTPRINT_MARGIN_M, bounds[:, 3:5] + FOOTPRINT_MARGIN_M, strict=True):
            over |= np.all((level >= low) & (level <= high), axis=1)
        if len(level) and float(np.mean(~over)) > 0.5:
            return height, count
    return None


def _without_overlaps(fitted: list[FittedBox], unfitted: dict[str, str]) -> list[FittedBox]:
    """The fitted boxes, best fits first, leaving out each that overlaps an accepted one by more
    than a scene allows (:data:`~unstack.checks.REFUSED_OVERLAP`; its reason goes to ``unfitted``)."""
    from unstack.checks import REFUSED_OVERLAP
    from unstack.geometry import overlapping_pairs

    accepted: list[FittedBox] = []
    for item in sorted(fitted, key=lambda item: (-item.fill, item.size_error_m, item.box.id)):
        clashes = [
            accepted[i].box.id
            for i, j, _ in overlapping_pairs([*(other.box for other in accepted), item.box], REFUSED_OVERLAP)
            if j == len(accepted)
        ]
        if clashes:
            unfitted[item.box.id] = f"{item.box.id}: the fitted box overlaps {clashes[0]} by more than half"
        else:
            accepted.append(item)
    order = {item.box.id: k for k, item in enumerate(fitted)}
    return sorted(accepted, key=lambda item: order[item.box.id])


#: A piece of a mask (8-connected) smaller than this share of its largest piece is a speck a
#: detector left on something else (a few pixels on the box beside): left out with a warning.
#: Two pieces of a box a thin thing in front cuts apart are each far larger.
SPECK_SHARE = 0.05


#: Pieces of a mask more than twice this many pixels apart are apart (a strap in front of a
#: box cuts it into pieces closer than that).
PIECES_GAP = 3


#: A piece of a fitted mask with less than this share of its points in (or within 3 cm of) the
#: fitted box belongs to another box.
PIECE_INSIDE_SHARE = 0.5


#: A box fitted to a mask that holds (within 3 cm) less than this share of the mask's points is
#: left out: the mask is not one box's (the floor, the whole image, several boxes). On simulated
#: piles a fit holds 20 % of its mask's points at the least (exact depth), 30 % with flying pixels.
MIN_HELD_SHARE = 0.1


def _mask_cloud(
    depth_m: np.ndarray, intrinsics: Intrinsics, pose: np.ndarray, frame: GravityFrame, mask: np.ndarray, seed: int
) -> np.ndarray:
    """A mask's points in the gravity frame: at most :data:`MAX_MASK_POINTS`, a subset drawn
    from the mask's own pixels (the same wherever the mask stands among others)."""
    points = frame.apply(depth_points(depth_m, intrinsics, pose, mask))
    if len(points) > MAX_MASK_POINTS:
        points = points[content_rng(seed, np.flatnonzero(mask)).choice(len(points), MAX_MASK_POINTS, replace=False)]
    return points


def _boxes_holding_their_points(
    mask_points: dict[str, np.ndarray], **fitting: Any
) -> tuple[list[FittedBox], dict[str, str]]:
    """The boxes fitted to the masks' points (:func:`~unstack.camera.boxes.boxes_from_masks`
    with ``fitting``) that hold :data:`MIN_HELD_SHARE` of their masks' points or more, and why
    each other mask has none."""
    fitted, unfitted = boxes_from_masks(list(mask_points.values()), list(mask_points), **fitting)
    kept = []
    for item in fitted:
        points = mask_points[item.box.id]
        held = float(np.mean(points_in_box(points, item.box, margin=0.03)))
        if held < MIN_HELD_SHARE:
            low, high = (round(float(height), 2) + 0.0 for height in np.percentile(points[:, 2], [5, 95]))
            unfitted[item.box.id] = (
                f"the box fitted to its mask holds {100 * held:.0f} % of the mask's points, which lie {low:.2f} "
                f"to {high:.2f} m high over {np.ptp(points[:, 0]):.1f} x {np.ptp(points[:, 1]):.1f} m: a detection "
                "of the floor, of several boxes or of the whole image, or a mask reaching far past its box?"
            )
        else:
            kept.append(item)
    return kept, unfitted


#: A surface this much nearer than all but 2 % of a mask's readings (metres) hides part of its box ...
OCCLUDER_M = 0.1
#: ... when it borders this share of the mask's outline, or more.
OCCLUDED_SHARE = 0.05


def _cut_off(depth_m: np.ndarray, mask: np.ndarray) -> bool:
    """Whether a mask meets the image's edge, or a surface nearer than all but 2 % of its
    readings by :data:`OCCLUDER_M` along :data:`OCCLUDED_SHARE` of its outline (a box in
    front): its box may reach on, out of sight.

    Examples
    --------
    >>> depth = np.full((20, 20), 3.0)
    >>> mask = np.zeros((20, 20), bool); mask[5:15, 5:15] = True
    >>> _cut_off(depth, mask)
    False
    >>> depth[5:15, 12:18] = 2.5  # a box in front hides its right side
    >>> _cut_off(depth, mask & (depth > 2.9))
    True
    """
    from scipy.ndimage import binary_dilation

    if mask[0].any() or mask[-1].any() or mask[:, 0].any() or mask[:, -1].any():
        return True
    readings = depth_m[mask & (depth_m > 0)]
    if len(readings) == 0:
        return False
    outline = binary_dilation(mask) & ~mask
    # nearer than (almost) all the box shows: a box's own faces seen at a grazing angle are not
    nearer = outline & (depth_m > 0) & (depth_m < np.percentile(readings, 2) - OCCLUDER_M)
    return bool(nearer.sum() >= OCCLUDED_SHARE * outline.sum())


def _window(mask: np.ndarray) -> tuple[slice, slice] | None:
    """The rows and columns of the rectangle around ``mask``'s pixels (None when it has none)."""
    rows, columns = np.flatnonzero(mask.any(axis=1)), np.flatnonzero(mask.any(axis=0))
    if len(rows) == 0:
        return None
    return slice(rows[0], rows[-1] + 1), slice(columns[0], columns[-1] + 1)


def _pieces(mask: np.ndarray) -> list[np.ndarray]:
    """The pieces of ``mask`` that lie apart (:data:`PIECES_GAP`), each as a mask."""
    from scipy.ndimage import binary_dilation, label

    window = _window(mask)
    if window is None:
        return []
    grown = binary_dilation(mask[window], structure=np.ones((3, 3), dtype=bool), iterations=PIECES_GAP, border_value=0)
    labels, count = label(grown, structure=np.ones((3, 3), dtype=bool))
    pieces = []
    for piece in range(1, count + 1):
        whole = np.zeros_like(mask)
        whole[window] = mask[window] & (labels == piece)
        pieces.append(whole)
    return pieces


def _without_specks(mask: np.ndarray, name: str) -> np.ndarray:
    """``mask`` without its specks (:data:`SPECK_SHARE`), with a warning naming them."""
    from scipy.ndimage import label

    window = _window(mask)
    if window is None:
        return mask
    pieces, count = label(mask[window], structure=np.ones((3, 3), dtype=bool))
    if count < 2:
        return mask
    sizes = np.bincount(pieces.ravel())[1:]
    specks = np.flatnonzero(sizes < SPECK_SHARE * sizes.max())
    if len(specks) == 0:
        return mask
    kept = mask.copy()
    kept[window] &= ~np.isin(pieces, specks + 1)
    pixels = ", ".join(str(int(sizes[k])) for k in specks[:5]) + (" ..." if len(specks) > 5 else "")
    warnings.warn(
        f"mask {name}: {len(specks)} piece(s) of {pixels} pixels apart from its main region of "
        f"{int(sizes.max())} left out (a detector's speck on something else, or a part of the box seen through a "
        "gap: too little to fit)",
        stacklevel=3,
    )
    return kept


def _mask_array(mask: np.ndarray, name: str, shape: tuple[int, ...]) -> np.ndarray:
    """A mask as booleans (non-zero where the box is: 0/1, 0/255 or bool), of the depth image's shape."""
    array = np.asarray(mask)
    if array.shape != shape:
        raise UnstackError(f"mask {name} is {array.shape[::-1]} pixels, the depth image {shape[::-1]}")
    if not (np.issubdtype(array.dtype, np.number) or array.dtype == bool):
        raise UnstackError(f"mask {name}: expected numbers or booleans, got {array.dtype}")
    selected: np.ndarray = np.nan_to_num(array) != 0
    return selected


def scene_from_depth(
    depth_m: np.ndarray,
    intrinsics: Intrinsics,
    camera_to_world: np.ndarray,
    masks: Sequence[np.ndarray],
    *,
    ids: Sequence[str] | None = None,
    known_sizes: Sequence[Sequence[float]] | None = None,
    door: Sequence[float] | None = None,
    seed: int = 0,
    gravity: str = "planes",
) -> CameraScene:
    """Build an ``unstack.scene/1`` scene: gravity frame, one fitted box per mask, the cloud.

    Parameters
    ----------
    depth_m : numpy.ndarray, shape (height, width)
        Depth along the optical axis in metres, 0 where there is no reading.
    intrinsics : Intrinsics
    camera_to_world : numpy.ndarray, shape (4, 4)
        The camera's pose in a world frame whose z is roughly up.
    masks : sequence of numpy.ndarray of bool
        One per detected box.
    ids : sequence of str, optional
        Box ids (default ``b00``, ``b01``, ...).
    known_sizes : sequence of (3,) sizes, optional
        The carton sizes that can occur (metres).
    door : (3,) direction, optional
        Out of the container through the door, in the input frame; default: towards the camera
        (the pose frame's -x when the camera looks down from above the pile).
    seed : int
        Seeds RANSAC and the subsets.
    gravity : {"planes", "pose"}
        Up from the cloud's level planes, or the pose frame's z taken as up (a calibrated robot
        frame: a ramp or a leaning layer in view cannot turn it); see
        :func:`~unstack.camera.planes.gravity_frame`.
    """
    gravity = check_gravity(gravity)
    pose = check_pose(camera_to_world)
    rng = np.random.default_rng(seed)
    names = [f"b{k:02d}" for k in range(len(masks))] if ids is None else list(ids)
    if len(names) != len(masks) or len(set(names)) != len(names):
        raise UnstackError(f"expected {len(masks)} distinct box ids, got {names}")
    if not masks:
        raise UnstackError("at least one box mask is needed")
    depth_m = np.asarray(depth_m, dtype=np.float64)
    if np.isinf(depth_m).any():
        raise UnstackError(
            f"the depth image holds {int(np.isinf(depth_m).sum()):,} infinite readings; expected metres, "
            "with 0 or NaN where there is no reading"
        )
    masks = [_mask_array(mask, name, depth_m.shape) for mask, name in zip(masks, names, strict=True)]
    cloud = depth_points(depth_m, intrinsics, pose)
    if len(cloud) < 100:
        raise UnstackError(f"the depth image holds {len(cloud)} readings; at least 100 are needed")
    if len(cloud) > MAX_SCENE_POINTS:
        cloud = cloud[np.sort(rng.choice(len(cloud), MAX_SCENE_POINTS, replace=False))]
    # without a door, towards the camera; a camera above the pile says nothing: the pose frame's -x,
    # as it is where the gravity found makes the direction towards the camera steep
    given = None if door is None else np.asarray(door, dtype=np.float64)
    toward_camera = pose[:3, 3] - np.median(cloud, axis=0)
    horizontal = np.linalg.norm(toward_camera[:2])
    guess = toward_camera if horizontal > DEFAULT_DOOR_SHARE * np.linalg.norm(toward_camera) else [-1.0, 0.0, 0.0]
    frame = gravity_frame(
        cloud, door=given, seed=seed, gravity=gravity, default_door=np.asarray(guess, dtype=np.float64)
    )
    masks = [_without_specks(mask, name) for mask, name in zip(masks, names, strict=True)]
    duplicates = duplicate_masks(masks)
    merged = merged_masks(masks)
    kept = [k for k in range(len(masks)) if k not in duplicates and k not in merged]
    mask_points = {names[k]: _mask_cloud(depth_m, intrinsics, pose, frame, masks[k], seed) for k in kept}
    _check_upright(frame, pose, [_core_points(depth_m, intrinsics, pose, frame, masks[k]) for k in kept])
    fitting = {
        "known_sizes": known_sizes,
        "seed": seed,
        "viewpoint": frame.apply(pose[None, :3, 3])[0],
        "levels": [height for height, _ in frame.plane_heights],
    }
    fitted, unfitted = _boxes_holding_their_points(mask_points, **fitting)
    originals = {k: j for k, j in duplicates.items() if names[j] in unfitted}
    if originals:  # a larger mask no box holds: its duplicates are boxes of their own, fitted among the rest
        for k in originals:
            del duplicates[k]
            kept.append(k)
            mask_points[names[k]] = _mask_cloud(depth_m, intrinsics, pose, frame, masks[k], seed)
        refused = dict(unfitted)
        fitted, unfitted = _boxes_holding_their_points(
            {name: points for name, points in mask_points.items() if name not in refused}, **fitting
        )
        unfitted.update(refused)
    by_id = {item.box.id: item.box for item in fitted}
    for k in kept:  # a mask of pieces apart: two boxes under one label, fitted as one or not at all
        pieces = _pieces(masks[k])
        if len(pieces) > 1 and names[k] in unfitted:
            unfitted[names[k]] += f" (its mask is {len(pieces)} pieces apart: two boxes under one label?)"
        elif len(pieces) > 1:  # one box seen on both sides of something in front: every piece on the fitted box
            seen = [frame.apply(depth_points(depth_m, intrinsics, pose, piece)) for piece in pieces]
            inside = [
                float(np.mean(points_in_box(points, by_id[names[k]], margin=0.03))) for points in seen if len(points)
            ]
            if inside and min(inside) < PIECE_INSIDE_SHARE:
                warnings.warn(
                    f"mask {names[k]} is {len(pieces)} pieces apart and the box fitted to it holds "
                    f"{100 * min(inside):.0f} % of one piece's points: two boxes under one label, or one box seen "
                    "on both sides of something in front and fitted to one side; check its pose",
                    stacklevel=2,
                )
    for j, held in merged.items():
        named = [names[k] for k in held[:3]]
        others = (
            f"{', '.join(named[:-1])} and {named[-1]}"
            if len(held) <= 3
            else f"{', '.join(named)} and {len(held) - 3} more"
        )
        unfitted[names[j]] = (
            f"its mask holds the masks of {others}: a detection of several boxes (or of the whole image)"
        )
    if not fitted:
        raise UnstackError(f"no box could be fitted: {'; '.join(f'{k}: {why}' for k, why in unfitted.items())}")
    fitted = _without_overlaps(fitted, unfitted)
    fronts = {item.box.id for item in fitted if item.face == "front"}
    cut_off = {names[k] for k in kept if names[k] in fronts and _cut_off(depth_m, masks[k])}
    # a front seen whole fixes its face only: one cut off by the image or a box in front is seen in part
    fitted = [
        dataclasses.replace(item, partial=True) if item.face == "front" and item.box.id in cut_off else item
        for item in fitted
    ]
    boxes: list[Box] = [item.box for item in fitted]
    metadata = {
        "camera": {
            "gravity": frame.gravity,
            "tilt_deg": frame.tilt_deg,
            "gravity_rotation": frame.rotation.tolist(),
            "gravity_translation": frame.translation.tolist(),
            "duplicates": {names[k]: names[j] for k, j in duplicates.items()},
        }
    }
    scene = Scene(boxes, frame.apply(cloud), [box.id for box in boxes], metadata=metadata, source="<camera>")
    camera_x, camera_y, camera_z = (float(value) for value in frame.apply(pose[None, :3, 3])[0])
    duplicated = {names[k]: names[j] for k, j in duplicates.items()}
    return CameraScene(scene, frame, tuple(fitted), duplicated, unfitted, (camera_x, camera_y, camera_z))
