"""How much of the hidden pile a belief must know: the belief's pick one pick ahead when the
boxes nobody sees are given to it, all of them or a share of them, at their true poses.

The physics look-ahead knows the true pile; with the boxes the cloud does not show held static
at their true poses it keeps nearly all of its lead (results page, "Where the look-ahead's edge
comes from"). This asks how that lead falls as the belief knows fewer of them. Each development
pile is emptied highest first (:func:`unstack.sim.unloading.unload_container` with the true
outcome of every candidate probed); in every state the belief world holds the boxes in view
and each box nobody sees with chance ``q``, at their true poses, free to move, of the typical
mass, nothing else (drawn anew in each of ``--worlds`` worlds; ``q`` = 1 and 0 are one world;
the oracle ``rebuilt_typical`` of the results page is ``q`` = 1 in the closed loop). Printed
per ``q``: the boxes the belief's fewest and height vetoed by it would have moved, summed over
the states, beside highest first and the look-ahead.

Usage::

    python benchmarks/occupancy_knowledge.py d10-four --piles 3
"""

from __future__ import annotations

import dataclasses

import numpy as np
from script_arguments import data_sets_parser

from unstack.dataset_folders import require_configurations
from unstack.geometry import bounding_boxes
from unstack.scene import Scene, load_scene
from unstack.sim.belief import belief_settings, choose_by_expected_moves, removals_in_world
from unstack.sim.unloading import in_view_scene, unload_container

SHARES = (1.0, 0.75, 0.5, 0.25, 0.0)


def _knowing(current: Scene, believed: Scene, hidden: list[str]) -> Scene:
    """The belief's scene with the boxes ``hidden`` given to it at their true poses, free to move."""
    known = set(believed.detected) | set(hidden)
    return dataclasses.replace(believed, detected=tuple(box_id for box_id in current.box_ids if box_id in known))


def pile_states(path: str, worlds: int, seed: int) -> list[dict[str, int]]:
    """Boxes moved by each rule's pick in every state of one pile emptied highest first."""
    scene = load_scene(path)
    rng = np.random.default_rng(seed)
    states: list[dict[str, int]] = []

    def policy(current: Scene, outcomes: dict) -> str:  # type: ignore[type-arg]
        believed = in_view_scene(current)
        settings = belief_settings(believed)
        hidden = [box_id for box_id in current.box_ids if box_id not in set(believed.detected)]
        resting = {box_id: float(bounding_boxes([current.box(box_id)])[0, 2]) for box_id in current.detected}
        highest = max(current.detected, key=lambda box_id: (resting[box_id], box_id))
        state = {"highest": outcomes[highest].boxes_moved}
        truth = {box_id: float(outcomes[box_id].boxes_moved) for box_id in current.detected}
        state["lookahead"] = outcomes[choose_by_expected_moves(truth, resting, "fewest")].boxes_moved
        for share in SHARES:
            count = 1 if share in (0.0, 1.0) else worlds
            drawn = [[box_id for box_id in hidden if rng.random() < share] for _ in range(count)]
            runs = [
                removals_in_world(_knowing(current, believed, kept), [], list(current.detected), settings, None, 0)
                for kept in drawn
            ]
            expected = {box_id: float(np.mean([len(run[box_id]) for run in runs])) for box_id in current.detected}
            for rule in ("fewest", "veto"):
                state[f"{rule} q={share:g}"] = outcomes[choose_by_expected_moves(expected, resting, rule)].boxes_moved
        states.append(state)
        return highest

    unload_container(scene, policy, seed=seed, probe=True)
    return states


def main() -> None:
    parser = data_sets_parser(__doc__.splitlines()[0], piles=3, several=False)
    parser.add_argument("--worlds", type=int, default=2)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    states: list[dict[str, int]] = []
    for number, path in enumerate(require_configurations(args.data)[: args.piles]):
        states += pile_states(str(path), args.worlds, args.seed + number)
        print(f"pile {number}: {len(states)} states so far", flush=True)
    totals = {rule: sum(state[rule] for state in states) for rule in states[0]}
    print(f"{args.data}, {len(states)} states: highest first {totals['highest']}, look-ahead {totals['lookahead']}")
    for share in SHARES:
        print(f"  hidden boxes known with chance {share:g}: fewest {totals[f'fewest q={share:g}']}, "
              f"height vetoed {totals[f'veto q={share:g}']}")  # fmt: skip


if __name__ == "__main__":
    main()
