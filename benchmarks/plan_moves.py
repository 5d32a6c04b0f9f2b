"""Unloading plans with different re-insertions per sweep: seconds, standard errors, order.

Two scenes: ``examples/pile31.supports.json`` and 40 boxes in 8 dense groups of 5 linked by
1e-3 (:func:`weak_links.weak_groups`, seed 0). For each value of
:data:`unstack.reasoner.sampling.MOVES` (``64``: every box, the sweep before 2026-12-02) the
plan (``unstack.plan(supports, seed=3, samples=...)``, ``--samples`` sweeps a step) runs
twice in this process (the first plan of the run, which loads the compiled kernels, is not
timed), and the largest EC standard error of a step, the smallest probability that a step's
choice is the best, and the first picks are printed.

Usage::

    python benchmarks/plan_moves.py --moves 64,8 --samples 1024,2048   # before / since 2026-12-02
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from weak_links import weak_groups

import unstack
import unstack.reasoner.sampling as sampling
from unstack.supports import Supports, load_supports

REPO = Path(__file__).resolve().parents[1]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--moves", type=lambda text: [int(v) for v in text.split(",")], default=[64, 8])
    parser.add_argument(
        "--samples",
        type=lambda text: [int(v) for v in text.split(",")],
        default=None,
        help="sweeps per step for each --moves value (default: the library's PLAN_SAMPLES)",
    )
    parser.add_argument("--repeat", type=int, default=2)
    args = parser.parse_args()
    scenes = {
        "pile31": load_supports(REPO / "examples" / "pile31.supports.json"),
        "weak40": Supports([f"b{i:02d}" for i in range(40)], weak_groups(8, 5, 1e-3, 0)),
    }
    unstack.plan(scenes["pile31"], seed=3)  # load the compiled kernels
    default_moves = sampling.MOVES
    budgets = args.samples or [None] * len(args.moves)
    for moves, samples in zip(args.moves, budgets, strict=True):
        sampling.MOVES = moves
        for name, supports in scenes.items():
            for _ in range(args.repeat):
                start = time.perf_counter()
                plan = unstack.plan(supports, seed=3, samples=samples)
                seconds = time.perf_counter() - start
                errors = [
                    float(np.max(step.decision.expected_cost_errors))
                    for step in plan.steps
                    if step.decision.expected_cost_errors is not None
                ]
                print(
                    f"moves {moves}, {samples or 'default'} sweeps, {name}: {seconds:.2f} s, "
                    f"largest EC s.e. {max(errors, default=0.0):.4f}, "
                    f"smallest P(choice) {min(step.decision.choice_probability for step in plan.steps):.2f}, "
                    f"first picks {[step.choice for step in plan.steps][:6]}",
                    flush=True,
                )
    sampling.MOVES = default_moves


if __name__ == "__main__":
    main()
