"""Unloading whole containers as a robot does, with every decision maker (issue: closed loop).

Each pile is emptied by :func:`unstack.sim.unloading.unload_container`: before every pick the
pile is scanned and the boxes detected again, only boxes reachable from the door are
candidates, and the policy picks one. Decision makers (:data:`CONTAINER_MAKERS`):

``unstack``
    unstack's default decision on a scene (:func:`unstack.decide`): the default model's
    probabilities, the default cost (hidden load counted), the highest box whose expected
    cost is below :data:`~unstack.height_veto.FREE_COST` (:func:`unstack.height_veto.free_highest`);
    when none is, near ties in expected cost to the box resting highest
    (:data:`~unstack.reasoner.decision.NEAR_TIE_MARGIN`).
``unstack_strict``
    the default with a box counted as holding nothing up below an expected cost of
    :data:`STRICT_FREE_COST` instead of :data:`~unstack.height_veto.FREE_COST`.
``near_ties``
    the reasoner's own choice: near ties alone (without the free-box rule above them).
``min_cost``
    the same expected costs with the minimum EC (Eq. 12; no near ties).
``unstack_count``
    the same probabilities with Eq. 11's cost (detected boxes supported) and the minimum EC (Eq. 12).
``hybrid``
    height vetoed by unstack (:func:`unstack.height_veto.highest_free_box`): the highest
    candidate whose expected cost (the default model and cost) is below
    :data:`~unstack.height_veto.HYBRID_MAX_COST` -- the highest box the model does not
    believe holds anything up; when every candidate costs more, unstack's choice.
``highest``
    the highest candidate first.
``footprint``
    the highest candidate that no other candidate covers from above.
``nearest_door``
    the free candidate (nothing on it) nearest the door first, as the Drake box-unloading
    demo does; ties by height.
``random``
    a seeded random candidate.
``lookahead``
    knows the true pile: tries every candidate's removal in the physics engine (in the world
    itself, undone after each try: :func:`unstack.sim.unloading.probe_removals`) and takes the
    one that moves the fewest boxes, ties to the box resting highest (the floor no policy can pass; slow).
``rebuilt``
    an oracle between the look-ahead and the robot: every box of the true pile (seen or
    not) at its pose and mass in a fresh world, settled, each candidate's removal tried
    there (:func:`unstack.sim.unloading.rebuilt_removals`); the fewest moved, ties to the box
    resting highest. It knows the pile's poses but not its state: what it loses against the
    look-ahead no perception of poses can win.
``rebuilt_typical``, ``rebuilt_draws``
    the same oracle of poses without the masses: every box of the settings' mean mass, or
    the mean over :data:`~unstack.sim.belief.BELIEF_WORLDS` worlds of masses drawn from the
    settings' range -- what a robot that sees every box but weighs none could know.
``rebuilt_hidden_fixed``
    ``rebuilt`` with the boxes the cloud does not show (:func:`unstack.sim.belief.seen_boxes`)
    fixed in place: the space they fill is known, what they would do is not.
``belief_seen``
    the belief (``belief``) with every box the cloud shows (:func:`unstack.sim.belief.seen_boxes`)
    as a box at its pose, not only the candidates: a detector that reports every box in view.
``moves``
    the learned cost of what a pick moves (:mod:`unstack.moves`): the default model's
    probabilities and the reasoner's marginals through the disturbance model; the fewest.
``moves_veto``
    the same expected moves, the ``veto`` rule: the box resting highest whose expected
    moves are below :data:`~unstack.moves.MOVES_VETO`.
``belief``
    physics on what the robot sees (:mod:`unstack.sim.belief`): the detected boxes at their
    reported poses and the unseen material of the cloud put in the engine, every candidate's
    removal tried; the fewest moved, ties to the box resting highest (slow).
``belief_veto``
    the same expected moves, the ``veto`` rule: the box resting highest unless the belief
    expects its removal to move at least :data:`~unstack.sim.belief.BELIEF_VETO` boxes.
``belief_occlusion``
    physics on what the robot sees with the unseen space filled: every box the detector
    reports (:data:`~unstack.sim.unloading.IN_VIEW`, reachable or not) at its pose and of the
    typical mass, the space the sensor cannot see next to them fixed
    (``fill="occlusion"`` of :func:`unstack.sim.belief.belief_removals`, one world), every
    candidate's removal tried; the fewest moved, ties to the box resting highest (slow).
``belief_bracket``
    the mean of two beliefs on the boxes in view: the unseen space all solid
    (``belief_occlusion``) and the cloud's columns with the boxes in view that fall held
    (``fill="cloud"``); the fewest moved.
``belief_occlusion_veto``
    height vetoed by the occlusion-filled belief: ``highest``'s pick unless that belief
    expects its removal to move at least :data:`~unstack.sim.belief.BELIEF_VETO` boxes; then
    ``belief_occlusion_free``'s pick.
``belief_occlusion_free``
    the same, among the candidates unstack's default decision believes hold nothing up
    (expected cost below :data:`~unstack.height_veto.HYBRID_MAX_COST`, as the ``hybrid``);
    all candidates when none does.
``belief_guard``
    height guarded by two beliefs: ``highest``'s pick unless the occlusion-filled belief (the
    unseen space solid: the most support the unseen can give) expects its removal to move at
    least :data:`~unstack.sim.belief.BELIEF_VETO` boxes; then, among that pick and the
    candidates unstack's default decision believes hold nothing up, the fewest moved by the
    worse of the two beliefs (solid, and the cloud's columns: the least support), ties to the
    box resting highest.
``belief_sampled``
    physics on the boxes in view with the space the sensor cannot see sampled
    (``fill="sampled"`` of :func:`unstack.sim.belief.belief_removals`: each run of it solid
    with probability :data:`~unstack.sim.belief.OCCUPANCY`, :data:`~unstack.sim.belief.BELIEF_WORLDS`
    worlds), every candidate tried; the fewest expected moved, ties to the box resting highest.
``belief_sampled_veto``
    height vetoed by the same belief: ``highest``'s pick unless its removal is expected to
    move at least :data:`~unstack.sim.belief.BELIEF_VETO` boxes; then ``belief_sampled``'s pick.
``belief_scaled_veto``
    the same with the chance of each run of unseen space scaled by that space's volume in the
    scene (``fill="scaled"``, :func:`unstack.sim.belief.scaled_occupancy`): a deep pile hides
    boxes, a sliver behind a stack is air.
``belief_faces_veto``
    the same, and behind every surface the cloud shows that no detected box explains (a box
    nobody detected) a carton's depth of the unseen space solid in every world
    (``fill="faces"``, :func:`unstack.sim.belief.behind_seen_faces`).
``hybrid_faces_veto``
    ``belief_faces_veto`` starting from the ``hybrid``'s pick instead of the highest box: the
    reasoner's hidden load first, then physics on the belief.
``hybrid_faces_free``
    the same, the alternatives to a vetoed pick only the boxes the reasoner believes hold
    nothing up (expected cost below :data:`~unstack.height_veto.HYBRID_MAX_COST`); the faces
    belief's fewest among them.
``hybrid_faces_free_any``
    the same, vetoed where the pick moves a box in any of the belief worlds (expected moves
    of at least one box over :data:`~unstack.physics_veto.PHYSICS_WORLDS`).
``hybrid_faces_free_8``
    ``hybrid_faces_free`` in twice :data:`~unstack.physics_veto.PHYSICS_WORLDS` belief worlds.
``hybrid_faces_free_net``
    ``hybrid_faces_free`` counting, in each belief world, only the boxes that stay still there
    with nothing taken (``net=True`` of :func:`unstack.physics_veto.physics_veto`).
``hybrid_faces_free_gated``
    ``hybrid_faces_free`` only where the disturbance model (``moves``) expects the hybrid's
    pick to move :data:`GATE_MOVES` boxes or more; elsewhere the hybrid's pick.
``hybrid_faces_free_sure``
    ``hybrid_faces_free``, a vetoed pick replaced only by a box expected to move fewer than
    :data:`~unstack.physics_veto.PHYSICS_VETO` boxes (among boxes as bad, height stands).
``hybrid_moves_free``
    the default's pick unless the disturbance model (``moves``) expects its removal to move
    :data:`~unstack.moves.MOVES_VETO` boxes or more; then the fewest expected moves among the
    boxes the reasoner believes hold nothing up.
``hybrid_moves_free_1``
    the same, vetoed at :data:`~unstack.physics_veto.PHYSICS_VETO` expected boxes (as the
    physics veto), not :data:`~unstack.moves.MOVES_VETO`.
``hybrid_moves_walk``
    down the boxes the reasoner believes hold nothing up, highest first, the first that the
    disturbance model does not expect to move :data:`~unstack.physics_veto.PHYSICS_VETO` boxes
    or more: the default's pick unless vetoed, then the next highest not vetoed.
``hybrid_faces_walk``
    the same walk with the faces belief's physics as the veto (as ``hybrid_faces_free``, which
    takes the belief's fewest among every such box once the hybrid's pick is vetoed).
``hybrid_cartons_free``
    ``hybrid_faces_free`` with whole hidden cartons drawn into the unseen space of each belief
    world instead of runs of it kept one by one (``fill="cartons"``,
    :func:`unstack.understanding.hidden_cartons.draw_hidden_cartons`).
``hybrid_faces_free_masses``
    ``hybrid_faces_free`` with each belief world's masses drawn from the settings' range
    (``draw_masses=True``), not the typical mass in every world.

Metrics per pile and per maker: boxes moved more than 2 cm or turned more than 5 degrees, boxes
fallen (dropped more than 0.2 m or tipped more than 45 degrees), the share of picks that move
nothing, and paired differences from ``unstack`` with standard errors. Seeded and reproducible (sample budgets,
not time limits); resumable per pile; piles in parallel processes.

Examples
--------
>>> CONTAINER_MAKERS[:4]
('unstack', 'near_ties', 'min_cost', 'unstack_count')
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from unstack.experiments.dispatch import run_unordered
from unstack.parameters import (
    COUNT,
    DETECTOR_NOISE,
    JOBS,
    MISSED_SHARE,
    OPTIONAL_COUNT,
    OPTIONAL_SHARE,
    SEED,
    OneOf,
    validate_params,
)
from unstack.scene import Scene
from unstack.sim.unloading import REACH_RULES

__all__ = [
    "CONTAINER_MAKERS",
    "CONTAINER_SAMPLES",
    "DEFAULT_CONTAINER_MAKERS",
    "ORACLE_MAKERS",
    "TRIED_MAKERS",
    "container_experiment",
    "container_policies",
]

#: The makers run when none are named: robot policies that read only what the robot sees, and
#: the look-ahead that knows the true pile.
DEFAULT_CONTAINER_MAKERS = (
    "unstack", "near_ties", "min_cost", "unstack_count", "hybrid", "highest", "footprint", "nearest_door", "random",
    "lookahead", "moves", "moves_veto", "belief", "belief_veto",
)  # fmt: skip
#: Diagnostic oracles that read every box of the pile, seen or not (never a robot's policy);
#: run only when named.
ORACLE_MAKERS = ("rebuilt", "rebuilt_typical", "rebuilt_draws", "rebuilt_hidden_fixed", "belief_seen")
#: Robot policies of physics on the belief with the unseen space filled, slow (0.25-4 s a pick,
#: benchmarks page) and needing the physics engine (results page, "Filling the space the sensor
#: cannot see" and after), and variants measured no better than what they change: run only when
#: named.
TRIED_MAKERS = (
    "belief_occlusion", "belief_occlusion_free", "belief_bracket", "belief_occlusion_veto", "belief_guard",
    "belief_sampled", "belief_sampled_veto", "belief_scaled_veto",
    "belief_faces_veto", "hybrid_faces_veto", "hybrid_faces_free", "hybrid_faces_free_any",
    "hybrid_faces_free_8", "hybrid_faces_free_sure", "hybrid_moves_free", "unstack_strict", "hybrid_moves_free_1",
    "hybrid_faces_free_net", "hybrid_faces_free_gated", "hybrid_moves_walk", "hybrid_faces_walk",
    "hybrid_cartons_free", "hybrid_faces_free_masses",
)  # fmt: skip
#: Every decision maker.
CONTAINER_MAKERS = (*DEFAULT_CONTAINER_MAKERS, *ORACLE_MAKERS, *TRIED_MAKERS)
#: The free cost of the maker ``unstack_strict``.
STRICT_FREE_COST = 0.2
#: ``hybrid_faces_free_gated`` runs the physics only where the disturbance model expects the
#: pick to move this many boxes or more: on the closed-loop states of piles emptied by
#: ``hybrid_faces_free`` (four, stacked, mixed), 95 % of its vetoes lie there, and 40 % of the
#: states (fitted on the first 101 piles collected; 0.087 on all 102:
#: ``python benchmarks/veto_features.py report``).
GATE_MOVES = 0.086
#: Makers that read the disturbance model (:mod:`unstack.moves`).
MOVES_MAKERS = (
    "moves", "moves_veto", "hybrid_moves_free", "hybrid_moves_free_1", "hybrid_faces_free_gated", "hybrid_moves_walk",
)  # fmt: skip
#: Makers that read ``occupancy``, the ``sampled`` fill's share of unseen space kept solid.
OCCUPANCY_MAKERS = ("belief_sampled", "belief_sampled_veto")
#: Makers whose policy is told what every candidate's removal does in the engine (the true pile).
PROBING_MAKERS = ("lookahead",)
#: Recorded sweeps per sampled group in each decision: 512 when a sweep re-inserted every box,
#: 3 times that since it re-inserts :data:`~unstack.reasoner.sampling.MOVES` (as the default
#: budget, :func:`~unstack.reasoner.sampling.default_samples`). On the first 10 wall piles with
#: half the boxes missed, 1536 sweeps gave the same boxes moved on every pile as the former
#: 512 sweeps of every box (512 sweeps of 8 boxes: one pile changed, +1 box), in the same time.
CONTAINER_SAMPLES = 1536


def _free(scene: Scene, candidates: Sequence[str]) -> list[str]:
    """Candidates that no box of the scene covers from above (:func:`uncovered_boxes`)."""
    from unstack.experiments.decisions import uncovered_boxes

    index = {box.id: k for k, box in enumerate(scene.boxes)}
    free = set(uncovered_boxes(scene.boxes, [index[box_id] for box_id in candidates]))
    return [box_id for box_id in candidates if index[box_id] in free]


def container_policies(
    model: Any,
    *,
    seed: int,
    samples: int = CONTAINER_SAMPLES,
    makers: Sequence[str] = CONTAINER_MAKERS,
    disturbance: Any = None,
    occupancy: float | None = None,
) -> dict[str, Callable[..., str]]:
    """The decision makers: each maps the freshly sensed scene to one of its ``detected`` boxes
    (those of :data:`PROBING_MAKERS` take the probe's outcomes as well); ``occupancy``: the
    ``sampled`` fill's (default :data:`~unstack.sim.belief.OCCUPANCY`)."""
    from unstack.experiments.decisions import free_pick
    from unstack.height_veto import FREE_COST
    from unstack.moves import MOVES_VETO
    from unstack.physics_veto import PHYSICS_VETO, PHYSICS_WORLDS
    from unstack.sim.belief import OCCUPANCY

    kept_share = OCCUPANCY if occupancy is None else occupancy

    rng = np.random.default_rng(seed)

    def decision(scene: Scene, cost: str, margin: float | None = None) -> Any:
        from unstack.pipeline import scene_support_probabilities
        from unstack.reasoner.decision import decide

        supports = scene_support_probabilities(scene, model)
        return decide(supports, cost=cost, samples=samples, seed=seed, near_tie_margin=margin)

    def deciding(cost: str, margin: float | None = None) -> Callable[[Scene], str]:
        def policy(scene: Scene) -> str:
            return str(decision(scene, cost, margin).choice)

        return policy

    def height(scene: Scene, box_id: str) -> float:
        return float(scene.box(box_id).position[2])

    def free_below(free_cost: float) -> Callable[[Scene], str]:
        def policy(scene: Scene) -> str:
            from unstack.height_veto import free_highest

            return str(free_highest(decision(scene, "load"), scene, free_cost=free_cost).choice)

        return policy

    def hybrid(scene: Scene) -> str:
        from unstack.height_veto import hybrid_choice

        return hybrid_choice(scene, decision(scene, "load"))

    def highest(scene: Scene) -> str:
        return max(scene.detected, key=lambda box_id: (height(scene, box_id), box_id))

    def footprint(scene: Scene) -> str:
        candidates = list(scene.detected)
        return candidates[free_pick([scene.box(box_id) for box_id in candidates])]

    def nearest_door(scene: Scene) -> str:
        free = _free(scene, scene.detected) or list(scene.detected)
        return min(free, key=lambda box_id: (scene.box(box_id).position[0], -height(scene, box_id), box_id))

    def random(scene: Scene) -> str:
        return str(rng.choice(sorted(scene.detected)))

    def fewest(scene: Scene, expected: dict[str, float]) -> str:
        """The candidate expected to move the fewest boxes, ties to the box resting highest."""
        from unstack.geometry import bounding_boxes

        resting = {box_id: float(bounding_boxes([scene.box(box_id)])[0, 2]) for box_id in scene.detected}
        return min(scene.detected, key=lambda box_id: (expected[box_id], -resting[box_id], box_id))

    def lookahead(scene: Scene, outcomes: dict[str, Any]) -> str:
        return fewest(scene, {box_id: outcomes[box_id].boxes_moved for box_id in scene.detected})

    def rebuilding(own_masses: bool) -> Callable[[Scene], str]:
        def policy(scene: Scene) -> str:
            from unstack.sim.belief import belief_settings
            from unstack.sim.unloading import rebuilt_removals

            typical = float(np.mean(belief_settings(scene).pile.mass_range))
            masses = None if own_masses else {box.id: typical for box in scene.boxes}
            return lookahead(scene, rebuilt_removals(scene, masses=masses))

        return policy

    def rebuilt_hidden_fixed(scene: Scene) -> str:
        from unstack.sim.belief import seen_boxes
        from unstack.sim.unloading import rebuilt_removals

        seen = set(seen_boxes(scene)) | set(scene.detected)
        hidden = [box.id for box in scene.boxes if box.id not in seen]
        return lookahead(scene, rebuilt_removals(scene, fixed=hidden))

    def rebuilt_draws(scene: Scene) -> str:
        from unstack.sim.belief import BELIEF_WORLDS, belief_settings
        from unstack.sim.unloading import rebuilt_removals

        low, high = belief_settings(scene).pile.mass_range
        draws = np.random.default_rng(seed)
        moved = {box_id: 0.0 for box_id in scene.detected}
        for _ in range(BELIEF_WORLDS):
            masses = {box.id: float(draws.uniform(low, high)) for box in scene.boxes}
            for box_id, outcome in rebuilt_removals(scene, masses=masses).items():
                moved[box_id] += outcome.boxes_moved / BELIEF_WORLDS
        return fewest(scene, moved)

    def in_view_moves(
        scene: Scene, candidates: Sequence[str], fill: str = "occlusion", worlds: int = 1
    ) -> dict[str, float]:
        from unstack.sim.belief import belief_removals
        from unstack.sim.unloading import in_view_scene

        outcomes = belief_removals(
            in_view_scene(scene), candidates, worlds=worlds, fill=fill, seed=seed, occupancy=kept_share
        )
        return {box_id: outcome.expected_moved for box_id, outcome in outcomes.items()}

    def belief_occlusion(scene: Scene) -> str:
        return fewest(scene, in_view_moves(scene, scene.detected))

    def belief_bracket(scene: Scene) -> str:
        solid, columns = (in_view_moves(scene, scene.detected, fill) for fill in ("occlusion", "cloud"))
        return fewest(scene, {box_id: (solid[box_id] + columns[box_id]) / 2 for box_id in scene.detected})

    def belief_occlusion_veto(scene: Scene) -> str:
        from unstack.sim.belief import BELIEF_VETO

        top = highest(scene)
        if in_view_moves(scene, [top])[top] < BELIEF_VETO:
            return top
        return belief_occlusion_free(scene)

    def expected_costs(reasoned: Any) -> dict[str, float]:
        return dict(zip(reasoned.objects, (float(cost) for cost in reasoned.expected_costs), strict=True))

    def believed_free(scene: Scene) -> list[str]:
        from unstack.height_veto import HYBRID_MAX_COST

        costs = expected_costs(decision(scene, "load"))
        return [box_id for box_id in scene.detected if costs[box_id] < HYBRID_MAX_COST] or list(scene.detected)

    def belief_occlusion_free(scene: Scene) -> str:
        moves = in_view_moves(scene, believed_free(scene))
        return fewest(scene, {box_id: moves.get(box_id, np.inf) for box_id in scene.detected})

    def belief_guard(scene: Scene) -> str:
        from unstack.sim.belief import BELIEF_VETO

        top = highest(scene)
        solid_top = in_view_moves(scene, [top])[top]
        if solid_top < BELIEF_VETO:
            return top
        others = [box_id for box_id in believed_free(scene) if box_id != top]
        solid = {top: solid_top, **(in_view_moves(scene, others) if others else {})}
        columns = in_view_moves(scene, [top, *others], "cloud")
        worse = {box_id: max(solid[box_id], columns[box_id]) for box_id in solid}
        return fewest(scene, {box_id: worse.get(box_id, np.inf) for box_id in scene.detected})

    def belief_sampled(scene: Scene) -> str:
        from unstack.sim.belief import BELIEF_WORLDS

        return fewest(scene, in_view_moves(scene, scene.detected, "sampled", BELIEF_WORLDS))

    def sampled_veto(fill: str, base: Callable[[Scene], str] = highest) -> Callable[[Scene], str]:
        """``base``'s pick unless the ``fill`` belief expects its removal to move a box, then that
        belief's fewest among every detected box."""

        def policy(scene: Scene) -> str:
            from unstack.sim.belief import BELIEF_VETO, BELIEF_WORLDS

            top = base(scene)
            top_moves = in_view_moves(scene, [top], fill, BELIEF_WORLDS)
            if top_moves[top] < BELIEF_VETO:
                return top
            others = [box_id for box_id in scene.detected if box_id != top]  # each candidate's worlds are its own
            return fewest(scene, {**top_moves, **(in_view_moves(scene, others, fill, BELIEF_WORLDS) if others else {})})

        return policy

    def faces_vetoed(
        scene: Scene,
        veto_at: float = PHYSICS_VETO,
        worlds: int = PHYSICS_WORLDS,
        net: bool = False,
        reasoned: Any = None,
        fill: str = "faces",
        draw_masses: bool = False,
    ) -> tuple[str, Any]:
        """The hybrid's pick, and the decision with it vetoed where the faces belief expects its
        removal to move ``veto_at`` boxes: then that belief's fewest among the boxes the
        reasoner believes hold nothing up (:func:`unstack.physics_veto.physics_veto` on the
        boxes in view). ``reasoned``: the load decision on ``scene``, when already made."""
        import dataclasses

        from unstack.height_veto import hybrid_choice
        from unstack.physics_veto import physics_veto
        from unstack.sim.unloading import in_view_scene

        if reasoned is None:
            reasoned = decision(scene, "load")
        pick = hybrid_choice(scene, reasoned)
        vetoed = physics_veto(
            dataclasses.replace(reasoned, choice=pick), scene, seed=seed, world_scene=in_view_scene(scene),
            veto_at=veto_at, worlds=worlds, net=net, fill=fill, draw_masses=draw_masses,
        )  # fmt: skip
        return pick, vetoed

    def faces_free(
        veto_at: float, worlds: int = PHYSICS_WORLDS, net: bool = False, fill: str = "faces", draw_masses: bool = False
    ) -> Callable[[Scene], str]:
        def policy(scene: Scene) -> str:
            return str(faces_vetoed(scene, veto_at, worlds, net, fill=fill, draw_masses=draw_masses)[1].choice)

        return policy

    def hybrid_faces_walk(scene: Scene) -> str:
        """Down the boxes the reasoner believes hold nothing up, the hybrid's pick first and
        then highest first, the first the faces belief does not expect to move
        :data:`~unstack.physics_veto.PHYSICS_VETO` boxes or more; if every one is vetoed, the
        belief's fewest (``hybrid_faces_free`` tries every such box once its pick is vetoed)."""
        from unstack.height_veto import FREE_COST, hybrid_choice
        from unstack.physics_veto import expected_moves_in_view

        reasoned = decision(scene, "load")
        pick = hybrid_choice(scene, reasoned)
        costs = expected_costs(reasoned)
        free = [box_id for box_id in scene.detected if costs[box_id] < FREE_COST and box_id != pick]
        order = [pick, *sorted(free, key=lambda box_id: (height(scene, box_id), box_id), reverse=True)]
        tried: dict[str, float] = {}
        for box_id in order:
            tried.update(expected_moves_in_view(scene, [box_id], seed=seed))
            if tried[box_id] < PHYSICS_VETO:
                return box_id
        return fewest(scene, {box_id: tried.get(box_id, np.inf) for box_id in scene.detected})

    def hybrid_faces_free_gated(scene: Scene) -> str:
        """``hybrid_faces_free`` where the disturbance model expects the hybrid's pick to move
        :data:`GATE_MOVES` boxes or more; elsewhere the hybrid's pick, without the physics."""
        from unstack.height_veto import hybrid_choice
        from unstack.learning.pick_features import pick_features
        from unstack.pipeline import scene_support_probabilities
        from unstack.reasoner.decision import decide

        supports = scene_support_probabilities(scene, model)
        reasoned = decide(supports, cost="load", samples=samples, seed=seed)
        pick = hybrid_choice(scene, reasoned)
        features = pick_features(scene, supports, reasoned.marginals, reasoned.expected_costs)
        score = float(disturbance_model().expected_moves(features)[list(supports.objects).index(pick)])
        if score < GATE_MOVES:
            return pick
        return str(faces_vetoed(scene, reasoned=reasoned)[1].choice)

    def hybrid_faces_free_sure(scene: Scene) -> str:
        """``hybrid_faces_free``, but a vetoed pick is replaced only by a box the belief expects
        to move fewer than :data:`~unstack.physics_veto.PHYSICS_VETO` boxes; else it stands."""
        pick, vetoed = faces_vetoed(scene)
        record = vetoed.physics_veto
        moved = {item["box"]: item["expected_moved"] for item in record["tried"]}
        if record["vetoed"] and moved[str(vetoed.choice)] >= PHYSICS_VETO:
            return pick
        return str(vetoed.choice)

    def predicted_moves(scene: Scene) -> tuple[str, dict[str, float], list[str]]:
        """The default's pick, the disturbance model's expected moves of every candidate, and
        the boxes the reasoner believes hold nothing up (every box if none)."""
        from unstack.height_veto import FREE_COST, free_highest
        from unstack.learning.pick_features import pick_features
        from unstack.pipeline import scene_support_probabilities
        from unstack.reasoner.decision import decide

        supports = scene_support_probabilities(scene, model)
        reasoned = decide(supports, cost="load", samples=samples, seed=seed)
        pick = str(free_highest(reasoned, scene).choice)
        features = pick_features(scene, supports, reasoned.marginals, reasoned.expected_costs)
        predicted = disturbance_model().expected_moves(features)
        expected = dict(zip(supports.objects, (float(moved) for moved in predicted), strict=True))
        costs = expected_costs(reasoned)
        free = [box_id for box_id in scene.detected if costs[box_id] < FREE_COST] or list(scene.detected)
        return pick, expected, free

    def moves_free(veto_at: float) -> Callable[[Scene], str]:
        def policy(scene: Scene) -> str:
            """The default's pick unless the disturbance model expects its removal to move
            ``veto_at`` boxes or more; then the fewest expected moves among the boxes the
            reasoner believes hold nothing up, ties to the box resting highest."""
            pick, expected, free = predicted_moves(scene)
            if expected[pick] < veto_at:
                return pick
            return fewest(scene, {box_id: expected[box_id] if box_id in free else np.inf for box_id in scene.detected})

        return policy

    def moves_walk(veto_at: float) -> Callable[[Scene], str]:
        def policy(scene: Scene) -> str:
            """The highest of the boxes the reasoner believes hold nothing up that the
            disturbance model does not expect to move ``veto_at`` boxes or more (the default's
            pick when it is not vetoed); if every one is vetoed, the fewest expected moves."""
            _, expected, free = predicted_moves(scene)
            for box_id in sorted(free, key=lambda box_id: (height(scene, box_id), box_id), reverse=True):
                if expected[box_id] < veto_at:
                    return box_id
            return fewest(scene, {box_id: expected[box_id] if box_id in free else np.inf for box_id in scene.detected})

        return policy

    def belief_seen(scene: Scene) -> str:
        import dataclasses

        from unstack.sim.belief import belief_removals, seen_boxes

        seen = sorted(set(seen_boxes(scene)) | set(scene.detected), key=scene.box_ids.index)
        outcomes = belief_removals(dataclasses.replace(scene, detected=tuple(seen)), scene.detected, seed=seed)
        return fewest(scene, {box_id: outcome.expected_moved for box_id, outcome in outcomes.items()})

    loaded: list[Any] = []

    def moving(rule: str) -> Callable[[Scene], str]:
        def policy(scene: Scene) -> str:
            return moves(scene, rule)

        return policy

    def disturbance_model() -> Any:
        from unstack.learning.disturbance import load_disturbance_model

        if not loaded:  # once per set of policies, at the first pick
            given = disturbance
            loaded.append(load_disturbance_model(given) if isinstance(given, str | os.PathLike | None) else given)
        return loaded[0]

    def moves(scene: Scene, rule: str) -> str:
        from unstack.moves import decide_on_moves
        from unstack.pipeline import scene_support_probabilities

        supports = scene_support_probabilities(scene, model)
        decision = decide_on_moves(
            scene, supports, disturbance=disturbance_model(), samples=samples, seed=seed, rule=rule
        )
        return str(decision.choice)

    def believing(rule: str) -> Callable[[Scene], str]:
        def policy(scene: Scene) -> str:
            from unstack.sim.belief import belief_choice

            return belief_choice(scene, rule=rule)

        return policy

    every: dict[str, Callable[..., str]] = {
        "unstack": free_below(FREE_COST),
        "unstack_strict": free_below(STRICT_FREE_COST),
        "near_ties": deciding("load"),
        "min_cost": deciding("load", 0.0),
        "unstack_count": deciding("count", 0.0),
        "hybrid": hybrid,
        "highest": highest,
        "footprint": footprint,
        "nearest_door": nearest_door,
        "random": random,
        "lookahead": lookahead,
        "moves": moving("fewest"),
        "moves_veto": moving("veto"),
        "belief": believing("fewest"),
        "belief_veto": believing("veto"),
        "rebuilt": rebuilding(True),
        "rebuilt_typical": rebuilding(False),
        "rebuilt_draws": rebuilt_draws,
        "rebuilt_hidden_fixed": rebuilt_hidden_fixed,
        "belief_seen": belief_seen,
        "belief_occlusion": belief_occlusion,
        "belief_occlusion_free": belief_occlusion_free,
        "belief_bracket": belief_bracket,
        "belief_occlusion_veto": belief_occlusion_veto,
        "belief_guard": belief_guard,
        "belief_sampled": belief_sampled,
        "belief_sampled_veto": sampled_veto("sampled"),
        "belief_scaled_veto": sampled_veto("scaled"),
        "belief_faces_veto": sampled_veto("faces"),
        "hybrid_faces_veto": sampled_veto("faces", hybrid),
        "hybrid_faces_free": faces_free(PHYSICS_VETO),
        "hybrid_faces_free_any": faces_free(1.0 / PHYSICS_WORLDS),
        "hybrid_faces_free_8": faces_free(PHYSICS_VETO, 2 * PHYSICS_WORLDS),
        "hybrid_faces_free_net": faces_free(PHYSICS_VETO, net=True),
        "hybrid_faces_free_gated": hybrid_faces_free_gated,
        "hybrid_faces_free_sure": hybrid_faces_free_sure,
        "hybrid_moves_free": moves_free(MOVES_VETO),
        "hybrid_moves_free_1": moves_free(PHYSICS_VETO),
        "hybrid_moves_walk": moves_walk(PHYSICS_VETO),
        "hybrid_faces_walk": hybrid_faces_walk,
        "hybrid_cartons_free": faces_free(PHYSICS_VETO, fill="cartons"),
        "hybrid_faces_free_masses": faces_free(PHYSICS_VETO, draw_masses=True),
    }
    unknown = [maker for maker in makers if maker not in every]
    if unknown:
        from unstack.errors import UnstackError

        raise UnstackError(f"unknown decision makers {unknown}; expected some of {', '.join(CONTAINER_MAKERS)}")
    return {maker: every[maker] for maker in makers}


def _run_pile(
    path: Path, number: int, model: Any, makers: Sequence[str], options: dict[str, Any]
) -> tuple[int, dict[str, Any]]:
    """Every decision maker empties one pile (``number`` comes back for the caller's order)."""
    from unstack.scene import load_scene
    from unstack.sim.progress import pick_progress
    from unstack.sim.unloading import unload_container

    scene = load_scene(path)
    runs = {}
    policies = container_policies(
        model, seed=options["seed"], samples=options["samples"], makers=makers, disturbance=options["disturbance"],
        occupancy=options["occupancy"],
    )  # fmt: skip
    watch = pick_progress()
    for maker, policy in policies.items():
        if watch is not None:
            watch.pile(path.stem, maker)
        run = unload_container(
            scene, policy, detector_noise=options["detector_noise"], detector_misses=options["detector_misses"],
            reach=options["reach"], max_picks=options["max_picks"], seed=options["seed"],
            probe=maker in PROBING_MAKERS,
        )  # fmt: skip
        runs[maker] = run.to_dict()
    return number, {"scene": path.name, "boxes": len(scene.boxes), "runs": runs}


def _pile_metrics(run: dict[str, Any]) -> dict[str, float]:
    steps = run["steps"]
    return {
        "picks": float(len(steps)),
        "boxes_moved": float(run["boxes_moved"]),
        "boxes_fallen": float(sum(len(step["fallen"]) for step in steps)),
        "calm_picks": float(np.mean([step["boxes_moved"] == 0 for step in steps])) if steps else 1.0,
    }


def _read_by_makers(makers: Sequence[str], occupancy: float | None, disturbance: Any) -> tuple[float | None, Any]:
    """``occupancy`` and ``disturbance``, each None with a warning where no maker named reads it
    (it was recorded among the run's settings and joined its checkpoints' key, unused)."""
    import warnings

    for given, readers, what in (
        (occupancy, OCCUPANCY_MAKERS, f"occupancy {occupancy}"),
        (disturbance, MOVES_MAKERS, "the disturbance model"),
    ):
        if given is not None and not set(readers) & set(makers):
            warnings.warn(
                f"{what} is not used: only {', '.join(readers)} read it, and none of them is among the makers",
                stacklevel=3,
            )
    return (
        occupancy if set(OCCUPANCY_MAKERS) & set(makers) else None,
        disturbance if set(MOVES_MAKERS) & set(makers) else None,
    )


@validate_params({
    "piles": COUNT, "detector_noise": DETECTOR_NOISE, "detector_misses": MISSED_SHARE, "reach": OneOf(REACH_RULES),
    "max_picks": OPTIONAL_COUNT, "samples": COUNT, "seed": SEED, "n_jobs": JOBS, "occupancy": OPTIONAL_SHARE,
})  # fmt: skip
def container_experiment(
    data_dir: str | os.PathLike[str],
    model: Any,
    *,
    piles: int = 2,
    makers: Sequence[str] = DEFAULT_CONTAINER_MAKERS,
    detector_noise: float = 0.0,
    detector_misses: float = 0.0,
    reach: str = "door",
    max_picks: int | None = None,
    samples: int = CONTAINER_SAMPLES,
    seed: int = 0,
    progress: Callable[[int, int], None] | None = None,
    checkpoints: str | os.PathLike[str] | None = None,
    n_jobs: int = 1,
    client: Any = None,
    disturbance: Any = None,
    occupancy: float | None = None,
) -> dict[str, Any]:
    """Empty the first ``piles`` piles of a data set with every decision maker; compare them.

    Returns a JSON-ready dict: the settings, per maker the means per pile (picks, boxes
    moved, boxes fallen, share of calm picks) and boxes moved per pick, the paired
    differences from ``unstack`` (mean and standard error over piles), and every run.
    ``checkpoints``: a folder keeping each pile's result; a run started again with the same
    settings reuses them. ``n_jobs``: piles run in parallel processes; ``client``: on the
    workers of a ``distributed.Client`` instead (the results depend on neither).
    ``disturbance``: the disturbance model of the ``moves`` maker (default: the shipped one).
    ``occupancy``: the ``sampled`` fill's share of unseen space kept solid (default
    :data:`~unstack.sim.belief.OCCUPANCY`).
    """
    import json

    from unstack.atomic import atomic_write_text
    from unstack.dataset_folders import first_configurations, scene_digest
    from unstack.experiments.decisions import paired_difference
    from unstack.experiments.outputs import checkpoint_folder, file_digest, model_digest, stored_result

    container_policies(model, seed=seed, makers=makers)  # unknown makers fail before any work
    occupancy, disturbance = _read_by_makers(makers, occupancy, disturbance)
    if disturbance is not None and not isinstance(disturbance, str | os.PathLike):
        disturbance = disturbance.source  # sent to the workers by path
    if set(MOVES_MAKERS) & set(makers):
        from unstack.learning.disturbance import default_disturbance_path

        disturbance_path = Path(default_disturbance_path() if disturbance is None else disturbance)
        disturbance_digest = file_digest(disturbance_path)
    files = first_configurations(data_dir, piles)
    model_sha256 = model_digest(model)
    settings = {"detector_noise": detector_noise, "detector_misses": detector_misses, "reach": reach,
                "max_picks": max_picks, "samples": samples, "occupancy": occupancy}  # fmt: skip

    def key(number: int, path: Path) -> dict[str, Any]:
        digest = scene_digest(path)
        # detector_misses and occupancy join the key only when set: earlier runs keep their checkpoints
        unset = {"detector_misses": 0.0, "occupancy": None}
        kept = {name: value for name, value in settings.items() if name not in unset or value != unset[name]}
        if set(MOVES_MAKERS) & set(makers):  # the disturbance model joins the key only where it is used
            kept["disturbance_sha256"] = disturbance_digest
        return {"scene_sha256": digest, "model_sha256": model_sha256, "makers": list(makers),
                **kept, "seed": seed + number}  # fmt: skip

    def finished(number: int, path: Path) -> dict[str, Any] | None:
        if folder is None:
            return None
        result = stored_result(folder / f"{path.stem}.json", key(number, path))
        runs = None if result is None else result.get("runs")
        return result if isinstance(runs, dict) and all(isinstance(runs.get(maker), dict) for maker in makers) else None

    with checkpoint_folder(checkpoints) as folder:
        results: list[dict[str, Any] | None] = [finished(number, path) for number, path in enumerate(files)]
        todo = [number for number, result in enumerate(results) if result is None]
        if progress is not None:
            progress(len(files) - len(todo), len(files))
        options = {**settings, "disturbance": None if disturbance is None else str(disturbance)}
        arguments = [(files[number], number, model, makers, {**options, "seed": seed + number}) for number in todo]
        running: Iterator[tuple[int, dict[str, Any]]] = run_unordered(
            _run_pile, arguments, n_jobs=n_jobs, client=client
        )
        for number, pile in running:
            results[number] = pile
            if folder is not None:
                stored = {"key": key(number, files[number]), "result": pile}
                atomic_write_text(folder / f"{files[number].stem}.json", json.dumps(stored) + "\n")
            if progress is not None:
                progress(sum(result is not None for result in results), len(files))
    done = [result for result in results if result is not None]
    metrics = {maker: [_pile_metrics(pile["runs"][maker]) for pile in done] for maker in makers}
    summary = {}
    for maker in makers:
        rows = metrics[maker]
        picks = sum(row["picks"] for row in rows)
        summary[maker] = {
            **{f"{name}_per_pile": float(np.mean([row[name] for row in rows])) for name in rows[0]},
            "boxes_moved_per_pick": float(sum(row["boxes_moved"] for row in rows) / max(picks, 1.0)),
        }
    against_unstack = {}
    if "unstack" in makers:
        for maker in makers:
            if maker == "unstack":
                continue
            against_unstack[maker] = {
                name: paired_difference(
                    np.array([row[name] for row in metrics[maker]]), np.array([row[name] for row in metrics["unstack"]])
                )
                for name in ("boxes_moved", "boxes_fallen")
            }
    return {
        "data": str(data_dir),
        "piles": len(done),
        "seed": seed,
        **settings,
        "makers": list(makers),
        "summary": summary,
        "against_unstack": against_unstack,
        "runs": done,
    }
