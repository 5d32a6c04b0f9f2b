"""Physics on the belief: what a pick would move, tried in the engine on what the robot sees.

The physics look-ahead of the container experiment (:func:`unstack.sim.unloading.probe_removals`)
knows the true pile. A robot knows less: the detected boxes at the poses its detector reports,
and a point cloud. This module builds a physics world from that alone (issue 34, route b):

* every detected box at its reported pose, as a dynamic body of the typical mass (the
  settings' mean; a detector reports no masses);
* the cloud points no detected box explains and no container wall holds
  (:func:`unstack.understanding.hidden_load.unexplained_points`) are binned into columns of
  :data:`CELL` metres across; in each column, the points between two detected boxes (or
  between the floor and the lowest detected box, or above the highest) are one stretch of
  unseen material, filled down to what lies under it: a detected box's top or the floor;
* stretches standing on the floor are **fixed** blocks (something unseen holds them up;
  the robot will not move it by taking a detected box); the stretches resting on one
  detected box are together **one dynamic body** on it -- the load nobody detected, which
  falls when that box is taken (its footprint clipped to the box's, its height the median
  top of its stretches).

A box the robot sees standing still that falls in the belief world rests or leans on boxes
nobody sees (behind the front of the pile). First the space under it that no detected box
fills is taken to be solid (:func:`unseen_supports`); a box that still falls leans on
something unseen and is fixed in place, and a removal that touches it counts it as moved --
the belief cannot say what it would do, only that it leant on the removed box
(:data:`HOLD_ROUNDS` rounds of settling and looking).

With ``fill="occlusion"`` the unseen material is instead the space the sensor cannot see
next to the boxes in the belief (:func:`unstack.understanding.occlusion.occluded_space`: behind
the visible surface, from the sensor's position), all of it fixed, and nothing is held or
supported afterwards: boxes deeper in the container and under others are taken to fill the
space the sensor cannot see into, as a pile packed from the back wall does.

With ``fill="sampled"`` that space is mostly air, as it is in the simulated piles (of the
space the sensor cannot see next to the boxes in view on the first scan, 18 % lies inside a
hidden box on four-size piles, 23 % on dropped ones, 14 % mixed, 11 % walls, 2 % stacked:
``benchmarks/occlusion_truth.py`` on 8 development piles each): each belief world keeps each run of
unseen cells (a block of :func:`occlusion_blocks`) with probability :data:`OCCUPANCY`, drawn
independently, every box of the typical mass; the expected moves are the mean over the
worlds -- a hidden box holds a visible one up in some worlds and not in others.

With ``fill="scaled"`` the chance comes from the scene instead: :data:`OCCUPANCY_PER_CUBIC_METRE`
times the volume of that space, at most :data:`OCCUPANCY_CAP` (:func:`scaled_occupancy`). A
pile deep enough to hide much space hides boxes in it; a sliver behind a stack is air. On the
first scans of 50 development piles (10 per family) the occupied share grows with the unseen
volume (correlation 0.81 pile by pile, share = 0.213 x volume in cubic metres, least squares);
on 30 fresh piles of each family the rule gives family means of 0.16 four (true 0.18), 0.04
stacked (0.07), 0.15 mixed (0.14), 0.12 walls (0.13) (``benchmarks/occlusion_truth.py``).

With ``fill="faces"`` the space is sampled as ``scaled`` does, and a surface the cloud shows that
no detected box explains is taken for a box nobody detected: of each run of unseen space within
:data:`FACE_REACH` of such a surface (above the floor), the first :data:`FACE_DEPTH` from the
sensor's side is solid in every world (:func:`behind_seen_faces`). With a detector that misses
half the boxes, 58-76 % of that space lies inside a hidden box on 8 development piles of each
family, against 16-35 % of the rest (``benchmarks/occlusion_truth.py --misses 0.5``).

With ``fill="cartons"`` the faces fill's solid fronts stay, and instead of runs kept one by one
each world draws whole hidden cartons into the unseen space (:func:`carton_blocks`,
:func:`unstack.understanding.hidden_cartons.draw_hidden_cartons`: the sizes of the boxes in
view, each resting on something, up to the ``scaled`` share): a truer hypothesis of where hidden
boxes stand (``benchmarks/carton_truth.py``), measured no better as the physics veto's belief
(results page, maker ``hybrid_cartons_free``).

The world settles for :data:`~unstack.sim.unloading.RESETTLE_SECONDS`; then each candidate's
removal is tried as the look-ahead tries it (the same horizon, thresholds and parking, the
state restored after each try), counting the detected boxes and the hidden-load bodies that
move more than 2 cm or turn more than 5 degrees. This is done in :data:`BELIEF_WORLDS`
worlds: the first with the typical mass, the others with masses drawn from the settings'
range (a detector reports no masses, and a pile near a tipping point answers differently).
:func:`belief_choice` takes the candidate whose removal
moves the fewest on average, ties to the box resting highest.

Examples
--------
>>> from unstack.scene import Box, Scene
>>> from unstack.understanding.clouds import surface_cloud
>>> boxes = [Box("low", [0.4, 0.4, 0.3], [1.0, 0.0, 0.15]), Box("high", [0.4, 0.4, 0.3], [1.0, 0.0, 0.45])]
>>> scene = Scene(boxes, surface_cloud(boxes, viewpoint=[-2.0, 0.0, 1.5], seed=0), ["low"])
>>> [block.resting_on for block in belief_blocks(scene)]   # "high" is not detected: load on "low"
['low']
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from unstack.errors import UnstackError
from unstack.scene import Box, Scene

__all__ = [
    "CELL",
    "FACE_DEPTH",
    "FACE_REACH",
    "FILLS",
    "OCCUPANCY",
    "OCCUPANCY_CAP",
    "OCCUPANCY_PER_CUBIC_METRE",
    "BeliefBlock",
    "BeliefOutcome",
    "behind_seen_faces",
    "belief_blocks",
    "belief_choice",
    "belief_removals",
    "belief_settings",
    "carton_blocks",
    "choose_by_expected_moves",
    "container_interior",
    "drawn_worlds",
    "occlusion_blocks",
    "removals_in_world",
    "restless_boxes",
    "scaled_occupancy",
    "seen_boxes",
    "unseen_supports",
]

#: Width of the columns the unexplained points are binned into (metres).
CELL = 0.08
#: Points lower than this are the floor (metres).
FLOOR_LEVEL = 0.05
#: A stretch of unexplained points whose lowest point is within this of a detected box's top
#: rests on that box (metres); the box's footprint is grown by it to catch its load's front face.
REST_TOLERANCE = 0.08
#: Blocks are made this much smaller than their column on every side (metres), so that a
#: fixed block does not touch the detected boxes beside it before anything moves.
CLEARANCE = 0.005
#: Fewer unexplained points than this in a column are noise.
MIN_POINTS = 3
#: Rounds of fixing in place the boxes a belief world lets fall (:func:`belief_removals`).
HOLD_ROUNDS = 3
#: What the belief puts where the robot sees no box: the cloud's unexplained points as columns
#: and hidden loads (:func:`belief_blocks`), all the space the sensor cannot see next to the
#: boxes it sees (:func:`occlusion_blocks`), or that space sampled: each run of it kept with a
#: fixed chance (:data:`OCCUPANCY`) or one scaled by its volume (:func:`scaled_occupancy`), the
#: space behind surfaces no detected box explains solid (:func:`behind_seen_faces`), or that
#: space solid and whole hidden cartons drawn into the rest (:func:`carton_blocks`).
FILLS = ("cloud", "occlusion", "sampled", "scaled", "faces", "cartons")
#: Chance that a run of space the sensor cannot see is kept solid in a world of the
#: ``sampled`` fill: about the share of that space hidden boxes fill on the first scan of the
#: simulated piles (2-23 % by family; ``benchmarks/occlusion_truth.py``).
OCCUPANCY = 0.2
#: The ``scaled`` fill's chance per cubic metre of space the sensor cannot see (the least-squares
#: slope on the first scans of 10 development piles of each of five families).
OCCUPANCY_PER_CUBIC_METRE = 0.213
#: The ``scaled`` fill's chance is at most this.
OCCUPANCY_CAP = 0.5
#: A run of unseen space this close to a cloud point no detected box explains (metres) lies
#: behind the face of a box nobody detected (``faces`` fill): the cells start three quarters of
#: an occlusion cell behind the surface, and a cell is 6 cm.
FACE_REACH = 0.08
#: How deep behind such a face the ``faces`` fill keeps the run solid (metres): about a carton.
FACE_DEPTH = 0.3
#: How :func:`belief_choice` picks: the fewest expected moves, or height vetoed by them.
BELIEF_RULES = ("fewest", "veto")
#: The ``veto`` rule passes over the highest box when its removal is expected to move this many.
BELIEF_VETO = 1.0
#: Belief worlds per decision (:func:`belief_removals`).
BELIEF_WORLDS = 4
#: A box with at least this many cloud points on it (within :data:`SEEN_MARGIN`) is seen.
SEEN_POINTS = 20
#: How far from a box's surface (metres) a cloud point still lies on it.
SEEN_MARGIN = 0.005


@dataclass(frozen=True)
class BeliefBlock:
    """Unseen material put into the belief world: a fixed block or a detected box's hidden load.

    Made by the fills (:func:`belief_blocks`, :func:`occlusion_blocks`, :func:`carton_blocks`,
    :func:`unseen_supports`) and placed in the engine by :func:`removals_in_world`.

    Attributes
    ----------
    size, center : numpy.ndarray, shape (3,)
        Axis-aligned extents and centre (metres).
    resting_on : str or None
        The detected box the block rests on (a dynamic body) or None (fixed, on the floor).
    """

    size: np.ndarray
    center: np.ndarray
    resting_on: str | None


@dataclass(frozen=True)
class BeliefOutcome:
    """What removing one candidate does in the belief world."""

    box: str
    moved: tuple[str, ...]  # in the first world: detected boxes moved, ``load:<box>`` for a hidden load
    expected_moved: float  # the mean over the belief worlds


def _stretches(zs: np.ndarray, floors: list[tuple[float, float]]) -> list[tuple[float, float, float]]:
    """Split a column's point heights by the detected boxes' z-intervals over it.

    Returns ``(base, lowest, top)`` per stretch: the height of what lies under it (a box's
    top or 0), its lowest and its highest point.
    """
    intervals = sorted(floors)
    result = []
    base = 0.0
    edges = [*intervals, (np.inf, np.inf)]
    for bottom, top in edges:
        inside = zs[(zs > base) & (zs < bottom)]
        if len(inside) >= MIN_POINTS:
            result.append((base, float(inside.min()), float(inside.max())))
        base = max(base, top)
    return result


def belief_blocks(scene: Scene, detected: Sequence[str] | None = None) -> list[BeliefBlock]:
    """The unseen material of a scene as blocks (see the module docstring).

    Parameters
    ----------
    scene : Scene
        Only the detected boxes' poses and the point cloud are used.
    detected : sequence of str, optional
        Box ids to treat as detected instead of ``scene.detected``.

    Returns
    -------
    list of BeliefBlock
        Fixed blocks first (one per column stretch on the floor), then one hidden load per
        detected box that carries one.
    """
    from unstack.geometry import bounding_boxes
    from unstack.understanding.hidden_load import unexplained_points

    ids = list(scene.detected if detected is None else detected)
    boxes = [scene.box(box_id) for box_id in ids]
    points = scene.points
    if len(points) == 0:
        return []
    points = points[unexplained_points(points, boxes) & (points[:, 2] > FLOOR_LEVEL)]
    if len(points) == 0:
        return []
    bounds = bounding_boxes(boxes) if boxes else np.zeros((0, 6))
    cells = np.floor(points[:, :2] / CELL).astype(np.int64)
    order = np.lexsort((cells[:, 1], cells[:, 0]))
    cells, points = cells[order], points[order]
    starts = np.flatnonzero(np.any(np.diff(cells, axis=0) != 0, axis=1)) + 1
    fixed: list[BeliefBlock] = []
    loads: dict[int, list[tuple[np.ndarray, float]]] = {}
    for chunk in np.split(np.arange(len(points)), starts):
        low = cells[chunk[0]] * CELL
        high = low + CELL
        over = np.flatnonzero(
            np.all(bounds[:, :2] < high + REST_TOLERANCE, axis=1)
            & np.all(bounds[:, 3:5] > low - REST_TOLERANCE, axis=1)
        )
        inside = [k for k in over if np.all(bounds[k, :2] < high) and np.all(bounds[k, 3:5] > low)]
        for base, lowest, top in _stretches(points[chunk, 2], [(bounds[k, 2], bounds[k, 5]) for k in inside]):
            resting = [
                k for k in over if abs(bounds[k, 5] - base) < 1e-9 or 0.0 <= lowest - bounds[k, 5] < REST_TOLERANCE
            ]
            if resting and lowest > FLOOR_LEVEL + REST_TOLERANCE:
                carrier = int(max(resting, key=lambda k: bounds[k, 5]))
                loads.setdefault(carrier, []).append((np.array([*low, *high]), top))
                continue
            size = np.array([CELL - 2 * CLEARANCE, CELL - 2 * CLEARANCE, top - base - CLEARANCE])
            if size[2] <= 0.01:
                continue
            fixed.append(BeliefBlock(size, np.array([*(low + CELL / 2), base + CLEARANCE + size[2] / 2]), None))
    carried = []
    for k, columns in sorted(loads.items()):
        area = np.array([column for column, _ in columns])
        lower = np.maximum(area[:, :2].min(axis=0), bounds[k, :2]) + CLEARANCE
        upper = np.minimum(area[:, 2:].max(axis=0), bounds[k, 3:5]) - CLEARANCE
        top = float(np.median([top for _, top in columns]))
        height = top - bounds[k, 5]
        if np.any(upper - lower < 0.02) or height < 0.02:
            continue
        size = np.array([*(upper - lower), height - CLEARANCE])
        center = np.array([*((upper + lower) / 2), bounds[k, 5] + CLEARANCE + size[2] / 2])
        carried.append(BeliefBlock(size, center, ids[k]))
    return fixed + carried


def seen_boxes(scene: Scene) -> list[str]:
    """The boxes of the scene the point cloud shows: at least :data:`SEEN_POINTS` points on each.

    A detector that reports every box in view reports these; the scene's ``detected`` may be
    fewer (the container experiment hands its policies the reachable ones).

    Examples
    --------
    >>> from unstack.scene import Box, Scene
    >>> from unstack.understanding.clouds import surface_cloud
    >>> front = Box("front", [0.4, 0.4, 0.4], [1.0, 0.0, 0.2])
    >>> behind = Box("behind", [0.4, 0.4, 0.4], [1.4, 0.0, 0.2])
    >>> seen_boxes(Scene([front, behind], surface_cloud([front], viewpoint=[-2.0, 0.0, 0.2], seed=0), ["front"]))
    ['front']
    """
    from unstack.geometry import points_in_box

    return [
        box.id for box in scene.boxes if int(points_in_box(scene.points, box, margin=SEEN_MARGIN).sum()) >= SEEN_POINTS
    ]


def container_interior(settings: Any) -> list[list[float]]:
    """The lowest and highest corner of the inside of ``settings``' container (the door at x = 0).

    Examples
    --------
    >>> from unstack.sim.settings import SimulationSettings
    >>> container_interior(SimulationSettings())
    [[0.0, -1.175, 0.0], [2.0, 1.175, 2.39]]
    """
    container = settings.container
    return [[0.0, -container.width / 2.0, 0.0], [container.depth, container.width / 2.0, container.height]]


def occlusion_blocks(scene: Scene, settings: Any = None) -> list[BeliefBlock]:
    """The space the sensor cannot see next to the scene's detected boxes, as fixed blocks.

    :func:`unstack.understanding.occlusion.occluded_space` from the scene's cloud, its
    detected boxes, the sensor's position and the container's inside (of ``settings``,
    default: the scene's own).

    Examples
    --------
    >>> from unstack.scene import Box, Scene
    >>> from unstack.understanding.clouds import surface_cloud
    >>> step = [Box("front", [0.4, 0.6, 0.4], [0.6, 0.0, 0.2]), Box("hidden", [0.4, 0.6, 0.3], [1.0, 0.0, 0.15]),
    ...         Box("on_hidden", [0.4, 0.6, 0.3], [1.0, 0.0, 0.45])]
    >>> cloud = surface_cloud(step, spacing=0.005, seed=0)   # seen from the default sensor's position
    >>> blocks = occlusion_blocks(Scene(step, cloud, ["front", "on_hidden"]))
    >>> any(np.all(np.abs(block.center - [1.0, 0.0, 0.15]) <= block.size / 2) for block in blocks)   # fills "hidden"
    True
    """
    from unstack.understanding.occlusion import occluded_space

    simulation = belief_settings(scene, settings)
    space = occluded_space(
        scene.points,
        [scene.box(box_id) for box_id in scene.detected],
        viewpoint=simulation.sensor.position,
        interior=container_interior(simulation),
    )
    return [BeliefBlock(size, center, None) for size, center in zip(space.sizes, space.centers, strict=True)]


def scaled_occupancy(blocks: Sequence[BeliefBlock]) -> float:
    """The ``scaled`` fill's chance that a run of unseen space is solid, from the space's volume.

    :data:`OCCUPANCY_PER_CUBIC_METRE` times the blocks' total volume, at most :data:`OCCUPANCY_CAP`.

    Examples
    --------
    >>> sliver = BeliefBlock(np.array([0.1, 1.0, 1.0]), np.zeros(3), None)
    >>> round(scaled_occupancy([sliver]), 4), scaled_occupancy([sliver] * 40)
    (0.0213, 0.5)
    """
    volume = float(sum(np.prod(block.size) for block in blocks))
    return min(OCCUPANCY_CAP, OCCUPANCY_PER_CUBIC_METRE * volume)


def behind_seen_faces(scene: Scene, blocks: Sequence[BeliefBlock]) -> np.ndarray:
    """Which blocks of unseen space lie behind a surface the cloud shows and no detected box explains.

    A block is behind such a face when a cloud point higher than the floor that no detected
    box explains and no container wall holds
    (:func:`unstack.understanding.hidden_load.unexplained_points`) lies within
    :data:`FACE_REACH` of it.

    Examples
    --------
    >>> from unstack.understanding.clouds import surface_cloud
    >>> seen, missed = Box("seen", [0.4, 0.4, 0.4], [1.0, -0.4, 0.2]), Box("missed", [0.4, 0.4, 0.4], [1.0, 0.4, 0.2])
    >>> scene = Scene([seen, missed], surface_cloud([seen, missed], spacing=0.01, seed=0), ["seen"])
    >>> blocks = [BeliefBlock(np.array([0.3, 0.3, 0.3]), np.array([1.05, y, 0.2]), None) for y in (-0.4, 0.4)]
    >>> behind_seen_faces(scene, blocks).tolist()   # the first inside the detected box: nothing unexplained
    [False, True]
    """
    from unstack.understanding.hidden_load import unexplained_points

    points = scene.points
    detected = [scene.box(box_id) for box_id in scene.detected]
    loose = points[unexplained_points(points, detected) & (points[:, 2] > FLOOR_LEVEL)] if len(points) else points
    # sorted by depth, the points within a block's reach in x are one slice
    depths, across, heights = (np.ascontiguousarray(axis) for axis in loose[np.argsort(loose[:, 0], kind="stable")].T)
    behind = np.zeros(len(blocks), dtype=bool)
    for k, block in enumerate(blocks):
        low = block.center - block.size / 2 - FACE_REACH
        high = block.center + block.size / 2 + FACE_REACH
        first, last = np.searchsorted(depths, low[0], side="left"), np.searchsorted(depths, high[0], side="right")
        y, z = across[first:last], heights[first:last]
        behind[k] = bool(np.any((y >= low[1]) & (y <= high[1]) & (z > low[2]) & (z < high[2])))
    return behind


def _faced(blocks: Sequence[BeliefBlock], behind: np.ndarray) -> tuple[list[BeliefBlock], list[BeliefBlock]]:
    """Each block behind a seen face split at :data:`FACE_DEPTH` from its sensor side (its lowest x).

    Returns the solid fronts and, per block in order, what the sampling draws for (the rest of a
    split block, the whole of any other; a block wholly within the depth has a rest of zero size).
    """
    fronts, rests = [], []
    for block, faced in zip(blocks, behind, strict=True):
        if not faced:
            rests.append(block)
            continue
        start = block.center[0] - block.size[0] / 2
        end = block.center[0] + block.size[0] / 2
        cut = min(end, start + FACE_DEPTH)
        fronts.append(
            BeliefBlock(
                np.array([cut - start, *block.size[1:]]), np.array([(start + cut) / 2, *block.center[1:]]), None
            )
        )
        rests.append(
            BeliefBlock(np.array([end - cut, *block.size[1:]]), np.array([(cut + end) / 2, *block.center[1:]]), None)
        )
    return fronts, rests


def carton_blocks(
    scene: Scene,
    settings: Any,
    share: float,
    rng: np.random.Generator,
    solid: Sequence[BeliefBlock] = (),
    worlds: int = 1,
) -> list[list[BeliefBlock]]:
    """Hypotheses of whole hidden cartons next to the scene's detected boxes, as fixed blocks, one per world.

    :func:`unstack.understanding.hidden_cartons.draw_hidden_cartons` from the scene's cloud,
    its detected boxes, the sensor's position and the container's inside (of ``settings``),
    covering ``share`` of the unseen space near them, around the blocks ``solid`` already
    placed (the ``cartons`` fill: the faces fill's solid fronts, and these drawn anew in every world).

    Examples
    --------
    >>> from unstack.scene import Box, Scene
    >>> from unstack.understanding.clouds import surface_cloud
    >>> front = Box("front", [0.4, 0.4, 0.4], [0.6, 0.0, 0.2])
    >>> behind = Box("behind", [0.4, 0.4, 0.4], [1.0, 0.0, 0.2])
    >>> scene = Scene([front, behind], surface_cloud([front, behind], spacing=0.005, seed=0), ["front"])
    >>> [blocks] = carton_blocks(scene, belief_settings(scene), 1.0, np.random.default_rng(0))
    >>> len(blocks) > 0 and all(block.resting_on is None for block in blocks)
    True
    """
    from unstack.understanding.hidden_cartons import CARTON_REACH, draw_hidden_cartons
    from unstack.understanding.occlusion import occlusion_grid

    interior = container_interior(settings)
    obstacles = np.array([[*(b.center - b.size / 2), *(b.center + b.size / 2)] for b in solid]).reshape(-1, 6)
    boxes = [scene.box(box_id) for box_id in scene.detected]
    grid = occlusion_grid(
        scene.points, boxes, viewpoint=settings.sensor.position, interior=interior, reach=CARTON_REACH
    )
    hypotheses = []
    for _ in range(worlds):
        cartons = draw_hidden_cartons(grid, boxes, interior=interior, share=share, rng=rng, obstacles=obstacles)
        hypotheses.append(
            [BeliefBlock(size, center, None) for size, center in zip(cartons.sizes, cartons.centers, strict=True)]
        )
    return hypotheses


def belief_settings(scene: Scene, settings: Any = None) -> Any:
    """The simulation settings belief worlds of ``scene`` are built with: ``settings`` when
    given, else a simulated scene's own (``metadata.settings``), else the defaults."""
    from unstack.sim.settings import SimulationSettings, scene_settings

    if settings is not None:
        return settings
    return scene_settings(scene) or SimulationSettings()


def _disturbed(before: tuple[np.ndarray, np.ndarray], after: tuple[np.ndarray, np.ndarray], truth: Any) -> np.ndarray:
    """Which bodies moved more than the ground truth's thresholds between two pose sets."""
    from unstack.geometry import rotation_angles_deg

    moved: np.ndarray = (np.linalg.norm(after[0] - before[0], axis=1) > truth.displacement_threshold) | (
        rotation_angles_deg(before[1], after[1]) > truth.rotation_threshold_deg
    )
    return moved


def _bottom_heights(box: Box, xy: np.ndarray) -> np.ndarray:
    """Height of the box's underside above each point ``xy`` (nan where a vertical line misses it)."""
    from unstack.geometry import rotation_matrix

    rotation = rotation_matrix(box.orientation_xyzw)
    half = np.asarray(box.size, dtype=np.float64) / 2.0
    origins = (np.column_stack([xy, np.zeros(len(xy))]) - box.position) @ rotation  # in the box's frame
    direction = rotation[2]  # the world's up in the box's frame
    low = np.full(len(xy), -np.inf)
    high = np.full(len(xy), np.inf)
    for axis in range(3):
        if abs(direction[axis]) < 1e-9:
            outside = np.abs(origins[:, axis]) > half[axis]
            low[outside], high[outside] = np.inf, -np.inf
            continue
        first = (-half[axis] - origins[:, axis]) / direction[axis]
        second = (half[axis] - origins[:, axis]) / direction[axis]
        low = np.maximum(low, np.minimum(first, second))
        high = np.minimum(high, np.maximum(first, second))
    return np.where(low <= high, low, np.nan)


def unseen_supports(box: Box, others: Sequence[Box]) -> list[BeliefBlock]:
    """Fixed blocks filling the space under ``box`` where no box of ``others`` stands.

    A box the robot sees standing still that falls in the belief world rests on something
    nobody sees; the space under it that no detected box fills is taken to be that.

    Examples
    --------
    >>> from unstack.scene import Box
    >>> floating = Box("up", [0.4, 0.4, 0.3], [1.0, 0.0, 0.55])
    >>> half_under = Box("under", [0.2, 0.4, 0.4], [0.9, 0.0, 0.2])
    >>> blocks = unseen_supports(floating, [half_under])
    >>> bool(min(block.center[0] - block.size[0] / 2 for block in blocks) >= 1.0)   # only the other half
    True
    """
    from unstack.geometry import bounding_boxes

    bound = bounding_boxes([box])[0]
    others_bounds = bounding_boxes(list(others)) if others else np.zeros((0, 6))
    xs = np.arange(np.floor(bound[0] / CELL), np.ceil(bound[3] / CELL)) * CELL + CELL / 2
    ys = np.arange(np.floor(bound[1] / CELL), np.ceil(bound[4] / CELL)) * CELL + CELL / 2
    centres = np.array([(x, y) for x in xs for y in ys]).reshape(-1, 2)
    bottoms = _bottom_heights(box, centres)
    blocks = []
    for centre, bottom in zip(centres, bottoms, strict=True):
        if not np.isfinite(bottom) or bottom < 0.02:
            continue
        low, high = centre - CELL / 2, centre + CELL / 2
        under = np.all(others_bounds[:, :2] < high, axis=1) & np.all(others_bounds[:, 3:5] > low, axis=1)
        under &= others_bounds[:, 2] < bottom
        if under.any():
            continue  # a detected box stands in this cell: it is the support there, or the belief's error
        height = bottom - 2 * CLEARANCE
        size = np.array([CELL - 2 * CLEARANCE, CELL - 2 * CLEARANCE, height])
        blocks.append(BeliefBlock(size, np.array([*centre, CLEARANCE + height / 2]), None))
    return blocks


def _build(
    world: Any, scene: Scene, blocks: Sequence[BeliefBlock], masses: dict[str, float], held: set[str]
) -> dict[str, int]:
    """Put the detected boxes, the blocks and the hidden loads in ``world``; body ids by name."""
    bodies = {}
    for box_id in scene.detected:
        box = scene.box(box_id)
        mass = 0.0 if box_id in held else masses[box_id]
        bodies[box_id] = world.add_box(box.size, box.position, box.orientation_xyzw, mass=mass)
    typical_mass = float(np.mean(list(masses.values()))) if masses else 1.0
    for block in blocks:
        if block.resting_on is not None:
            volume = float(np.prod(scene.box(block.resting_on).size))
            load_mass = typical_mass * min(1.0, float(np.prod(block.size)) / volume)
            bodies[f"load:{block.resting_on}"] = world.add_box(block.size, block.center, [0, 0, 0, 1], mass=load_mass)
    fixed = [block for block in blocks if block.resting_on is None]
    world.add_fixed_blocks([block.size for block in fixed], [block.center for block in fixed])
    return bodies


def _falling(world: Any, bodies: dict[str, int], truth: Any) -> set[str]:
    """The bodies that move, with nothing taken, over a settle and a horizon."""
    from unstack.sim.ground_truth import run_horizon
    from unstack.sim.unloading import RESETTLE_SECONDS

    names = list(bodies)
    every = [bodies[name] for name in names]
    start = world.poses(every)
    world.step(RESETTLE_SECONDS)
    run_horizon(world, truth, every)
    return {names[k] for k in np.flatnonzero(_disturbed(start, world.poses(every), truth))}


def removals_in_world(
    scene: Scene,
    blocks: list[BeliefBlock],
    tried: list[str],
    simulation: Any,
    rng: np.random.Generator | None,
    hold_rounds: int = HOLD_ROUNDS,
    net: bool = False,
) -> dict[str, tuple[str, ...]]:
    """One belief world: build, support or hold what it cannot hold, try each removal and undo it.

    The detected boxes of ``scene`` (free to move) and ``blocks`` (fixed, or a detected box's
    hidden load) in a world of ``simulation``'s settings; ``hold_rounds`` rounds of supporting,
    then holding, a detected box that falls with nothing taken (the ``cloud`` fill's). ``rng``
    None: every detected box of the typical mass; else masses drawn uniformly from the
    settings' range. ``net``: the bodies that move in this world with nothing taken (over the
    same horizon) are not counted for any candidate. Returns what moved per candidate of ``tried``.

    Examples
    --------
    >>> column = [Box("low", [0.4, 0.4, 0.3], [1.0, 0.0, 0.15]), Box("top", [0.4, 0.4, 0.3], [1.0, 0.0, 0.45])]
    >>> scene = Scene(column, np.zeros((0, 3)), ["low", "top"])
    >>> removals_in_world(scene, [], ["low", "top"], belief_settings(scene), None, 0)
    {'low': ('top',), 'top': ()}
    """
    from unstack.sim.ground_truth import PARKING, run_horizon
    from unstack.sim.unloading import RESETTLE_SECONDS
    from unstack.sim.world import PhysicsWorld

    truth = simulation.ground_truth
    low_mass, high_mass = simulation.pile.mass_range
    masses = {
        box_id: (low_mass + high_mass) / 2.0 if rng is None else float(rng.uniform(low_mass, high_mass))
        for box_id in scene.detected
    }
    detected_boxes = [scene.box(box_id) for box_id in scene.detected]
    held: set[str] = set()
    supported: set[str] = set()
    all_blocks = list(blocks)
    for _ in range(hold_rounds):  # what falls in the belief stands on, or leans on, something unseen
        with PhysicsWorld(simulation, door=False) as world:
            falling = _falling(world, _build(world, scene, all_blocks, masses, held), truth) - held
        falling = {name for name in falling if not name.startswith("load:")}
        if not falling:
            break
        fresh = falling - supported
        if fresh:  # first: the unseen space under a falling box holds it
            for box_id in sorted(fresh):
                others = [box for box in detected_boxes if box.id != box_id]
                all_blocks += unseen_supports(scene.box(box_id), others)
            supported |= fresh
        else:  # still falling on its supports: it leans on something unseen; fixed in place
            held |= falling
    with PhysicsWorld(simulation, door=False) as world:
        client = world.client
        bodies = _build(world, scene, all_blocks, masses, held)
        names = list(bodies)
        world.step(RESETTLE_SECONDS)
        state = client.saveState()
        outcomes = {}
        try:
            anyway: set[str] = set()
            if net:
                watched_names = [name for name in names if name not in held]
                watched = [bodies[name] for name in watched_names]
                before = world.poses(watched)
                run_horizon(world, truth, watched)
                anyway = {watched_names[k] for k in np.flatnonzero(_disturbed(before, world.poses(watched), truth))}
                client.restoreState(stateId=state)
            for box_id in tried:
                watched_names = [name for name in names if name != box_id and name not in held]
                watched = [bodies[name] for name in watched_names]
                leaning = tuple(
                    name for name in sorted(held - {box_id}) if client.getContactPoints(bodies[box_id], bodies[name])
                )
                before = world.poses(watched)
                client.resetBasePositionAndOrientation(bodies[box_id], PARKING.tolist(), [0.0, 0.0, 0.0, 1.0])
                client.resetBaseVelocity(bodies[box_id], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0])
                run_horizon(world, truth, watched)
                moved = _disturbed(before, world.poses(watched), truth)
                outcomes[box_id] = (
                    tuple(watched_names[k] for k in np.flatnonzero(moved) if watched_names[k] not in anyway) + leaning
                )
                client.restoreState(stateId=state)
        finally:
            client.removeState(state)
    return outcomes


def drawn_worlds(
    scene: Scene, simulation: Any, fill: str, occupancy: float, worlds: int, rng: np.random.Generator
) -> list[list[BeliefBlock]]:
    """The fixed blocks of each belief world of a fill that draws the unseen space (``sampled``,
    ``scaled``, ``faces``, ``cartons``): what :func:`belief_removals` builds its worlds of.

    Examples
    --------
    >>> from unstack.understanding.clouds import surface_cloud
    >>> front = Box("front", [0.4, 0.4, 0.4], [0.6, 0.0, 0.2])
    >>> behind = Box("behind", [0.4, 0.4, 0.4], [1.0, 0.0, 0.2])
    >>> scene = Scene([front, behind], surface_cloud([front, behind], spacing=0.005, seed=0), ["front"])
    >>> worlds = drawn_worlds(scene, belief_settings(scene), "cartons", OCCUPANCY, 2, np.random.default_rng(0))
    >>> len(worlds), all(block.resting_on is None for blocks in worlds for block in blocks)
    (2, True)
    """
    from unstack.understanding.occlusion import THINNEST  # the rest of a block split at a face may be thinner

    space = occlusion_blocks(scene, simulation)
    kept_share = occupancy if fill == "sampled" else scaled_occupancy(space)
    solid, drawn = _faced(space, behind_seen_faces(scene, space)) if fill in ("faces", "cartons") else ([], space)
    if fill == "cartons":
        return [solid + cartons for cartons in carton_blocks(scene, simulation, kept_share, rng, solid, worlds)]
    return [
        solid + [block for block in drawn if rng.random() < kept_share and block.size[0] > THINNEST]
        for _ in range(worlds)
    ]


def restless_boxes(
    scene: Scene, *, seed: int = 0, settings: Any = None, fill: str = "faces", occupancy: float = OCCUPANCY
) -> tuple[str, ...]:
    """The detected boxes that move in the first belief world with nothing taken.

    A belief world built from poses that cannot stand as reported (boxes inside one another,
    a box floating or reaching into another) does not come to rest: what such boxes do is
    counted in every candidate's expected moves (:func:`belief_removals`, the same first
    world: the same ``seed``, ``settings``, ``fill`` and ``occupancy``).

    Parameters
    ----------
    scene, seed, settings, occupancy
        As in :func:`belief_removals`.
    fill : {"occlusion", "sampled", "scaled", "faces", "cartons"}
        A fill without the cloud fill's rounds of holding what falls.

    Returns
    -------
    tuple of str
        In the order of ``scene.detected``; empty when the world is at rest.

    Examples
    --------
    >>> import unstack
    >>> restless_boxes(unstack.load("examples/pile5.scene.json"))
    ()
    """
    from unstack.sim.ground_truth import run_horizon
    from unstack.sim.unloading import RESETTLE_SECONDS
    from unstack.sim.world import PhysicsWorld

    if fill not in FILLS or fill == "cloud":
        resting = ", ".join(name for name in FILLS if name != "cloud")
        raise UnstackError(f"unknown belief fill {fill!r} for a rest check; expected one of {resting}")
    simulation = belief_settings(scene, settings)
    if fill == "occlusion":
        blocks = occlusion_blocks(scene, simulation)
    else:
        blocks = drawn_worlds(scene, simulation, fill, occupancy, 1, np.random.default_rng(seed))[0]
    low_mass, high_mass = simulation.pile.mass_range
    masses = {box_id: (low_mass + high_mass) / 2.0 for box_id in scene.detected}
    with PhysicsWorld(simulation, door=False) as world:
        bodies = _build(world, scene, blocks, masses, set())
        world.step(RESETTLE_SECONDS)
        watched = [bodies[box_id] for box_id in scene.detected]
        before = world.poses(watched)
        run_horizon(world, simulation.ground_truth, watched)
        moved = _disturbed(before, world.poses(watched), simulation.ground_truth)
    return tuple(scene.detected[k] for k in np.flatnonzero(moved))


def belief_removals(
    scene: Scene,
    candidates: Sequence[str] | None = None,
    *,
    worlds: int = BELIEF_WORLDS,
    seed: int = 0,
    settings: Any = None,
    fill: str = "cloud",
    occupancy: float = OCCUPANCY,
    net: bool = False,
    draw_masses: bool = False,
) -> dict[str, BeliefOutcome]:
    """What removing each candidate moves in the belief worlds built from ``scene``.

    Parameters
    ----------
    scene : Scene
        The detected boxes (reported poses) and the point cloud; the poses of undetected
        boxes are never read.
    candidates : sequence of str, optional
        Detected boxes to try (default: all detected).
    worlds : int
        Belief worlds: the first with the typical mass and the reported poses, the others
        with masses drawn from the settings' range and poses jittered (a detector reports
        neither masses nor exact poses, and a pile near a tipping point answers differently).
    seed : int
        Seeds the draws of the other worlds.
    settings : SimulationSettings, optional
        Container, friction, time step, masses and the removal thresholds; default: the
        scene's own (``metadata.settings`` of a simulated scene), else the defaults.
    fill : {"cloud", "occlusion", "sampled", "scaled", "faces", "cartons"}
        What stands where no detected box is (:data:`FILLS`, the module docstring); with
        ``"sampled"``, ``"scaled"``, ``"faces"`` or ``"cartons"`` the worlds differ in the unseen space kept,
        not in poses, nor in masses unless ``draw_masses``.
    occupancy : float
        With ``fill="sampled"``: the chance that a run of unseen space is kept solid
        (:data:`OCCUPANCY`); ``"scaled"``, ``"faces"`` and ``"cartons"`` take :func:`scaled_occupancy` instead.
    net : bool
        Count, in each world, only the boxes that stay still there when nothing is taken (a
        world that does not come to rest moves some boxes whatever is taken).
    draw_masses : bool
        With a fill that draws the unseen space: draw each world's masses of the detected boxes
        too, uniformly from the settings' range (seeded apart from the space's draws, which stay
        as they are), instead of the typical mass in every world. Refused with the ``cloud`` and
        ``occlusion`` fills, whose worlds after the first draw masses already.

    Returns
    -------
    dict of str to BeliefOutcome
        ``expected_moved``: the mean over the worlds.
    """
    detected = list(scene.detected)
    tried = detected if candidates is None else list(candidates)
    unknown = [box_id for box_id in tried if box_id not in detected]
    if unknown:
        raise UnstackError(f"{scene.source}: candidates {unknown} are not detected boxes of the scene")
    if worlds < 1:
        raise UnstackError(f"worlds must be at least 1, got {worlds}")
    if fill not in FILLS:
        raise UnstackError(f"unknown belief fill {fill!r}; expected one of {', '.join(FILLS)}")
    if not 0.0 <= occupancy <= 1.0:
        raise UnstackError(f"occupancy must lie between 0 and 1, got {occupancy}")
    if draw_masses and fill in ("cloud", "occlusion"):
        raise UnstackError(
            f"draw_masses is for the fills that draw the unseen space (sampled, scaled, faces, cartons); the {fill} "
            "fill's worlds after the first draw masses already"
        )
    simulation = belief_settings(scene, settings)
    rng = np.random.default_rng(seed)
    if fill in ("sampled", "scaled", "faces", "cartons"):
        mass_rng = np.random.default_rng((seed, 1)) if draw_masses else None
        runs = [
            removals_in_world(scene, blocks, tried, simulation, mass_rng, 0, net)
            for blocks in drawn_worlds(scene, simulation, fill, occupancy, worlds, rng)
        ]
    else:
        blocks = belief_blocks(scene) if fill == "cloud" else occlusion_blocks(scene, simulation)
        hold_rounds = HOLD_ROUNDS if fill == "cloud" else 0
        runs = [
            removals_in_world(scene, blocks, tried, simulation, None if world == 0 else rng, hold_rounds, net)
            for world in range(worlds)
        ]
    return {
        box_id: BeliefOutcome(box_id, runs[0][box_id], float(np.mean([len(run[box_id]) for run in runs])))
        for box_id in tried
    }


def belief_choice(
    scene: Scene, *, rule: str = "fewest", worlds: int = BELIEF_WORLDS, seed: int = 0, settings: Any = None
) -> str:
    """The detected box to take by the belief's expected moves (:data:`BELIEF_RULES`).

    ``fewest``: the box whose removal moves the fewest on average, ties to the box resting
    highest. ``veto``: the box resting highest, unless the belief expects its removal to move
    at least :data:`BELIEF_VETO` boxes; then the fewest.

    Examples
    --------
    >>> from unstack.scene import Box, Scene
    >>> from unstack.understanding.clouds import surface_cloud
    >>> boxes = [Box("low", [0.4, 0.4, 0.3], [1.0, 0.0, 0.15]), Box("high", [0.4, 0.4, 0.3], [1.0, 0.0, 0.45])]
    >>> belief_choice(Scene(boxes, surface_cloud(boxes, viewpoint=[-2.0, 0.0, 1.5], seed=0), ["low", "high"]))
    'high'
    """
    from unstack.geometry import bounding_boxes

    if rule not in BELIEF_RULES:
        raise UnstackError(f"unknown belief rule {rule!r}; expected one of {', '.join(BELIEF_RULES)}")
    outcomes = belief_removals(scene, worlds=worlds, seed=seed, settings=settings)
    resting = {box_id: float(bounding_boxes([scene.box(box_id)])[0, 2]) for box_id in scene.detected}
    expected = {box_id: outcome.expected_moved for box_id, outcome in outcomes.items()}
    return choose_by_expected_moves(expected, resting, rule)


def choose_by_expected_moves(expected: dict[str, float], resting: dict[str, float], rule: str) -> str:
    """The pick of ``rule`` (:data:`BELIEF_RULES`) from each candidate's expected moves and resting height.

    Examples
    --------
    >>> choose_by_expected_moves({"a": 0.0, "b": 0.5}, {"a": 0.0, "b": 0.3}, "fewest")
    'a'
    >>> choose_by_expected_moves({"a": 0.0, "b": 0.5}, {"a": 0.0, "b": 0.3}, "veto")
    'b'
    """
    highest = max(expected, key=lambda box_id: (resting[box_id], box_id))
    if rule == "veto" and expected[highest] < BELIEF_VETO:
        return highest
    return min(expected, key=lambda box_id: (expected[box_id], -resting[box_id], box_id))
