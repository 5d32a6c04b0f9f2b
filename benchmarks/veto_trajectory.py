"""Along the states a policy reached itself, what the default's pick would have moved there.

Reads a collection of ``unstack experiment pick-responses --behaviour MAKER`` (every candidate
of every state probed in the engine on the true pile) and, state by state, compares the box the
policy took (the one gone in the next state) with the default's pick on the same state (the
highest box the reasoner believes holds nothing up) and with the fewest any candidate moves
(the look-ahead's). Printed per data set, per pile: states, the states where the policy
departed from the default, and the boxes moved one pick ahead, summed over the pile, by the
default's picks, by the policy's own picks and by the fewest.

A policy whose departures save boxes one pick ahead yet moves as many over the pile as the
default on its own states (``unstack experiment container ... --makers unstack,MAKER``) has
led the pile into states where the default's picks would move more: what it saves comes back.

Usage::

    unstack experiment pick-responses dag-four --out states --behaviour hybrid_moves_free_1
    python benchmarks/veto_trajectory.py states --jobs 2
"""

from __future__ import annotations

import argparse
import itertools
import sys
from pathlib import Path

import numpy as np


def pile_rows(folder: Path) -> tuple[str, np.ndarray]:
    """Per state followed by a pick: boxes moved by the default's pick, by the pick taken,
    whether the two differ, and the fewest any candidate moves."""
    from unstack.experiments.container import CONTAINER_SAMPLES
    from unstack.experiments.pick_responses import load_states
    from unstack.height_veto import free_highest
    from unstack.learning.model_file import default_model_path, load_model
    from unstack.pipeline import scene_support_probabilities
    from unstack.reasoner.decision import decide

    model = load_model(default_model_path())
    states = list(load_states(folder))
    rows = []
    for (header, scene), (_, after) in itertools.pairwise(states):
        gone = set(scene.box_ids) - set(after.box_ids)
        if len(gone) != 1:  # a box lost below the floor with the pick: the pick is not known
            continue
        taken = gone.pop()
        decision = decide(scene_support_probabilities(scene, model), cost="load", samples=CONTAINER_SAMPLES, seed=0)
        default = str(free_highest(decision, scene).choice)
        moved = {box_id: len(boxes) for box_id, boxes in header["moved"].items()}
        rows.append((moved[default], moved[taken], float(default != taken), min(moved.values())))
    return folder.parent.name, np.array(rows, dtype=np.float64).reshape(-1, 4)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("states", type=Path, help="a collection of unstack experiment pick-responses")
    parser.add_argument("--jobs", type=int, default=1)
    args = parser.parse_args()
    from joblib import Parallel, delayed

    folders = sorted(path.parent for path in args.states.glob("*/*/done.json"))
    if not folders:
        print(f"veto_trajectory.py: error: {args.states}: no collected piles", file=sys.stderr)
        sys.exit(2)
    results = Parallel(n_jobs=args.jobs)(delayed(pile_rows)(folder) for folder in folders)
    per_set: dict[str, list[np.ndarray]] = {}
    for data_set, rows in results:
        per_set.setdefault(data_set, []).append(rows)
    for data_set, piles in sorted(per_set.items()):
        sums = np.array([rows.sum(axis=0) if len(rows) else np.zeros(4) for rows in piles])
        states = np.mean([len(rows) for rows in piles])
        print(f"{data_set}: {len(piles)} piles, {states:.1f} states a pile; per pile: departures from the default "
              f"{sums[:, 2].mean():.2f}; boxes moved one pick ahead by the default's picks {sums[:, 0].mean():.2f}, "
              f"by the picks taken {sums[:, 1].mean():.2f}, by the fewest {sums[:, 3].mean():.2f}")  # fmt: skip


if __name__ == "__main__":
    main()
