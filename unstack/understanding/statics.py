"""Boxes that cannot stand on what is under them without another: statics finds supporters.

A learned model reads support from the geometry of a pair of boxes; the piles it was trained
on rarely hold a lone box standing on its edge and leaning on another, and it calls the box
leant on nearly free (the generalisation page of the docs). Statics settles such cases
without a model. For each detected box ``Y``:

* its *base* is where something holds it from below: the points of its surface within
  :data:`CONTACT_GAP` of the floor, the points where a detected box touches it with a
  push that is mostly upward (within 45 degrees of vertical), and the points of the cloud
  just under its downward faces that lie on no detected box (an undetected box under it);
* a box tilted by at least :data:`MIN_TILT_DEG` whose centre of mass (the box's centre) lies
  more than :data:`MIN_OVERHANG` outside the convex hull of its base seen from above would
  tip over that edge: a detected box ``X`` that touches it at least :data:`MIN_RISE` above
  its lowest point, beyond that edge, and pushes it back (its push has a horizontal part of
  at least :data:`MIN_PUSH` against the overhang and does not press ``Y`` down) holds it up
  -- the box it leans on. A box standing upright is examined the same way when its centre
  lies more than :data:`UPRIGHT_OVERHANG` outside its base, measured to the edges of where its
  bottom and the tops of the upright boxes under it overlap (a carton on a short box whose
  centre is past that box's edge, kept from tipping by a taller box beside it), by no more
  than a push from the side can hold, and the cloud shows nothing nobody detected under the
  part of it beyond its base (what stands there may hold it); it is held at its side below its
  top (not by a box on it whose pose reaches into it), and one whose bottom is within
  :data:`UPRIGHT_FLOOR_GAP` of the floor stands on the floor;
* a box that stands, tilted or not, is held up by a detected box of its base without whose
  contacts it would tip (the centre more than :data:`MIN_OVERHANG` outside the rest of the
  base, that box's contacts beyond its edge): a box across a gap between two, a box on its
  edge whose top rests on another's top edge, a plank from one box to another;
* for each box that holds ``Y`` up, ``P(X supports Y)`` is raised to at least
  :data:`TIP_SUPPORT_PROBABILITY`, never lowered. A box that rests on one box alone is not
  raised: on simulated piles the model's low probabilities there were mostly right.

Contacts are found on a grid of points over ``Y``'s faces: a point touches ``X`` when it
lies within :data:`CONTACT_GAP` of ``X`` and within :data:`CONTACT_BAND` of the closest
approach of the two boxes. The push at a point is along the normal of ``Y``'s face there,
along ``X``'s face normal where an edge or corner of ``Y`` meets a face of ``X`` or where the
two faces do not face each other (poses that overlap: a box reaching into another's side does
not hold it from below), and across both edges where two edges cross. The measured precision of the rule on simulated
piles (how often the box leant on really holds the leaning one up when removed) and its
effect on the suite are on the generalisation page.

Examples
--------
>>> import numpy as np
>>> from unstack.scene import Box, Scene
>>> angle = np.radians(22.0)
>>> lean = Box("lean", [0.15, 0.4, 0.6], [0.0, 0.0, 0.0], [0.0, np.sin(angle / 2), 0.0, np.cos(angle / 2)])
>>> from unstack.geometry import box_corners
>>> corners = box_corners(lean)
>>> lean = Box("lean", lean.size, [1.2 - corners[:, 0].max() - 0.002, 0.0, -corners[:, 2].min() + 0.001],
...            lean.orientation_xyzw)
>>> upright = Box("upright", [0.4, 0.5, 0.65], [1.4, 0.0, 0.326])
>>> found = tip_supports(Scene([upright, lean], np.zeros((0, 3)), ["upright", "lean"]))
>>> [(f.supporter, f.held, round(f.overhang, 2), f.on_floor) for f in found]
[('upright', 'lean', 0.04, True)]
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from unstack.geometry import bounding_boxes, convex_hull_2d, convex_overlap, rotation_matrix, tilt_deg
from unstack.scene import Box, Scene
from unstack.understanding.cloud_columns import CloudColumns, columns_of

__all__ = [
    "CONTACT_GAP",
    "MIN_OVERHANG",
    "MIN_TILT_DEG",
    "TIP_SUPPORT_PROBABILITY",
    "UPRIGHT_FLOOR_GAP",
    "UPRIGHT_OVERHANG",
    "TipSupport",
    "raise_tip_supports",
    "tip_supports",
]

#: Names before the rule's names said what it finds (a box kept from tipping, not only one
#: leaning); they warn and go with version 0.2.
_RENAMED = {
    "Leaning": "TipSupport",
    "leaning_supports": "tip_supports",
    "raise_leaning_supports": "raise_tip_supports",
    "LEAN_SUPPORT_PROBABILITY": "TIP_SUPPORT_PROBABILITY",
}


def __getattr__(name: str) -> object:
    if name in _RENAMED:
        warnings.warn(
            f"unstack.understanding.statics.{name} is renamed {_RENAMED[name]}", DeprecationWarning, stacklevel=2
        )
        return globals()[_RENAMED[name]]
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


#: Boxes tilted less than this (degrees from standing on a face) are examined only for what
#: their base needs, not for leaning: their overhang is more often a pose error.
MIN_TILT_DEG = 8.0
#: Two surfaces closer than this touch (metres): poses from a detector are a centimetre off.
CONTACT_GAP = 0.015
#: Of the points within :data:`CONTACT_GAP`, those within this of the closest approach touch (metres).
CONTACT_BAND = 0.005
#: Spacing of the points laid over a box's faces (metres).
SAMPLE_SPACING = 0.02
#: A push whose vertical part is at least this (cos 45 degrees) holds a box from below.
UPWARD = 0.7
#: The centre of mass must lie this far outside the base for the box to tip (metres).
MIN_OVERHANG = 0.01
#: A box standing upright (tilted less than :data:`MIN_TILT_DEG`) is examined for leaning when
#: its centre lies more than this outside its base (metres): its pose and the pose of the box
#: under it, a centimetre off each, do not make a box on a box look as if it overhangs (its base
#: on an upright box is measured to the edges of the two faces' overlap, not to the grid).
UPRIGHT_OVERHANG = 0.02
#: An upright box whose bottom is at most this far above the floor stands on it (metres): its
#: pose is off in z by a detector's error, and the floor is under all of it.
UPRIGHT_FLOOR_GAP = 0.03
#: Points of the cloud, near no detected box, under the part of an upright box beyond its base
#: that show something nobody detected standing there: the rule for upright boxes then finds nothing.
SEEN_UNDER_POINTS = 3
#: Friction between two cartons (the simulator's, and cardboard's 0.4-0.6): with it, how far past
#: its base a push from the side can hold an upright box (:func:`_held_overhang`).
FRICTION = 0.5
#: A box holding the leaning one pushes back against the overhang by at least this share.
MIN_PUSH = 0.3
#: ... and touches it at least this high above its lowest point (metres).
MIN_RISE = 0.05
#: The support probability a box found to hold another gets at least: of the findings whose
#: probability the rule raises, the share in which removing that box moved the other on the
#: simulated piles the rule was tuned on (68 of 101; 66 of 110 on fresh piles: generalisation page).
TIP_SUPPORT_PROBABILITY = 0.65


@dataclass(frozen=True)
class TipSupport:
    """A detected box that cannot stand without another detected box, and that box.

    Found by :func:`tip_supports`; :func:`raise_tip_supports` lifts ``P(supporter supports
    held)`` to at least :data:`TIP_SUPPORT_PROBABILITY` for each one.

    Attributes
    ----------
    held : str
        The box that would tip over without ``supporter``.
    supporter : str
        The box it leans on or rests on.
    overhang : float
        How far its centre of mass lies outside its base (without the supporter's contacts
        when the supporter is part of the base), seen from above (metres).
    on_floor : bool
        Whether that base is the floor alone.
    """

    held: str
    supporter: str
    overhang: float
    on_floor: bool

    @property
    def leaning(self) -> str:
        """Deprecated name of :attr:`held` (it goes with version 0.2)."""
        warnings.warn("TipSupport.leaning is renamed TipSupport.held", DeprecationWarning, stacklevel=2)
        return self.held

    def describe(self) -> str:
        """One sentence for a warning."""
        base = "the floor" if self.on_floor else "what is under it"
        return (
            f"box {self.held!r} cannot stand on {base} without {self.supporter!r} "
            f"(its centre of mass lies {self.overhang:.2f} m beyond)"
        )


def _face_samples(box: Box, *, downward_only: bool = False) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Points on a grid over the box's six faces (``downward_only``: the faces whose outward
    normal points down, all a box standing on a face rests on), their outward normals, which
    local bounds each point lies on (boolean, shape (m, 3)), and the box's rotation."""
    rotation = rotation_matrix(box.orientation_xyzw)
    half = box.size / 2.0
    local: list[np.ndarray] = []
    normals: list[np.ndarray] = []
    for axis in range(3):
        first, second = (other for other in range(3) if other != axis)
        grids = [
            np.linspace(-half[k], half[k], max(2, int(np.ceil(2.0 * half[k] / SAMPLE_SPACING)) + 1))
            for k in (first, second)
        ]
        a, b = np.meshgrid(*grids, indexing="ij")
        for sign in (-1.0, 1.0):
            if downward_only and sign * rotation[2, axis] > -UPWARD:
                continue
            face = np.zeros((a.size, 3))
            face[:, first], face[:, second], face[:, axis] = a.ravel(), b.ravel(), sign * half[axis]
            normal = np.zeros(3)
            normal[axis] = sign
            local.append(face)
            normals.append(np.repeat(normal[None], len(face), axis=0))
    points = np.concatenate(local)
    on_bounds = np.isclose(np.abs(points), half[None], atol=1e-9)
    return points @ rotation.T + box.position, np.concatenate(normals) @ rotation.T, on_bounds, rotation


def _distances(points: np.ndarray, box: Box) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Signed distance of each point to the box, the outward normal of its nearest face,
    which local bounds the nearest surface point lies within :data:`CONTACT_GAP` of, and the
    box's rotation."""
    rotation = rotation_matrix(box.orientation_xyzw)
    half = box.size / 2.0
    local = (points - box.position) @ rotation
    excess = np.abs(local) - half
    distance = np.linalg.norm(np.maximum(excess, 0.0), axis=1) + np.minimum(excess.max(axis=1), 0.0)
    nearest_axis = np.argmax(excess, axis=1)
    sign = np.sign(local[np.arange(len(local)), nearest_axis])
    normals = sign[:, None] * rotation[:, nearest_axis].T
    near_bounds = np.abs(np.clip(local, -half, half)) >= half - CONTACT_GAP
    return distance, normals, near_bounds, rotation


def _pushes(
    own_normals: np.ndarray,
    own_bounds: np.ndarray,
    own_rotation: np.ndarray,
    other_normals: np.ndarray,
    other_bounds: np.ndarray,
    other_rotation: np.ndarray,
) -> np.ndarray:
    """Direction in which the other box pushes this one at each contact point (unit vectors)."""
    pushes = -own_normals.copy()  # a face of this box: the push is along its normal
    own_count, other_count = own_bounds.sum(axis=1), other_bounds.sum(axis=1)
    other_face = (own_count >= 3) | ((own_count == 2) & (other_count < 2))  # a corner or edge on a face
    # a face against a face of the other that does not face it back (poses that overlap): the other's face pushes
    other_face |= (own_count == 1) & (other_count <= 1) & (np.einsum("ij,ij->i", own_normals, other_normals) > -UPWARD)
    pushes[other_face] = other_normals[other_face]
    crossing = (own_count == 2) & (other_count == 2)  # two edges cross: the push is across both
    if np.any(crossing):
        own_edges = own_rotation[:, np.argmin(own_bounds[crossing], axis=1)].T
        other_edges = other_rotation[:, np.argmin(other_bounds[crossing], axis=1)].T
        across = np.cross(own_edges, other_edges)
        length = np.linalg.norm(across, axis=1)
        across /= np.maximum(length, 1e-12)[:, None]
        across *= np.where(np.einsum("ij,ij->i", across, other_normals[crossing]) < 0.0, -1.0, 1.0)[:, None]
        pushes[crossing] = np.where((length > 0.2)[:, None], across, other_normals[crossing])
    return pushes


def _outside_hull(point: np.ndarray, hull: np.ndarray) -> tuple[float, np.ndarray]:
    """How far a 2-D point lies outside a convex hull (counter-clockwise), and the hull's nearest point."""
    if len(hull) == 1:
        return float(np.linalg.norm(point - hull[0])), hull[0]
    starts = hull if len(hull) > 2 else hull[:1]
    ends = np.roll(hull, -1, axis=0) if len(hull) > 2 else hull[1:]
    edges = ends - starts
    along = np.clip(np.einsum("ij,ij->i", point - starts, edges) / np.maximum((edges**2).sum(axis=1), 1e-18), 0, 1)
    nearest = starts + along[:, None] * edges
    gaps = np.linalg.norm(point - nearest, axis=1)
    crosses = edges[:, 0] * (point[1] - starts[:, 1]) - edges[:, 1] * (point[0] - starts[:, 0])
    if len(hull) > 2 and np.all(crosses >= 0.0):
        return 0.0, point
    closest = int(np.argmin(gaps))
    return float(gaps[closest]), nearest[closest]


def _near(bounds: np.ndarray, row: int, margin: float) -> np.ndarray:
    """Which boxes' bounding boxes come within ``margin`` of box ``row``'s."""
    low, high = bounds[row, :3] - margin, bounds[row, 3:] + margin
    near: np.ndarray = np.all((bounds[:, :3] <= high) & (bounds[:, 3:] >= low), axis=1)
    return near


def _downward_top(box: Box) -> float:
    """The highest point of the box's downward faces (outward normal's z at most ``-UPWARD``);
    minus infinity when the box has none."""
    rotation = rotation_matrix(box.orientation_xyzw)
    half = box.size / 2.0
    across = np.abs(rotation[2]) * half  # each axis's reach in z
    tops = [
        box.position[2] + sign * rotation[2, axis] * half[axis] + across.sum() - across[axis]
        for axis in range(3)
        for sign in (-1.0, 1.0)
        if sign * rotation[2, axis] <= -UPWARD
    ]
    return float(max(tops, default=-np.inf))


def _cloud_under(columns: CloudColumns, box: Box, bound: np.ndarray, others: Sequence[Box]) -> np.ndarray:
    """Points of the cloud just under the box's downward faces, away from its edges (its own
    visible faces, noisy near the edges, are not taken for something under it), and not within
    :data:`CONTACT_GAP` of a detected box (whose contacts count already: a sensor's noise puts
    points of the face a box leans on 5-10 mm off it, and those once made a leaning box's base
    reach past its centre of mass); in the order of the cloud sorted by x."""
    low, high = bound[:3] - CONTACT_GAP, bound[3:] + CONTACT_GAP
    high[2] = min(high[2], _downward_top(box) + CONTACT_GAP + 1e-9)  # none higher lies that near a downward face
    column = columns.points[columns.indices_over(low[:2], high[:2])]
    candidates: np.ndarray = column[np.all((column >= low) & (column <= high), axis=1)]
    if len(candidates) == 0:
        return candidates[:, :2]
    distance, normals, _, rotation = _distances(candidates, box)
    excess = np.abs((candidates - box.position) @ rotation) - box.size / 2.0
    excess[np.arange(len(excess)), np.argmax(excess, axis=1)] = -np.inf
    away_from_edges = excess.max(axis=1) <= -0.01
    under = (distance >= 0.002) & (distance <= CONTACT_GAP) & (normals[:, 2] <= -UPWARD) & away_from_edges
    candidates = candidates[under]  # each test holds point by point: the cheapest set is checked against the others
    candidates = candidates[np.argsort(candidates[:, 0], kind="stable")]
    for other in others:
        if len(candidates) == 0:
            break
        candidates = candidates[_distances(candidates, other)[0] > CONTACT_GAP]
    return candidates[:, :2]


def tip_supports(
    scene: Scene, objects: Sequence[str] | None = None, *, columns: CloudColumns | None = None
) -> list[TipSupport]:
    """The detected boxes that cannot stand without another detected box, and those boxes.

    Parameters
    ----------
    scene : Scene
        Boxes, cloud and floor (``z = 0``).
    objects : sequence of str, optional
        The boxes to consider detected (default: the scene's ``detected``); other boxes are
        not used -- a robot would not know them.
    columns : CloudColumns, optional
        The scene's points binned already (one binning serves the whole pipeline).

    Returns
    -------
    list of TipSupport
        In the order of ``objects`` (leaning box first, then its supporters).
    """
    index = {box_id: k for k, box_id in enumerate(scene.box_ids)}
    names = _known_ids(scene.detected if objects is None else objects, index, "objects", "the scene's boxes")
    boxes = [scene.boxes[index[name]] for name in names]
    bounds = bounding_boxes(boxes) if boxes else np.zeros((0, 6))
    cloud = columns_of(scene.points, columns)  # binned once, looked up per box
    found: list[TipSupport] = []
    for row, box in enumerate(boxes):
        tilted = tilt_deg(box) >= MIN_TILT_DEG
        neighbours = [other for other in np.flatnonzero(_near(bounds, row, CONTACT_GAP)).tolist() if other != row]
        base, beside, lowest = _contacts(box, boxes, neighbours, downward_only=not tilted)
        touched = [boxes[key] for key in base if key >= 0]
        base[_CLOUD] = _cloud_under(cloud, box, bounds[row], touched)
        tipping = _tipping(box, base, exclude=None)
        if tipping is not None and not tilted:  # upright: how far past the edges of the faces under it
            tipping = _tipping(box, _to_overlap_edges(base, box, boxes), exclude=None)
        if tipping is not None and not tilted and _seen_under(cloud, box, tipping[1], tipping[2], boxes):
            tipping = None  # upright over something nobody detected: what stands there may hold it
        if tipping is not None and not tilted and lowest <= UPRIGHT_FLOOR_GAP:
            tipping = None  # upright with its bottom a pose error off the floor: it stands on the floor
        if tipping is not None and (tilted or tipping[0] > UPRIGHT_OVERHANG):  # it cannot stand on its base
            if not tilted:  # upright, its centre well beyond its base: its sides were not sampled
                _, beside, lowest = _contacts(box, boxes, neighbours, downward_only=False)
            overhang, edge, direction, on_floor = tipping
            leant_on = []  # what it leans on holds it
            for supporter, (contacts, pushes) in beside.items():
                holds = (
                    (pushes[:, :2] @ direction <= -MIN_PUSH)
                    & (pushes[:, 2] >= -0.1)
                    & (contacts[:, 2] >= lowest + MIN_RISE)
                    & ((contacts[:, :2] - edge) @ direction > 0.0)
                    # an upright box is held at its side, not at its top (where a box on it reaches, poses off)
                    & (tilted | (contacts[:, 2] <= bounds[row, 5] - CONTACT_GAP))
                )
                if np.any(holds) and (tilted or overhang <= _held_overhang(contacts[holds], edge, direction, lowest)):
                    leant_on.append(supporter)
            found += [TipSupport(names[row], names[supporter], overhang, on_floor) for supporter in leant_on]
            if tilted:
                continue  # an upright box may also stand on boxes it needs each of: examined below
        for supporter in (key for key, part in base.items() if key >= 0 and len(part)):
            # it stands, but would it without this box? (a box on its edge resting on another's top edge)
            if not any(len(part) for key, part in base.items() if key not in (supporter, _CLOUD)):
                continue  # it rests on this box alone (as far as anyone knows): left to the model
            without = _tipping(box, base, exclude=supporter)
            if without is None:
                continue
            overhang, edge, direction, on_floor = without
            contacts = base[supporter]
            if np.any((contacts - edge) @ direction > 0.0):
                found.append(TipSupport(names[row], names[supporter], overhang, on_floor))
    return found


def _known_ids(ids: Any, known: dict[str, int], name: str, among: str) -> list[str]:
    """``ids`` as a list of box ids, each among ``known`` (when ``among`` names them)."""
    from unstack.errors import InvalidArgument

    if isinstance(ids, str) or not isinstance(ids, Sequence | np.ndarray):
        raise InvalidArgument(f"{name}: expected a sequence of box ids, got {type(ids).__name__} {ids!r}")
    listed = [str(box_id) if isinstance(box_id, np.str_) else box_id for box_id in ids]
    unknown = [box_id for box_id in listed if not isinstance(box_id, str) or (among and box_id not in known)]
    if unknown:
        raise InvalidArgument(f"{name}: {unknown[0]!r} is not one of {among or 'the box ids (strings)'}")
    return listed


#: Keys of the floor's and the cloud's part of a base (boxes are keyed by their index).
_FLOOR, _CLOUD = -1, -2


def _contacts(
    box: Box, boxes: Sequence[Box], neighbours: Sequence[int], *, downward_only: bool
) -> tuple[dict[int, np.ndarray], dict[int, tuple[np.ndarray, np.ndarray]], float]:
    """Where the floor and each neighbouring box hold ``box`` from below (points seen from
    above, keyed by the neighbour's index, the floor's :data:`_FLOOR`), where each pushes it
    sideways (the points and the pushes), and the box's lowest sampled point; sampled over its
    downward faces only, or over all six."""
    samples, normals, on_bounds, rotation = _face_samples(box, downward_only=downward_only)
    base: dict[int, np.ndarray] = {_FLOOR: samples[samples[:, 2] <= CONTACT_GAP, :2]}
    beside: dict[int, tuple[np.ndarray, np.ndarray]] = {}
    for other in neighbours:
        distance, other_normals, other_bounds, other_rotation = _distances(samples, boxes[other])
        closest = float(distance.min())
        if closest > CONTACT_GAP:
            continue
        touching = distance <= max(closest, 0.0) + CONTACT_BAND
        pushes = _pushes(
            normals[touching], on_bounds[touching], rotation,
            other_normals[touching], other_bounds[touching], other_rotation,
        )  # fmt: skip
        base[other] = samples[touching][pushes[:, 2] >= UPWARD, :2]
        side = np.abs(pushes[:, 2]) < UPWARD
        if np.any(side):
            beside[other] = (samples[touching][side], pushes[side])
    return base, beside, float(samples[:, 2].min())


def _face_outline(box: Box, *, upward: bool) -> np.ndarray:
    """The corners of the box's face whose outward normal points most nearly up (``upward``)
    or down, seen from above, counter-clockwise."""
    rotation = rotation_matrix(box.orientation_xyzw)
    axis = int(np.argmax(np.abs(rotation[2])))
    half = box.size / 2.0
    first, second = (other for other in range(3) if other != axis)
    local = np.zeros((4, 3))
    local[:, first] = half[first] * np.array([-1.0, 1.0, 1.0, -1.0])
    local[:, second] = half[second] * np.array([-1.0, -1.0, 1.0, 1.0])
    local[:, axis] = half[axis] * np.sign(rotation[2, axis]) * (1.0 if upward else -1.0)
    return convex_hull_2d((local @ rotation.T + box.position)[:, :2])


#: The corners of a square of half-side 1 (a grid step around a sampled contact).
_SQUARE = np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]])


def _to_overlap_edges(base: dict[int, np.ndarray], box: Box, boxes: Sequence[Box]) -> dict[int, np.ndarray]:
    """An upright box's base with its contacts on each upright box under it extended to the
    edges of where the two faces overlap, as far as they lie within one :data:`SAMPLE_SPACING`
    of a contact: the grid stops up to a step short of the overlap's edge, and a base measured
    on it puts the centre up to a step too far out."""
    extended = dict(base)
    for key, contacts in base.items():
        if key < 0 or len(contacts) == 0 or tilt_deg(boxes[key]) >= MIN_TILT_DEG:
            continue
        overlap = convex_overlap(_face_outline(box, upward=False), _face_outline(boxes[key], upward=True))
        around = convex_hull_2d((contacts[:, None, :] + SAMPLE_SPACING * _SQUARE[None]).reshape(-1, 2))
        extended[key] = np.concatenate([contacts, convex_overlap(overlap, around)])
    return extended


def _seen_under(columns: CloudColumns, box: Box, edge: np.ndarray, direction: np.ndarray, boxes: Sequence[Box]) -> bool:
    """Whether the cloud shows something nobody detected under the part of ``box`` beyond its
    base's ``edge``: at least :data:`SEEN_UNDER_POINTS` points over that part of its footprint,
    between the floor and its bottom (a :data:`CONTACT_GAP` off each), near no detected box."""
    rotation = rotation_matrix(box.orientation_xyzw)
    half = box.size / 2.0
    reach = np.abs(rotation[:2, :2]) @ half[:2] + CONTACT_GAP
    points = columns.points[columns.indices_over(box.position[:2] - reach, box.position[:2] + reach)]
    lowest = float(box.position[2] - np.abs(rotation[2]) @ half)
    local = (points[:, :2] - box.position[:2]) @ rotation[:2, :2]
    under = (
        (points[:, 2] > CONTACT_GAP)
        & (points[:, 2] < lowest - CONTACT_GAP)
        & np.all(np.abs(local) <= half[:2] + CONTACT_GAP, axis=1)
        & ((points[:, :2] - edge) @ direction > 0.0)
    )
    candidates = points[under]
    for other in boxes:
        if len(candidates) < SEEN_UNDER_POINTS:
            return False
        candidates = candidates[_distances(candidates, other)[0] > CONTACT_GAP]
    return len(candidates) >= SEEN_UNDER_POINTS


def _held_overhang(contacts: np.ndarray, edge: np.ndarray, direction: np.ndarray, lowest: float) -> float:
    """The largest overhang (metres) a push at ``contacts`` can keep an upright box from tipping over
    ``edge``, with :data:`FRICTION` at that push and at the edge: about the edge, the weight's
    moment ``m g d`` against the push ``N`` at height ``h`` and its friction ``mu N`` at reach ``w``,
    and the push no more than the edge's friction holds, ``N <= mu m g / (1 + mu^2)``, so
    ``d <= mu (h + mu w) / (1 + mu^2)``. A larger one rests on something nobody detected.

    Examples
    --------
    >>> contacts = np.array([[0.3, 0.0, 0.45]])  # 0.25 m above the edge, 0.3 m beyond it
    >>> round(_held_overhang(contacts, np.zeros(2), np.array([1.0, 0.0]), 0.2), 3)
    0.16
    """
    height = float(contacts[:, 2].max()) - lowest
    reach = float(((contacts[:, :2] - edge) @ direction).max())
    return FRICTION * (height + FRICTION * reach) / (1.0 + FRICTION**2)


def _tipping(
    box: Box, base: dict[int, np.ndarray], *, exclude: int | None
) -> tuple[float, np.ndarray, np.ndarray, bool] | None:
    """Whether the box tips over its base (without the contacts of ``exclude``): how far its
    centre lies outside, the base's nearest point, the unit direction of the overhang and
    whether the base is the floor alone; None when it stands or nothing is known under it."""
    parts = {key: part for key, part in base.items() if key != exclude and len(part)}
    if not parts:  # nothing known under it: the floating warning's business
        return None
    overhang, edge = _outside_hull(box.position[:2], convex_hull_2d(np.concatenate(list(parts.values()))))
    if overhang <= MIN_OVERHANG:
        return None
    return overhang, edge, (box.position[:2] - edge) / overhang, set(parts) == {_FLOOR}


def raise_tip_supports(
    probabilities: np.ndarray, objects: Sequence[str], found: Sequence[TipSupport]
) -> tuple[np.ndarray, list[str]]:
    """``P(X supports Y)`` raised to at least :data:`TIP_SUPPORT_PROBABILITY` for each
    finding, and one sentence per raised pair.

    Examples
    --------
    >>> p = np.array([[0.0, 0.05], [0.01, 0.0]])
    >>> raised, said = raise_tip_supports(p, ["upright", "lean"], [TipSupport("lean", "upright", 0.04, True)])
    >>> raised[0, 1], said[0].endswith("raised from 0.05 to 0.65")
    (np.float64(0.65), True)
    """
    position = {name: k for k, name in enumerate(_known_ids(objects, {}, "objects", ""))}
    for finding in found:
        _known_ids([finding.supporter, finding.held], position, "found", "objects")
    raised = np.array(probabilities, dtype=np.float64, copy=True)
    said: list[str] = []
    for finding in found:
        supporter, held = position[finding.supporter], position[finding.held]
        before = float(raised[supporter, held])
        if before < TIP_SUPPORT_PROBABILITY:
            raised[supporter, held] = TIP_SUPPORT_PROBABILITY
            said.append(
                f"{finding.describe()}: P({finding.supporter} supports {finding.held}) raised from "
                f"{before:.2f} to {TIP_SUPPORT_PROBABILITY:.2f}"
            )
    return raised, said
