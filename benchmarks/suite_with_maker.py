"""The generalisation suite's first picks made by a container maker instead of the decision's.

``unstack experiment generalisation`` checks the decision's own pick (or the minimum EC (Eq. 12), or the
hybrid's); a maker of :mod:`unstack.experiments.container` such as ``hybrid_faces_free`` (the
hybrid vetoed by physics on the belief) runs the engine and is not one of its ``--pick`` choices.
This runs the same canonical scenes (every kind, seeds ``--first-seed`` onwards, both clouds)
with the maker's pick and the default decision's expected costs, and prints the right first
picks per kind and cloud, the total, and every wrong pick.

Usage::

    python benchmarks/suite_with_maker.py hybrid_faces_free --seeds 10 --first-seed 30
"""

from __future__ import annotations

import argparse
import dataclasses
from typing import Any

import unstack
from unstack.api import load_model
from unstack.experiments.container import CONTAINER_MAKERS, ORACLE_MAKERS, PROBING_MAKERS, container_policies
from unstack.experiments.generalisation import run_suite, summary_rows
from unstack.scene import Scene


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    robot_makers = [maker for maker in CONTAINER_MAKERS if maker not in ORACLE_MAKERS + PROBING_MAKERS]
    parser.add_argument(
        "maker", choices=robot_makers, metavar="MAKER", help="a container maker that sees what a robot does"
    )
    parser.add_argument("--seeds", type=int, default=10, help="seeds per kind and cloud (default 10)")
    parser.add_argument("--first-seed", type=int, default=30, help="the first seed (default 30)")
    arguments = parser.parse_args()
    if arguments.seeds < 1:
        parser.error("--seeds must be at least 1")
    policy = container_policies(load_model(None), seed=0, makers=(arguments.maker,))[arguments.maker]

    def decide(scene: Scene) -> Any:
        return dataclasses.replace(unstack.decide(scene, seed=0), choice=policy(scene))

    seeds = range(arguments.first_seed, arguments.first_seed + arguments.seeds)
    results = run_suite(decide, seeds=list(seeds))
    for row in summary_rows(results):
        print(f"{row['kind']:<20} {row['cloud']:<8} right first pick {row['right_pick']} of {row['scenes']}")
    right = sum(result.choice in result.pickable for result in results)
    print(f"{arguments.maker}: right first pick {right} of {len(results)}")
    for result in results:
        if result.choice not in result.pickable:
            where = f"{result.kind} seed {result.seed} {result.cloud}"
            print(f"wrong: {where}: {result.choice} (pickable {result.pickable})")


if __name__ == "__main__":
    main()
