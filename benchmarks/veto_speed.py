"""How long height vetoed by a belief takes per pick, beside the load cost.

The container maker ``belief_occlusion_veto`` (:mod:`unstack.experiments.container`): the
highest box unless physics on the belief with the unseen space filled expects its removal to
move a box, then the belief's fewest among the boxes unstack's reasoner believes free; or
another maker of that module named by ``--maker`` (``belief_scaled_veto``: the unseen space
sampled in four worlds, every candidate tried when the highest box is vetoed). A
robot's pick takes about 4-5 s; the decision must take under 1 s median for 40 detected boxes
and under 50 ms for 5 (issue 34, part 3). The first ``N`` boxes of each simulated pile are
taken as detected (and as the boxes in view); the maker and ``unstack.decide`` with the load
cost are timed alternately on the same scenes after one warm-up call each. ``load`` is
unstack's default decision on a scene (``unstack.decide(scene)``); ``--maker unstack`` times it
beside the container maker of the same name (the same rule with the container runs' sample
budget), the cheapest companion when the default alone is wanted.

Usage::

    python benchmarks/veto_speed.py f30-stacked --piles 6 --repeat 2 --sizes 5,15
    python benchmarks/veto_speed.py f30-stacked --piles 6 --repeat 2 --sizes 5,15 --maker belief_scaled_veto
    python benchmarks/veto_speed.py f30-four --piles 6 --repeat 2 --sizes 5,20 --maker unstack

``f30-stacked`` is made by::

    unstack simulate --family stacked --configs 30 --seed 9191 --viewpoint-jitter 0.3 --out f30-stacked
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from alternating import compare_by_size

import unstack
from unstack.api import load_model
from unstack.experiments.container import container_policies

if __name__ == "__main__":
    chooser = argparse.ArgumentParser(add_help=False)
    chooser.add_argument("--maker", default="belief_occlusion_veto")
    chosen, rest = chooser.parse_known_args()
    sys.argv[1:] = rest  # the rest is compare_by_size's
    veto = container_policies(load_model(None), seed=0, makers=(chosen.maker,))[chosen.maker]
    calls = {chosen.maker: veto, "load": lambda scene: unstack.decide(scene, seed=0)}
    compare_by_size(__doc__.splitlines()[0], calls, piles=6, repeat=2)
