"""The exact engine's last two levels: transforms (``collapse=2``) against the pair sum (``collapse=1``).

Times a sample of the parallel tasks of one dense instance (pairs ``U(0.05, 0.95)``, seed 0)
with both ways of finishing the walk, alternated in one process, in CPU seconds of one
thread (run it with ``NUMBA_NUM_THREADS=1`` so nothing else runs in parallel). Both ways
must give the same subtree sums; the script checks that before it reports.

Usage::

    NUMBA_NUM_THREADS=1 python benchmarks/two_levels.py --boxes 9 --stride 25   # 15 of 355 tasks
    NUMBA_NUM_THREADS=1 python benchmarks/two_levels.py --boxes 8 --stride 1    # every task
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from unstack.reasoner import _insertion_kernels as kernels
from unstack.reasoner import marginals
from unstack.reasoner.consistency import PREORDER_COUNTS

DEPTH = 4


def time_tasks(n: int, stride: int, rounds: int) -> dict[int, list[float]]:
    """CPU seconds of every ``stride``-th task at depth 4, per collapse, ``rounds`` times each."""
    p = np.random.default_rng(0).uniform(0.05, 0.95, (n, n))
    np.fill_diagonal(p, 0.0)
    tables = marginals._level_weights(p)
    small = np.ascontiguousarray(p[:6, :6])
    marginals._compiled_marginals(small, 1)  # load both compiled ways
    marginals._compiled_marginals(small, 2)
    tasks = kernels.collect_tasks(n, DEPTH, PREORDER_COUNTS[DEPTH], *tables)
    sample = [column[::stride] for column in tasks[:5]]
    seconds: dict[int, list[float]] = {1: [], 2: []}
    sums: dict[int, np.ndarray] = {}
    for _ in range(rounds):
        for collapse in (1, 2):
            start = time.process_time()
            sums[collapse] = np.array(
                [kernels.run_task(t, n, DEPTH, collapse, False, *sample, *tables)[0] for t in range(len(sample[0]))]
            )
            seconds[collapse].append(time.process_time() - start)
    np.testing.assert_allclose(sums[2], sums[1], rtol=1e-10)
    return seconds


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--boxes", type=int, default=8, help="boxes of the dense instance (default 8)")
    parser.add_argument("--stride", type=int, default=1, help="time every STRIDE-th task (default: all)")
    parser.add_argument("--rounds", type=int, default=2, help="alternations of the two ways (default 2)")
    args = parser.parse_args()
    seconds = time_tasks(args.boxes, args.stride, args.rounds)
    tasks = len(range(0, PREORDER_COUNTS[DEPTH], args.stride))
    old, new = min(seconds[1]), min(seconds[2])
    print(f"n = {args.boxes}, {tasks} of {PREORDER_COUNTS[DEPTH]} tasks: pair sum {old:.2f} s, transforms {new:.2f} s")
    print(f"speed-up {old / new:.1f} (best of {args.rounds}, CPU seconds)")


if __name__ == "__main__":
    main()
