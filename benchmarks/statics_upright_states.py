"""What statics' rule for upright boxes finds in the closed loop's probed states, and what it changes.

For every state of a pick-responses collection (``unstack experiment pick-responses``: every
candidate's removal probed in the engine), :func:`unstack.understanding.statics.tip_supports` is
run with the rule for upright boxes (:data:`~unstack.understanding.statics.UPRIGHT_OVERHANG`) and
without it (the bound set to infinity): the pairs only the rule finds, how many of them are right
where the supporter was probed (its removal moved the held box), and where the default decision's
pick changes, what each pick moved.

Usage::

    python benchmarks/statics_upright_states.py states/train-four states/dag-four
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import unstack
import unstack.understanding.statics as statics
from unstack.experiments.pick_responses import load_states


def _found(scene: unstack.Scene, bound: float) -> set[tuple[str, str]]:
    statics.UPRIGHT_OVERHANG = bound  # a script's own process: the module's bound set for the comparison
    return {(finding.held, finding.supporter) for finding in statics.tip_supports(scene)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("collections", nargs="+", type=Path, help="folders DATA-SET of a pick-responses collection")
    args = parser.parse_args()
    bound = statics.UPRIGHT_OVERHANG
    for folder in args.collections:
        states = with_new = pairs = right = changed = 0
        for pile in sorted(path for path in folder.iterdir() if path.is_dir()):
            for header, scene in load_states(pile):
                states += 1
                added = _found(scene, bound) - _found(scene, math.inf)
                if not added:
                    continue
                with_new += 1
                pairs += len(added)
                moved = header["moved"]
                right += sum(held in moved.get(supporter, ()) for held, supporter in added)
                picks = {}
                for limit in (bound, math.inf):
                    statics.UPRIGHT_OVERHANG = limit
                    picks[limit] = unstack.decide(scene, seed=0).choice
                statics.UPRIGHT_OVERHANG = bound
                if picks[bound] != picks[math.inf]:
                    changed += 1
                    before, after = (
                        len(moved[pick]) if pick in moved else "?" for pick in (picks[math.inf], picks[bound])
                    )
                    print(
                        f"  {pile.name} step {header['step']}: "
                        f"{picks[math.inf]} ({before} moved) -> {picks[bound]} ({after})"
                    )
        print(
            f"{folder}: {states} states, {with_new} with pairs only the rule finds ({pairs} pairs, {right} right where "
            f"the supporter was probed), {changed} picks changed",
            flush=True,
        )


if __name__ == "__main__":
    main()
