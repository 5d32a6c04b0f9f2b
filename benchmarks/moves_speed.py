"""How long a decision on the moves cost takes, beside the load cost, for 5 and 40 detected boxes.

A robot's pick takes about 4-5 s; the decision must take under 1 s median for 40 detected
boxes and under 50 ms for 5. Each scene is a simulated pile with its own cloud; the first
``N`` boxes (by the pile's order) are taken as detected. Both costs are timed alternately on
the same scenes after one warm-up call each, ``--repeat`` calls per scene and cost; the
script prints medians and the ratio moves / load.

Usage::

    python benchmarks/moves_speed.py fresh30-dropped --piles 5 --repeat 5 --sizes 5,40 \\
        --json benchmarks/results/moves-speed.json

``fresh30-dropped`` (the results page's set) is made by::

    unstack simulate --family dropped --configs 30 --seed 9001 --viewpoint-jitter 0.3 --out fresh30-dropped
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from alternating import compare_by_size

import unstack

if __name__ == "__main__":
    calls = {cost: (lambda scene, cost=cost: unstack.decide(scene, cost=cost, seed=0)) for cost in ("moves", "load")}
    compare_by_size(__doc__.splitlines()[0], calls, piles=5, repeat=5)
