"""How long physics on the belief takes per decision, beside the load cost, for 5 and 40 detected boxes.

A robot's pick takes about 4-5 s; the decision must take under 1 s median for 40 detected
boxes and under 50 ms for 5 (issue 34, part 3). Each scene is a simulated pile with its own
cloud; the first ``N`` boxes (by the pile's order) are taken as detected, every one a
candidate. ``belief_removals`` (4 belief worlds, every candidate tried) and ``unstack.decide``
with the load cost are timed alternately on the same scenes after one warm-up call each; the
script prints medians and the ratio belief / load.

Usage::

    python benchmarks/belief_speed.py t30-dropped --piles 3 --repeat 2 --sizes 5,30 \\
        --json benchmarks/results/belief-speed.json

``t30-dropped`` is made by::

    unstack simulate --configs 30 --seed 8808 --out t30-dropped
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from alternating import compare_by_size

import unstack
from unstack.sim.belief import belief_removals

if __name__ == "__main__":
    calls = {"belief": lambda scene: belief_removals(scene), "load": lambda scene: unstack.decide(scene, seed=0)}
    compare_by_size(__doc__.splitlines()[0], calls, piles=3, repeat=2)
