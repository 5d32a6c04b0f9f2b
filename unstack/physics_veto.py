"""Physics on what the robot sees vetoes the default pick (opt-in; needs the physics engine).

The default pick on a scene is the highest box the reasoner believes holds nothing up
(:mod:`unstack.height_veto`). With a physics engine at hand (``pip install 'unstack[sim]'``),
:func:`physics_veto` tries that pick in belief worlds built from the scene -- the detected
boxes at their reported poses, and behind every surface of the cloud that no detected box
explains a carton's depth of solid space, the rest of the unseen space kept at random
(``fill="faces"`` of :func:`unstack.sim.belief.belief_removals`, :data:`PHYSICS_WORLDS`
worlds). When taking it is expected to move at least :data:`PHYSICS_VETO` boxes, the boxes the
reasoner believes hold nothing up (expected cost below :data:`~unstack.height_veto.FREE_COST`)
are tried too and the one expected to move the fewest is taken, ties to the box resting
highest. It is the container maker ``hybrid_faces_free`` of the results page (which starts from
the hybrid's pick, the default's whenever some box is below the free cost; when none is, the
hybrid takes the lowest expected cost and the default the near ties): over the five
families of 30 fresh piles it moved fewer boxes than highest first with every seen box detected
and with a detector missing half the boxes -- on stacked piles in every set of piles, on the
other families in some sets (results page) -- at about 0.35 s a pick for 5 detected boxes (benchmarks
page).

The scene must be in the container frame of the simulator (x from the door inwards, y across
the container about its middle, the floor at z = 0): the container's walls stand in the belief
worlds (:func:`world_settings`: a simulated scene's own, the scene's ``metadata.container``, else
the simulator's 2 m section). A detected box that reaches into them is slid inside for the belief
worlds and the decision warns (a camera's fit of a box seen in part guesses its unseen extent);
one beyond them by more than its own longest side is refused (boxes may spill out of the door,
up to :data:`DOOR_SPILL` before it).

Examples
--------
>>> import unstack
>>> scene = unstack.load("examples/pile5.scene.json")
>>> vetoed = physics_veto(unstack.decide(scene), scene)
>>> vetoed.physics_veto["tried"][0]["box"] == unstack.decide(scene).choice
True
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

import numpy as np

from unstack.errors import InvalidArgument
from unstack.height_veto import FREE_COST, probability_below
from unstack.scene import Scene
from unstack.understanding.plausibility import standing_doubts

if TYPE_CHECKING:
    from unstack.reasoner.decision import Decision

__all__ = [
    "PHYSICS_FILL",
    "PHYSICS_VETO",
    "PHYSICS_WORLDS",
    "expected_moves_in_view",
    "physics_veto",
    "world_settings",
]

#: Belief worlds the pick (and, when it is vetoed, each alternative) is tried in.
PHYSICS_WORLDS = 4
#: A pick whose removal is expected to move at least this many boxes is vetoed.
PHYSICS_VETO = 1.0
#: What stands in the space the sensor cannot see (:data:`unstack.sim.belief.FILLS`).
PHYSICS_FILL = "faces"
#: A detected box may reach this far (metres) into the container's walls, floor or ceiling and
#: stay where it is (poses from a camera do); further, it is slid inside for the belief worlds
#: (a box seen in part is placed from the part seen, its unseen extent a guess) and the
#: decision warns, and beyond by more than its own longest side it is refused.
WALL_SLACK = 0.02
#: Boxes that fell out of the door lie on the floor before it (the simulator's apron reaches 1.5 m),
#: at most this far (metres); a box further out than its own size beyond it is a scene in another frame.
DOOR_SPILL = 2.0
#: Poses that cannot stand named one by one in the warning of a veto not applied, before "N more".
NAMED_DOUBTS = 4


def _expected_moved(
    world_scene: Scene,
    boxes: list[str],
    seed: int,
    settings: Any,
    worlds: int,
    net: bool = False,
    fill: str = PHYSICS_FILL,
    draw_masses: bool = False,
) -> dict[str, float]:
    from unstack.sim.belief import belief_removals

    outcomes = belief_removals(
        world_scene, boxes, worlds=worlds, fill=fill, seed=seed, settings=settings, net=net, draw_masses=draw_masses
    )
    return {box_id: float(outcome.expected_moved) for box_id, outcome in outcomes.items()}


def expected_moves_in_view(
    scene: Scene, boxes: list[str], *, seed: int = 0, worlds: int = PHYSICS_WORLDS
) -> dict[str, float]:
    """The boxes each of ``boxes`` is expected to move in the veto's belief worlds of a closed
    loop's scene (built from its boxes in view, :func:`unstack.sim.unloading.in_view_scene`),
    one box at a time as a caller tries them (the maker ``hybrid_faces_walk``).

    Examples
    --------
    >>> import unstack
    >>> scene = unstack.load("examples/pile5.scene.json")
    >>> moved = expected_moves_in_view(scene, ["b13"], seed=0)
    >>> list(moved), moved["b13"] >= 0.0
    (['b13'], True)
    """
    from unstack.sim.unloading import in_view_scene

    given = in_view_scene(scene)
    settings = world_settings(given)
    built, _ = _inside_container(given, settings)
    return _expected_moved(built, boxes, seed, settings, worlds)


def world_settings(scene: Scene) -> Any:
    """The simulation settings the belief worlds of ``scene`` are built with: a simulated scene's
    own, else the defaults; ``metadata.container`` (``depth``, ``width``, ``height`` in metres)
    sets the container's inner extent.

    Raises
    ------
    InvalidScene
        ``metadata.container`` is not three positive extents.

    Examples
    --------
    >>> import numpy as np
    >>> from unstack.scene import Box
    >>> box = Box("a", [0.4, 0.4, 0.4], [9.0, 0.0, 0.2])
    >>> deep = {"container": {"depth": 12.0, "width": 2.35, "height": 2.39}}  # a 40-foot container
    >>> scene = Scene([box], np.zeros((0, 3)), ["a"], metadata=deep)
    >>> world_settings(scene).container.depth
    12.0
    """
    from unstack.sim.belief import belief_settings
    from unstack.sim.settings import Container

    settings = belief_settings(scene)
    given = scene.metadata.get("container")
    if given is None:
        return settings
    keys = ("depth", "width", "height")
    if not isinstance(given, dict) or sorted(given) != sorted(keys):
        from unstack.errors import InvalidScene

        raise InvalidScene(scene.source, "$.metadata.container", f"expected an object with {', '.join(keys)}")
    from unstack.checks import finite_number, number_text
    from unstack.errors import InvalidScene, UnstackError
    from unstack.sim.settings import MAX_EXTENT

    extent = []
    for key in keys:
        value = given[key]
        number = finite_number(value)
        if number is None or not 0.0 < number <= MAX_EXTENT:
            raise InvalidScene(
                scene.source,
                f"$.metadata.container.{key}",
                f"expected a positive extent of at most {MAX_EXTENT:g} m (metres?), got {number_text(value)}",
            )
        extent.append(number)
    container = Container(*extent)
    # the pile the simulator would drop is not this scene's: two boxes, and a size set that fits, keep its checks away
    for sizes in (settings.sizes, "cartons"):
        try:
            return dataclasses.replace(settings, container=container, boxes=(2, 2), sizes=sizes)
        except UnstackError:
            continue
    raise InvalidScene(
        scene.source,
        "$.metadata.container",
        f"a container of {' x '.join(f'{v:g}' for v in extent)} m is smaller than a carton's edges (metres?)",
    )


def _inside_container(scene: Scene, settings: Any) -> tuple[Scene, dict[str, float]]:
    """``scene`` with every detected box that reaches into the container's walls, floor or ceiling
    slid inside by the least shift, and the shifts (metres) of those slid more than
    :data:`WALL_SLACK`; a box beyond them by more than its own longest side is refused."""
    from unstack.geometry import bounding_boxes

    container = settings.container
    # boxes may spill out of the door (x < 0) onto the floor before it, nowhere else
    low = np.array([-DOOR_SPILL, -container.width / 2.0, 0.0])
    high = np.array([container.depth, container.width / 2.0, container.height])
    boxes = {box.id: box for box in scene.boxes}
    slid: dict[str, float] = {}
    for box_id, bounds in zip(scene.detected, bounding_boxes([scene.box(b) for b in scene.detected]), strict=True):
        below, above = np.maximum(low - bounds[:3], 0.0), np.maximum(bounds[3:] - high, 0.0)
        shift = below - above
        distance = float(np.linalg.norm(shift))
        if distance <= WALL_SLACK:
            continue
        box = scene.box(box_id)
        if np.any((below > 0) & (above > 0)) or distance > float(np.max(box.size)):
            raise InvalidArgument(
                f"{scene.source}: box {box_id!r} lies outside the container the physics veto builds (x from "
                f"{-DOOR_SPILL:g} m before the door to {container.depth:g} m, y within {container.width / 2:g} m of "
                f"the middle, z 0 to {container.height:g} m) by {distance:.2f} m, more than its own size: a pose "
                "error, a scene in another frame, or another container (give its inner extent in the scene's "
                "metadata.container: depth, width, height)"
            )
        boxes[box_id] = dataclasses.replace(box, position=np.asarray(box.position) + shift)
        slid[box_id] = distance
    if not slid:
        return scene, slid
    return dataclasses.replace(scene, boxes=tuple(boxes[box.id] for box in scene.boxes)), slid


def physics_veto(
    decision: Decision,
    scene: Scene,
    *,
    seed: int = 0,
    world_scene: Scene | None = None,
    free_cost: float = FREE_COST,
    veto_at: float = PHYSICS_VETO,
    worlds: int = PHYSICS_WORLDS,
    net: bool = False,
    fill: str = PHYSICS_FILL,
    draw_masses: bool = False,
) -> Decision:
    """The decision with its pick vetoed where physics on the belief expects it to move boxes.

    Parameters
    ----------
    decision : Decision
        A decision on ``scene``'s detected boxes (its ``objects``) with a cost that counts
        boxes; its ``choice`` is tried first.
    scene : Scene
        Where the boxes are, and the cloud the belief's unseen space comes from.
    seed : int
        Seeds the belief worlds' draws: the same seed gives the same worlds.
    world_scene : Scene, optional
        The scene the belief worlds are built from, when it holds more detected boxes than
        the candidates (the closed loop's boxes in view); default ``scene``.
    free_cost : float
        The alternatives to a vetoed pick: the boxes whose expected cost is below it.
    veto_at : float
        A pick expected to move at least this many boxes is vetoed (positive; default
        :data:`PHYSICS_VETO`).
    worlds : int
        Belief worlds each box is tried in (default :data:`PHYSICS_WORLDS`).
    net : bool
        Count, in each world, only the boxes that stay still there with nothing taken (measured
        no better than counting every box: the results page, maker ``hybrid_faces_free_net``);
        recorded as ``physics_veto["net"]``.
    fill : {"faces", "cartons", "scaled", "sampled", "occlusion"}
        What the belief worlds put where the sensor sees no box (:data:`unstack.sim.belief.FILLS`;
        default :data:`PHYSICS_FILL`; ``"cartons"``, whole hidden cartons drawn into the unseen
        space, is the maker ``hybrid_cartons_free`` of the results page).
    draw_masses : bool
        Draw each belief world's masses from the settings' range instead of the typical mass
        in every world (the maker ``hybrid_faces_free_masses``); recorded as
        ``physics_veto["masses_drawn"]``.

    Returns
    -------
    Decision
        ``physics_veto`` records the boxes tried with the boxes each is expected to move
        (``tried``, the first the decision's own pick), whether that pick was vetoed, the
        worlds and the fill. When the pick was vetoed, ``choice`` is the fewest expected among
        them (ties: the box resting highest, then the smaller id), ``ties`` the boxes expected
        to move as few, and ``choice_probability`` (with a free cost) the probability that the
        choice's true expected cost is below it; else the decision with the record added.
        When poses of ``scene`` cannot stand as reported
        (:func:`~unstack.understanding.plausibility.standing_doubts`), nothing is tried: the
        record's ``skipped`` names them, the choice is the decision's and a warning says why.

    Raises
    ------
    InvalidArgument
        A box of the decision not detected in the scene, or a detected box outside the
        container by more than its own longest side (one reaching less far into a wall is
        slid inside for the belief worlds, listed in ``physics_veto["slid_inside"]`` and
        warned about).
    UnstackError
        The physics engine is not installed.

    Examples
    --------
    >>> import unstack
    >>> scene = unstack.load("examples/pile5.scene.json")
    >>> kept = physics_veto(unstack.decide(scene, seed=0), scene, seed=0)
    >>> kept.physics_veto["vetoed"], kept.choice == unstack.decide(scene, seed=0).choice
    (False, True)
    """
    from unstack.geometry import bounding_boxes
    from unstack.reasoner.arguments import check_flag, check_margin

    free_cost = check_margin(free_cost, "free_cost")
    if not check_margin(veto_at, "veto_at") > 0:
        raise InvalidArgument(f"veto_at must be positive (a pick moving no box is never vetoed), got {veto_at!r}")
    if isinstance(worlds, bool) or not isinstance(worlds, int) or worlds < 1:
        raise InvalidArgument(f"worlds must be a positive integer, got {worlds!r}")
    net, draw_masses = check_flag(net, "net"), check_flag(draw_masses, "draw_masses")
    from unstack.sim.belief import FILLS

    if fill not in FILLS or fill == "cloud":
        known = ", ".join(name for name in FILLS if name != "cloud")
        raise InvalidArgument(f"unknown belief fill {fill!r} for the physics veto; expected one of {known}")
    missing = [box_id for box_id in decision.objects if box_id not in scene.detected]
    if missing:
        raise InvalidArgument(f"{scene.source}: the decision's boxes {missing} are not detected boxes of the scene")
    doubts = standing_doubts(scene)
    if doubts:  # physics would act out the poses' errors, whatever is taken: no evidence on the pick
        more = f"; {len(doubts) - NAMED_DOUBTS} more" if len(doubts) > NAMED_DOUBTS else ""
        named = "; ".join(doubts[:NAMED_DOUBTS]) + more
        record = {**_record({}, decision.choice, False, veto_at, worlds, fill), "skipped": doubts}
        warning = (
            f"physics veto: not applied: poses of the scene cannot stand as reported ({named}); physics on them "
            "would move those boxes whatever is taken, so the reasoner's pick is kept"
        )
        return dataclasses.replace(decision, physics_veto=record, warnings=(*decision.warnings, warning))
    given = scene if world_scene is None else world_scene
    settings = world_settings(given)
    built, slid = _inside_container(given, settings)
    pick = decision.choice
    expected = _expected_moved(built, [pick], seed, settings, worlds, net, fill, draw_masses)
    vetoed = expected[pick] >= veto_at
    if vetoed:
        costs = dict(zip(decision.objects, (float(cost) for cost in decision.expected_costs), strict=True))
        others = [box_id for box_id in decision.objects if box_id != pick and costs[box_id] < free_cost]
        if others:
            expected.update(_expected_moved(built, others, seed, settings, worlds, net, fill, draw_masses))
    record = _record(expected, pick, vetoed, veto_at, worlds, fill)
    if net:
        record["net"] = True
    if draw_masses:
        record["masses_drawn"] = True
    warnings = decision.warnings
    if vetoed:  # a world that does not come to rest moves boxes whatever is taken
        from unstack.sim.belief import restless_boxes

        restless = restless_boxes(built, seed=seed, settings=settings, fill=fill)
        if restless:
            record["restless"] = list(restless)
            warnings = (*warnings, f"physics veto: with nothing taken, {', '.join(restless)} move in the belief "
                        "world (poses that cannot stand as reported); the moves expected of every pick count "
                        "them")  # fmt: skip
    if slid:
        record["slid_inside"] = {box_id: round(distance, 6) for box_id, distance in slid.items()}
        reached = ", ".join(f"{box_id} {distance:.2f} m" for box_id, distance in slid.items())
        warnings = (*warnings, f"physics veto: boxes reaching into the container's walls were slid inside for the "
                    f"belief worlds ({reached}); check their poses or give the container's inner extent")  # fmt: skip
    if not vetoed:
        return dataclasses.replace(decision, physics_veto=record, warnings=warnings)
    resting = {box_id: float(bounding_boxes([scene.box(box_id)])[0, 2]) for box_id in expected}
    choice = min(expected, key=lambda box_id: (expected[box_id], -resting[box_id], box_id))
    fewest = tuple(sorted(box_id for box_id in expected if expected[box_id] == expected[choice]))
    below = probability_below(decision, choice, decision.free_cost) if decision.free_cost else 1.0
    return dataclasses.replace(
        decision, choice=choice, ties=fewest, choice_probability=below, physics_veto=record, warnings=warnings,
    )  # fmt: skip


def _record(
    expected: Mapping[str, float], pick: str, vetoed: bool, veto_at: float, worlds: int, fill: str = PHYSICS_FILL
) -> dict[str, Any]:
    """The ``physics_veto`` object of ``unstack.decision/1``."""
    return {
        "fill": fill,
        "worlds": worlds,
        "veto_at": veto_at,
        "vetoed": vetoed,
        "tried": [{"box": box_id, "expected_moved": round(moved, 6)} for box_id, moved in expected.items()],
    }
